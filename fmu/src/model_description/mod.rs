//! The model-neutral part of the FMUs' interface: the variable types and
//! the static-table mechanics ([`variables`]), the variables every model has
//! ([`COMMON_VARIABLES`]: `substeps` and the execution parameters, served by
//! the instance), the scene file limits, the log categories, and the
//! `modelDescription.xml` writer with the GUID hash ([`xml`]). Each model's
//! own table is in its folder ([`crate::models::yarn::variables`],
//! [`crate::models::massspring::variables`](mod@crate::models::massspring::variables)); this module imports none of
//! them.

pub mod variables;
pub mod xml;
pub mod xml3;

pub use variables::*;
pub use xml::*;
pub use xml3::*;

/// Name of the scene file inside the FMU's `resources/` folder.
pub const SCENE_FILE: &str = "scene.toml";

/// `substeps` (Integer output of every model).
pub const VR_SUBSTEPS: u32 = 200;
/// `max_substeps_per_step` (Integer parameter of every model).
pub const VR_MAX_SUBSTEPS: u32 = 201;
/// `threads` (Integer parameter of every model).
pub const VR_THREADS: u32 = 202;

/// `time`, the independent variable of the FMI 3.0 FMU (FMI 3.0 asks for
/// exactly one; the FMI 2.0 FMU has none).
pub const VR_TIME: u32 = 0;

/// The first value reference of the FMI 3.0 Float64 arrays
/// ([`ArrayVariable`]), far above every scalar's.
pub const VR_ARRAY_BASE: u32 = 1 << 30;

/// Largest scene file the FMU reads (the bundled one and the `scene`
/// parameter): 1 MiB. The built-in scenes are below 4 KiB.
pub const MAX_SCENE_BYTES: u64 = 1 << 20;

/// Reads a scene file: a regular file (symbolic links are followed) of at
/// most [`MAX_SCENE_BYTES`], UTF-8. Devices, FIFOs, directories and larger
/// files are refused before anything is read.
pub fn read_scene_text(path: &std::path::Path) -> Result<String, String> {
    use std::io::Read as _;
    let shown = path.display();
    let meta =
        std::fs::metadata(path).map_err(|e| format!("cannot read scene file {shown}: {e}"))?;
    if !meta.is_file() {
        let what = if meta.is_dir() {
            "a directory"
        } else {
            "not a regular file (device, FIFO or socket)"
        };
        return Err(format!("scene file {shown} is {what}"));
    }
    if meta.len() > MAX_SCENE_BYTES {
        return Err(format!(
            "scene file {shown} has {} bytes, more than the limit of {MAX_SCENE_BYTES}",
            meta.len()
        ));
    }
    let file =
        std::fs::File::open(path).map_err(|e| format!("cannot read scene file {shown}: {e}"))?;
    // The file may grow between the check and the read: read one byte
    // past the limit at most.
    let mut bytes = Vec::new();
    file.take(MAX_SCENE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read scene file {shown}: {e}"))?;
    if bytes.len() as u64 > MAX_SCENE_BYTES {
        return Err(format!(
            "scene file {shown} is larger than the limit of {MAX_SCENE_BYTES} bytes"
        ));
    }
    String::from_utf8(bytes).map_err(|_| format!("scene file {shown} is not UTF-8 text"))
}

/// Default of `max_substeps_per_step`: about 2.3 s of work for a step of the
/// default yarn scene (228 us per substep), 12 s on the cloth (1.2 ms per
/// substep), 0.06 s on the wire.
pub const DEFAULT_MAX_SUBSTEPS: u32 = 10_000;

/// Default of `threads`: 0, the process-wide rayon pool (one thread per core).
pub const DEFAULT_THREADS: u32 = 0;

/// Largest accepted `threads`.
pub const MAX_THREADS: u32 = 1024;
// The `threads` description in [`COMMON_VARIABLES`] names this limit.
const _: () = assert!(MAX_THREADS == 1024);

/// The variables every model has, after the model's own and before its
/// per-object outputs: the substep count and the execution parameters
/// (the substep budget of one `fmi2DoStep`, the instance's thread count).
/// They are served by the instance ([`crate::instance`]), not the models.
/// A row of [`COMMON_VARIABLES`]: name, value reference, causality,
/// variability, start value, description (all Integer).
pub type CommonVariable = (
    &'static str,
    u32,
    &'static str,
    &'static str,
    Option<u32>,
    &'static str,
);

pub static COMMON_VARIABLES: [CommonVariable; 3] = [
    ("substeps", VR_SUBSTEPS, "output", "discrete", None, "Substeps taken since initialization"),
    ("max_substeps_per_step", VR_MAX_SUBSTEPS, "parameter", "fixed", Some(DEFAULT_MAX_SUBSTEPS), "Most substeps one fmi2DoStep may run (at least 1); a longer step is refused with fmi2Error before any substep runs"),
    ("threads", VR_THREADS, "parameter", "fixed", Some(DEFAULT_THREADS), "Worker threads of this instance's own thread pool (1 to 1024); 0: the process-wide pool, one thread per core. Results are bit-identical for every value"),
];

/// [`COMMON_VARIABLES`] as written in `modelDescription.xml` (all Integer).
pub fn common_variables() -> impl Iterator<Item = Variable> {
    COMMON_VARIABLES
        .iter()
        .map(
            |&(name, vr, causality, variability, start, description)| Variable {
                name: name.into(),
                vr,
                ty: VarType::Integer,
                causality,
                variability,
                unit: None,
                start: start.map(|s| s.to_string()),
                description: description.into(),
            },
        )
}

/// The standard FMI 2.0 log categories, all of which this FMU uses.
pub const LOG_CATEGORIES: [(&str, &str); 7] = [
    (
        "logEvents",
        "Life-cycle events: instantiation, initialization, termination, reset, state restore",
    ),
    ("logStatusWarning", "Calls that return fmi2Warning"),
    (
        "logStatusDiscard",
        "Calls that return fmi2Discard (a diverged step)",
    ),
    (
        "logStatusError",
        "Calls that return fmi2Error (always logged)",
    ),
    (
        "logStatusFatal",
        "Calls that return fmi2Fatal (always logged)",
    ),
    (
        "logStatusPending",
        "Calls that return fmi2Pending (never: no asynchronous steps)",
    ),
    ("logAll", "Every call with its arguments"),
];
