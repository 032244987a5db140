//! The `<ModelStructure>` dependencies against the FMU's behaviour: an
//! input set between steps changes exactly the outputs that declare it in
//! `<Outputs>`, and an input or parameter set in initialization mode
//! changes only outputs that declare it in `<InitialUnknowns>`.

mod common;

use std::ffi::{c_int, CString};

use common::*;
use yarnsim::massspring::scenes::wire;
use yarnsim_fmu::fmi2::*;
use yarnsim_fmu::model_description::{self as neutral, Dependency, VarType, Variable, VR_SUBSTEPS};
use yarnsim_fmu::models::yarn::variables::{self as model, VR_AXIAL, VR_INTEGRATOR, VR_SCENE};

/// How a variable is changed in the test.
#[derive(Clone, Debug)]
enum Change {
    Real(f64),
    Bool(bool),
    Str(String),
    Int(c_int),
}

fn apply(f: &Fmu, vr: u32, c: &Change) -> fmi2Status {
    match c {
        Change::Real(v) => f.set_real(&[vr], &[*v]),
        Change::Bool(b) => f.set_bool(vr, *b),
        // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
        // pointer argument is a local that outlives the call.
        Change::Int(v) => unsafe { fmi2SetInteger(f.c, &vr, 1, v) },
        Change::Str(s) => {
            let s = CString::new(s.as_str()).unwrap();
            let p = s.as_ptr();
            // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
            // pointer argument is a local that outlives the call.
            unsafe { fmi2SetString(f.c, &vr, 1, &p) }
        }
    }
}

/// A different, valid value for each input and parameter (`None`: none
/// that the yarn scenes here accept).
fn change_of(v: &Variable, alt_scene: &str) -> Option<Change> {
    let start = v.start.as_deref().unwrap_or("");
    Some(match v.ty {
        VarType::Real => {
            let x: f64 = start.parse().unwrap();
            Change::Real(match v.name.as_str() {
                "dt" if x == 0.0 => 0.01,
                "dt" => x / 2.0,
                "material.friction" => x + 0.1,
                "transfer.flip_ratio" => x / 2.0,
                _ if x == 0.0 => 1.0,
                _ => 1.5 * x,
            })
        }
        VarType::Boolean => Change::Bool(start != "true"),
        VarType::Integer => Change::Int(if v.name == "threads" { 1 } else { 7 }),
        VarType::String if v.vr == VR_SCENE => Change::Str(alt_scene.to_string()),
        VarType::String if v.name == "transfer.scheme" => {
            Change::Str(if start == "flip" { "apic" } else { "flip" }.into())
        }
        // the small and driven scenes are outside the implicit step's
        // scope (refused at initialization); tests/integrator.rs checks
        // that the integrator changes no output at initialization
        VarType::String if v.vr == VR_INTEGRATOR => return None,
        // the small and driven scenes run pure FLIP, under which the
        // axial step is refused at initialization; tests/axial.rs checks
        // that it changes no output there
        VarType::String if v.vr == VR_AXIAL => return None,
        VarType::String => Change::Str("symplectic-euler".into()),
    })
}

fn real_outputs(vars: &[Variable]) -> Vec<u32> {
    vars.iter()
        .filter(|v| v.causality == "output" && v.ty == VarType::Real)
        .map(|v| v.vr)
        .collect()
}

fn declared(deps: &[Dependency], output: u32, initial: bool) -> Vec<u32> {
    deps.iter()
        .find(|d| d.output == output)
        .map(|d| {
            if initial {
                d.initial.clone()
            } else {
                d.step.clone()
            }
        })
        .unwrap_or_default()
}

/// Sets each input between steps (from a saved state) and compares every
/// output before and after, without stepping.
fn check_outputs(new: &dyn Fn() -> Fmu, d: &neutral::Description, h: f64) -> usize {
    let outs = real_outputs(&d.variables);
    let f = new();
    f.init();
    for k in 0..3 {
        assert_eq!(f.do_step(k as f64 * h, h), fmi2OK);
    }
    let base = f.get_real(&outs).unwrap();
    let substeps = f.substeps();
    let state = f.get_state();
    let mut checked = 0;
    for v in d.variables.iter().filter(|v| v.causality == "input") {
        let c = change_of(v, "").unwrap();
        assert_eq!(apply(&f, v.vr, &c), fmi2OK, "{} {:?}", v.name, f.lines());
        let now = f.get_real(&outs).unwrap();
        assert_eq!(f.substeps(), substeps);
        for (k, &o) in outs.iter().enumerate() {
            let changed = now[k].to_bits() != base[k].to_bits();
            let listed = declared(&d.dependencies, o, false).contains(&v.vr);
            assert_eq!(
                changed, listed,
                "output vr {o}: {} changed {changed}, declared {listed}",
                v.name
            );
            checked += 1;
        }
        f.set_state(state);
        assert_eq!(f.get_real(&outs).unwrap(), base);
    }
    checked
}

/// Sets each input and parameter in initialization mode and compares the
/// outputs read there with those of an untouched instance: an output that
/// changes must declare the variable among its initial dependencies.
fn check_initial(new: &dyn Fn() -> Fmu, d: &neutral::Description, alt_scene: &str) -> usize {
    check_initial_with(new, d, alt_scene, &alt_scene_text())
}

fn check_initial_with(
    new: &dyn Fn() -> Fmu,
    d: &neutral::Description,
    alt_scene: &str,
    alt_text: &str,
) -> usize {
    let outs = real_outputs(&d.variables);
    let enter = |f: &Fmu| {
        assert_eq!(f.setup(0.0, None), fmi2OK);
        // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
        // pointer argument is a local that outlives the call.
        assert_eq!(unsafe { fmi2EnterInitializationMode(f.c) }, fmi2OK);
    };
    let f = new();
    enter(&f);
    let base = f.get_real(&outs).unwrap();
    let mut seen = 0;
    for v in d
        .variables
        .iter()
        .filter(|v| matches!(v.causality, "input" | "parameter"))
    {
        let Some(c) = change_of(v, alt_scene) else {
            continue;
        };
        let g = new();
        if v.vr == VR_SCENE {
            std::fs::write(g.dir.join(alt_scene), alt_text).unwrap();
        }
        enter(&g);
        assert_eq!(apply(&g, v.vr, &c), fmi2OK, "{} {:?}", v.name, g.lines());
        let now = g.get_real(&outs).unwrap();
        for (k, &o) in outs.iter().enumerate() {
            if now[k].to_bits() != base[k].to_bits() {
                assert!(
                    declared(&d.dependencies, o, true).contains(&v.vr),
                    "initial output vr {o} changed with {} but does not declare it",
                    v.name
                );
                seen += 1;
            }
        }
        let mut n = -1;
        assert_eq!(
            // SAFETY: `g.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
            // pointer argument is a local that outlives the call.
            unsafe { fmi2GetInteger(g.c, &VR_SUBSTEPS, 1, &mut n) },
            fmi2OK
        );
        assert_eq!(n, 0);
    }
    seen
}

fn alt_scene_text() -> String {
    let shifted = SMALL_SCENE
        .replace("start = [0.25, 0.65]", "start = [0.25, 0.6]")
        .replace("end = [0.75, 0.65]", "end = [0.75, 0.6]");
    assert_ne!(shifted, SMALL_SCENE);
    shifted
}

#[test]
fn yarn_outputs_depend_on_no_input_and_declare_their_initial_dependencies() {
    let scene = small_scene();
    let d = model::description(&scene);
    // Every output is listed with an empty step dependency.
    assert!(d.dependencies.iter().all(|dep| dep.step.is_empty()));
    let xml = model::model_description(&scene);
    let outputs = xml
        .split("<Outputs>")
        .nth(1)
        .unwrap()
        .split("</Outputs>")
        .next()
        .unwrap();
    assert!(outputs
        .lines()
        .filter(|l| l.contains("<Unknown"))
        .all(|l| l.contains("dependencies=\"\"")));
    let new = || Fmu::new(&scene);
    assert!(check_outputs(&new, &d, 0.01) > 0);
    // The shifted scene moves the 3 yarns' ends in y (and the parameters
    // change no other output at initialization).
    let seen = check_initial(&new, &d, "shifted.toml");
    assert!(seen >= 2 * 3, "{seen}");
}

/// The driven scene: the pin inputs change no output at the same instant
/// or at initialization, the pin forces depend on nothing.
#[test]
fn pin_inputs_feed_through_nothing() {
    const DRIVEN: &str = include_str!("../scenes/driven.toml");
    let scene = yarnsim::scene::YarnScene::from_toml_str(DRIVEN).unwrap();
    let d = model::description(&scene);
    let pins: Vec<&Variable> = d
        .variables
        .iter()
        .filter(|v| v.name.starts_with("pin["))
        .collect();
    assert_eq!(pins.len(), 4 + 2 + 2, "{pins:?}");
    assert!(d.dependencies.iter().all(|dep| dep.step.is_empty()));
    let new = || Fmu::new(&scene);
    assert!(check_outputs(&new, &d, 0.01) > 0);
    let shifted = DRIVEN.replace("start = [0.25, 0.65]", "start = [0.25, 0.6]");
    assert_ne!(shifted, DRIVEN);
    let seen = check_initial_with(&new, &d, "shifted.toml", &shifted);
    // The shifted start moves both yarns' left ends in y (their right ends stay).
    assert!(seen >= 2, "{seen}");
}

#[test]
fn mass_spring_energies_declare_gravity_and_nothing_else_does() {
    let layout = wire();
    let d = yarnsim_fmu::models::massspring::description(&layout).unwrap();
    let new = || Fmu::mass_spring(&layout);
    assert!(check_outputs(&new, &d, 0.05) > 0);
    // Gravity changes gravity_energy and total_energy in initialization
    // mode too, and those declare it.
    let seen = check_initial(&new, &d, "unused.toml");
    assert!(seen >= 2, "{seen}");
    let xml = yarnsim_fmu::models::massspring::description(&layout)
        .map(|d| neutral::write_model_description(&d))
        .unwrap();
    let index = |name: &str| 1 + d.variables.iter().position(|v| v.name == name).unwrap();
    let g = format!(
        "dependencies=\"{} {} {}\"",
        index("gravity.x"),
        index("gravity.y"),
        index("gravity.z")
    );
    for out in ["gravity_energy", "total_energy"] {
        let line = format!("<Unknown index=\"{}\" {g}/>", index(out));
        assert_eq!(xml.matches(&line).count(), 2, "{out}: {line}");
    }
}

#[test]
fn generation_date_is_reproducible() {
    assert_eq!(neutral::utc_date_time(0), "1970-01-01T00:00:00Z");
    assert_eq!(
        neutral::utc_date_time(1_764_547_200),
        "2025-12-01T00:00:00Z"
    );
    assert_eq!(neutral::utc_date_time(951_782_400), "2000-02-29T00:00:00Z");
    assert_eq!(
        neutral::utc_date_time(4_102_444_799),
        "2099-12-31T23:59:59Z"
    );
    let xml = model::model_description(&small_scene());
    let expected = neutral::generation_date_and_time();
    assert!(xml.contains(&format!("generationDateAndTime=\"{expected}\"")));
    assert_eq!(xml, model::model_description(&small_scene()));
}
