//! Yarn materials in engineering units (`[material] preset`, `tex`, `EA`,
//! ...): the conversion to the model's per-depth parameters as the loader
//! applies it, presets and their overrides, errors, the round trip through
//! `scene show`, obstacles taking the yarn-on-solid friction, and the
//! physical check that a converted material's pin force per metre of depth
//! times the spacing is one yarn's weight.

mod common;

use yarnsim::math::Vec2;
use yarnsim::scene::material_units::per_yarn;
use yarnsim::scene::presets::{preset, PRESETS};
use yarnsim::scene::{Scene, SceneError, YarnScene};
use yarnsim::YarnSim;

/// A bare scene around a `[material]` body: one straight yarn, one circle
/// well away from it (no friction given) and one with friction 0.7.
fn with_material(material: &str) -> String {
    format!(
        r#"
[grid]
resolution = 64
[time]
dt = 1e-5
[material]
{material}
[[obstacles]]
center = [0.2, 0.2]
radius = 0.05
[[obstacles]]
center = [0.8, 0.2]
radius = 0.05
friction = 0.7
[[yarns]]
start = [0.3, 0.6]
end = [0.7, 0.6]
vertices = 20
"#
    )
}

fn load(material: &str) -> Result<YarnScene, SceneError> {
    YarnScene::from_toml_str(&with_material(material))
}

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

#[test]
fn every_preset_loads_to_its_per_depth_parameters() {
    for p in PRESETS {
        let s = load(&format!("preset = {:?}", p.name)).unwrap();
        let m = &s.material;
        // spacing = diameter: k = EA / d, density = tex 1e-6 / d, bending =
        // EI / d, E = E_T (pi d^2 / 4) / d, gamma = 0.4 that; 1e-15 relative
        // (one product and one quotient)
        let d = p.diameter;
        let area = std::f64::consts::PI * d * d / 4.0;
        for (got, want) in [
            (m.k, p.ea / d),
            (m.density, p.tex * 1e-6 / d),
            (m.bending, p.ei / d),
            (m.youngs_modulus, p.transverse_modulus * area / d),
            (m.gamma, 0.4 * p.transverse_modulus * area / d),
            (m.friction, p.friction),
        ] {
            assert!(rel(got, want) < 1e-15, "{}: {got} against {want}", p.name);
        }
        assert_eq!(s.material.spacing(), Some(d));
        // the first obstacle has no friction: the preset's yarn-on-solid one
        assert_eq!(s.obstacles[0].friction, p.friction_solid, "{}", p.name);
        assert_eq!(s.obstacles[1].friction, 0.7);
        // and back per yarn: EA, tex and EI as the preset gives them
        let y = s.material.per_yarn().unwrap();
        assert!(rel(y.ea, p.ea) < 1e-14 && rel(y.tex, p.tex) < 1e-14 && rel(y.ei, p.ei) < 1e-14);
    }
}

#[test]
fn fields_override_the_preset_and_model_fields_override_the_derived_ones() {
    let p = preset("polyester-167dtex").unwrap();
    // a sheet at twice the diameter, a softer yarn by its specific modulus,
    // the model's k given outright for a softened run
    let s = load(&format!(
        "preset = {:?}\nspacing = {}\nspecific_modulus = 5.0\nfriction = 0.4",
        p.name,
        2.0 * p.diameter
    ))
    .unwrap();
    let sp = 2.0 * p.diameter;
    assert!(rel(s.material.k, 5.0 * p.tex / sp) < 1e-15);
    assert!(rel(s.material.density, p.tex * 1e-6 / sp) < 1e-15);
    assert_eq!(s.material.friction, 0.4);
    let soft = load(&format!("preset = {:?}\nk = 1e4", p.name)).unwrap();
    assert_eq!(soft.material.k, 1e4);
    assert!(rel(soft.material.density, p.tex * 1e-6 / p.diameter) < 1e-15);
    // no preset: tex, diameter and EA alone; the cross-section given per depth
    let own = load("tex = 10\ndiameter = 2e-4\nEA = 100\nEI = 1e-9\ngamma = 0\nyoungs_modulus = 0\nfriction = 0.1").unwrap();
    assert!(rel(own.material.k, 100.0 / 2e-4) < 1e-15);
    assert!(rel(own.material.density, 10e-6 / 2e-4) < 1e-15);
    assert!(rel(own.material.bending, 1e-9 / 2e-4) < 1e-15);
    // no friction_solid: obstacles keep the default 0.3
    assert_eq!(own.obstacles[0].friction, 0.3);
}

#[test]
fn bad_material_fields_name_the_field_and_line() {
    let e = load("preset = \"cotton-30tex\"").unwrap_err().to_string();
    // line 7: the preset's line in `with_material`'s text
    assert!(
        e.contains("line 7") && e.contains("material.preset") && e.contains("cotton-20tex"),
        "{e}"
    );
    for p in PRESETS {
        assert!(e.contains(p.name), "{e}");
    }
    let e = load("tex = 10\nEA = 100\nfriction = 0.1\ngamma = 0\nyoungs_modulus = 0")
        .unwrap_err()
        .to_string();
    assert!(e.contains("diameter"), "{e}");
    let e = load("preset = \"cotton-20tex\"\nEA = 10\nspecific_modulus = 2")
        .unwrap_err()
        .to_string();
    assert!(e.contains("EA") && e.contains("specific_modulus"), "{e}");
    let e = load("preset = \"cotton-20tex\"\ntex = -1")
        .unwrap_err()
        .to_string();
    assert!(e.contains("material.tex") && e.contains("line 8"), "{e}");
    let e = load("tex = 10\ndiameter = 2e-4\nfriction = 0.1\ngamma = 0\nyoungs_modulus = 0")
        .unwrap_err()
        .to_string();
    assert!(e.contains("material.k") && e.contains("EA"), "{e}");
}

#[test]
fn a_preset_scene_writes_back_to_the_same_parameters() {
    for material in [
        "preset = \"kevlar29-1670dtex\"".to_string(),
        "preset = \"wool-worsted-40tex\"\nspacing = 1e-3\nk = 50.0\nplasticity = false".into(),
        "tex = 10\ndiameter = 2e-4\nEA = 100\ntransverse_modulus = 1e6\nfriction = 0.1".into(),
    ] {
        let s = Scene::from_toml_str(&with_material(&material)).unwrap();
        for text in [s.to_toml_string(), s.to_commented_toml()] {
            let back = Scene::from_toml_str(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
            assert_eq!(back, s, "{text}");
        }
    }
    // the written file names the preset and leaves out what it derives
    let s = load("preset = \"kevlar29-1670dtex\"").unwrap();
    let text = s.to_toml_string();
    assert!(text.contains("preset = \"kevlar29-1670dtex\""), "{text}");
    assert!(!text.contains("\nk = "), "{text}");
}

/// A straight yarn of the nylon monofilament preset, L = 0.8 m, hanging
/// from a pin at its top at rest, on a 64^2 grid at `dt = "auto"`: its
/// weight starts the axial (fixed-free) mode of period `4 L / c`; the pin's
/// force per metre of depth, averaged over whole periods, times the
/// spacing is one yarn's weight `mu g L`.
#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn a_hanging_yarn_pin_carries_one_yarns_weight_per_spacing() {
    let (len, g) = (
        yarnsim::testing::CHAIN_LENGTH,
        yarnsim::testing::CHAIN_GRAVITY,
    );
    let text = yarnsim::testing::hanging_preset_yarn_toml("nylon66-mono-0.30mm");
    let s = common::scene(&text);
    let y = s.material.per_yarn().unwrap();
    let p = preset("nylon66-mono-0.30mm").unwrap();
    let mut sim = YarnSim::new(&s).unwrap();
    // the fixed-free rod's first period 4 L / c with c = sqrt(EA / mu)
    let period = 4.0 * len / y.wave_speed();
    let periods = 10.0;
    let (mut impulse, mut t) = (Vec2::zeros(), 0.0);
    while t < periods * period {
        let before = sim.time();
        sim.step().unwrap();
        let h = sim.time() - before;
        impulse += sim.pin_reactions()[0] * h;
        t = sim.time();
    }
    let mean = impulse / t;
    let weight = p.tex * 1e-6 * g * len;
    let measured = per_yarn(mean.y, y.spacing);
    let err = (measured - weight) / weight;
    eprintln!(
        "hanging nylon monofilament: {} substeps over {t:.4e} s ({periods} axial periods of {period:.3e} s); \
         pin force {:.4e} N/m x spacing {:.3e} m = {measured:.4e} N per yarn, mu g L = {weight:.4e} N, error {:+.2} %",
        sim.steps(),
        mean.y,
        y.spacing,
        100.0 * err
    );
    // tolerance 2 %: the average over a whole number of the continuum's
    // periods of an undamped oscillation between 0 and about twice the
    // weight leaves a fraction of a period unmatched (the discrete chain's
    // period differs from 4 L / c), and the vertices' mass sits from the
    // first to the last vertex (a quarter-segment at each end)
    assert!(err.abs() < 0.02, "per-yarn weight error {err:+.4}");
    assert!(mean.x.abs() < 1e-6 * mean.y.abs(), "sideways {}", mean.x);
}
