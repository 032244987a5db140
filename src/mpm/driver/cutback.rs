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
//! **Stretch.** Under the same conditions and `dt = "auto"` a substep is
//! also undone when it takes a segment's stretch `|x_r - x_l| / l0` out
//! of the band `1 +- w` that the scene's fibre stiffness implies ([`stretch_band`]:
//! the strain `v / c` of a yarn stopped from [`IMPACT_SPEED`], `c =
//! sqrt(k / rho)` its fibre wave speed, at least [`STRETCH_FLOOR`]), or
//! further out than the farthest segment at its start. At the deepest
//! cutback such a substep is refused ([`SimError::Refused`], naming
//! `time.integrator` and `material.k`). A fixed `dt` is not checked: its
//! runs keep every bit.
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

/// Speed of the fall from which [`stretch_band`] takes its strain, m/s:
/// `sqrt(2 g h)` for a drop of h = 0.5 m at g = 9.8 m/s^2 (half the
/// built-in scenes' 1 m domain; the reference bundle lands at about
/// 1.1 m/s).
pub const IMPACT_SPEED: f64 = 3.13;

/// The narrowest half-width of [`stretch_band`]: 1 % strain.
pub const STRETCH_FLOOR: f64 = 1e-2;

/// Half-width `w` of the band `[1 - w, 1 + w]` of segment stretch that a
/// grid implicit substep must keep, for fibre stiffness `k` (N/m) and
/// density `rho` (kg/m^2): the strain `v / c` of a bar stopped from speed
/// `v` = [`IMPACT_SPEED`], `c = sqrt(k / rho)` its longitudinal wave speed
/// (the elastic bar's impact, Timoshenko and Goodier, "Theory of
/// Elasticity", 3rd ed. 1970, §154: the stress `rho c v` of the wave front),
/// at least [`STRETCH_FLOOR`]. The reference material (rho 1): 0.099 at
/// k 1e3, 0.0099 -> 0.01 at k 1e5 and above. Infinite at `k = 0`.
pub fn stretch_band(k: f64, rho: f64) -> f64 {
    if k > 0.0 {
        (IMPACT_SPEED * (rho / k).sqrt()).max(STRETCH_FLOOR)
    } else {
        f64::INFINITY
    }
}

/// The farthest any segment's stretch is from 1, and which segment.
fn stretch_deviation(sim: &YarnSim) -> (f64, usize, f64) {
    let mut out = (0.0, 0, 1.0);
    for (i, s) in sim.stretches().into_iter().enumerate() {
        if (s - 1.0).abs() > out.0 {
            out = ((s - 1.0).abs(), i, s);
        }
    }
    out
}

/// What a checked substep may do to the segments' stretch: leave it within
/// the band `1 +- w` ([`stretch_band`]) or, where a segment started out of
/// it, no farther out than the farthest did.
#[derive(Clone, Copy, Debug)]
struct StretchGuard {
    w: f64,
    allowed: f64,
}

impl StretchGuard {
    fn of(sim: &YarnSim) -> Self {
        let m = &sim.scene.material;
        let w = stretch_band(m.k, m.density);
        StretchGuard {
            w,
            allowed: w.max(stretch_deviation(sim).0),
        }
    }

    /// `Err((segment, stretch))`: the segment farthest out of what the
    /// guard allows after the substep.
    fn check(&self, sim: &YarnSim) -> Result<(), (usize, f64)> {
        if !self.allowed.is_finite() {
            return Ok(());
        }
        let (d, i, s) = stretch_deviation(sim);
        if d > self.allowed {
            Err((i, s))
        } else {
            Ok(())
        }
    }
}

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
            let (ledger, guard) = self.checks();
            let keep = guard.is_some().then(|| Checkpoint::of(self));
            self.substep_once(dt).map_err(|e| self.exhausted(e, dt))?;
            if let (Some(g), Some(keep)) = (guard, keep) {
                if let Err((i, s)) = g.check(self) {
                    // refused: the state stays the one before it
                    keep.restore(self);
                    return Err(self.out_of_band(g, i, s, dt));
                }
            }
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
            let (ledger, guard) = self.checks();
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
                Ok(()) if guard.is_some_and(|g| g.check(self).is_err()) => {
                    keep.restore(self);
                    self.implicit_stats.undone += 1;
                    self.implicit_stats.stretch_cuts += 1;
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

    /// The refusal of a substep that took segment `i`'s stretch to `s`,
    /// out of what `guard` allows, at the deepest cutback (`dt` long),
    /// recorded in `failed`; the state is the one before it.
    fn out_of_band(&mut self, guard: StretchGuard, i: usize, s: f64, dt: f64) -> SimError {
        let m = &self.scene.material;
        let e = SimError::Refused {
            step: self.steps,
            time: self.time,
            what: format!(
                "under time.integrator = \"implicit\" with time.dt = \"auto\", segment {i}'s \
                 stretch {s:.4} leaves the band [{:.4}, {:.4}] that material.k = {} (density {}) \
                 allows (the strain of a yarn stopped from {IMPACT_SPEED} m/s, at least 1 %), even \
                 after {MAX_CUTBACKS} cutbacks of the substep, to dt {dt:.3e} s; a softer \
                 material.k, time.integrator = \"explicit\", or a fixed time.dt runs it",
                1.0 - guard.w,
                1.0 + guard.w,
                m.k,
                m.density,
            ),
        };
        self.failed = Some(e.clone());
        e
    }

    /// What a substep from this state is checked against: the energy
    /// ledger where its energy is checked (`energy_checked`), and the
    /// stretch guard ([`StretchGuard`]) where, besides, `dt = "auto"` (a
    /// fixed `dt` is the user's choice, run as it was).
    fn checks(&self) -> (Option<Ledger>, Option<StretchGuard>) {
        if !self.energy_checked() {
            return (None, None);
        }
        let guard = self
            .scene
            .time
            .dt
            .fixed()
            .is_none()
            .then(|| StretchGuard::of(self));
        (Some(Ledger::of(self)), guard)
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The band is the bar-impact strain `v / c`, `c = sqrt(k / rho)`:
    /// for the reference material (rho 1 kg/m^2) at k 1e3, `c` = 31.62
    /// m/s and `w` = 3.13 / 31.62 = 0.0990 (1e-12); at k 1e5 and 1e7 the
    /// strain (0.0099, 0.00099) is below the 1 % floor; no band at k = 0;
    /// a 4x denser yarn has half the wave speed and twice the strain.
    #[test]
    fn the_stretch_band_is_the_impact_strain_floored_at_one_percent() {
        let c = (1e3f64 / 1.0).sqrt();
        assert!((stretch_band(1e3, 1.0) - IMPACT_SPEED / c).abs() < 1e-12);
        assert!((stretch_band(1e3, 1.0) - 0.0990).abs() < 1e-4);
        assert_eq!(stretch_band(1e5, 1.0), STRETCH_FLOOR);
        assert_eq!(stretch_band(1e7, 1.0), STRETCH_FLOOR);
        assert!(stretch_band(0.0, 1.0).is_infinite());
        let ratio = stretch_band(1e3, 4.0) / stretch_band(1e3, 1.0);
        assert!((ratio - 2.0).abs() < 1e-12, "{ratio}");
    }
}
