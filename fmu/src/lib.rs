//! # YarnBundle and MassSpring: FMI 2.0 and FMI 3.0 Co-Simulation FMUs of yarnsim
//!
//! The cdylib (`libYarnBundle.so`, shipped as `binaries/linux64/YarnBundle.so`,
//! or as `binaries/linux64/MassSpring.so` in a mass-spring FMU) exports the 34
//! `fmi2*` functions of FMI 2.0 Co-Simulation ([`ffi`]) and the 75 `fmi3*`
//! functions of FMI 3.0 ([`fmi3`]; Co-Simulation works, the rest returns
//! fmi3Error with a logged reason). The FMI 3.0 FMU (`build-fmu
//! --fmi-version 3`, the library under `binaries/x86_64-linux/`) has the same
//! variables plus Float64 arrays of the whole state: every yarn's vertex
//! positions and velocities, every particle's position, with sizes fixed
//! by the bundled scene ([`model::ArrayVariable`], [`yarn::arrays`]). The scene it runs
//! travels in the FMU's `resources/scene.toml`: a yarn scene makes it the MPM
//! yarn bundle (`YarnBundle`), a mass-spring scene (`wire`, `cloth`, ...) the
//! mass-spring system (`MassSpring`). The scene fixes the outputs (yarns or
//! particles), so `modelDescription.xml` is generated from it
//! ([`SceneFmu::model_description`] on [`yarnsim::scene::Scene`]) by the
//! `build-fmu` packager (crate `yarnsim-fmu-pack` in `fmu-pack/`, so this
//! library does not carry the zip writer and the ELF reader).
//!
//! Model-neutral (they import no model):
//! * [`model`]: the variable types and static-table mechanics, the variables
//!   every model has, the `modelDescription.xml` writers (FMI 2.0, FMI 3.0)
//!   and the GUID hash.
//! * [`fmu_model`]: the [`fmu_model::FmuModel`] trait between the FMI front
//!   end and the models, with typed errors.
//! * [`state_bytes`]: the framing of a serialized FMU state (magics, version,
//!   writer and reader); [`clock`]: the wrapper's time keeping.
//! * [`snapshot`]: FMU state snapshots and their serialization.
//! * [`state_machine`]: statuses, states and the table of the states each
//!   function is allowed in.
//! * [`resources`], [`logging`]: the resource location and the logger.
//!
//! One module per model, each with its variable table and its `FmuModel`:
//! * [`yarn`] (table in [`yarn::variables`]), [`massspring`].
//!
//! Above them:
//! * [`models`]: the bundled scene's model, identifier, GUID and description
//!   (the one module that knows both models).
//! * [`instance`]: an instance around either model: stepping, values.
//! * [`ffi`]: the FMI 2.0 C ABI; [`fmi3`]: the FMI 3.0 C ABI (the same
//!   instance with [`state_machine::Api::Fmi3`]: the table's fmi3 rows, FMI
//!   3.0 words in the log, the non-variadic logger).
//!
//! See `docs/fmu.md` for the FMI 2.0 FMUs (variables, build command),
//! `docs/fmu-masters.md` for fmpy and other masters, and `docs/fmu3.md` for
//! the FMI 3.0 ones (arrays, fmpy, what differs).

// The crate is named after the FMI modelIdentifier `YarnBundle`.
#![allow(non_snake_case)]
// Every unsafe operation sits in its own `unsafe` block with a SAFETY
// comment, also inside `unsafe fn` (the C ABIs in `ffi/` and `fmi3/`): the workspace
// lints `unsafe_op_in_unsafe_fn` and `clippy::undocumented_unsafe_blocks`
// (Cargo.toml) deny anything else.

pub mod clock;
pub mod ffi;
pub mod fmi3;
pub mod fmu_model;
pub mod instance;
pub mod logging;
pub mod massspring;
pub mod model;
pub mod models;
pub mod resources;
pub mod snapshot;
pub mod state_bytes;
pub mod state_machine;
pub mod yarn;

pub use models::{new_model, scene_from_toml_str, SceneFmu};
pub use yarn::variables::{guid, model_description, MODEL_IDENTIFIER};

/// The exit code of a command-line tool of the FMU crates (`fmu-replay`,
/// and `build-fmu` in yarnsim-fmu-pack): success, or failure with the error
/// printed after the tool's name.
pub fn tool_exit(tool: &str, result: Result<(), String>) -> std::process::ExitCode {
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{tool}: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}
