//! The 34 exported FMI 2.0 functions (25 common, 9 co-simulation): a
//! hand-written C ABI over [`Instance`]. Every export checks its pointers,
//! catches panics (a panic becomes `fmi2Fatal` for that instance and never
//! unwinds into the host) and logs every failure through the callback
//! ([`shell`]: the wrapper and the pointer helpers, shared with the FMI 3.0
//! front end [`crate::fmi3`]; [`states`]: the FMU-state functions, their
//! bodies shared with FMI 3.0).

#![allow(
    non_snake_case,
    non_camel_case_types,
    non_upper_case_globals,
    clippy::missing_safety_doc
)]

use std::ffi::{c_char, c_int, c_uint, c_void};
use std::panic::{catch_unwind, AssertUnwindSafe};

use libc::size_t;

use crate::instance::{error, Instance, Logger, Res, Status, LOG_ALL};

mod shell;
mod states;

pub(crate) use shell::*;
pub use states::*;

pub type fmi2Component = *mut c_void;
pub type fmi2ComponentEnvironment = *mut c_void;
pub type fmi2FMUstate = *mut c_void;
pub type fmi2ValueReference = c_uint;
pub type fmi2Real = f64;
pub type fmi2Integer = c_int;
/// A C `int`, not a Rust `bool`.
pub type fmi2Boolean = c_int;
pub type fmi2Char = c_char;
pub type fmi2String = *const fmi2Char;
pub type fmi2Byte = c_char;
pub type fmi2Status = c_int;
pub type fmi2Type = c_int;
pub type fmi2StatusKind = c_int;

pub const fmi2True: fmi2Boolean = 1;
pub const fmi2False: fmi2Boolean = 0;
pub const fmi2ModelExchange: fmi2Type = 0;
pub const fmi2CoSimulation: fmi2Type = 1;
pub const fmi2DoStepStatus: fmi2StatusKind = 0;
pub const fmi2PendingStatus: fmi2StatusKind = 1;
pub const fmi2LastSuccessfulTime: fmi2StatusKind = 2;
pub const fmi2Terminated: fmi2StatusKind = 3;

pub const fmi2OK: fmi2Status = Status::Ok as c_int;
pub const fmi2Warning: fmi2Status = Status::Warning as c_int;
pub const fmi2Discard: fmi2Status = Status::Discard as c_int;
pub const fmi2Error: fmi2Status = Status::Error as c_int;
pub const fmi2Fatal: fmi2Status = Status::Fatal as c_int;

/// `fmi2CallbackFunctions`.
#[repr(C)]
#[derive(Clone, Copy)]
pub struct fmi2CallbackFunctions {
    pub logger: Option<Logger>,
    pub allocateMemory: Option<unsafe extern "C" fn(size_t, size_t) -> *mut c_void>,
    pub freeMemory: Option<unsafe extern "C" fn(*mut c_void)>,
    pub stepFinished: Option<unsafe extern "C" fn(fmi2ComponentEnvironment, fmi2Status)>,
    pub componentEnvironment: fmi2ComponentEnvironment,
}

/// The 34 functions of FMI 2.0 Co-Simulation (25 common, 9 co-simulation).
pub const FMI2_FUNCTIONS: [&str; 34] = [
    "fmi2GetTypesPlatform",
    "fmi2GetVersion",
    "fmi2SetDebugLogging",
    "fmi2Instantiate",
    "fmi2FreeInstance",
    "fmi2SetupExperiment",
    "fmi2EnterInitializationMode",
    "fmi2ExitInitializationMode",
    "fmi2Terminate",
    "fmi2Reset",
    "fmi2GetReal",
    "fmi2GetInteger",
    "fmi2GetBoolean",
    "fmi2GetString",
    "fmi2SetReal",
    "fmi2SetInteger",
    "fmi2SetBoolean",
    "fmi2SetString",
    "fmi2GetFMUstate",
    "fmi2SetFMUstate",
    "fmi2FreeFMUstate",
    "fmi2SerializedFMUstateSize",
    "fmi2SerializeFMUstate",
    "fmi2DeSerializeFMUstate",
    "fmi2GetDirectionalDerivative",
    "fmi2SetRealInputDerivatives",
    "fmi2GetRealOutputDerivatives",
    "fmi2DoStep",
    "fmi2CancelStep",
    "fmi2GetStatus",
    "fmi2GetRealStatus",
    "fmi2GetIntegerStatus",
    "fmi2GetBooleanStatus",
    "fmi2GetStringStatus",
];

// ---------------------------------------------------------------- common

#[no_mangle]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

#[no_mangle]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

exports! { call(fmi2Component) -> fmi2Status;
    fmi2SetDebugLogging(loggingOn: fmi2Boolean, nCategories: size_t, categories: *const fmi2String) |inst| {
        // SAFETY: FMI passes `nCategories` category strings.
        unsafe { debug_logging(inst, "fmi2SetDebugLogging", loggingOn != fmi2False, categories, nCategories) }
    };
}

#[no_mangle]
pub unsafe extern "C" fn fmi2Instantiate(
    instanceName: fmi2String,
    fmuType: fmi2Type,
    fmuGUID: fmi2String,
    fmuResourceLocation: fmi2String,
    functions: *const fmi2CallbackFunctions,
    _visible: fmi2Boolean,
    loggingOn: fmi2Boolean,
) -> fmi2Component {
    // SAFETY: `functions` is null or points to the environment's callback
    // struct, valid for the call; it is copied out.
    let Some(cb) = (unsafe { functions.as_ref() }).copied() else {
        return std::ptr::null_mut();
    };
    // SAFETY: null or a NUL-terminated string (FMI contract).
    let name = unsafe { string(instanceName) };
    let fail = |msg: &str| {
        if let Some(logger) = cb.logger {
            let n = crate::instance::escape_nul(name.as_deref().unwrap_or("?"));
            let m = crate::instance::escape_log(&format!("fmi2Instantiate: {msg}"));
            // SAFETY: the environment's logger; the message is
            // pre-formatted and escaped, so no variadic argument is read.
            unsafe {
                logger(
                    cb.componentEnvironment,
                    n.as_ptr(),
                    fmi2Error,
                    c"logStatusError".as_ptr(),
                    m.as_ptr(),
                )
            };
        }
        std::ptr::null_mut()
    };
    let checks = || {
        if fmuType != fmi2CoSimulation {
            return Err(format!(
                "fmuType {fmuType} is not fmi2CoSimulation: this is a Co-Simulation FMU only"
            ));
        }
        Ok(())
    };
    let make = |name: &str, guid: &str, res: &str| {
        let on = loggingOn != fmi2False;
        Instance::new(name, guid, res, cb.logger, cb.componentEnvironment, on)
    };
    let what = ("the GUID", "the resource location");
    // SAFETY: null or NUL-terminated strings (FMI contract).
    match unsafe {
        instantiate(
            name.as_deref(),
            fmuGUID,
            fmuResourceLocation,
            what,
            checks,
            make,
        )
    } {
        Ok(inst) => Box::into_raw(inst) as fmi2Component,
        Err(msg) => fail(&msg),
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
    // SAFETY: `c` is null or a component this FMU handed out and the
    // environment has not freed (FMI contract); the magic number rejects
    // foreign pointers in most cases.
    let Some(inst) = (unsafe { Instance::from_ptr(c) }) else {
        return;
    };
    inst.invalidate();
    // SAFETY: the component was made by `Box::into_raw` in fmi2Instantiate
    // and is freed once (the magic is cleared above).
    let b = unsafe { Box::from_raw(inst as *mut Instance) };
    let _ = catch_unwind(AssertUnwindSafe(move || drop(b)));
}

exports! { call(fmi2Component) -> fmi2Status;
    fmi2SetupExperiment(_toleranceDefined: fmi2Boolean, _tolerance: fmi2Real, startTime: fmi2Real, stopTimeDefined: fmi2Boolean, stopTime: fmi2Real) |inst| {
        ok(inst.setup_experiment(startTime, (stopTimeDefined != fmi2False).then_some(stopTime)))
    };
    fmi2EnterInitializationMode() |inst| ok(inst.enter_initialization_mode());
    fmi2ExitInitializationMode() |inst| inst.exit_initialization_mode();
    fmi2Terminate() |inst| ok(inst.terminate());
    fmi2Reset() |inst| ok(inst.reset());
    fmi2GetDirectionalDerivative(_vUnknown_ref: *const fmi2ValueReference, _nUnknown: size_t, _vKnown_ref: *const fmi2ValueReference, _nKnown: size_t, _dvKnown: *const fmi2Real, _dvUnknown: *mut fmi2Real) |_| {
        error("not supported (providesDirectionalDerivative=\"false\")")
    };
}

value_exports! { call(fmi2Component) -> fmi2Status, "vr or value", [];
    fmi2GetReal(*mut fmi2Real, get_args) |inst, _f, vrs, out| ok(inst.get_real(vrs, out));
    fmi2GetInteger(*mut fmi2Integer, get_args) |inst, _f, vrs, out| ok(inst.get_integer(vrs, out));
    fmi2GetBoolean(*mut fmi2Boolean, get_args) |inst, _f, vrs, out| ok(inst.get_boolean(vrs, out));
    fmi2GetString(*mut fmi2String, get_args) |inst, _f, vrs, out| get_strings(inst, vrs, out);
    fmi2SetReal(*const fmi2Real, set_args) |inst, _f, vrs, vals| ok(inst.set_real(vrs, vals));
    fmi2SetInteger(*const fmi2Integer, set_args) |inst, _f, vrs, vals| ok(inst.set_integer(vrs, vals));
    fmi2SetBoolean(*const fmi2Boolean, set_args) |inst, _f, vrs, vals| ok(inst.set_boolean(vrs, vals));
    // SAFETY: each value is null or a NUL-terminated string (FMI contract).
    fmi2SetString(*const fmi2String, set_args) |inst, _f, vrs, vals| unsafe { set_strings(inst, vrs, vals) };
}

// ---------------------------------------------------------- co-simulation

exports! { call(fmi2Component) -> fmi2Status;
    fmi2SetRealInputDerivatives(_vr: *const fmi2ValueReference, _nvr: size_t, _order: *const fmi2Integer, _value: *const fmi2Real) |_| {
        error("not supported (canInterpolateInputs=\"false\")")
    };
    fmi2GetRealOutputDerivatives(_vr: *const fmi2ValueReference, _nvr: size_t, _order: *const fmi2Integer, _value: *mut fmi2Real) |_| {
        error("not supported (maxOutputDerivativeOrder=\"0\")")
    };
    fmi2DoStep(currentCommunicationPoint: fmi2Real, communicationStepSize: fmi2Real, _noSetFMUStatePriorToCurrentPoint: fmi2Boolean) |inst| {
        if inst.log_all() {
            let (t, h) = (currentCommunicationPoint, communicationStepSize);
            inst.log(Status::Ok, LOG_ALL, &format!("fmi2DoStep(t = {t}, h = {h})"));
        }
        inst.do_step(currentCommunicationPoint, communicationStepSize)
    };
    fmi2CancelStep() |_| {
        error("no asynchronous step is in progress (fmi2DoStep never returns fmi2Pending)")
    };
}

fn discard(msg: String) -> Res<Status> {
    Err(crate::instance::Fail {
        status: Status::Discard,
        msg,
    })
}

/// Exports the status getters: `name(value type) |inst, kind, value| body;`
/// after the state check and the null check of `value`.
macro_rules! status_exports {
    ($($name:ident($ty:ty) |$i:ident, $s:ident, $v:pat_param| $body:expr;)*) => {$(
        #[no_mangle]
        pub unsafe extern "C" fn $name(
            c: fmi2Component,
            $s: fmi2StatusKind,
            value: *mut $ty,
        ) -> fmi2Status {
            call(c, stringify!($name), |$i| {
                $i.require(stringify!($name))?;
                // SAFETY: `value` is null or points to a writable value (FMI contract).
                let Some($v) = (unsafe { value.as_mut() }) else {
                    return null(stringify!($name), "value");
                };
                $body
            })
        }
    )*};
}

status_exports! {
    fmi2GetStatus(fmi2Status) |_inst, s, _| {
        discard(format!("status kind {s} is not available: fmi2DoStep never returns fmi2Pending"))
    };
    fmi2GetRealStatus(fmi2Real) |inst, s, v| {
        if s != fmi2LastSuccessfulTime {
            return discard(format!("status kind {s} has no Real value"));
        }
        *v = inst.last_successful_time();
        Ok(Status::Ok)
    };
    fmi2GetIntegerStatus(fmi2Integer) |_inst, s, _| discard(format!("status kind {s} has no Integer value"));
    fmi2GetBooleanStatus(fmi2Boolean) |inst, s, v| {
        if s != fmi2Terminated {
            return discard(format!("status kind {s} has no Boolean value"));
        }
        *v = inst.terminated() as fmi2Boolean;
        Ok(Status::Ok)
    };
    fmi2GetStringStatus(fmi2String) |_inst, s, v| {
        *v = c"".as_ptr();
        discard(format!("status kind {s} has no String value: fmi2DoStep never returns fmi2Pending"))
    };
}
