//! Step cutback of the implicit substep. A backward Euler substep that
//! fails (its Newton solve does not converge, or its result moves a vertex
//! more than one cell, the gather's advection check) is undone and run
//! again as two substeps of half the size, each under the same rule, at
//! most [`MAX_CUTBACKS`] halvings deep. A substep longer than the advection
//! limit of the state it starts from (`timestep::implicit_auto_dt` at
//! safety 1: the fastest particle, sped up by gravity over the substep,
//! would pass a cell) is halved without being tried, so a failed solve is
//! not paid for a step that the speeds already rule out. This is the automatic incrementation
//! of implicit finite-element codes (cut the increment back when Newton
//! does not converge) with the advection limit of CFL-rate implicit MPM
//! (Wang et al. 2020, "Hierarchical optimization time integration for
//! CFL-rate MPM stepping") as the second criterion. Each outer substep
//! starts again from its full size: the choice depends on the state only,
//! so the same inputs give the same substeps (and bits) for any thread
//! count, and a saved state needs nothing more.
//!
//! **Energy.** Under the grid integrator (`"implicit"`) a substep is also
//! undone when it raises the total energy (kinetic, elastic and
//! gravitational, [`YarnSim::diagnostics`]) by more than [`ENERGY_TOL`]
//! of the kinetic and elastic energy it starts from plus the work gravity
//! does over it. Backward Euler on a convex energy, inelastic contact,
//! friction and plasticity only take energy out; what puts it in is a
//! first-order splitting taken at too large a step (the contact's
//! friction acting on the solved velocities, the cross-sections advected
//! by the velocity gradient it leaves), whose error shrinks as `dt^2`.
//! A substep that still raises it at the deepest cutback is kept and
//! counted (`ImplicitStats::energy_kept`, the largest such rise
//! `max_energy_kept`): a rise that `dt / 32` does not remove is not the
//! step size's (measured on the reference bundle: +4.97 J at dt 8.2e-5
//! at k 1e5, the vertices pressed into a circle by the yarns above them,
//! see docs/yarn-integrators.md). Not checked where a force outside the ledger does
//! work (the attractor on, or a pin that moves), nor on the first substep
//! of a new, loaded or edited state.
//!
//! The explicit integrator has no cutback: there a failed substep is a
//! diverging run, and the stable step is known before it.

use super::stats::DtStats;
use super::{SimError, YarnSim};
use crate::math::Vec2;
use crate::mpm::driver::timestep::implicit_auto_dt;
use crate::mpm::machinery::particles::Particles;

/// Most halvings of one implicit substep: down to `dt / 32`.
pub const MAX_CUTBACKS: u32 = 5;

/// The most a grid implicit substep may raise the total energy, as a share
/// of the kinetic and elastic energy at its start plus the work of gravity
/// over it (see the module documentation).
pub const ENERGY_TOL: f64 = 1e-2;

/// The energy ledger of a state: kinetic plus elastic, and gravitational
/// potential, J.
#[derive(Clone, Copy, Debug)]
struct Ledger {
    inner: f64,
    potential: f64,
}

impl Ledger {
    fn of(sim: &YarnSim) -> Self {
        let d = sim.diagnostics();
        Ledger {
            inner: d.kinetic_energy + d.elastic_energy,
            potential: d.potential_energy,
        }
    }

    /// The rise of the total energy from `self` to `after` and the most
    /// a substep may make ([`ENERGY_TOL`], with a round-off floor of 1e-12
    /// of the energies).
    fn rise(&self, after: &Ledger) -> (f64, f64) {
        let rise = (after.inner + after.potential) - (self.inner + self.potential);
        let work = (after.potential - self.potential).abs();
        let scale = self.inner + work;
        let floor = 1e-12 * (self.inner + self.potential.abs() + after.inner);
        (rise, ENERGY_TOL * scale + floor)
    }
}

/// What a failed substep may have changed and a retry needs back (the grids
/// are rebuilt by every substep; the cost counters keep the failed work).
struct Checkpoint {
    particles: Particles,
    pin_reactions: Vec<Vec2>,
    time: f64,
    steps: u64,
    dt_stats: DtStats,
    frames_stale: bool,
}

impl Checkpoint {
    fn of(sim: &YarnSim) -> Self {
        Checkpoint {
            particles: sim.particles.clone(),
            pin_reactions: sim.pin_reactions.clone(),
            time: sim.time,
            steps: sim.steps,
            dt_stats: sim.dt_stats,
            frames_stale: sim.frames_stale,
        }
    }

    fn restore(self, sim: &mut YarnSim) {
        sim.particles = self.particles;
        sim.pin_reactions = self.pin_reactions;
        sim.time = self.time;
        sim.steps = self.steps;
        sim.dt_stats = self.dt_stats;
        sim.frames_stale = self.frames_stale;
        sim.failed = None;
    }
}

impl YarnSim {
    /// [`YarnSim::step_dt`] on this thread: one substep of `dt`, under the
    /// implicit integrator with cutbacks; the clock then reads `t + dt`
    /// however it was divided.
    pub(super) fn substep(&mut self, dt: f64) -> Result<(), SimError> {
        if let Some(e) = &self.failed {
            return Err(e.clone());
        }
        if !(dt.is_finite() && dt > 0.0) {
            return Err(SimError::BadInput(format!(
                "substep dt {dt} must be finite and > 0"
            )));
        }
        if !self.is_implicit() {
            return self.substep_once(dt);
        }
        let end = self.time + dt;
        self.cut(dt, 0)?;
        self.time = end;
        Ok(())
    }

    /// `dt` at cutback depth `depth`: as one substep, or, when that fails
    /// and `depth < MAX_CUTBACKS`, as two halves.
    fn cut(&mut self, dt: f64, depth: u32) -> Result<(), SimError> {
        if depth == MAX_CUTBACKS {
            let ledger = self.energy_checked().then(|| Ledger::of(self));
            self.substep_once(dt).map_err(|e| self.exhausted(e, dt))?;
            if let Some(l) = ledger {
                let (rise, tol) = l.rise(&Ledger::of(self));
                if rise > tol {
                    // not the step size's: kept, and counted
                    let st = &mut self.implicit_stats;
                    st.energy_kept += 1;
                    st.max_energy_kept = st.max_energy_kept.max(rise);
                }
            }
            return Ok(());
        }
        if self.is_gridless() || dt <= self.advection_limit() {
            let keep = Checkpoint::of(self);
            let ledger = self.energy_checked().then(|| Ledger::of(self));
            match self.substep_once(dt) {
                Err(SimError::NonFinite { .. }) => {
                    keep.restore(self);
                    self.implicit_stats.undone += 1;
                }
                Ok(())
                    if ledger.is_some_and(|l| {
                        let (rise, tol) = l.rise(&Ledger::of(self));
                        rise > tol
                    }) =>
                {
                    keep.restore(self);
                    self.implicit_stats.undone += 1;
                    self.implicit_stats.energy_cuts += 1;
                }
                r => return r,
            }
        }
        let st = &mut self.implicit_stats;
        st.cutbacks += 1;
        st.deepest_cut = st.deepest_cut.max(depth + 1);
        self.cut(0.5 * dt, depth + 1)?;
        self.cut(0.5 * dt, depth + 1)
    }

    /// The longest substep from this state whose fastest particle, sped up
    /// by gravity over it, moves at most one cell.
    fn advection_limit(&self) -> f64 {
        let (dx, g) = (self.grid_geom().dx, self.gravity().norm());
        implicit_auto_dt(dx, self.max_speed(), g, 1.0)
    }

    /// Whether this substep's energy is checked: the grid implicit
    /// integrator, with no attractor on and no pin that moves (their work
    /// is not in the ledger), and not the first substep of a new, loaded or
    /// edited state (`frames_stale`): that one re-derives the quadrature
    /// particles from the vertices, a change of the ledger that does not
    /// shrink with dt (measured on the capstan of `testing::capstan_toml`:
    /// +1.48e-5 J at dt 1e-3, 1e-4 and 1e-5, explicit and implicit alike).
    fn energy_checked(&self) -> bool {
        use crate::mpm::PinMotion;
        let still = |m: &PinMotion| match m {
            PinMotion::Fixed => true,
            PinMotion::Input { velocity, .. } => *velocity == Vec2::zeros(),
            _ => false,
        };
        self.is_implicit()
            && !self.is_gridless()
            && !self.frames_stale
            && !self.passes().attractor
            && self.pins.iter().all(|p| still(&p.motion))
    }

    /// The error of a substep that failed at the deepest cutback, saying so.
    fn exhausted(&mut self, e: SimError, dt: f64) -> SimError {
        let e = match e {
            SimError::NonFinite { step, time, what } => SimError::NonFinite {
                step,
                time,
                what: format!(
                    "{what} (after {MAX_CUTBACKS} cutbacks of the implicit substep, to dt {dt:.3e} s)"
                ),
            },
            e => e,
        };
        self.failed = Some(e.clone());
        e
    }
}
