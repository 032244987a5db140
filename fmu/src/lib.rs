//! # YarnBundle: an FMI 2.0 Co-Simulation FMU of the yarnsim MPM yarn bundle
//!
//! The cdylib (`libYarnBundle.so`, shipped as `binaries/linux64/YarnBundle.so`)
//! exports the 34 `fmi2*` functions of FMI 2.0 Co-Simulation ([`ffi`]). The
//! scene it runs travels in the FMU's `resources/scene.toml`; its number of
//! yarns fixes the outputs, so `modelDescription.xml` is generated from the
//! scene ([`model::model_description`]) by the `build-fmu` packager.
//!
//! * [`model`]: variables, value references, GUID, `modelDescription.xml`.
//! * [`instance`]: the FMI state machine around a [`yarnsim::YarnSim`],
//!   FMU state snapshots and their serialization.
//! * [`ffi`]: the C ABI.
//!
//! See the README, section "YarnBundle: the FMI 2.0 Co-Simulation FMU", for
//! the variables and the build command.

// The crate is named after the FMI modelIdentifier `YarnBundle`.
#![allow(non_snake_case)]

pub mod ffi;
pub mod instance;
pub mod model;
pub mod package;

pub use model::{guid, model_description, MODEL_IDENTIFIER};
