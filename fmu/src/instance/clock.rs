//! The wrapper's time keeping, the part of an FMU state besides the model's.

/// The wrapper's time keeping and flags, as an FMU state holds them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Clock {
    /// The simulation must be rebuilt from the scene and the parameters
    /// before use (a parameter changed).
    pub dirty: bool,
    pub start_time: f64,
    pub stop_time: Option<f64>,
    /// Current communication point.
    pub time: f64,
    pub last_successful_time: f64,
    /// Substeps taken since initialization.
    pub substeps: u64,
    /// Set when a step diverged (`fmi2Terminated` status).
    pub terminated: bool,
}

impl Clock {
    /// At time 0, nothing run.
    pub(crate) const START: Clock = Clock {
        dirty: false,
        start_time: 0.0,
        stop_time: None,
        time: 0.0,
        last_successful_time: 0.0,
        substeps: 0,
        terminated: false,
    };
}
