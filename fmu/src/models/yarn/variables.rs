//! The YarnBundle's variables: one static table ([`YARN_VARIABLES`]: name,
//! value reference, type, causality, variability, unit, start, description,
//! and for the Real parameters the scene field that the getter and setter
//! use), the per-yarn and per-pin outputs and inputs, the GUID and the
//! description its `modelDescription.xml` is written from. All derived from
//! the scene the FMU runs: the number of yarns fixes the outputs, the
//! scene's material, substep and inputs give the start values.

use yarnsim::scene::{Axial, Integrator, PinMotionKind, StepSize, TransferScheme, YarnScene};

use crate::model_description::*;
use Causality::{Input, Parameter};

/// The FMI model identifier: the shared library's and the C symbols' name.
pub const MODEL_IDENTIFIER: &str = "YarnBundle";

/// Bumped whenever the variable layout changes; part of the GUID.
pub const INTERFACE_VERSION: u32 = 6;

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
/// `transfer.flip_time` (Real parameter in s; 0: none, the scene without
/// a relaxation time).
pub const VR_FLIP_TIME: u32 = 19;
pub const VR_KINETIC_ENERGY: u32 = 100;
pub const VR_ELASTIC_ENERGY: u32 = 101;
pub const VR_MAX_STRETCH: u32 = 102;
pub const VR_SCENE: u32 = 300; // String
/// `transfer.scheme` (String parameter, `"flip"` or `"apic"`).
pub const VR_TRANSFER_SCHEME: u32 = 301;
/// `integrator` (String parameter, `"explicit"` or `"implicit"`: the
/// scene's `time.integrator`).
pub const VR_INTEGRATOR: u32 = 302;
/// `time.axial` (String parameter, `"explicit"` or `"implicit"`: the
/// scene's `[time] axial`).
pub const VR_AXIAL: u32 = 303;
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

/// Number of yarns the scene creates (fixes the outputs).
pub fn num_yarns(scene: &YarnScene) -> usize {
    scene.curves().len()
}

const fn material(
    get: fn(&YarnScene) -> f64,
    set: fn(&mut YarnScene, f64),
    positive: bool,
) -> Start<YarnScene> {
    Start::Scene(SceneField {
        get,
        set,
        positive,
        max: 1e12,
    })
}

/// The transfer schemes by their name as the scene and `transfer.scheme`
/// write it (the scene's spelling, [`TransferScheme::NAMES`]).
pub const SCHEMES: [(&str, TransferScheme); 2] = [
    (TransferScheme::NAMES[0], TransferScheme::Flip),
    (TransferScheme::NAMES[1], TransferScheme::Apic),
];

/// The integrators by their name as the scene and `integrator` write it
/// (the scene's spelling, [`Integrator::NAMES`]).
pub const INTEGRATORS: [(&str, Integrator); 4] = [
    (Integrator::NAMES[0], Integrator::Explicit),
    (Integrator::NAMES[1], Integrator::Implicit),
    (Integrator::NAMES[2], Integrator::ImplicitVertices),
    (Integrator::NAMES[3], Integrator::MidpointVertices),
];

/// The treatments of the fibre stretch by their name as the scene and
/// `time.axial` write it (the scene's spelling, [`Axial::NAMES`]).
pub const AXIALS: [(&str, Axial); 2] = [
    (Axial::NAMES[0], Axial::Explicit),
    (Axial::NAMES[1], Axial::Implicit),
];

/// The name of `value` in a table of names ([`SCHEMES`], [`INTEGRATORS`]).
pub fn choice_name<T: PartialEq>(table: &[(&'static str, T)], value: T) -> &'static str {
    let (name, _) = table
        .iter()
        .find(|(_, v)| *v == value)
        .expect("every value has a name");
    name
}

/// The value named `name` in a table of names.
pub fn parse_choice<T: Copy>(table: &[(&str, T)], name: &str) -> Option<T> {
    table.iter().find(|(n, _)| *n == name).map(|&(_, v)| v)
}

/// The names of a table, quoted, as a refusal lists them: `"a", "b" or "c"`.
pub fn choice_list<T>(table: &[(&str, T)]) -> String {
    let quoted: Vec<String> = table.iter().map(|(n, _)| format!("{n:?}")).collect();
    match quoted.split_last() {
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        None => String::new(),
    }
}

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

/// Sets the scene's `transfer.flip_time` from the parameter: 0 is none
/// (the FLIP particles keep their own velocity, blended by
/// `transfer.flip_ratio`), a positive value the relaxation time.
fn set_flip_time(s: &mut YarnScene, v: f64) {
    s.transfer.flip_time = (v != 0.0).then_some(v);
}

/// The YarnBundle's variables before the ones every model has
/// ([`COMMON_VARIABLES`]) and the per-yarn outputs ([`yarn_outputs`]), in
/// `ModelVariables` order. The Real parameters read and override the scene
/// through their [`SceneField`].
pub static YARN_VARIABLES: [VarSpec<YarnScene>; 23] = [
    var(Input, "attractor.x", VR_ATTRACTOR_X, Some("m"), Start::Real(|s| s.attractor.position[0]), "Attractor position x"),
    var(Input, "attractor.y", VR_ATTRACTOR_Y, Some("m"), Start::Real(|s| s.attractor.position[1]), "Attractor position y"),
    var(Input, "attractor.strength", VR_ATTRACTOR_STRENGTH, Some("m/s2"), Start::Real(|s| s.attractor.strength), "Attractor acceleration magnitude, 0 to 1e6"),
    var(Input, "attractor.active", VR_ATTRACTOR_ACTIVE, None, Start::Bool(|s| s.attractor.active), "Whether the attractor acts"),
    var(Input, "gravity.x", VR_GRAVITY_X, Some("m/s2"), Start::Real(|s| s.gravity[0]), "Gravity x, |g| at most 1e6"),
    var(Input, "gravity.y", VR_GRAVITY_Y, Some("m/s2"), Start::Real(|s| s.gravity[1]), "Gravity y, |g| at most 1e6"),
    var(Parameter, "material.k", VR_K, Some("N/m"), material(|s| s.material.k, |s, v| s.material.k = v, false), "Fiber stretch stiffness (per m of depth)"),
    var(Parameter, "material.gamma", VR_GAMMA, Some("N/m"), material(|s| s.material.gamma, |s, v| s.material.gamma = v, false), "Fiber shear stiffness (per m of depth)"),
    var(Parameter, "material.youngs_modulus", VR_YOUNGS_MODULUS, Some("N/m"), material(|s| s.material.youngs_modulus, |s, v| s.material.youngs_modulus = v, false), "Young's modulus of the cross-section (per m of depth)"),
    var(Parameter, "material.friction", VR_FRICTION, None, material(|s| s.material.friction, |s, v| s.material.friction = v, false), "Mohr-Coulomb friction coefficient"),
    var(Parameter, "material.bending", VR_BENDING, Some("N.m"), material(|s| s.material.bending, |s, v| s.material.bending = v, false), "Bending stiffness B of the energy int B/2 kappa^2 ds, N m^2 per m of depth (0 disables bending)"),
    var(Parameter, "material.density", VR_DENSITY, Some("kg/m2"), material(|s| s.material.density, |s, v| s.material.density = v, true), "Line density (kg per m of yarn, per m of depth)"),
    var(Parameter, "dt", VR_DT, Some("s"), Start::Scene(SceneField { get: |s| s.time.dt.fixed().unwrap_or(0.0), set: set_dt, positive: false, max: 1e12 }), "Substep size; 0: adaptive (the scene's dt = \"auto\": each substep is the safety factor times the stability bound of the current state, the last one before a communication point shortened to land on it). A fixed dt runs an integer number of substeps per communication step"),
    var(Parameter, "material.plasticity", VR_PLASTICITY, None, Start::Bool(|s| s.material.plasticity), "Mohr-Coulomb return mapping on or off"),
    var(Parameter, "transfer.scheme", VR_TRANSFER_SCHEME, None, Start::Name(|s| choice_name(&SCHEMES, s.transfer.scheme)), "Particle velocity update of grid-to-particle: flip (FLIP/APIC blend by transfer.flip_ratio) or apic"),
    var(Parameter, "transfer.flip_ratio", VR_FLIP_RATIO, None, Start::Scene(SceneField { get: |s| s.transfer.flip_ratio, set: |s, v| s.transfer.flip_ratio = v, positive: false, max: 1.0 }), "FLIP ratio in [0, 1] of the flip scheme (1: pure FLIP; ignored by apic)"),
    var(Parameter, "transfer.flip_time", VR_FLIP_TIME, Some("s"), Start::Scene(SceneField { get: |s| s.transfer.flip_time.unwrap_or(0.0), set: set_flip_time, positive: false, max: 1e12 }), "Relaxation time of the flip scheme: each substep relaxes a particle's own velocity to the grid's by exp(-dt / flip_time), a damping per simulated second that does not follow the number of substeps; 0: none (then transfer.flip_ratio blends per substep). A positive value needs transfer.flip_ratio = 1"),
    var(Parameter, "integrator", VR_INTEGRATOR, None, Start::Name(|s| choice_name(&INTEGRATORS, s.time.integrator)), "Time integrator (the scene's time.integrator): explicit (symplectic Euler), implicit (backward Euler, Newton on the grid velocities), implicit-vertices (backward Euler on the vertices of a single yarn without the grid) or midpoint-vertices (generalized midpoint there); the last two only for one yarn with gamma = youngs_modulus = 0 and no walls: another scene is refused with fmi2Error at the end of initialization, the log naming the scene field; a Newton solve that fails in a step gives fmi2Discard"),
    var(Parameter, "time.axial", VR_AXIAL, None, Start::Name(|s| choice_name(&AXIALS, s.time.axial)), "Fibre stretch under the explicit integrator (the scene's [time] axial): explicit (a grid force; its axial wave bounds the substep) or implicit (backward Euler on each yarn's vertices after the grid-to-particle pass, so the axial wave no longer bounds the substep; needs integrator = explicit and transfer.scheme = apic or a transfer.flip_time, else fmi2Error at the end of initialization naming time.axial)"),
    var(Parameter, "scene", VR_SCENE, None, Start::Text(SCENE_FILE), "Scene file: a path relative to the FMU's resources folder, or absolute; it must create as many yarns as the bundled scene and have its pins (same number, same input pins)"),
    output("kinetic_energy", VR_KINETIC_ENERGY, Some("J/m"), "Kinetic energy (per m of depth)"),
    output("elastic_energy", VR_ELASTIC_ENERGY, Some("J/m"), "Elastic energy (per m of depth)"),
    output("max_stretch", VR_MAX_STRETCH, None, "Largest segment stretch |x_r - x_l| / l0"),
];

/// The yarn's Real parameters that live in the scene, in table order (the
/// order of [`crate::models::yarn::Config::reals`] and of the FMU state).
pub fn yarn_real_parameters() -> impl Iterator<Item = (u32, SceneField<YarnScene>)> {
    YARN_VARIABLES.iter().filter_map(|v| match v.start {
        Start::Scene(f) => Some((v.vr, f)),
        _ => None,
    })
}

/// Number of [`yarn_real_parameters`].
pub const YARN_REAL_PARAMETERS: usize = 9;
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

/// Stop time of the `DefaultExperiment`: 30 output frames of the scene.
pub fn default_stop_time(scene: &YarnScene) -> f64 {
    30.0 * scene.time.frame_dt
}

/// The complete `modelDescription.xml` of the FMU for this scene.
pub fn model_description(scene: &YarnScene) -> String {
    write_model_description(&description(scene))
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
        arrays: super::arrays::yarn_arrays(scene, &[VR_SCENE]),
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn choice_lists_are_the_refusals_words() {
        assert_eq!(choice_list(&SCHEMES), "\"flip\" or \"apic\"");
        assert_eq!(
            choice_list(&INTEGRATORS),
            "\"explicit\", \"implicit\", \"implicit-vertices\" or \"midpoint-vertices\""
        );
        for (name, i) in INTEGRATORS {
            assert_eq!(parse_choice(&INTEGRATORS, name), Some(i));
            assert_eq!(choice_name(&INTEGRATORS, i), name);
            assert_eq!(i.name(), name);
        }
        for (name, s) in SCHEMES {
            assert_eq!(parse_choice(&SCHEMES, name), Some(s));
            assert_eq!(choice_name(&SCHEMES, s), name);
            assert_eq!(s.name(), name);
        }
        assert_eq!(parse_choice(&SCHEMES, "pic"), None);
        assert_eq!(choice_list(&AXIALS), "\"explicit\" or \"implicit\"");
        for (name, a) in AXIALS {
            assert_eq!(parse_choice(&AXIALS, name), Some(a));
            assert_eq!(choice_name(&AXIALS, a), name);
            assert_eq!(a.name(), name);
        }
    }
}
