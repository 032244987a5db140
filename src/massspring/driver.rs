//! The scene-independent driver (the course notes' `SIMULATION_DRIVER`): frame loop,
//! step-size choice and the per-step sequence shared by all integrators:
//!
//! 1. velocity damping of the free particles, `v *= d^(h / frame_time)`;
//! 2. the integrator's step (kinematic particles end at their state at `t+h`);
//! 3. strain limiting, when a limit is configured (the `pbd` integrator does
//!    its own, with limit 0 unless one is configured);
//! 4. sphere collisions (projection and velocity fix-up).
//!
//! Step size: the option `dt` if given; else for the explicit schemes
//! `cfl_number x` the stability bound of [`StabilityInfo`] (computed once
//! from the initial configuration); for the trapezoidal rule the scene's
//! `time_step` but at most `2 / w_max` (beyond that the linearised rule,
//! which does not damp stiff modes, lets the undamped cloth blow up: at
//! h = 1/30 s it does after about 35 frames); else the scene's `time_step`. A frame
//! is split into equal steps no longer than that.

use super::forces::{elastic_energy, gravity_energy, kinetic_energy, max_strain};
use super::integrators::implicit::Scheme;
use super::integrators::stability::{analyze, StabilityInfo};
use super::integrators::{
    chebyshev, explicit, implicit, pbd, Integrator, IntegratorOptions, State, StepStats,
};
use super::MassSpringError;
use crate::scene::massspring::{MassSpringScene, System, V3};

/// Energies of the current state in J.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Energies {
    /// Kinetic energy `sum m v^2 / 2`.
    pub kinetic: f64,
    /// Elastic energy of the springs `sum k (l - l0)^2 / 2`.
    pub elastic: f64,
    /// `-sum m g . x`.
    pub gravity: f64,
}

impl Energies {
    /// Kinetic + elastic + gravitational.
    pub fn total(&self) -> f64 {
        self.kinetic + self.elastic + self.gravity
    }
}

/// What one frame did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameReport {
    /// Frame number just completed (1-based).
    pub frame: u32,
    /// Time at the end of the frame in s.
    pub time: f64,
    /// Steps taken in the frame.
    pub steps: usize,
    /// CG iterations in the frame.
    pub cg_iterations: usize,
    /// The frame's last step.
    pub last_step: StepStats,
}

/// Per-frame diagnostics of a simulation ([`Simulation::diagnostics`]): what
/// the CLI prints or writes as one CSV row per frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Diagnostics {
    /// Frames completed.
    pub frame: u32,
    /// Time in s.
    pub time: f64,
    /// Nominal step size in s.
    pub dt: f64,
    /// Kinetic, elastic and gravitational energy in J.
    pub energies: Energies,
    /// Largest `|l/l0 - 1|` over the springs.
    pub max_strain: f64,
    /// Linear momentum `sum m v` in kg m/s.
    pub momentum: [f64; 3],
    /// Lowest particle height (y) in m.
    pub min_height: f64,
    /// Statistics of the last step.
    pub last_step: StepStats,
    /// Totals since the start.
    pub totals: RunTotals,
}

/// Totals since the simulation was built.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct RunTotals {
    /// Steps taken.
    pub steps: u64,
    /// Conjugate-gradient iterations over all linear solves.
    pub cg_iterations: u64,
    /// Linear solves.
    pub linear_solves: u64,
    /// Sphere collisions resolved (particles projected out of a sphere).
    pub collisions: u64,
}

/// A mass-spring simulation: a system, an integrator and its state.
#[derive(Clone, Debug)]
pub struct Simulation {
    system: System,
    integrator: Integrator,
    options: IntegratorOptions,
    state: State,
    frame: u32,
    dt: f64,
    stability: Option<StabilityInfo>,
    last: StepStats,
    totals: RunTotals,
}

impl Simulation {
    /// Builds a simulation of `scene` with `integrator`.
    pub fn new(
        scene: &MassSpringScene,
        integrator: Integrator,
        options: IntegratorOptions,
    ) -> Result<Simulation, MassSpringError> {
        Simulation::from_system(scene.build()?, integrator, options)
    }

    /// Builds a simulation of an already expanded system.
    pub fn from_system(
        system: System,
        integrator: Integrator,
        options: IntegratorOptions,
    ) -> Result<Simulation, MassSpringError> {
        if let Some(dt) = options.dt {
            if !(dt > 0.0 && dt.is_finite()) {
                return Err(MassSpringError::Argument(format!(
                    "step size dt must be positive and finite, got {dt}"
                )));
            }
        }
        let state = State::initial(&system);
        let stability = (integrator.is_explicit() || integrator == Integrator::Trapezoidal)
            .then(|| analyze(&system, &state.x));
        let dt = match (options.dt, stability) {
            (Some(dt), _) => dt,
            (None, Some(st)) if integrator == Integrator::Trapezoidal => {
                // The linearised trapezoidal rule does not damp the stiff
                // modes; beyond h w_max = 2 it pumps energy into the cloth.
                let w = st.omega_max_sq.sqrt();
                if w > 0.0 {
                    system.time_step.min(2.0 / w)
                } else {
                    system.time_step
                }
            }
            (None, Some(st)) => {
                let bound = match integrator {
                    Integrator::ForwardEuler => st.forward_euler,
                    _ => st.symplectic_euler,
                };
                if bound <= 0.0 {
                    return Err(MassSpringError::Unsupported {
                        integrator,
                        reason: "the springs have no damping, so forward Euler is unstable at every step size (its CFL bound b/k is 0); use symplectic-euler or an implicit integrator, or force a step with the dt option".into(),
                    });
                }
                let cfl = options.cfl_number.unwrap_or(system.cfl_number);
                (cfl * bound).min(system.frame_time)
            }
            (None, None) => system.time_step,
        };
        Ok(Simulation {
            system,
            integrator,
            options,
            state,
            frame: 0,
            dt,
            stability,
            last: StepStats::new(0.0),
            totals: RunTotals::default(),
        })
    }

    /// Advances one step of size `h` (any positive size).
    pub fn step(&mut self, h: f64) -> Result<StepStats, MassSpringError> {
        if !(h > 0.0 && h.is_finite()) {
            return Err(MassSpringError::Argument(format!(
                "step size must be positive and finite, got {h}"
            )));
        }
        let sys = &self.system;
        let s = &mut self.state;
        let opt = &self.options;
        if sys.velocity_damping < 1.0 {
            let d = sys.velocity_damping.powf(h / sys.frame_time);
            for i in 0..sys.len() {
                if sys.is_free(i) {
                    s.v[i] *= d;
                }
            }
        }
        let limit = opt.strain_limit.or(sys.strain_limit);
        let mut stats = match self.integrator {
            Integrator::ForwardEuler => explicit::forward_euler(sys, s, h),
            Integrator::SymplecticEuler => explicit::symplectic_euler(sys, s, h),
            Integrator::BackwardEuler => implicit::step(sys, s, h, Scheme::BackwardEuler, opt)?,
            Integrator::Trapezoidal => implicit::step(sys, s, h, Scheme::Trapezoidal, opt)?,
            Integrator::ChebyshevJacobi => {
                chebyshev::step(sys, s, h, opt.rho, opt.iterations, None)
            }
            Integrator::Pbd => pbd::step(
                sys,
                s,
                h,
                limit.unwrap_or(0.0),
                opt.strain_iterations,
                opt.strain_solver,
            ),
        };
        if self.integrator != Integrator::Pbd {
            if let Some(limit) = limit {
                let (n, after) = pbd::strain_limit(
                    sys,
                    &mut s.x,
                    &mut s.v,
                    h,
                    limit,
                    opt.strain_iterations,
                    opt.strain_solver,
                );
                stats.strain_passes = n;
                stats.strain_after_limiting = after;
            }
        }
        stats.collisions = pbd::collide_spheres(sys, &mut s.x, &mut s.v, h);
        s.t += h;
        self.totals.steps += 1;
        self.totals.cg_iterations += stats.cg_iterations as u64;
        self.totals.linear_solves += stats.linear_solves as u64;
        self.totals.collisions += stats.collisions as u64;
        self.last = stats;
        if s.x
            .iter()
            .chain(&s.v)
            .any(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Err(MassSpringError::Diverged {
                time: s.t,
                step: self.totals.steps,
            });
        }
        Ok(stats)
    }

    /// Advances one frame (`frame_time`) in equal steps no longer than [`Self::dt`].
    pub fn step_frame(&mut self) -> Result<FrameReport, MassSpringError> {
        let ft = self.system.frame_time;
        let n = steps_for(ft, self.dt);
        let h = ft / n as f64;
        let start = self.frame as f64 * ft;
        let mut cg = 0;
        let mut last = StepStats::new(h);
        for k in 0..n {
            // Keep the clock on the frame grid (no drift from summing h).
            self.state.t = start + k as f64 * h;
            last = self.step(h)?;
            cg += last.cg_iterations;
        }
        self.frame += 1;
        self.state.t = self.frame as f64 * ft;
        Ok(FrameReport {
            frame: self.frame,
            time: self.state.t,
            steps: n,
            cg_iterations: cg,
            last_step: last,
        })
    }

    /// Runs the scene's `frames` frames from the current frame on.
    pub fn run(&mut self) -> Result<(), MassSpringError> {
        while self.frame < self.system.frames {
            self.step_frame()?;
        }
        Ok(())
    }

    /// Advances to time `t_end` in equal steps no longer than [`Self::dt`]
    /// (for work-precision runs: the same end time at any step size).
    pub fn run_to(&mut self, t_end: f64) -> Result<usize, MassSpringError> {
        let span = t_end - self.state.t;
        if !span.is_finite() || span < 0.0 {
            return Err(MassSpringError::Argument(format!(
                "end time {t_end} is before the current time {}",
                self.state.t
            )));
        }
        if span == 0.0 {
            return Ok(0);
        }
        let n = steps_for(span, self.dt);
        let h = span / n as f64;
        let t0 = self.state.t;
        for k in 0..n {
            self.state.t = t0 + k as f64 * h;
            self.step(h)?;
        }
        self.state.t = t_end;
        Ok(n)
    }

    /// Changes gravity from the next step on (`[gx, gy, gz]` in m/s^2, finite,
    /// |g| at most 1e6); the FMU's gravity inputs use this.
    pub fn set_gravity(&mut self, g: V3) -> Result<(), MassSpringError> {
        if !g.iter().all(|c| c.is_finite()) || g.norm() > 1e6 {
            return Err(MassSpringError::Argument(format!(
                "gravity ({}, {}, {}) must be finite with |g| at most 1e6 m/s^2",
                g.x, g.y, g.z
            )));
        }
        self.system.gravity = g;
        Ok(())
    }
    /// Gravity in m/s^2.
    pub fn gravity(&self) -> V3 {
        self.system.gravity
    }

    /// Current positions in m.
    pub fn positions(&self) -> &[V3] {
        &self.state.x
    }
    /// Current velocities in m/s.
    pub fn velocities(&self) -> &[V3] {
        &self.state.v
    }
    /// The full state.
    pub fn state(&self) -> &State {
        &self.state
    }
    /// The state to set: the clock before a substep (the FMU and the CLI put
    /// it on their substep grid, `k dt`, so the driven particles follow it),
    /// positions and velocities when a saved state is restored (the FMU's
    /// `fmi2SetFMUstate`), or a perturbed start. Kinematic particles are
    /// reset by the next step.
    pub fn state_mut(&mut self) -> &mut State {
        &mut self.state
    }
    /// Current time in s.
    pub fn time(&self) -> f64 {
        self.state.t
    }
    /// Frames completed.
    pub fn frame(&self) -> u32 {
        self.frame
    }
    /// The nominal step size in s.
    pub fn dt(&self) -> f64 {
        self.dt
    }
    /// The expanded scene.
    pub fn system(&self) -> &System {
        &self.system
    }
    /// The integrator this simulation steps with.
    pub fn integrator(&self) -> Integrator {
        self.integrator
    }
    /// The integrator's options.
    pub fn options(&self) -> &IntegratorOptions {
        &self.options
    }
    /// Stability bounds (explicit integrators and the trapezoidal rule).
    pub fn stability(&self) -> Option<StabilityInfo> {
        self.stability
    }
    /// The largest step this integrator runs stably on this system, in s
    /// (linearised at the initial configuration, [`StabilityInfo`]):
    /// forward Euler's and symplectic Euler's bounds; for the trapezoidal
    /// rule `2 / w_max`, beyond which the linearised step pumps energy into
    /// the stiff modes (the bound its default step uses). `None` for the
    /// A-stable schemes (backward Euler, Chebyshev-Jacobi, PBD) and when
    /// there are no springs.
    pub fn stable_dt(&self) -> Option<f64> {
        let st = self.stability?;
        let bound = match self.integrator {
            Integrator::ForwardEuler => st.forward_euler,
            Integrator::SymplecticEuler => st.symplectic_euler,
            Integrator::Trapezoidal if st.omega_max_sq > 0.0 => 2.0 / st.omega_max_sq.sqrt(),
            _ => return None,
        };
        bound.is_finite().then_some(bound)
    }
    /// Statistics of the last step.
    pub fn last_step(&self) -> StepStats {
        self.last
    }
    /// Totals since the start.
    pub fn totals(&self) -> RunTotals {
        self.totals
    }
    /// Energies of the current state.
    pub fn energies(&self) -> Energies {
        Energies {
            kinetic: kinetic_energy(&self.system, &self.state.v),
            elastic: elastic_energy(&self.system.springs, &self.state.x),
            gravity: gravity_energy(&self.system, &self.state.x),
        }
    }
    /// Everything worth printing about the current state (see [`Diagnostics`]).
    pub fn diagnostics(&self) -> Diagnostics {
        let mut p = V3::zeros();
        for (m, v) in self.system.masses.iter().zip(&self.state.v) {
            p += v * *m;
        }
        Diagnostics {
            frame: self.frame,
            time: self.state.t,
            dt: self.dt,
            energies: self.energies(),
            max_strain: self.max_strain(),
            momentum: [p.x, p.y, p.z],
            min_height: self
                .state
                .x
                .iter()
                .map(|x| x.y)
                .fold(f64::INFINITY, f64::min),
            last_step: self.last,
            totals: self.totals,
        }
    }
    /// Frames of a full run (the scene's `time.frames`).
    pub fn frames(&self) -> u32 {
        self.system.frames
    }
    /// Frame interval in s (the scene's `time.frame_time`).
    pub fn frame_time(&self) -> f64 {
        self.system.frame_time
    }
    /// Largest `|l/l0 - 1|` over the springs now.
    pub fn max_strain(&self) -> f64 {
        max_strain(&self.system.springs, &self.state.x)
    }
    /// Spring end points as particle index pairs (for drawing).
    pub fn edges(&self) -> Vec<[usize; 2]> {
        self.system.springs.iter().map(|s| [s.a, s.b]).collect()
    }
}

/// Number of equal steps no longer than `dt` that cover `span`.
fn steps_for(span: f64, dt: f64) -> usize {
    let n = (span / dt * (1.0 - 1e-12)).ceil();
    (n.max(1.0)) as usize
}
