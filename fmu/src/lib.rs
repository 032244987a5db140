//! # YarnBundle and MassSpring: FMI 2.0 Co-Simulation FMUs of yarnsim
//!
//! The cdylib (`libYarnBundle.so`, shipped as `binaries/linux64/YarnBundle.so`,
//! or as `binaries/linux64/MassSpring.so` in a mass-spring FMU) exports the 34
//! `fmi2*` functions of FMI 2.0 Co-Simulation ([`ffi`]). The scene it runs
//! travels in the FMU's `resources/scene.toml`: a yarn scene makes it the MPM
//! yarn bundle (`YarnBundle`), a mass-spring layout (`wire`, `cloth`, ...) the
//! mass-spring system (`MassSpring`). The scene fixes the outputs (yarns or
//! particles), so `modelDescription.xml` is generated from it
//! ([`model::FmuScene::model_description`]) by the `build-fmu` packager (crate
//! `yarnsim-fmu-pack` in `fmu-pack/`, so this library does not carry the zip
//! writer and the ELF reader).
//!
//! * [`model`]: the YarnBundle variables and value references, GUIDs, the
//!   `modelDescription.xml` writer shared by both FMUs.
//! * [`fmu_model`]: the [`fmu_model::FmuModel`] trait between the FMI front
//!   end and the models, with typed errors.
//! * [`yarn`], [`massspring`]: each model's inputs, parameters, outputs and
//!   its part of a serialized FMU state (they implement `FmuModel`).
//! * [`instance`]: an instance around either model: clock, stepping, values.
//! * [`state_machine`]: statuses, states and the table of the states each
//!   function is allowed in.
//! * [`state_bytes`]: FMU state snapshots and their serialization.
//! * [`resources`], [`logging`]: the resource location and the logger.
//! * [`ffi`]: the C ABI.
//!
//! See the README, section "YarnBundle: the FMI 2.0 Co-Simulation FMU", for
//! the variables and the build command.

// The crate is named after the FMI modelIdentifier `YarnBundle`.
#![allow(non_snake_case)]
// Every unsafe operation sits in its own `unsafe` block with a SAFETY
// comment, also inside `unsafe fn` (the C ABI in `ffi.rs`): the workspace
// lints `unsafe_op_in_unsafe_fn` and `clippy::undocumented_unsafe_blocks`
// (Cargo.toml) deny anything else.

pub mod ffi;
pub mod fmu_model;
pub mod instance;
pub mod logging;
pub mod massspring;
pub mod model;
pub mod resources;
pub mod state_bytes;
pub mod state_machine;
pub mod yarn;

pub use model::{guid, model_description, FmuScene, MODEL_IDENTIFIER};
