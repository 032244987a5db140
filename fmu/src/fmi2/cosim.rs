//! The FMI 2.0 Co-Simulation functions: `fmi2DoStep`, `fmi2CancelStep`
//! (no asynchronous step), the input and output derivatives (not
//! supported) and the status getters.

use libc::size_t;

use super::*;
use crate::instance::{error, Operation, Res, Status, LOG_ALL};
use crate::shell::{exports, null};

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

/// Exports the status getters: `name(value type) operation |inst, kind,
/// value| body;`
/// after the state check and the null check of `value`.
macro_rules! status_exports {
    ($($name:ident($ty:ty) $op:ident |$i:ident, $s:ident, $v:pat_param| $body:expr;)*) => {$(
        #[no_mangle]
        pub unsafe extern "C" fn $name(
            c: fmi2Component,
            $s: fmi2StatusKind,
            value: *mut $ty,
        ) -> fmi2Status {
            call(c, stringify!($name), |$i| {
                $i.require(Operation::$op)?;
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
    fmi2GetStatus(fmi2Status) GetStatus |_inst, s, _| {
        discard(format!("status kind {s} is not available: fmi2DoStep never returns fmi2Pending"))
    };
    fmi2GetRealStatus(fmi2Real) GetRealStatus |inst, s, v| {
        if s != fmi2LastSuccessfulTime {
            return discard(format!("status kind {s} has no Real value"));
        }
        *v = inst.last_successful_time();
        Ok(Status::Ok)
    };
    fmi2GetIntegerStatus(fmi2Integer) GetIntegerStatus |_inst, s, _| discard(format!("status kind {s} has no Integer value"));
    fmi2GetBooleanStatus(fmi2Boolean) GetBooleanStatus |inst, s, v| {
        if s != fmi2Terminated {
            return discard(format!("status kind {s} has no Boolean value"));
        }
        *v = inst.terminated() as fmi2Boolean;
        Ok(Status::Ok)
    };
    fmi2GetStringStatus(fmi2String) GetStringStatus |_inst, s, v| {
        *v = c"".as_ptr();
        discard(format!("status kind {s} has no String value: fmi2DoStep never returns fmi2Pending"))
    };
}
