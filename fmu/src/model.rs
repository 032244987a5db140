//! The FMU's variables, its GUID and its `modelDescription.xml`, all derived
//! from the scene the FMU runs: the number of yarns fixes the outputs, the
//! scene's material, substep and inputs give the start values. The
//! YarnBundle's variables are one static table ([`YARN_VARIABLES`]: name,
//! value reference, type, causality, variability, unit, start, description,
//! and for the Real parameters the scene field that the getter and setter
//! use); the variables every model has ([`COMMON_VARIABLES`]: `substeps` and
//! the execution parameters) are another, served by the instance.

use std::fmt::Write as _;

use yarnsim::mpm::state::fnv1a;
use yarnsim::scene::{PinMotionKind, StepSize, TransferScheme, YarnScene};

/// The FMI model identifier: the shared library's and the C symbols' name.
pub const MODEL_IDENTIFIER: &str = "YarnBundle";

/// Bumped whenever the variable layout changes; part of the GUID.
pub const INTERFACE_VERSION: u32 = 3;

/// Name of the scene file inside the FMU's `resources/` folder.
pub const SCENE_FILE: &str = "scene.toml";

// Value references. They are unique across all types.
pub const VR_ATTRACTOR_X: u32 = 1;
pub const VR_ATTRACTOR_Y: u32 = 2;
pub const VR_ATTRACTOR_STRENGTH: u32 = 3;
pub const VR_ATTRACTOR_ACTIVE: u32 = 4; // Boolean
pub const VR_GRAVITY_X: u32 = 5;
pub const VR_GRAVITY_Y: u32 = 6;
pub const VR_K: u32 = 10;
pub const VR_GAMMA: u32 = 11;
pub const VR_YOUNGS_MODULUS: u32 = 12;
pub const VR_FRICTION: u32 = 13;
pub const VR_BENDING: u32 = 14;
pub const VR_DENSITY: u32 = 15;
pub const VR_DT: u32 = 16;
pub const VR_PLASTICITY: u32 = 17; // Boolean
/// `transfer.flip_ratio` (Real parameter in [0, 1]).
pub const VR_FLIP_RATIO: u32 = 18;
pub const VR_KINETIC_ENERGY: u32 = 100;
pub const VR_ELASTIC_ENERGY: u32 = 101;
pub const VR_MAX_STRETCH: u32 = 102;
pub const VR_SUBSTEPS: u32 = 200; // Integer
/// `max_substeps_per_step` (Integer parameter of every model).
pub const VR_MAX_SUBSTEPS: u32 = 201;
/// `threads` (Integer parameter of every model).
pub const VR_THREADS: u32 = 202;
pub const VR_SCENE: u32 = 300; // String
/// `transfer.scheme` (String parameter, `"flip"` or `"apic"`).
pub const VR_TRANSFER_SCHEME: u32 = 301;
/// `yarn[i].left.x` has `VR_YARN_BASE + 4 i`, then `left.y`, `right.x`, `right.y`.
pub const VR_YARN_BASE: u32 = 1000;
/// Pin `i` (`[[pins]]` order) has `VR_PIN_BASE + 8 i + k`: k = 0..3 the
/// inputs `pin[i].x`, `.y`, `.vx`, `.vy` (only `motion = "input"` pins),
/// k = 4, 5 the outputs `pin[i].force.x`, `.force.y` (every pin).
pub const VR_PIN_BASE: u32 = 2000;
/// Offset of `pin[i].force.x` within a pin's block of 8.
pub const PIN_FORCE: u32 = 4;
/// Most pins an FMU serves (value references 2000 to 2000 + 8 * 1024 - 1).
pub const MAX_FMU_PINS: usize = 1024;

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

/// The FMI base type of a variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VarType {
    Real,
    Integer,
    Boolean,
    String,
}

/// A variable of the FMU as it appears in `modelDescription.xml`.
#[derive(Clone, Debug, PartialEq)]
pub struct Variable {
    pub name: String,
    pub vr: u32,
    pub ty: VarType,
    /// `"parameter"`, `"input"` or `"output"`.
    pub causality: &'static str,
    /// `"fixed"`, `"discrete"` or `"continuous"`.
    pub variability: &'static str,
    pub unit: Option<&'static str>,
    /// Start value as written in the XML (inputs and parameters only).
    pub start: Option<String>,
    pub description: String,
}

/// Formats an `f64` so that it reads back to the same bits (shortest round trip).
pub fn real(v: f64) -> String {
    format!("{v:?}")
}

fn boolean(b: bool) -> String {
    if b { "true" } else { "false" }.to_string()
}

/// Number of yarns the scene creates (fixes the outputs).
pub fn num_yarns(scene: &YarnScene) -> usize {
    scene.curves().len()
}

/// A Real parameter that lives in the scene (of type `S`, the yarn scene
/// by default): how to read and override it.
pub struct SceneField<S = YarnScene> {
    pub get: fn(&S) -> f64,
    pub set: fn(&mut S, f64),
    /// Must be > 0 (else >= 0).
    pub positive: bool,
    /// Largest accepted value.
    pub max: f64,
}

impl<S> Clone for SceneField<S> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<S> Copy for SceneField<S> {}

/// Where a variable's start value comes from (a scene of type `S`).
pub enum Start<S = YarnScene> {
    /// Outputs have none.
    None,
    /// A Real parameter in the scene (also its getter and setter).
    Scene(SceneField<S>),
    /// A Real read from the scene.
    Real(fn(&S) -> f64),
    /// A Boolean read from the scene.
    Bool(fn(&S) -> bool),
    /// A fixed text.
    Text(&'static str),
    /// A name read from the scene.
    Name(fn(&S) -> &'static str),
}

impl<S> Clone for Start<S> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<S> Copy for Start<S> {}

/// One row of a model's variable table; `S` is the scene type its start
/// values are read from (the yarn scene, or the mass-spring layout).
pub struct VarSpec<S = YarnScene> {
    pub name: &'static str,
    pub vr: u32,
    pub ty: VarType,
    pub causality: &'static str,
    pub variability: &'static str,
    pub unit: Option<&'static str>,
    pub start: Start<S>,
    pub description: &'static str,
}

impl<S> Clone for VarSpec<S> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<S> Copy for VarSpec<S> {}

impl<S> VarSpec<S> {
    /// The variable as written in `modelDescription.xml`, for this scene.
    pub fn variable(&self, scene: &S) -> Variable {
        Variable {
            name: self.name.to_string(),
            vr: self.vr,
            ty: self.ty,
            causality: self.causality,
            variability: self.variability,
            unit: self.unit,
            start: match self.start {
                Start::None => None,
                Start::Scene(f) => Some(real((f.get)(scene))),
                Start::Real(f) => Some(real(f(scene))),
                Start::Bool(f) => Some(boolean(f(scene))),
                Start::Text(t) => Some(t.to_string()),
                Start::Name(f) => Some(f(scene).to_string()),
            },
            description: self.description.to_string(),
        }
    }
}

/// An input row (Real inputs continuous, others discrete).
pub const fn input<S>(
    name: &'static str,
    vr: u32,
    ty: VarType,
    unit: Option<&'static str>,
    start: Start<S>,
    description: &'static str,
) -> VarSpec<S> {
    VarSpec {
        name,
        vr,
        ty,
        causality: "input",
        variability: match ty {
            VarType::Real => "continuous",
            _ => "discrete",
        },
        unit,
        start,
        description,
    }
}

/// A fixed parameter row.
pub const fn parameter<S>(
    name: &'static str,
    vr: u32,
    ty: VarType,
    unit: Option<&'static str>,
    start: Start<S>,
    description: &'static str,
) -> VarSpec<S> {
    VarSpec {
        name,
        vr,
        ty,
        causality: "parameter",
        variability: "fixed",
        unit,
        start,
        description,
    }
}

/// A continuous Real output row.
pub const fn output<S>(
    name: &'static str,
    vr: u32,
    unit: Option<&'static str>,
    description: &'static str,
) -> VarSpec<S> {
    VarSpec {
        name,
        vr,
        ty: VarType::Real,
        causality: "output",
        variability: "continuous",
        unit,
        start: Start::None,
        description,
    }
}

const fn material(
    get: fn(&YarnScene) -> f64,
    set: fn(&mut YarnScene, f64),
    positive: bool,
) -> Start {
    Start::Scene(SceneField {
        get,
        set,
        positive,
        max: 1e12,
    })
}

/// The name of a transfer scheme as the scene and `transfer.scheme` write it.
pub fn scheme_name(s: TransferScheme) -> &'static str {
    match s {
        TransferScheme::Flip => "flip",
        TransferScheme::Apic => "apic",
    }
}

/// The transfer scheme of a `transfer.scheme` value.
pub fn parse_scheme(s: &str) -> Option<TransferScheme> {
    match s {
        "flip" => Some(TransferScheme::Flip),
        "apic" => Some(TransferScheme::Apic),
        _ => None,
    }
}

use VarType::{Boolean, Real};

/// Sets the scene's `time.dt` from the `dt` parameter: 0 is `"auto"` (the
/// scene's `safety` and `dt_max` kept), a positive value a fixed substep
/// (`safety` and `dt_max`, which only `"auto"` takes, dropped).
fn set_dt(s: &mut YarnScene, v: f64) {
    if v == 0.0 {
        s.time.dt = StepSize::Auto;
    } else {
        s.time.dt = StepSize::Fixed(v);
        s.time.safety = None;
        s.time.dt_max = None;
    }
}

/// The YarnBundle's variables before the ones every model has
/// ([`COMMON_VARIABLES`]) and the per-yarn outputs ([`yarn_outputs`]), in
/// `ModelVariables` order. The Real parameters read and override the scene
/// through their [`SceneField`].
pub static YARN_VARIABLES: [VarSpec; 20] = [
    input("attractor.x", VR_ATTRACTOR_X, Real, Some("m"), Start::Real(|s| s.attractor.position[0]), "Attractor position x"),
    input("attractor.y", VR_ATTRACTOR_Y, Real, Some("m"), Start::Real(|s| s.attractor.position[1]), "Attractor position y"),
    input("attractor.strength", VR_ATTRACTOR_STRENGTH, Real, Some("m/s2"), Start::Real(|s| s.attractor.strength), "Attractor acceleration magnitude, 0 to 1e6"),
    input("attractor.active", VR_ATTRACTOR_ACTIVE, Boolean, None, Start::Bool(|s| s.attractor.active), "Whether the attractor acts"),
    input("gravity.x", VR_GRAVITY_X, Real, Some("m/s2"), Start::Real(|s| s.gravity[0]), "Gravity x, |g| at most 1e6"),
    input("gravity.y", VR_GRAVITY_Y, Real, Some("m/s2"), Start::Real(|s| s.gravity[1]), "Gravity y, |g| at most 1e6"),
    parameter("material.k", VR_K, Real, Some("Pa"), material(|s| s.material.k, |s, v| s.material.k = v, false), "Fiber stretch stiffness"),
    parameter("material.gamma", VR_GAMMA, Real, Some("Pa"), material(|s| s.material.gamma, |s, v| s.material.gamma = v, false), "Fiber shear stiffness"),
    parameter("material.youngs_modulus", VR_YOUNGS_MODULUS, Real, Some("Pa"), material(|s| s.material.youngs_modulus, |s, v| s.material.youngs_modulus = v, false), "Young's modulus of the cross-section"),
    parameter("material.friction", VR_FRICTION, Real, None, material(|s| s.material.friction, |s, v| s.material.friction = v, false), "Mohr-Coulomb friction coefficient"),
    parameter("material.bending", VR_BENDING, Real, Some("Pa"), material(|s| s.material.bending, |s, v| s.material.bending = v, false), "Bending modulus (0 disables bending)"),
    parameter("material.density", VR_DENSITY, Real, Some("kg/m"), material(|s| s.material.density, |s, v| s.material.density = v, true), "Line density"),
    parameter("dt", VR_DT, Real, Some("s"), Start::Scene(SceneField { get: |s| s.time.dt.fixed().unwrap_or(0.0), set: set_dt, positive: false, max: 1e12 }), "Substep size; 0: adaptive (the scene's dt = \"auto\": each substep is the safety factor times the stability bound of the current state, the last one before a communication point shortened to land on it). A fixed dt runs an integer number of substeps per communication step"),
    parameter("material.plasticity", VR_PLASTICITY, Boolean, None, Start::Bool(|s| s.material.plasticity), "Mohr-Coulomb return mapping on or off"),
    parameter("transfer.scheme", VR_TRANSFER_SCHEME, VarType::String, None, Start::Name(|s| scheme_name(s.transfer.scheme)), "Particle velocity update of grid-to-particle: flip (FLIP/APIC blend by transfer.flip_ratio) or apic"),
    parameter("transfer.flip_ratio", VR_FLIP_RATIO, Real, None, Start::Scene(SceneField { get: |s| s.transfer.flip_ratio, set: |s, v| s.transfer.flip_ratio = v, positive: false, max: 1.0 }), "FLIP ratio in [0, 1] of the flip scheme (1: pure FLIP; ignored by apic)"),
    parameter("scene", VR_SCENE, VarType::String, None, Start::Text(SCENE_FILE), "Scene file: a path relative to the FMU's resources folder, or absolute; it must create as many yarns as the bundled scene and have its pins (same number, same input pins)"),
    output("kinetic_energy", VR_KINETIC_ENERGY, Some("J"), "Kinetic energy (per unit depth)"),
    output("elastic_energy", VR_ELASTIC_ENERGY, Some("J"), "Elastic energy (per unit depth)"),
    output("max_stretch", VR_MAX_STRETCH, None, "Largest segment stretch |x_r - x_l| / l0"),
];

/// The yarn's Real parameters that live in the scene, in table order (the
/// order of [`crate::yarn::Config::reals`] and of the FMU state).
pub fn yarn_real_parameters() -> impl Iterator<Item = (u32, SceneField)> {
    YARN_VARIABLES.iter().filter_map(|v| match v.start {
        Start::Scene(f) => Some((v.vr, f)),
        _ => None,
    })
}

/// Number of [`yarn_real_parameters`].
pub const YARN_REAL_PARAMETERS: usize = 8;
const _: () = {
    let mut n = 0;
    let mut i = 0;
    while i < YARN_VARIABLES.len() {
        if let Start::Scene(_) = YARN_VARIABLES[i].start {
            n += 1;
        }
        i += 1;
    }
    assert!(n == YARN_REAL_PARAMETERS);
};

/// The per-yarn outputs of yarn `i`: `yarn[i].left.x`, `.left.y`,
/// `.right.x`, `.right.y`.
pub fn yarn_outputs(i: usize) -> impl Iterator<Item = Variable> {
    [
        (0, "left", "x"),
        (1, "left", "y"),
        (2, "right", "x"),
        (3, "right", "y"),
    ]
    .into_iter()
    .map(move |(k, end, axis)| Variable {
        name: format!("yarn[{i}].{end}.{axis}"),
        vr: VR_YARN_BASE + 4 * i as u32 + k,
        ty: VarType::Real,
        causality: "output",
        variability: "continuous",
        unit: Some("m"),
        start: None,
        description: format!("Yarn {i}, {end} end, {axis}"),
    })
}

/// One `[[pins]]` entry as the FMU sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FmuPin {
    /// `motion = "input"`: the pin has the inputs `pin[i].x` ... `.vy`.
    pub input: bool,
    /// Start position of its first vertex (the start of `pin[i].x`, `.y`).
    pub start: [f64; 2],
}

/// The pins of a (validated) scene, in `[[pins]]` order.
pub fn fmu_pins(scene: &YarnScene) -> Vec<FmuPin> {
    let curves = scene.curves();
    scene
        .pin_ranges()
        .expect("a validated scene")
        .into_iter()
        .zip(&scene.pins)
        .map(|((yarn, r), spec)| {
            let x = curves[yarn][r.start];
            FmuPin {
                input: spec.motion == PinMotionKind::Input,
                start: [x.x, x.y],
            }
        })
        .collect()
}

/// The variables of pin `i`: for an input pin the inputs `pin[i].x`,
/// `.y`, `.vx`, `.vy`, then (every pin) the outputs `pin[i].force.x`,
/// `.force.y`.
pub fn pin_variables(i: usize, pin: &FmuPin) -> Vec<Variable> {
    let base = VR_PIN_BASE + 8 * i as u32;
    let mut v = Vec::new();
    if pin.input {
        for (k, name, unit, start, what) in [
            (0, "x", "m", pin.start[0], "position x of its first vertex; the pin's vertices are at x + vx (t - t_c) during the communication step from t_c"),
            (1, "y", "m", pin.start[1], "position y of its first vertex (as x)"),
            (2, "vx", "m/s", 0.0, "velocity x given to its vertices in every substep of the communication step"),
            (3, "vy", "m/s", 0.0, "velocity y (as vx)"),
        ] {
            v.push(Variable {
                name: format!("pin[{i}].{name}"),
                vr: base + k,
                ty: VarType::Real,
                causality: "input",
                variability: "continuous",
                unit: Some(unit),
                start: Some(real(start)),
                description: format!("Driven pin {i}: {what}"),
            });
        }
    }
    for (k, axis) in [(0, "x"), (1, "y")] {
        v.push(Variable {
            name: format!("pin[{i}].force.{axis}"),
            vr: base + PIN_FORCE + k,
            ty: VarType::Real,
            causality: "output",
            variability: "continuous",
            unit: Some("N/m"),
            start: None,
            description: format!(
                "Pin {i}: force {axis} the yarn exerts on the pin, per m of depth, averaged over the substeps of the last communication step (0 before the first)"
            ),
        });
    }
    v
}

/// The per-yarn and per-pin value references do not collide: at most
/// [`MAX_FMU_PINS`] pins, and with pins at most 250 yarns (whose outputs
/// end below [`VR_PIN_BASE`]).
pub fn check_value_references(scene: &YarnScene) -> Result<(), String> {
    let (yarns, pins) = (num_yarns(scene), scene.pins.len());
    if pins > MAX_FMU_PINS {
        return Err(format!(
            "the scene has {pins} pins; an FMU serves at most {MAX_FMU_PINS}"
        ));
    }
    if pins > 0 && VR_YARN_BASE as usize + 4 * yarns > VR_PIN_BASE as usize {
        return Err(format!(
            "the scene has {yarns} yarns and pins; an FMU with pins serves at most 250 yarns"
        ));
    }
    Ok(())
}

/// Every variable of the FMU for this scene, in `ModelVariables` order:
/// [`YARN_VARIABLES`], [`COMMON_VARIABLES`], the yarn ends, then the pins'
/// inputs and outputs ([`pin_variables`]).
pub fn variables(scene: &YarnScene) -> Vec<Variable> {
    let mut v: Vec<Variable> = YARN_VARIABLES.iter().map(|s| s.variable(scene)).collect();
    v.extend(common_variables());
    for i in 0..num_yarns(scene) {
        v.extend(yarn_outputs(i));
    }
    for (i, pin) in fmu_pins(scene).iter().enumerate() {
        v.extend(pin_variables(i, pin));
    }
    v
}

/// The GUID of the FMU for this scene: a hash of the interface version and
/// the scene's normalized TOML text.
pub fn guid(scene: &YarnScene) -> String {
    guid_of(&format!(
        "{MODEL_IDENTIFIER} fmi2 interface {INTERFACE_VERSION}\n{}",
        scene.to_toml_string()
    ))
}

/// A GUID-formatted 128-bit hash of `text`.
pub fn guid_of(text: &str) -> String {
    let a = fnv1a(text.as_bytes());
    let b = fnv1a(format!("{text}\u{1}").as_bytes());
    format!(
        "{{{:08x}-{:04x}-{:04x}-{:04x}-{:012x}}}",
        a >> 32,
        (a >> 16) & 0xffff,
        a & 0xffff,
        b >> 48,
        b & 0xffff_ffff_ffff
    )
}

/// Escapes text for an XML attribute.
pub fn xml_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c if (c as u32) < 0x20 => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

/// Units used by the variables with their SI base-unit exponents.
const UNITS: [(&str, &str); 8] = [
    ("J", r#"kg="1" m="2" s="-2""#),
    ("N/m", r#"kg="1" s="-2""#),
    ("m/s", r#"m="1" s="-1""#),
    ("Pa", r#"kg="1" m="-1" s="-2""#),
    ("kg/m", r#"kg="1" m="-1""#),
    ("m", r#"m="1""#),
    ("m/s2", r#"m="1" s="-2""#),
    ("s", r#"s="1""#),
];

/// Stop time of the `DefaultExperiment`: 30 output frames of the scene.
pub fn default_stop_time(scene: &YarnScene) -> f64 {
    30.0 * scene.time.frame_dt
}

/// The complete `modelDescription.xml` of the FMU for this scene.
pub fn model_description(scene: &YarnScene) -> String {
    write_model_description(&description(scene))
}

/// What `modelDescription.xml` is written from.
#[derive(Clone, Debug, PartialEq)]
pub struct Description {
    pub identifier: &'static str,
    pub guid: String,
    pub description: String,
    pub variables: Vec<Variable>,
    /// `DefaultExperiment` stop time and step size in s.
    pub stop_time: f64,
    pub step_size: f64,
    /// What each output depends on ([`Dependency`]); an output without an
    /// entry depends on nothing (`dependencies=""`).
    pub dependencies: Vec<Dependency>,
}

/// The `ModelStructure` dependencies of one output, by value reference.
#[derive(Clone, Debug, PartialEq)]
pub struct Dependency {
    pub output: u32,
    /// Inputs that change the output at the same instant, without a step
    /// (`<Outputs>`).
    pub step: Vec<u32>,
    /// Inputs and parameters its value after initialization depends on
    /// (`<InitialUnknowns>`).
    pub initial: Vec<u32>,
}

/// `generationDateAndTime` when `SOURCE_DATE_EPOCH` is not set: the date of
/// the interface version (fixed, so the same sources give the same XML).
pub const GENERATION_DATE_AND_TIME: &str = "2026-12-01T00:00:00Z";

/// `generationDateAndTime`: `SOURCE_DATE_EPOCH` (seconds since 1970, the
/// reproducible-builds convention) when set to an integer, else
/// [`GENERATION_DATE_AND_TIME`].
pub fn generation_date_and_time() -> String {
    std::env::var("SOURCE_DATE_EPOCH")
        .ok()
        .and_then(|v| v.trim().parse::<i64>().ok())
        .map(utc_date_time)
        .unwrap_or_else(|| GENERATION_DATE_AND_TIME.to_string())
}

/// ISO 8601 UTC of a Unix time (proleptic Gregorian calendar).
pub fn utc_date_time(secs: i64) -> String {
    let days = secs.div_euclid(86_400);
    let sod = secs.rem_euclid(86_400);
    // Days to civil date (H. Hinnant's algorithm).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        sod / 3600,
        sod / 60 % 60,
        sod % 60
    )
}

/// The description of the YarnBundle FMU for this scene.
pub fn description(scene: &YarnScene) -> Description {
    let what = if scene.description.is_empty() {
        format!("MPM yarn bundle, scene {}", scene.name)
    } else {
        format!(
            "MPM yarn bundle, scene {}: {}",
            scene.name, scene.description
        )
    };
    Description {
        identifier: MODEL_IDENTIFIER,
        guid: guid(scene),
        description: what,
        variables: variables(scene),
        stop_time: default_stop_time(scene),
        step_size: scene.time.frame_dt,
        dependencies: yarn_dependencies(scene),
    }
}

/// The yarn bundle's outputs depend on no input at the same instant (the
/// inputs act through the substeps). After initialization (`<InitialUnknowns>`)
/// the yarn ends and the largest stretch depend on the `scene` parameter;
/// the kinetic energy on the scene and the density (the scene's initial
/// velocities); the elastic energy on the scene and the stiffnesses;
/// `substeps` on nothing. `dt`, `friction`, `plasticity` and the execution
/// parameters act only through the substeps.
pub fn yarn_dependencies(scene: &YarnScene) -> Vec<Dependency> {
    let dep = |output: u32, initial: &[u32]| Dependency {
        output,
        step: Vec::new(),
        initial: initial.to_vec(),
    };
    let mut d = vec![
        dep(VR_KINETIC_ENERGY, &[VR_DENSITY, VR_SCENE]),
        dep(
            VR_ELASTIC_ENERGY,
            &[VR_K, VR_GAMMA, VR_YOUNGS_MODULUS, VR_BENDING, VR_SCENE],
        ),
        dep(VR_MAX_STRETCH, &[VR_SCENE]),
    ];
    for k in 0..4 * num_yarns(scene) as u32 {
        d.push(dep(VR_YARN_BASE + k, &[VR_SCENE]));
    }
    // The pin forces are 0 until a step ran; the pin inputs act through
    // the substeps (a target set now moves the vertices in the next one).
    for i in 0..scene.pins.len() as u32 {
        for k in [PIN_FORCE, PIN_FORCE + 1] {
            d.push(dep(VR_PIN_BASE + 8 * i + k, &[]));
        }
    }
    d
}

/// Writes `modelDescription.xml`; only the units the variables use are defined.
pub fn write_model_description(d: &Description) -> String {
    let vars = &d.variables;
    let ident = d.identifier;
    let mut x = String::new();
    x.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        x,
        "<fmiModelDescription fmiVersion=\"2.0\" modelName=\"{ident}\" guid=\"{}\" description=\"{}\" generationTool=\"yarnsim-fmu {}\" generationDateAndTime=\"{}\" variableNamingConvention=\"structured\" numberOfEventIndicators=\"0\">",
        d.guid,
        xml_escape(&d.description),
        env!("CARGO_PKG_VERSION"),
        generation_date_and_time(),
    );
    let _ = writeln!(
        x,
        "  <CoSimulation modelIdentifier=\"{ident}\" canHandleVariableCommunicationStepSize=\"true\" canInterpolateInputs=\"false\" maxOutputDerivativeOrder=\"0\" canRunAsynchronuously=\"false\" canBeInstantiatedOnlyOncePerProcess=\"false\" canNotUseMemoryManagementFunctions=\"true\" canGetAndSetFMUstate=\"true\" canSerializeFMUstate=\"true\" providesDirectionalDerivative=\"false\"/>"
    );
    x.push_str("  <UnitDefinitions>\n");
    for (name, base) in UNITS
        .iter()
        .filter(|(u, _)| vars.iter().any(|v| v.unit == Some(*u)))
    {
        let _ = writeln!(
            x,
            "    <Unit name=\"{}\"><BaseUnit {base}/></Unit>",
            xml_escape(name)
        );
    }
    x.push_str("  </UnitDefinitions>\n  <LogCategories>\n");
    for (name, what) in LOG_CATEGORIES {
        let _ = writeln!(
            x,
            "    <Category name=\"{name}\" description=\"{}\"/>",
            xml_escape(what)
        );
    }
    x.push_str("  </LogCategories>\n");
    let _ = writeln!(
        x,
        "  <DefaultExperiment startTime=\"0.0\" stopTime=\"{}\" stepSize=\"{}\"/>",
        real(d.stop_time),
        real(d.step_size)
    );
    x.push_str("  <ModelVariables>\n");
    for (i, v) in vars.iter().enumerate() {
        let _ = writeln!(x, "    <!-- index {} -->", i + 1);
        let _ = write!(
            x,
            "    <ScalarVariable name=\"{}\" valueReference=\"{}\" description=\"{}\" causality=\"{}\" variability=\"{}\"",
            xml_escape(&v.name),
            v.vr,
            xml_escape(&v.description),
            v.causality,
            v.variability
        );
        // Parameters are initial="exact" by default, inputs take no initial,
        // outputs default to initial="calculated".
        x.push_str(">\n      <");
        x.push_str(match v.ty {
            VarType::Real => "Real",
            VarType::Integer => "Integer",
            VarType::Boolean => "Boolean",
            VarType::String => "String",
        });
        if let Some(u) = v.unit {
            let _ = write!(x, " unit=\"{}\"", xml_escape(u));
        }
        if let Some(s) = &v.start {
            let _ = write!(x, " start=\"{}\"", xml_escape(s));
        }
        x.push_str("/>\n    </ScalarVariable>\n");
    }
    x.push_str("  </ModelVariables>\n  <ModelStructure>\n    <Outputs>\n");
    let outputs: Vec<usize> = vars
        .iter()
        .enumerate()
        .filter(|(_, v)| v.causality == "output")
        .map(|(i, _)| i + 1)
        .collect();
    // 1-based indices of value references, ascending.
    let indices = |vrs: &[u32]| -> String {
        let mut ix: Vec<usize> = vrs
            .iter()
            .map(|vr| {
                1 + vars
                    .iter()
                    .position(|v| v.vr == *vr)
                    .unwrap_or_else(|| panic!("dependency on unknown value reference {vr}"))
            })
            .collect();
        ix.sort_unstable();
        ix.iter()
            .map(|i| i.to_string())
            .collect::<Vec<_>>()
            .join(" ")
    };
    let deps_of = |i: usize, initial: bool| -> String {
        d.dependencies
            .iter()
            .find(|dep| dep.output == vars[i - 1].vr)
            .map(|dep| indices(if initial { &dep.initial } else { &dep.step }))
            .unwrap_or_default()
    };
    for &i in &outputs {
        let _ = writeln!(
            x,
            "      <Unknown index=\"{i}\" dependencies=\"{}\"/>",
            deps_of(i, false)
        );
    }
    x.push_str("    </Outputs>\n    <InitialUnknowns>\n");
    for &i in &outputs {
        let _ = writeln!(
            x,
            "      <Unknown index=\"{i}\" dependencies=\"{}\"/>",
            deps_of(i, true)
        );
    }
    x.push_str("    </InitialUnknowns>\n  </ModelStructure>\n</fmiModelDescription>\n");
    x
}
