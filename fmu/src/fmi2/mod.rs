//! The 34 exported FMI 2.0 functions (25 common, 9 co-simulation): a
//! hand-written C ABI over [`Instance`](crate::instance::Instance), one file
//! per function group as in FMI 2.0.4, chapter 2.1 and 4.2 ([`common`],
//! [`values`], [`fmu_state`], [`cosim`]). Every export runs in the shell
//! both versions share ([`crate::shell`]): it checks its pointers, catches
//! panics (a panic becomes `fmi2Fatal` for that instance and never unwinds
//! into the host) and logs every failure through the callback. This module
//! imports nothing of [`crate::fmi3`], nor it of this one.

#![allow(
    non_snake_case,
    non_camel_case_types,
    non_upper_case_globals,
    clippy::missing_safety_doc
)]

use std::ffi::{c_char, c_int, c_uint, c_void};

use libc::size_t;

use crate::instance::{Logger, Status};
use crate::shell::call;

pub mod common;
pub mod cosim;
pub mod fmu_state;
pub mod values;

pub use common::*;
pub use cosim::*;
pub use fmu_state::*;
pub use values::*;

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
