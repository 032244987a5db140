//! The generated modelDescription.xml (checked-in copies, structure, GUID)
//! and the unsafe-code rules of the C ABI. The archive and the shared
//! library's ELF check are tested in `fmu-pack/tests/pack.rs`.

mod common;

use yarnsim::scene::builtin::yarn_reference;
use yarnsim::scene::YarnScene;
use yarnsim_fmu::models::yarn::variables::*;

#[test]
fn checked_in_model_description_is_current() {
    let checked_in = include_str!("../../modelDescription/YarnBundle.xml");
    let generated = model_description(&yarn_reference());
    assert!(
        checked_in == generated,
        "modelDescription/YarnBundle.xml drifted from the generator; refresh it with\n  cargo run --release -p yarnsim-fmu-pack --bin build-fmu -- --model-description modelDescription/YarnBundle.xml"
    );
}

/// Structure rules fmpy's validation checks: unique value references and
/// names, outputs listed by their 1-based index, inputs with start values.
#[test]
fn model_description_structure() {
    let scene = common::small_scene();
    let vars = variables(&scene);
    let xml = model_description(&scene);
    let yarns = num_yarns(&scene);
    assert_eq!(yarns, 3);
    let outputs = yarnsim_fmu::model_description::output_indices(&vars);
    assert_eq!(outputs.len(), 4 * yarns + 4);
    for i in &outputs {
        // Listed in <Outputs> and <InitialUnknowns>, always with dependencies.
        assert_eq!(
            xml.matches(&format!("<Unknown index=\"{i}\" dependencies=\""))
                .count(),
            2
        );
    }
    assert_eq!(
        xml.matches("<Unknown ").count(),
        xml.matches("dependencies=").count()
    );
    let mut vrs: Vec<(u32, String)> = vars.iter().map(|v| (v.vr, format!("{:?}", v.ty))).collect();
    vrs.sort();
    vrs.dedup();
    assert_eq!(vrs.len(), vars.len());
    let mut names: Vec<&str> = vars.iter().map(|v| v.name.as_str()).collect();
    names.sort();
    names.dedup();
    assert_eq!(names.len(), vars.len());
    for v in &vars {
        if v.causality == "input" || v.causality == "parameter" {
            assert!(v.start.is_some(), "{}", v.name);
        } else {
            assert!(v.start.is_none(), "{}", v.name);
        }
        if let Some(u) = v.unit {
            assert!(xml.contains(&format!("<Unit name=\"{u}\">")), "{u}");
        }
    }
    for name in [
        "yarn[2].right.y",
        "attractor.active",
        "gravity.y",
        "substeps",
        "kinetic_energy",
    ] {
        assert!(xml.contains(&format!("name=\"{name}\"")), "{name}");
    }
    assert!(xml.contains(&format!("guid=\"{}\"", guid(&scene))));
    // Gravity starts at the scene's (0, -9.8).
    let g = vars.iter().find(|v| v.name == "gravity.y").unwrap();
    assert_eq!(g.start.as_deref(), Some("-9.8"));
}

#[test]
fn guid_follows_the_scene_and_survives_the_scene_file() {
    let scene = common::small_scene();
    let text = scene.to_toml_string();
    let back = YarnScene::from_toml_str(&text).unwrap();
    assert_eq!(guid(&back), guid(&scene));
    let mut other = scene.clone();
    other.time.dt = (other.time.dt.fixed().unwrap() * 0.5).into();
    assert_ne!(guid(&other), guid(&scene));
    assert_ne!(guid(&yarn_reference()), guid(&scene));
}
