//! Mass-spring wires and cloth (course lecture notes; Baraff and Witkin 1998; Wang 2015, Müller et al. 2007). The scene
//! ([`MassSpringScene`], its expansion [`System`] and the built-in
//! [`scenes`]) lives in [`crate::scene::massspring`]; this module holds the
//! scene-independent forces, solvers and integrators ("driver").
//!
//! * [`scenes`]: the built-in `wire`, `three-particle` and `cloth`, each
//!   parsed from its file under `scenes/massspring/` by
//!   [`crate::scene::builtin`](mod@crate::scene::builtin).
//! * `forces`: spring, damping and gravity forces, energies, Hessian blocks.
//! * `linear`: sparse matrix, PCG with Jacobi / IC(0), dense direct solve.
//! * [`integrators`]: forward / symplectic Euler, trapezoidal, backward Euler,
//!   Chebyshev-accelerated Jacobi, PBD strain limiting, sphere collision.
//! * `driver`: [`Simulation`], the frame loop and the choice of step size.
//!
//! ```
//! use yarnsim::massspring::{scenes, Integrator, IntegratorOptions, Simulation};
//! let mut sim = Simulation::new(&scenes::wire(), Integrator::BackwardEuler,
//!                               IntegratorOptions::default()).unwrap();
//! sim.step_frame().unwrap();
//! assert_eq!(sim.positions().len(), 11);
//! ```

pub(crate) mod driver;
pub(crate) mod forces;
pub mod integrators;
pub(crate) mod linear;
#[cfg(test)]
mod solver_tests;

use std::fmt;

pub use crate::scene::massspring::{MassSpringScene, System, V3};
pub use driver::{Diagnostics, Energies, FrameReport, RunTotals, Simulation};
pub use integrators::stability::StabilityInfo;
pub use integrators::{Integrator, IntegratorOptions, State, StepStats, StrainSolver};
pub use linear::PreconditionerKind;

use crate::scene::SceneError;

/// The built-in mass-spring scenes, each parsed from its file under
/// `scenes/massspring/` (the one list of built-ins is
/// [`crate::scene::builtin`](mod@crate::scene::builtin)).
pub mod scenes {
    use crate::scene::{builtin, builtin_names, Scene};

    pub use crate::scene::builtin::{cloth, three_particle, wire};

    use super::MassSpringScene;

    /// `(name, one-line description)` of each built-in mass-spring scene.
    pub fn names() -> Vec<(&'static str, &'static str)> {
        builtin_names()
            .into_iter()
            .filter(|(name, _)| by_name(name).is_some())
            .collect()
    }

    /// A built-in mass-spring scene by name.
    pub fn by_name(name: &str) -> Option<MassSpringScene> {
        match builtin(name) {
            Some(Scene::MassSpring(s)) => Some(s),
            _ => None,
        }
    }
}

/// Why a mass-spring simulation could not be built or advanced.
#[derive(Debug, Clone, PartialEq)]
pub enum MassSpringError {
    /// The scene is invalid.
    Scene(SceneError),
    /// The integrator makes no sense for this scene (or these options).
    Unsupported {
        /// The integrator asked for.
        integrator: Integrator,
        /// Why it cannot run the scene.
        reason: String,
    },
    /// A linear solve failed.
    Solver {
        /// Simulation time of the failed step in s.
        time: f64,
        /// The solver's message.
        message: String,
    },
    /// Positions or velocities became non-finite.
    Diverged {
        /// Simulation time in s.
        time: f64,
        /// The step that diverged.
        step: u64,
    },
    /// A bad argument (step size, end time).
    Argument(String),
}

impl fmt::Display for MassSpringError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MassSpringError::Scene(e) => write!(f, "{e}"),
            MassSpringError::Unsupported { integrator, reason } => {
                write!(f, "integrator {integrator} cannot run this scene: {reason}")
            }
            MassSpringError::Solver { time, message } => {
                write!(f, "linear solve failed at t = {time:.6} s: {message}")
            }
            MassSpringError::Diverged { time, step } => write!(
                f,
                "the simulation diverged (non-finite state) at step {step}, t = {time:.6} s; use a smaller step"
            ),
            MassSpringError::Argument(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for MassSpringError {}

impl From<SceneError> for MassSpringError {
    fn from(e: SceneError) -> Self {
        MassSpringError::Scene(e)
    }
}
