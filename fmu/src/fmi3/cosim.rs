//! The FMI 3.0 Co-Simulation functions: `fmi3EnterStepMode` (a no-op: without
//! event mode the FMU is in Step Mode from `fmi3ExitInitializationMode` on),
//! `fmi3DoStep` and `fmi3GetOutputDerivatives` (not supported).

use libc::size_t;

use super::*;
use crate::instance::{error, Operation, LOG_ALL};

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterStepMode(instance: fmi3Instance) -> fmi3Status {
    call3(instance, "fmi3EnterStepMode", |inst| {
        inst.require(Operation::EnterStepMode)?;
        Ok(Status::Ok)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetOutputDerivatives(
    instance: fmi3Instance,
    _valueReferences: *const fmi3ValueReference,
    _nValueReferences: size_t,
    _orders: *const fmi3Int32,
    _values: *mut fmi3Float64,
    _nValues: size_t,
) -> fmi3Status {
    call3(instance, "fmi3GetOutputDerivatives", |_| {
        error("not supported (maxOutputDerivativeOrder=\"0\")")
    })
}

/// One communication step from `currentCommunicationPoint`: the same
/// stepping as `fmi2DoStep` ([`Instance::do_step`]). The flags are always
/// written (when their pointers are not null): no event handling, never an
/// early return, `terminateSimulation` after a step that diverged (then
/// fmi3Discard, and the outputs are those of `lastSuccessfulTime`).
#[no_mangle]
pub unsafe extern "C" fn fmi3DoStep(
    instance: fmi3Instance,
    currentCommunicationPoint: fmi3Float64,
    communicationStepSize: fmi3Float64,
    _noSetFMUStatePriorToCurrentPoint: fmi3Boolean,
    eventHandlingNeeded: *mut fmi3Boolean,
    terminateSimulation: *mut fmi3Boolean,
    earlyReturn: *mut fmi3Boolean,
    lastSuccessfulTime: *mut fmi3Float64,
) -> fmi3Status {
    let (t, h) = (currentCommunicationPoint, communicationStepSize);
    call3(instance, "fmi3DoStep", |inst| {
        if inst.log_all() {
            inst.log(
                Status::Ok,
                LOG_ALL,
                &format!("fmi3DoStep(t = {t}, h = {h})"),
            );
        }
        let result = inst.do_step(t, h);
        // SAFETY: each flag pointer is null or points to a writable value
        // (FMI contract).
        unsafe {
            if let Some(e) = eventHandlingNeeded.as_mut() {
                *e = false;
            }
            if let Some(e) = earlyReturn.as_mut() {
                *e = false;
            }
            if let Some(e) = terminateSimulation.as_mut() {
                *e = inst.terminated();
            }
            if let Some(e) = lastSuccessfulTime.as_mut() {
                *e = inst.last_successful_time();
            }
        }
        result
    })
}
