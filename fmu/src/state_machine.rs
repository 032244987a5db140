//! The FMI 2.0 and FMI 3.0 Co-Simulation state machine: the statuses, the
//! states an instance can be in, and one table of the states each function
//! of either version is allowed in ([`ALLOWED`], as in modelica/Reference-FMUs
//! `fmi2Functions.c` and `fmi3Functions.c`).
//!
//! The instance checks its calls by their FMI 2.0 names; an FMI 3.0 instance
//! ([`Api::Fmi3`]) looks up the FMI 3.0 function instead ([`FMI3_NAMES`],
//! [`name_in`]). FMI 3.0 Co-Simulation without event mode has the states
//! Instantiated, Initialization Mode, Step Mode, Terminated, Error and Fatal
//! (FMI 3.0, section 4.2.1): [`Phase::StepComplete`] is its Step Mode, and
//! [`Phase::StepFailed`], which FMI 3.0 does not have, is Step Mode after
//! `fmi3DoStep` returned `terminateSimulation = true` (only `fmi3Terminate`,
//! the getters, the FMU-state functions and `fmi3Reset` are then allowed,
//! as FMI 3.0 asks of a master after `terminateSimulation`).

use Phase::*;

/// `fmi2Status` values (`fmi3Status` has the same values, without Pending).
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
/// (no asynchronous steps, so never stepInProgress or stepCanceled); for
/// FMI 3.0 see the module documentation ([`phase_name_in`]).
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

/// The FMI version of the front end that drives an instance.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Api {
    Fmi2,
    Fmi3,
}

/// A state's name in the FMI 3.0 standard (section 4.2.1).
pub fn phase_name_in(api: Api, p: Phase) -> &'static str {
    match (api, p) {
        (Api::Fmi2, p) => phase_name(p),
        (Api::Fmi3, Phase::Instantiated) => "Instantiated",
        (Api::Fmi3, Phase::InitializationMode) => "Initialization Mode",
        (Api::Fmi3, Phase::StepComplete) => "Step Mode",
        (Api::Fmi3, Phase::StepFailed) => "Step Mode after terminateSimulation",
        (Api::Fmi3, Phase::Terminated) => "Terminated",
        (Api::Fmi3, Phase::Error) => "Error",
        (Api::Fmi3, Phase::Fatal) => "Fatal",
    }
}

/// The FMI 2.0 names the instance checks its calls by, and the FMI 3.0
/// function each stands for (`fmi2SetupExperiment`'s arguments are those of
/// `fmi3EnterInitializationMode`); then the other FMI 2.0 words of the log
/// messages and their FMI 3.0 counterparts.
pub const FMI3_NAMES: &[(&str, &str)] = &[
    ("fmi2SetDebugLogging", "fmi3SetDebugLogging"),
    ("fmi2SetupExperiment", "fmi3EnterInitializationMode"),
    ("fmi2EnterInitializationMode", "fmi3EnterInitializationMode"),
    ("fmi2ExitInitializationMode", "fmi3ExitInitializationMode"),
    ("fmi2Terminate", "fmi3Terminate"),
    ("fmi2Reset", "fmi3Reset"),
    ("fmi2GetReal", "fmi3GetFloat64"),
    ("fmi2GetInteger", "fmi3GetInt32"),
    ("fmi2GetBoolean", "fmi3GetBoolean"),
    ("fmi2GetString", "fmi3GetString"),
    ("fmi2SetReal", "fmi3SetFloat64"),
    ("fmi2SetInteger", "fmi3SetInt32"),
    ("fmi2SetBoolean", "fmi3SetBoolean"),
    ("fmi2SetString", "fmi3SetString"),
    ("fmi2GetFMUstate", "fmi3GetFMUState"),
    ("fmi2SetFMUstate", "fmi3SetFMUState"),
    ("fmi2SerializedFMUstateSize", "fmi3SerializedFMUStateSize"),
    ("fmi2SerializeFMUstate", "fmi3SerializeFMUState"),
    ("fmi2DeSerializeFMUstate", "fmi3DeserializeFMUState"),
    ("fmi2DoStep", "fmi3DoStep"),
    ("fmi2FreeInstance", "fmi3FreeInstance"),
    ("fmi2OK", "fmi3OK"),
    ("fmi2Warning", "fmi3Warning"),
    ("fmi2Discard", "fmi3Discard"),
    ("fmi2Error", "fmi3Error"),
    ("fmi2Fatal", "fmi3Fatal"),
];

/// The name of the function `fmi2` (an FMI 2.0 name) in `api`.
pub fn name_in(api: Api, fmi2: &str) -> &str {
    match api {
        Api::Fmi2 => fmi2,
        Api::Fmi3 => FMI3_NAMES
            .iter()
            .find(|(two, _)| *two == fmi2)
            .map_or(fmi2, |(_, three)| *three),
    }
}

/// A log message in `api`'s words: for FMI 3.0 every FMI 2.0 name of
/// [`FMI3_NAMES`] replaced by its FMI 3.0 counterpart (longest first).
pub fn message_in(api: Api, msg: &str) -> String {
    if api == Api::Fmi2 || !msg.contains("fmi2") {
        return msg.to_string();
    }
    let mut pairs: Vec<&(&str, &str)> = FMI3_NAMES.iter().collect();
    pairs.sort_by_key(|(two, _)| std::cmp::Reverse(two.len()));
    let mut s = msg.to_string();
    for (two, three) in pairs {
        if s.contains(two) {
            s = s.replace(two, three);
        }
    }
    s
}

/// Fixed parameters can be set only before `fmi2ExitInitializationMode`;
/// the refusal names the parameter (`name`).
pub fn parameter_settable(phase: Phase, func: &str, name: &str) -> Res {
    use Phase::*;
    if matches!(phase, Instantiated | InitializationMode) {
        Ok(())
    } else {
        error(format!(
            "{func}: {name} is a fixed parameter: it can be set only before fmi2ExitInitializationMode (state is {:?})",
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

/// Where the FMI 3.0 getters may read values: as FMI 2.0, and also in
/// Instantiated (the start values and the initial state), as
/// modelica/Reference-FMUs `fmi3Functions.c` allows (`MASK_fmi3GetFloat64`).
const GET3: &[Phase] = &[
    Instantiated,
    InitializationMode,
    StepComplete,
    StepFailed,
    Terminated,
];

/// Where the FMI 3.0 functions that end a step-mode run may be called: Step
/// Mode, also after `terminateSimulation`.
const STEP_MODE: &[Phase] = &[StepComplete, StepFailed];

/// Every function whose state the instance checks, with the states it is
/// allowed in (FMI 2.0.4, section 4.2.4; FMI 3.0, section 4.2.1, for the
/// Co-Simulation interface without event mode). `fmi2FreeInstance`,
/// `fmi2FreeFMUstate`, their FMI 3.0 counterparts and the unsupported
/// functions (which always return an error status) are not listed.
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
    ("fmi3SetDebugLogging", NOT_FATAL),
    ("fmi3EnterInitializationMode", &[Instantiated]),
    ("fmi3ExitInitializationMode", &[InitializationMode]),
    // Without event mode the FMU is in Step Mode from
    // fmi3ExitInitializationMode on; fmi3EnterStepMode is then a no-op.
    ("fmi3EnterStepMode", &[StepComplete]),
    ("fmi3Terminate", STEP_MODE),
    ("fmi3Reset", NOT_FATAL),
    ("fmi3GetFloat64", GET3),
    ("fmi3GetInt32", GET3),
    ("fmi3GetBoolean", GET3),
    ("fmi3GetString", GET3),
    ("fmi3SetFloat64", SET),
    ("fmi3SetInt32", SET),
    ("fmi3SetBoolean", SET),
    ("fmi3SetString", SET),
    ("fmi3GetNumberOfVariableDependencies", LIVE),
    ("fmi3GetVariableDependencies", LIVE),
    ("fmi3GetFMUState", LIVE),
    ("fmi3SetFMUState", NOT_FATAL),
    ("fmi3SerializedFMUStateSize", NOT_FATAL),
    ("fmi3SerializeFMUState", NOT_FATAL),
    ("fmi3DeserializeFMUState", NOT_FATAL),
    ("fmi3DoStep", &[StepComplete]),
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

/// Fails with fmi2Error (fmi3Error) unless `func` is allowed in `phase`;
/// the message names the state as `func`'s FMI version does.
pub fn require(phase: Phase, func: &str) -> Res {
    if allowed(func).contains(&phase) {
        Ok(())
    } else {
        let api = if func.starts_with("fmi3") {
            Api::Fmi3
        } else {
            Api::Fmi2
        };
        error(format!(
            "{func} is not allowed in state {:?}",
            phase_name_in(api, phase)
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

    #[test]
    fn fmi3_rows_follow_the_fmi3_state_machine() {
        // Every FMI 2.0 function the instance checks has an FMI 3.0 row.
        for (two, _) in ALLOWED.iter().filter(|(f, _)| f.starts_with("fmi2")) {
            let three = name_in(Api::Fmi3, two);
            if !two.contains("Status") {
                assert!(three.starts_with("fmi3"), "{two}");
                let _ = allowed(three);
            }
        }
        assert_eq!(allowed("fmi3DoStep"), &[StepComplete]);
        // after terminateSimulation: no further step, but Terminate
        assert!(require(StepFailed, "fmi3DoStep").is_err());
        assert!(require(StepFailed, "fmi3Terminate").is_ok());
        assert!(require(Instantiated, "fmi3EnterStepMode").is_err());
        assert!(require(Error, "fmi3Reset").is_ok());
        assert!(require(Error, "fmi3GetFloat64").is_err());
        assert!(require(Instantiated, "fmi3GetFloat64").is_ok());
        assert!(require(Instantiated, "fmi2GetReal").is_err());
        let e = require(Instantiated, "fmi3DoStep").unwrap_err();
        assert_eq!(e.msg, "fmi3DoStep is not allowed in state \"Instantiated\"");
        assert_eq!(name_in(Api::Fmi2, "fmi2GetReal"), "fmi2GetReal");
        assert_eq!(
            message_in(
                Api::Fmi3,
                "fmi2GetReal: x before fmi2ExitInitializationMode, fmi2Discard"
            ),
            "fmi3GetFloat64: x before fmi3ExitInitializationMode, fmi3Discard"
        );
    }
}
