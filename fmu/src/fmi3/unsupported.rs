//! The FMI 3.0 functions this Co-Simulation FMU does not support: Model
//! Exchange, Scheduled Execution, event mode, configuration mode, clocks
//! and intervals, directional and adjoint derivatives, and the variable
//! types it has none of (Float32, the 8-, 16- and 64-bit integers, UInt32,
//! Binary). Each returns fmi3Error with the reason logged, except that a
//! getter or setter of a type without variables given no value reference
//! has nothing to do and returns fmi3OK.

use libc::size_t;

use super::*;
use crate::instance::error;
use crate::shell::{exports, slice};

/// Exports functions that always refuse: `name(args) => reason;`.
macro_rules! refused {
    ($($name:ident ( $($arg:ident : $ty:ty),* ) => $why:expr;)*) => {$(
        #[no_mangle]
        pub unsafe extern "C" fn $name(instance: fmi3Instance, $($arg: $ty),*) -> fmi3Status {
            $(let _ = $arg;)*
            call3(instance, stringify!($name), |_| error($why))
        }
    )*};
}

/// A getter or setter of a type this FMU has no variable of: nothing to do
/// for no value reference, else the first one is refused, by name where it
/// is a variable of another type.
fn no_variable(
    inst: &crate::instance::Instance,
    ty: &str,
    vr: *const fmi3ValueReference,
    nvr: size_t,
) -> crate::instance::Res<Status> {
    if nvr == 0 {
        return Ok(Status::Ok);
    }
    // SAFETY: FMI passes `nvr` value references.
    match unsafe { slice(vr, nvr) } {
        Some(vrs) => {
            let which = match inst.variable(vrs[0]) {
                Some(_) => format!("{} is not a {ty} variable", inst.shown(vrs[0])),
                None => format!("no {ty} variable has value reference {}", vrs[0]),
            };
            error(format!(
                "{which} (this FMU has Float64, Int32, Boolean and String variables)"
            ))
        }
        None => error("valueReferences is a null pointer"),
    }
}

/// Exports getters and setters of types without variables: `name(the
/// arguments after nValueReferences) the operation whose state-table row it checks => "type";`.
macro_rules! no_variable {
    ($($name:ident($($arg:ident: $ty:ty),*) $op:ident => $tyname:literal;)*) => {$(
        exports! { call3(fmi3Instance) -> fmi3Status;
            $name(valueReferences: *const fmi3ValueReference, nValueReferences: size_t, $($arg: $ty),*) |inst| {
                inst.require(crate::instance::Operation::$op)?;
                no_variable(inst, $tyname, valueReferences, nValueReferences)
            };
        }
    )*};
}

/// Declares each type without variables (its `fmi3FunctionTypes.h` name)
/// and exports its getter and setter: `(getter, setter, type name, C type
/// = Rust type);`.
macro_rules! no_such_type {
    ($(($get:ident, $set:ident, $tyname:literal, $elem:ident = $rust:ty);)*) => {$(
        #[doc = concat!("`", stringify!($elem), "` (no variable of this type).")]
        pub type $elem = $rust;
        no_variable! {
            $get(_values: *mut $elem, _nValues: size_t) GetFloat => $tyname;
            $set(_values: *const $elem, _nValues: size_t) SetFloat => $tyname;
        }
    )*};
}

no_such_type! {
    (fmi3GetFloat32, fmi3SetFloat32, "Float32", fmi3Float32 = f32);
    (fmi3GetInt8, fmi3SetInt8, "Int8", fmi3Int8 = i8);
    (fmi3GetUInt8, fmi3SetUInt8, "UInt8", fmi3UInt8 = u8);
    (fmi3GetInt16, fmi3SetInt16, "Int16", fmi3Int16 = i16);
    (fmi3GetUInt16, fmi3SetUInt16, "UInt16", fmi3UInt16 = u16);
    (fmi3GetUInt32, fmi3SetUInt32, "UInt32", fmi3UInt32 = u32);
    (fmi3GetInt64, fmi3SetInt64, "Int64", fmi3Int64 = i64);
    (fmi3GetUInt64, fmi3SetUInt64, "UInt64", fmi3UInt64 = u64);
}

no_variable! {
    fmi3GetBinary(_valueSizes: *mut size_t, _values: *mut fmi3Binary, _nValues: size_t) GetFloat => "Binary";
    fmi3SetBinary(_valueSizes: *const size_t, _values: *const fmi3Binary, _nValues: size_t) SetFloat => "Binary";
}

const NO_CLOCKS: &str = "not supported: this FMU has no clocks";
const NO_ME: &str = "not supported: this FMU has no Model Exchange interface (Co-Simulation only)";
const NO_EVENTS: &str = "not supported: this FMU has no event mode (hasEventMode=\"false\")";

refused! {
    fmi3EnterEventMode() => NO_EVENTS;
    fmi3GetClock(_vr: *const fmi3ValueReference, _nvr: size_t, _values: *mut fmi3Clock) => NO_CLOCKS;
    fmi3SetClock(_vr: *const fmi3ValueReference, _nvr: size_t, _values: *const fmi3Clock) => NO_CLOCKS;
    fmi3GetDirectionalDerivative(_unknowns: *const fmi3ValueReference, _nUnknowns: size_t, _knowns: *const fmi3ValueReference, _nKnowns: size_t, _seed: *const fmi3Float64, _nSeed: size_t, _sensitivity: *mut fmi3Float64, _nSensitivity: size_t) => "not supported (providesDirectionalDerivatives=\"false\")";
    fmi3GetAdjointDerivative(_unknowns: *const fmi3ValueReference, _nUnknowns: size_t, _knowns: *const fmi3ValueReference, _nKnowns: size_t, _seed: *const fmi3Float64, _nSeed: size_t, _sensitivity: *mut fmi3Float64, _nSensitivity: size_t) => "not supported (providesAdjointDerivatives=\"false\")";
    fmi3EnterConfigurationMode() => "not supported: this FMU has no structural parameters";
    fmi3ExitConfigurationMode() => "not supported: this FMU has no structural parameters";
    fmi3GetIntervalDecimal(_vr: *const fmi3ValueReference, _nvr: size_t, _intervals: *mut fmi3Float64, _qualifiers: *mut fmi3IntervalQualifier) => NO_CLOCKS;
    fmi3GetIntervalFraction(_vr: *const fmi3ValueReference, _nvr: size_t, _counters: *mut fmi3UInt64, _resolutions: *mut fmi3UInt64, _qualifiers: *mut fmi3IntervalQualifier) => NO_CLOCKS;
    fmi3GetShiftDecimal(_vr: *const fmi3ValueReference, _nvr: size_t, _shifts: *mut fmi3Float64) => NO_CLOCKS;
    fmi3GetShiftFraction(_vr: *const fmi3ValueReference, _nvr: size_t, _counters: *mut fmi3UInt64, _resolutions: *mut fmi3UInt64) => NO_CLOCKS;
    fmi3SetIntervalDecimal(_vr: *const fmi3ValueReference, _nvr: size_t, _intervals: *const fmi3Float64) => NO_CLOCKS;
    fmi3SetIntervalFraction(_vr: *const fmi3ValueReference, _nvr: size_t, _counters: *const fmi3UInt64, _resolutions: *const fmi3UInt64) => NO_CLOCKS;
    fmi3SetShiftDecimal(_vr: *const fmi3ValueReference, _nvr: size_t, _shifts: *const fmi3Float64) => NO_CLOCKS;
    fmi3SetShiftFraction(_vr: *const fmi3ValueReference, _nvr: size_t, _counters: *const fmi3UInt64, _resolutions: *const fmi3UInt64) => NO_CLOCKS;
    fmi3EvaluateDiscreteStates() => "not supported (providesEvaluateDiscreteStates=\"false\")";
    fmi3UpdateDiscreteStates(_discreteStatesNeedUpdate: *mut fmi3Boolean, _terminateSimulation: *mut fmi3Boolean, _nominalsChanged: *mut fmi3Boolean, _valuesChanged: *mut fmi3Boolean, _nextEventTimeDefined: *mut fmi3Boolean, _nextEventTime: *mut fmi3Float64) => NO_EVENTS;
    fmi3EnterContinuousTimeMode() => NO_ME;
    fmi3CompletedIntegratorStep(_noSetFMUStatePriorToCurrentPoint: fmi3Boolean, _enterEventMode: *mut fmi3Boolean, _terminateSimulation: *mut fmi3Boolean) => NO_ME;
    fmi3SetTime(_time: fmi3Float64) => NO_ME;
    fmi3SetContinuousStates(_states: *const fmi3Float64, _n: size_t) => NO_ME;
    fmi3GetContinuousStateDerivatives(_derivatives: *mut fmi3Float64, _n: size_t) => NO_ME;
    fmi3GetEventIndicators(_indicators: *mut fmi3Float64, _n: size_t) => NO_ME;
    fmi3GetContinuousStates(_states: *mut fmi3Float64, _n: size_t) => NO_ME;
    fmi3GetNominalsOfContinuousStates(_nominals: *mut fmi3Float64, _n: size_t) => NO_ME;
    fmi3GetNumberOfEventIndicators(_n: *mut size_t) => NO_ME;
    fmi3GetNumberOfContinuousStates(_n: *mut size_t) => NO_ME;
    fmi3ActivateModelPartition(_clockReference: fmi3ValueReference, _activationTime: fmi3Float64) => "not supported: this FMU has no Scheduled Execution interface";
}
