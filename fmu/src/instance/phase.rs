//! The FMI 2.0 and FMI 3.0 Co-Simulation state machine, version-neutral:
//! the statuses, the phases an instance can be in (the "states" of the
//! standards' state machines; in this crate "FMU state" means only the
//! snapshot of `fmi2GetFMUstate` / `fmi3GetFMUState`), the operations an
//! instance offers ([`Operation`]) and, per operation and FMI version, the
//! function's name and the phases it is allowed in ([`Operation::name`],
//! [`Operation::allowed`]), as the `MASK_*` tables of
//! modelica/Reference-FMUs `fmi2Functions.c` and `fmi3Functions.c` do.
//!
//! The instance checks its calls by operation; the version it was made by
//! ([`Api`]) picks the row and names the function in the messages. FMI 3.0
//! Co-Simulation without event mode has the states
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

/// A model's refusal is an error status.
impl From<crate::models::model::ModelError> for Fail {
    fn from(e: crate::models::model::ModelError) -> Self {
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

/// The phases of the FMI 2.0 Co-Simulation state machine this FMU can be in
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

/// A status's name in `api` (`fmi2Discard`, `fmi3Discard`).
pub fn status_name(api: Api, s: Status) -> &'static str {
    match (api, s) {
        (Api::Fmi2, Status::Ok) => "fmi2OK",
        (Api::Fmi2, Status::Warning) => "fmi2Warning",
        (Api::Fmi2, Status::Discard) => "fmi2Discard",
        (Api::Fmi2, Status::Error) => "fmi2Error",
        (Api::Fmi2, Status::Fatal) => "fmi2Fatal",
        (Api::Fmi2, Status::Pending) => "fmi2Pending",
        (Api::Fmi3, Status::Ok) => "fmi3OK",
        (Api::Fmi3, Status::Warning) => "fmi3Warning",
        (Api::Fmi3, Status::Discard) => "fmi3Discard",
        (Api::Fmi3, Status::Error) => "fmi3Error",
        (Api::Fmi3, Status::Fatal) => "fmi3Fatal",
        // FMI 3.0 has no asynchronous step and no Pending.
        (Api::Fmi3, Status::Pending) => "fmi3Error",
    }
}

/// Declares [`Operation`] with its variants and [`Operation::ALL`], the
/// same list in the same order.
macro_rules! operations {
    ($(#[$meta:meta])* pub enum $name:ident { $($op:ident,)* }) => {
        $(#[$meta])*
        pub enum $name {
            $($op,)*
        }

        impl $name {
            /// Every operation, in the order of [`Operation`].
            pub const ALL: [$name; [$($name::$op),*].len()] = [$($name::$op),*];
        }
    };
}

operations! {
    /// What an instance does for a call, whatever the FMI version that calls
    /// it: the key of the state table. The getters and setters are by value
    /// type (`Float` is FMI 2.0 Real and FMI 3.0 Float64, `Integer` is Integer
    /// and Int32); `SetupExperiment` is FMI 2.0's function and the arguments of
    /// `fmi3EnterInitializationMode`.
    #[derive(Clone, Copy, Debug, PartialEq, Eq)]
    pub enum Operation {
        SetDebugLogging,
        FreeInstance,
        SetupExperiment,
        EnterInitializationMode,
        ExitInitializationMode,
        EnterStepMode,
        Terminate,
        Reset,
        GetFloat,
        GetInteger,
        GetBoolean,
        GetString,
        SetFloat,
        SetInteger,
        SetBoolean,
        SetString,
        GetNumberOfVariableDependencies,
        GetVariableDependencies,
        GetFmuState,
        SetFmuState,
        SerializedFmuStateSize,
        SerializeFmuState,
        DeserializeFmuState,
        DoStep,
        GetStatus,
        GetRealStatus,
        GetIntegerStatus,
        GetBooleanStatus,
        GetStringStatus,
    }
}

impl Operation {
    /// The names of the function that calls the operation in FMI 2.0 and in
    /// FMI 3.0 (`None`: the version has no such function).
    pub const fn names(self) -> (Option<&'static str>, Option<&'static str>) {
        use Operation::*;
        match self {
            SetDebugLogging => (Some("fmi2SetDebugLogging"), Some("fmi3SetDebugLogging")),
            FreeInstance => (Some("fmi2FreeInstance"), Some("fmi3FreeInstance")),
            SetupExperiment => (
                Some("fmi2SetupExperiment"),
                Some("fmi3EnterInitializationMode"),
            ),
            EnterInitializationMode => (
                Some("fmi2EnterInitializationMode"),
                Some("fmi3EnterInitializationMode"),
            ),
            ExitInitializationMode => (
                Some("fmi2ExitInitializationMode"),
                Some("fmi3ExitInitializationMode"),
            ),
            EnterStepMode => (None, Some("fmi3EnterStepMode")),
            Terminate => (Some("fmi2Terminate"), Some("fmi3Terminate")),
            Reset => (Some("fmi2Reset"), Some("fmi3Reset")),
            GetFloat => (Some("fmi2GetReal"), Some("fmi3GetFloat64")),
            GetInteger => (Some("fmi2GetInteger"), Some("fmi3GetInt32")),
            GetBoolean => (Some("fmi2GetBoolean"), Some("fmi3GetBoolean")),
            GetString => (Some("fmi2GetString"), Some("fmi3GetString")),
            SetFloat => (Some("fmi2SetReal"), Some("fmi3SetFloat64")),
            SetInteger => (Some("fmi2SetInteger"), Some("fmi3SetInt32")),
            SetBoolean => (Some("fmi2SetBoolean"), Some("fmi3SetBoolean")),
            SetString => (Some("fmi2SetString"), Some("fmi3SetString")),
            GetNumberOfVariableDependencies => (None, Some("fmi3GetNumberOfVariableDependencies")),
            GetVariableDependencies => (None, Some("fmi3GetVariableDependencies")),
            GetFmuState => (Some("fmi2GetFMUstate"), Some("fmi3GetFMUState")),
            SetFmuState => (Some("fmi2SetFMUstate"), Some("fmi3SetFMUState")),
            SerializedFmuStateSize => (
                Some("fmi2SerializedFMUstateSize"),
                Some("fmi3SerializedFMUStateSize"),
            ),
            SerializeFmuState => (Some("fmi2SerializeFMUstate"), Some("fmi3SerializeFMUState")),
            DeserializeFmuState => (
                Some("fmi2DeSerializeFMUstate"),
                Some("fmi3DeserializeFMUState"),
            ),
            DoStep => (Some("fmi2DoStep"), Some("fmi3DoStep")),
            GetStatus => (Some("fmi2GetStatus"), None),
            GetRealStatus => (Some("fmi2GetRealStatus"), None),
            GetIntegerStatus => (Some("fmi2GetIntegerStatus"), None),
            GetBooleanStatus => (Some("fmi2GetBooleanStatus"), None),
            GetStringStatus => (Some("fmi2GetStringStatus"), None),
        }
    }

    /// The name of the function that calls the operation in `api`.
    ///
    /// # Panics
    /// For an operation `api` has no function for (a programming error).
    pub fn name(self, api: Api) -> &'static str {
        let (two, three) = self.names();
        match api {
            Api::Fmi2 => two,
            Api::Fmi3 => three,
        }
        .unwrap_or_else(|| panic!("{self:?} is no {api:?} function"))
    }

    /// The phases the operation is allowed in when `api` calls it (FMI
    /// 2.0.4, section 4.2.4; FMI 3.0, section 4.2.1, for the Co-Simulation
    /// interface without event mode); `None` where the instance does not
    /// check the phase (freeing) or `api` has no such function.
    pub const fn allowed(self, api: Api) -> Option<&'static [Phase]> {
        use Operation::*;
        let (fmi2, fmi3): (&[Phase], &[Phase]) = match self {
            FreeInstance => return None,
            SetDebugLogging | Reset => (NOT_FATAL, NOT_FATAL),
            SetupExperiment | EnterInitializationMode => (&[Instantiated], &[Instantiated]),
            ExitInitializationMode => (&[InitializationMode], &[InitializationMode]),
            // Without event mode the FMU is in Step Mode from
            // fmi3ExitInitializationMode on; fmi3EnterStepMode is then a no-op.
            EnterStepMode => (&[], &[StepComplete]),
            Terminate => (STEP_MODE, STEP_MODE),
            GetFloat | GetInteger | GetBoolean | GetString => (GET, GET3),
            SetFloat | SetInteger | SetBoolean | SetString => (SET, SET),
            GetNumberOfVariableDependencies | GetVariableDependencies => (&[], LIVE),
            GetFmuState => (LIVE, LIVE),
            SetFmuState | SerializedFmuStateSize | SerializeFmuState | DeserializeFmuState => {
                (NOT_FATAL, NOT_FATAL)
            }
            DoStep => (&[StepComplete], &[StepComplete]),
            GetStatus | GetRealStatus | GetIntegerStatus | GetBooleanStatus | GetStringStatus => {
                (STATUS, &[])
            }
        };
        let phases = match api {
            Api::Fmi2 => fmi2,
            Api::Fmi3 => fmi3,
        };
        if phases.is_empty() {
            None
        } else {
            Some(phases)
        }
    }
}

/// Fixed parameters can be set only before `ExitInitializationMode`; the
/// refusal names the function (`op` in `api`) and the parameter (`name`).
pub fn parameter_settable(phase: Phase, api: Api, op: Operation, name: &str) -> Res {
    use Phase::*;
    if matches!(phase, Instantiated | InitializationMode) {
        Ok(())
    } else {
        error(format!(
            "{}: {name} is a fixed parameter: it can be set only before {} (state is {:?})",
            op.name(api),
            Operation::ExitInitializationMode.name(api),
            phase_name(phase)
        ))
    }
}

/// Where the FMI 2.0 getters may read values.
const GET: &[Phase] = &[InitializationMode, StepComplete, StepFailed, Terminated];

/// Where inputs (and, before `ExitInitializationMode`, parameters) may
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

/// Where the functions that end a step-mode run may be called: Step Mode
/// (FMI 2.0: stepComplete), also after a step that failed
/// (`terminateSimulation` in FMI 3.0).
const STEP_MODE: &[Phase] = &[StepComplete, StepFailed];

/// Fails with an error status unless `op` is allowed in `phase` when `api`
/// calls it; the message names the function and the state as `api` does.
///
/// # Panics
/// For an operation whose phase is not checked in `api` (a programming
/// error).
pub fn require(phase: Phase, api: Api, op: Operation) -> Res {
    let allowed = op
        .allowed(api)
        .unwrap_or_else(|| panic!("{op:?} is missing from the {api:?} state table"));
    if allowed.contains(&phase) {
        Ok(())
    } else {
        error(format!(
            "{} is not allowed in state {:?}",
            op.name(api),
            phase_name_in(api, phase)
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use Operation::*;

    #[test]
    fn every_phase_reads_back_from_its_code() {
        for p in NOT_FATAL.iter().copied().chain([Fatal]) {
            assert_eq!(Phase::from_code(p.code()), Some(p));
        }
        assert_eq!(Phase::from_code(Fatal.code() + 1), None);
    }

    #[test]
    fn one_name_per_function_and_no_function_in_the_fatal_state() {
        for api in [Api::Fmi2, Api::Fmi3] {
            // one operation per function, except the FMI 3.0 function that
            // does the work of two FMI 2.0 ones
            let mut names: Vec<&str> = Operation::ALL
                .iter()
                .filter(|op| **op != SetupExperiment)
                .filter_map(|op| match api {
                    Api::Fmi2 => op.names().0,
                    Api::Fmi3 => op.names().1,
                })
                .collect();
            let n = names.len();
            names.sort_unstable();
            names.dedup();
            assert_eq!(names.len(), n, "{api:?}");
            for op in Operation::ALL {
                if let Some(phases) = op.allowed(api) {
                    assert!(!phases.contains(&Fatal), "{op:?}");
                    assert!(!phases.is_empty(), "{op:?}");
                }
            }
        }
        assert_eq!(DoStep.allowed(Api::Fmi2), Some(&[StepComplete][..]));
        assert!(require(Error, Api::Fmi2, Reset).is_ok());
        assert!(require(Error, Api::Fmi2, Terminate).is_err());
        assert!(require(StepFailed, Api::Fmi2, GetFloat).is_ok());
    }

    #[test]
    fn fmi3_rows_follow_the_fmi3_state_machine() {
        // Every operation with an FMI 2.0 row has an FMI 3.0 row, but the
        // status getters.
        for op in Operation::ALL {
            if op.allowed(Api::Fmi2).is_some() && !op.name(Api::Fmi2).contains("Status") {
                assert!(op.name(Api::Fmi3).starts_with("fmi3"), "{op:?}");
                assert!(op.allowed(Api::Fmi3).is_some(), "{op:?}");
            }
        }
        assert_eq!(DoStep.allowed(Api::Fmi3), Some(&[StepComplete][..]));
        // after terminateSimulation: no further step, but Terminate
        assert!(require(StepFailed, Api::Fmi3, DoStep).is_err());
        assert!(require(StepFailed, Api::Fmi3, Terminate).is_ok());
        assert!(require(Instantiated, Api::Fmi3, EnterStepMode).is_err());
        assert!(require(Error, Api::Fmi3, Reset).is_ok());
        assert!(require(Error, Api::Fmi3, GetFloat).is_err());
        assert!(require(Instantiated, Api::Fmi3, GetFloat).is_ok());
        assert!(require(Instantiated, Api::Fmi2, GetFloat).is_err());
        let e = require(Instantiated, Api::Fmi3, DoStep).unwrap_err();
        assert_eq!(e.msg, "fmi3DoStep is not allowed in state \"Instantiated\"");
        assert_eq!(GetFloat.name(Api::Fmi2), "fmi2GetReal");
        assert_eq!(GetFloat.name(Api::Fmi3), "fmi3GetFloat64");
        assert_eq!(
            SetupExperiment.name(Api::Fmi3),
            "fmi3EnterInitializationMode"
        );
        assert_eq!(status_name(Api::Fmi3, Status::Discard), "fmi3Discard");
        let e = parameter_settable(StepComplete, Api::Fmi3, SetFloat, "x").unwrap_err();
        assert_eq!(
            e.msg,
            "fmi3SetFloat64: x is a fixed parameter: it can be set only before fmi3ExitInitializationMode (state is \"step complete\")"
        );
    }
}
