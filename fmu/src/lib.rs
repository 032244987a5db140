//! # YarnBundle and MassSpring: FMI 2.0 and FMI 3.0 Co-Simulation FMUs of yarnsim
//!
//! The cdylib (`libyarnsim_fmu.so`, [`LIBRARY_FILE`]; shipped as
//! `binaries/linux64/YarnBundle.so`, or as `binaries/linux64/MassSpring.so`
//! in a mass-spring FMU) exports the 34 `fmi2*` functions of FMI 2.0
//! Co-Simulation ([`fmi2`]) and the 75 `fmi3*` functions of FMI 3.0
//! ([`fmi3`]; Co-Simulation works, the rest returns fmi3Error with a logged
//! reason). The FMI 3.0 FMU (`build-fmu --fmi-version 3`, the library under
//! `binaries/x86_64-linux/`) has the same variables plus Float64 arrays of
//! the whole simulation: every yarn's vertex positions and velocities,
//! every particle's position, with sizes fixed by the bundled scene
//! ([`model_description::ArrayVariable`], [`models::yarn::arrays`],
//! [`models::massspring::arrays`]). The scene it runs travels in the FMU's
//! `resources/scene.toml`: a yarn scene makes it the MPM yarn bundle
//! (`YarnBundle`), a mass-spring scene (`wire`, `cloth`, ...) the
//! mass-spring system (`MassSpring`). The scene fixes the outputs (yarns or
//! particles), so `modelDescription.xml` is generated from it
//! ([`SceneFmu::model_description`] on [`yarnsim::scene::Scene`]) by the
//! `build-fmu` packager (crate `yarnsim-fmu-pack` in `fmu-pack/`, so this
//! library does not carry the zip writer and the ELF reader).
//!
//! The crate and its library have one name, `yarnsim_fmu`: the library
//! hosts both models, and FMI wants the file in an FMU named after the
//! modelIdentifier, which the packager does as it copies it.
//!
//! The layout follows modelica/Reference-FMUs, where `fmi2Functions.c` and
//! `fmi3Functions.c` are siblings over one `model.h` and each model is a
//! folder:
//! * [`fmi2`], [`fmi3`]: the FMI 2.0 and FMI 3.0 C ABIs, one file per
//!   function group; siblings, neither names the other (checked by
//!   `tools/checks/check_modules.py`).
//! * [`shell`]: the C-ABI shell both share (the instance check, the logged
//!   failures, the caught panics, the pointer helpers, the export macros,
//!   the FMU-state function bodies).
//! * [`instance`]: one instance around either model, version-neutral: its
//!   phase and the state table keyed by [`instance::Operation`]
//!   ([`instance::phase`]), stepping, values, FMU states (the snapshots of
//!   get/set FMU state and their bytes, [`instance::snapshot`]), clock,
//!   resources and logging; the version that made it ([`instance::Api`])
//!   only names the functions and picks the table's column.
//! * [`models`]: the bundled scene's model, identifier, GUID and
//!   description (the one module that knows both models), the
//!   [`models::model::FmuModel`] trait between the instance and the
//!   models, the framing of a model's part of a serialized FMU state
//!   ([`models::state_bytes`]), and one folder per model of the same shape:
//!   [`models::yarn`], [`models::massspring`] (`mod.rs`: the model and its
//!   step; `variables.rs`: value references, table, GUID, description;
//!   `arrays.rs`: the FMI 3.0 array outputs; `fmu_state.rs`: its part of an
//!   FMU state; the yarn bundle also holds its inputs and pin forces).
//! * [`model_description`]: model-neutral, imports no model: the variable
//!   types and static-table mechanics, the variables every model has, the
//!   `modelDescription.xml` writers (FMI 2.0, FMI 3.0) and the GUID hash.
//!
//! "State" means an FMU state only (what `fmi2GetFMUstate` /
//! `fmi3GetFMUState` save); the lifecycle of an instance is its phase
//! ([`instance::Phase`]), the simulation's quantities are its values.
//!
//! See `docs/fmu.md` for the FMI 2.0 FMUs (variables, build command),
//! `docs/fmu-masters.md` for fmpy and other masters, and `docs/fmu3.md` for
//! the FMI 3.0 ones (arrays, fmpy, what differs).

// Every unsafe operation sits in its own `unsafe` block with a SAFETY
// comment, also inside `unsafe fn` (the C ABIs in `fmi2/`, `fmi3/` and
// `shell/`): the workspace lints `unsafe_op_in_unsafe_fn` and `clippy::undocumented_unsafe_blocks`
// (Cargo.toml) deny anything else.

pub mod fmi2;
pub mod fmi3;
pub mod instance;
pub mod model_description;
pub mod models;
pub mod shell;

pub use models::{new_model, scene_from_toml_str, SceneFmu};

/// The shared library cargo builds (`target/<profile>/libyarnsim_fmu.so`):
/// named after the crate, not after a model, since it hosts both
/// (`YarnBundle`, `MassSpring`); the packager copies it into the FMU as
/// `binaries/<platform>/<modelIdentifier>.so`, the name FMI requires
/// (FMI 2.0.4, section 2.3; FMI 3.0, section 2.5, "FMU Distribution").
pub const LIBRARY_FILE: &str = "libyarnsim_fmu.so";
pub use models::yarn::variables::MODEL_IDENTIFIER;

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
