//! The FMI 3.0 C ABI: all 75 functions of `fmi3FunctionTypes.h` (FMI 3.0
//! standard, chapter 2.2 and 4.2), exported by the same cdylib as the FMI 2.0
//! functions ([`crate::fmi2`]) and a thin shell over the same [`Instance`] and
//! models. Co-Simulation without event mode works ([`common`], [`values`],
//! [`fmu_state`], [`cosim`]); Model Exchange, Scheduled Execution, clocks,
//! intervals, Binary and the other integer and float types, directional and
//! adjoint derivatives and output derivatives return `fmi3Error` with a
//! logged reason ([`unsupported`]), as the modelDescription declares.
//!
//! Every export checks its pointers, catches panics (a panic becomes
//! `fmi3Fatal` for that instance and never unwinds into the host) and logs
//! every failure through the `fmi3LogMessageCallback`, which is not variadic
//! (`(instanceEnvironment, status, category, message)`). The state table is
//! [`crate::instance::Operation::allowed`]'s FMI 3.0 rows.

#![allow(
    non_snake_case,
    non_camel_case_types,
    non_upper_case_globals,
    clippy::missing_safety_doc,
    clippy::too_many_arguments
)]

use std::ffi::{c_char, c_int, c_void};

pub mod common;
pub mod cosim;
pub mod fmu_state;
pub mod unsupported;
pub mod values;

use crate::instance::{Instance, Status};
use crate::shell::call;

pub type fmi3Instance = *mut c_void;
pub type fmi3InstanceEnvironment = *mut c_void;
pub type fmi3FMUState = *mut c_void;
pub type fmi3ValueReference = u32;
pub type fmi3Float64 = f64;
pub type fmi3Int32 = i32;
/// The other integer types and Float32: [`unsupported`] (no variables).
pub use unsupported::{
    fmi3Float32, fmi3Int16, fmi3Int64, fmi3Int8, fmi3UInt16, fmi3UInt32, fmi3UInt64, fmi3UInt8,
};
/// A C `bool` (one byte), unlike `fmi2Boolean` (a C `int`).
pub type fmi3Boolean = bool;
pub type fmi3Char = c_char;
pub type fmi3String = *const fmi3Char;
pub type fmi3Byte = u8;
pub type fmi3Binary = *const fmi3Byte;
pub type fmi3Clock = bool;
pub type fmi3Status = c_int;
pub type fmi3DependencyKind = c_int;
pub type fmi3IntervalQualifier = c_int;

pub const fmi3OK: fmi3Status = Status::Ok as c_int;
pub const fmi3Warning: fmi3Status = Status::Warning as c_int;
pub const fmi3Discard: fmi3Status = Status::Discard as c_int;
pub const fmi3Error: fmi3Status = Status::Error as c_int;
pub const fmi3Fatal: fmi3Status = Status::Fatal as c_int;
/// `fmi3DependencyKind` `fmi3Dependent`: no particular structure known.
pub const fmi3Dependent: fmi3DependencyKind = 5;

/// `fmi3LogMessageCallback`.
pub type fmi3LogMessageCallback = crate::instance::logging::Logger3;
/// `fmi3IntermediateUpdateCallback` (never called: no intermediate update).
pub type fmi3IntermediateUpdateCallback = Option<
    unsafe extern "C" fn(
        fmi3InstanceEnvironment,
        fmi3Float64,
        fmi3Boolean,
        fmi3Boolean,
        fmi3Boolean,
        fmi3Boolean,
        *mut fmi3Boolean,
        *mut fmi3Float64,
    ),
>;
/// `fmi3ClockUpdateCallback` (Scheduled Execution: not supported).
pub type fmi3ClockUpdateCallback = Option<unsafe extern "C" fn(fmi3InstanceEnvironment)>;
/// `fmi3LockPreemptionCallback` / `fmi3UnlockPreemptionCallback`.
pub type fmi3PreemptionCallback = Option<unsafe extern "C" fn()>;

/// Runs `f` on the FMI 3.0 instance behind `instance` ([`call`]); an
/// FMI 2.0 instance passed to an fmi3 function is refused.
pub(crate) fn call3(
    instance: fmi3Instance,
    func: &str,
    f: impl FnOnce(&mut Instance) -> crate::instance::Res<Status>,
) -> fmi3Status {
    call(instance, func, |inst| {
        if inst.api != crate::instance::Api::Fmi3 {
            return crate::instance::error(format!(
                "{func}: the instance was made by fmi2Instantiate, not fmi3InstantiateCoSimulation"
            ));
        }
        f(inst)
    })
}

/// The 75 functions of FMI 3.0 (`fmi3FunctionTypes.h`), all exported.
pub const FMI3_FUNCTIONS: [&str; 75] = [
    "fmi3GetVersion",
    "fmi3SetDebugLogging",
    "fmi3InstantiateModelExchange",
    "fmi3InstantiateCoSimulation",
    "fmi3InstantiateScheduledExecution",
    "fmi3FreeInstance",
    "fmi3EnterInitializationMode",
    "fmi3ExitInitializationMode",
    "fmi3EnterEventMode",
    "fmi3Terminate",
    "fmi3Reset",
    "fmi3GetFloat32",
    "fmi3GetFloat64",
    "fmi3GetInt8",
    "fmi3GetUInt8",
    "fmi3GetInt16",
    "fmi3GetUInt16",
    "fmi3GetInt32",
    "fmi3GetUInt32",
    "fmi3GetInt64",
    "fmi3GetUInt64",
    "fmi3GetBoolean",
    "fmi3GetString",
    "fmi3GetBinary",
    "fmi3GetClock",
    "fmi3SetFloat32",
    "fmi3SetFloat64",
    "fmi3SetInt8",
    "fmi3SetUInt8",
    "fmi3SetInt16",
    "fmi3SetUInt16",
    "fmi3SetInt32",
    "fmi3SetUInt32",
    "fmi3SetInt64",
    "fmi3SetUInt64",
    "fmi3SetBoolean",
    "fmi3SetString",
    "fmi3SetBinary",
    "fmi3SetClock",
    "fmi3GetNumberOfVariableDependencies",
    "fmi3GetVariableDependencies",
    "fmi3GetFMUState",
    "fmi3SetFMUState",
    "fmi3FreeFMUState",
    "fmi3SerializedFMUStateSize",
    "fmi3SerializeFMUState",
    "fmi3DeserializeFMUState",
    "fmi3GetDirectionalDerivative",
    "fmi3GetAdjointDerivative",
    "fmi3EnterConfigurationMode",
    "fmi3ExitConfigurationMode",
    "fmi3GetIntervalDecimal",
    "fmi3GetIntervalFraction",
    "fmi3GetShiftDecimal",
    "fmi3GetShiftFraction",
    "fmi3SetIntervalDecimal",
    "fmi3SetIntervalFraction",
    "fmi3SetShiftDecimal",
    "fmi3SetShiftFraction",
    "fmi3EvaluateDiscreteStates",
    "fmi3UpdateDiscreteStates",
    "fmi3EnterContinuousTimeMode",
    "fmi3CompletedIntegratorStep",
    "fmi3SetTime",
    "fmi3SetContinuousStates",
    "fmi3GetContinuousStateDerivatives",
    "fmi3GetEventIndicators",
    "fmi3GetContinuousStates",
    "fmi3GetNominalsOfContinuousStates",
    "fmi3GetNumberOfEventIndicators",
    "fmi3GetNumberOfContinuousStates",
    "fmi3EnterStepMode",
    "fmi3GetOutputDerivatives",
    "fmi3DoStep",
    "fmi3ActivateModelPartition",
];
