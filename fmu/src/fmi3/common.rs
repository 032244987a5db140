//! The common FMI 3.0 functions of Co-Simulation: version, debug logging,
//! instantiation (Co-Simulation only), freeing, initialization,
//! termination and reset.

use std::ffi::c_char;

use libc::size_t;

use super::*;
use crate::instance::{escape_nul, LOG_ERROR};
use crate::model_description::LOG_CATEGORIES;
use crate::shell::{debug_logging, exports, instantiate, ok, string};

#[no_mangle]
pub extern "C" fn fmi3GetVersion() -> *const c_char {
    c"3.0".as_ptr()
}

exports! { call3(fmi3Instance) -> fmi3Status;
    fmi3SetDebugLogging(loggingOn: fmi3Boolean, nCategories: size_t, categories: *const fmi3String) |inst| {
        // SAFETY: FMI passes `nCategories` category strings.
        unsafe { debug_logging(inst, "fmi3SetDebugLogging", loggingOn, categories, nCategories) }
    };
}

/// Logs a refused instantiation through the environment's callback.
fn refuse_instance(
    logger: Option<fmi3LogMessageCallback>,
    env: fmi3InstanceEnvironment,
    func: &str,
    msg: &str,
) -> fmi3Instance {
    if let Some(logger) = logger {
        let cat = escape_nul(LOG_CATEGORIES[LOG_ERROR].0);
        let m = escape_nul(&format!("{func}: {msg}"));
        // SAFETY: the environment's fmi3LogMessageCallback with its
        // instance environment and NUL-terminated strings.
        unsafe { logger(env, fmi3Error, cat.as_ptr(), m.as_ptr()) };
    }
    std::ptr::null_mut()
}

/// Exports the instantiations of the interfaces this FMU does not have:
/// `name(the arguments after logMessage) => reason;`.
macro_rules! refused_instantiate {
    ($($name:ident($($arg:ident: $ty:ty),*) => $why:literal;)*) => {$(
        #[no_mangle]
        pub unsafe extern "C" fn $name(
            _instanceName: fmi3String,
            _instantiationToken: fmi3String,
            _resourcePath: fmi3String,
            _visible: fmi3Boolean,
            _loggingOn: fmi3Boolean,
            instanceEnvironment: fmi3InstanceEnvironment,
            logMessage: Option<fmi3LogMessageCallback>,
            $($arg: $ty),*
        ) -> fmi3Instance {
            refuse_instance(logMessage, instanceEnvironment, stringify!($name), $why)
        }
    )*};
}

refused_instantiate! {
    fmi3InstantiateModelExchange() => "this FMU supports Co-Simulation only (no <ModelExchange> in modelDescription.xml)";
    fmi3InstantiateScheduledExecution(_clockUpdate: fmi3ClockUpdateCallback, _lockPreemption: fmi3PreemptionCallback, _unlockPreemption: fmi3PreemptionCallback) => "this FMU supports Co-Simulation only (no <ScheduledExecution> in modelDescription.xml)";
}

#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
    instanceName: fmi3String,
    instantiationToken: fmi3String,
    resourcePath: fmi3String,
    _visible: fmi3Boolean,
    loggingOn: fmi3Boolean,
    eventModeUsed: fmi3Boolean,
    earlyReturnAllowed: fmi3Boolean,
    requiredIntermediateVariables: *const fmi3ValueReference,
    nRequiredIntermediateVariables: size_t,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: Option<fmi3LogMessageCallback>,
    _intermediateUpdate: fmi3IntermediateUpdateCallback,
) -> fmi3Instance {
    let checks = || {
        if eventModeUsed {
            return Err(
                "eventModeUsed = true, but this FMU has no event mode (hasEventMode=\"false\")"
                    .into(),
            );
        }
        // earlyReturnAllowed: the FMU never returns early, so either value
        // is fine; the variables for intermediate update are refused.
        let _ = earlyReturnAllowed;
        if nRequiredIntermediateVariables > 0 {
            let _ = requiredIntermediateVariables;
            return Err(format!(
                "{nRequiredIntermediateVariables} required intermediate variables, but this FMU has no intermediate update (providesIntermediateUpdate=\"false\")"
            ));
        }
        Ok(())
    };
    let make = |name: &str, token: &str, res: &str| {
        Instance::new_fmi3(name, token, res, logMessage, instanceEnvironment, loggingOn)
    };
    // SAFETY: null or a NUL-terminated string (FMI contract).
    let name = unsafe { string(instanceName) };
    let what = ("the instantiationToken", "the resourcePath");
    // SAFETY: null or NUL-terminated strings (FMI contract).
    match unsafe {
        instantiate(
            name.as_deref(),
            instantiationToken,
            resourcePath,
            what,
            checks,
            make,
        )
    } {
        Ok(inst) => Box::into_raw(inst) as fmi3Instance,
        Err(msg) => refuse_instance(
            logMessage,
            instanceEnvironment,
            "fmi3InstantiateCoSimulation",
            &msg,
        ),
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3FreeInstance(instance: fmi3Instance) {
    // SAFETY: null (a no-op) or an instance this FMU handed out and the
    // environment has not freed (FMI contract).
    unsafe { crate::shell::free_instance(instance) }
}

exports! { call3(fmi3Instance) -> fmi3Status;
    fmi3EnterInitializationMode(_toleranceDefined: fmi3Boolean, _tolerance: fmi3Float64, startTime: fmi3Float64, stopTimeDefined: fmi3Boolean, stopTime: fmi3Float64) |inst| {
        inst.setup_experiment(startTime, stopTimeDefined.then_some(stopTime))?;
        ok(inst.enter_initialization_mode())
    };
    fmi3ExitInitializationMode() |inst| inst.exit_initialization_mode();
    fmi3Terminate() |inst| ok(inst.terminate());
    fmi3Reset() |inst| ok(inst.reset());
}
