//! The common FMI 2.0 functions of Co-Simulation: types platform, version,
//! debug logging, instantiation (Co-Simulation only), freeing, experiment
//! set-up, initialization, termination, reset, and the directional
//! derivatives (not supported).

use std::ffi::c_char;

use libc::size_t;

use super::*;
use crate::instance::{error, Instance};
use crate::shell::{debug_logging, exports, free_instance, instantiate, ok, string};

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
    // environment has not freed (FMI contract).
    unsafe { free_instance(c) }
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
