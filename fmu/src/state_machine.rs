//! The FMI 2.0 Co-Simulation state machine: the statuses, the states an
//! instance can be in, and one table of the states each function is allowed
//! in ([`ALLOWED`], as in modelica/Reference-FMUs `fmi2Functions.c`).

use Phase::*;

/// `fmi2Status` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
#[repr(i32)]
pub enum Status {
    Ok = 0,
    Warning = 1,
    Discard = 2,
    Error = 3,
    Fatal = 4,
    Pending = 5,
}

/// A failed call: its status (Discard, Error or Fatal) and the message logged.
#[derive(Clone, Debug, PartialEq)]
pub struct Fail {
    pub status: Status,
    pub msg: String,
}

pub type Res<T = ()> = Result<T, Fail>;

/// A model's refusal is an fmi2Error.
impl From<crate::fmu_model::ModelError> for Fail {
    fn from(e: crate::fmu_model::ModelError) -> Self {
        Fail {
            status: Status::Error,
            msg: e.0,
        }
    }
}

pub fn error<T>(msg: impl Into<String>) -> Res<T> {
    Err(Fail {
        status: Status::Error,
        msg: msg.into(),
    })
}

/// The states of the FMI 2.0 Co-Simulation state machine this FMU can be in
/// (no asynchronous steps, so never stepInProgress or stepCanceled).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    Instantiated,
    InitializationMode,
    StepComplete,
    StepFailed,
    Terminated,
    Error,
    Fatal,
}

/// Every phase but `Fatal`: where the functions that an error must not lock
/// out are allowed (debug logging, reset, the FMU-state functions).
const NOT_FATAL: &[Phase] = &[
    Phase::Instantiated,
    Phase::InitializationMode,
    Phase::StepComplete,
    Phase::StepFailed,
    Phase::Terminated,
    Phase::Error,
];

/// Every phase with a consistent simulation (not `Error`, not `Fatal`).
const LIVE: &[Phase] = &[
    Phase::Instantiated,
    Phase::InitializationMode,
    Phase::StepComplete,
    Phase::StepFailed,
    Phase::Terminated,
];

impl Phase {
    pub fn code(self) -> u8 {
        self as u8
    }
    /// The phase whose [`Self::code`] is `c`.
    pub fn from_code(c: u8) -> Option<Phase> {
        NOT_FATAL
            .iter()
            .copied()
            .chain([Phase::Fatal])
            .find(|p| p.code() == c)
    }
}

pub fn phase_name(p: Phase) -> &'static str {
    match p {
        Phase::Instantiated => "instantiated",
        Phase::InitializationMode => "initialization mode",
        Phase::StepComplete => "step complete",
        Phase::StepFailed => "step failed",
        Phase::Terminated => "terminated",
        Phase::Error => "error",
        Phase::Fatal => "fatal",
    }
}

/// Fixed parameters can be set only before `fmi2ExitInitializationMode`.
pub fn parameter_settable(phase: Phase, func: &str, vr: u32) -> Res {
    use Phase::*;
    if matches!(phase, Instantiated | InitializationMode) {
        Ok(())
    } else {
        error(format!(
            "{func}: value reference {vr} is a fixed parameter, settable only before fmi2ExitInitializationMode (state is {:?})",
            phase_name(phase)
        ))
    }
}

/// Where `fmi2Get*` may read values.
const GET: &[Phase] = &[InitializationMode, StepComplete, StepFailed, Terminated];

/// Where inputs (and, before `fmi2ExitInitializationMode`, parameters) may
/// be set.
const SET: &[Phase] = &[Instantiated, InitializationMode, StepComplete];

/// Where `fmi2Get*Status` may be called.
const STATUS: &[Phase] = &[StepComplete, StepFailed, Terminated];

/// Every function whose state the instance checks, with the states it is
/// allowed in (FMI 2.0.4, section 4.2.4). `fmi2FreeInstance`,
/// `fmi2FreeFMUstate` and the unsupported functions (which always return
/// fmi2Error) are not listed.
pub const ALLOWED: &[(&str, &[Phase])] = &[
    ("fmi2SetDebugLogging", NOT_FATAL),
    ("fmi2SetupExperiment", &[Instantiated]),
    ("fmi2EnterInitializationMode", &[Instantiated]),
    ("fmi2ExitInitializationMode", &[InitializationMode]),
    ("fmi2Terminate", &[StepComplete, StepFailed]),
    ("fmi2Reset", NOT_FATAL),
    ("fmi2GetReal", GET),
    ("fmi2GetInteger", GET),
    ("fmi2GetBoolean", GET),
    ("fmi2GetString", GET),
    ("fmi2SetReal", SET),
    ("fmi2SetInteger", SET),
    ("fmi2SetBoolean", SET),
    ("fmi2SetString", SET),
    ("fmi2GetFMUstate", LIVE),
    ("fmi2SetFMUstate", NOT_FATAL),
    ("fmi2SerializedFMUstateSize", NOT_FATAL),
    ("fmi2SerializeFMUstate", NOT_FATAL),
    ("fmi2DeSerializeFMUstate", NOT_FATAL),
    ("fmi2DoStep", &[StepComplete]),
    ("fmi2GetStatus", STATUS),
    ("fmi2GetRealStatus", STATUS),
    ("fmi2GetIntegerStatus", STATUS),
    ("fmi2GetBooleanStatus", STATUS),
    ("fmi2GetStringStatus", STATUS),
];

/// The states `func` is allowed in ([`ALLOWED`]).
///
/// # Panics
/// For a function missing from the table (a programming error).
pub fn allowed(func: &str) -> &'static [Phase] {
    ALLOWED
        .iter()
        .find(|(f, _)| *f == func)
        .map(|(_, p)| *p)
        .unwrap_or_else(|| panic!("{func} is missing from the state table"))
}

/// Fails with fmi2Error unless `func` is allowed in `phase`.
pub fn require(phase: Phase, func: &str) -> Res {
    if allowed(func).contains(&phase) {
        Ok(())
    } else {
        error(format!(
            "{func} is not allowed in state {:?}",
            phase_name(phase)
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_phase_reads_back_from_its_code() {
        for p in NOT_FATAL.iter().copied().chain([Fatal]) {
            assert_eq!(Phase::from_code(p.code()), Some(p));
        }
        assert_eq!(Phase::from_code(Fatal.code() + 1), None);
    }

    #[test]
    fn one_row_per_function_and_no_function_in_the_fatal_state() {
        let mut names: Vec<&str> = ALLOWED.iter().map(|(f, _)| *f).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), ALLOWED.len());
        for (f, phases) in ALLOWED {
            assert!(!phases.contains(&Fatal), "{f}");
            assert!(!phases.is_empty(), "{f}");
        }
        assert_eq!(allowed("fmi2DoStep"), &[StepComplete]);
        assert!(require(Error, "fmi2Reset").is_ok());
        assert!(require(Error, "fmi2Terminate").is_err());
        assert!(require(StepFailed, "fmi2GetReal").is_ok());
    }
}
