//! The error a simulation step returns.

/// Why a step failed.
#[derive(Clone, Debug, PartialEq)]
pub enum SimError {
    /// A particle's state became NaN or infinite, or a particle moved more
    /// than one grid cell in one substep, during this step; the simulation
    /// refuses further steps until its state is restored.
    NonFinite {
        /// The substep that failed.
        step: u64,
        /// Simulated time at its end, s.
        time: f64,
        /// What went wrong, and where.
        what: String,
    },
    /// A substep that the step control refuses to take (it would leave a
    /// bound the scene's settings imply, at every step size it may try);
    /// the simulation refuses further steps until its state is restored.
    Refused {
        /// The last substep taken (the state is the one after it).
        step: u64,
        /// Simulated time at its end, s.
        time: f64,
        /// What the refused substep would do, and which settings to change.
        what: String,
    },
    /// An input given to the simulation is unusable.
    BadInput(String),
}

impl std::fmt::Display for SimError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SimError::NonFinite { step, time, what } => {
                write!(
                    f,
                    "simulation diverged at step {step} (t = {time:.6} s): {what}"
                )
            }
            SimError::Refused { step, time, what } => {
                write!(
                    f,
                    "substep refused after step {step} (t = {time:.6} s): {what}"
                )
            }
            SimError::BadInput(m) => write!(f, "bad input: {m}"),
        }
    }
}

impl std::error::Error for SimError {}
