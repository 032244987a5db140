//! Scene files: round trip, and malformed files name the field and the line.

use yarnsim::scene::{
    builtin, builtin_names, builtin_toml, Integrator, Scene, SceneError, YarnScene,
};
use yarnsim::testing::assert_mentions;

/// The smallest complete yarn scene file.
const GOOD: &str = yarnsim::testing::MINIMAL_TOML;

fn err(text: &str) -> SceneError {
    YarnScene::from_toml_str(text).expect_err("must be rejected")
}

#[test]
fn good_file_loads_with_defaults() {
    let s = YarnScene::from_toml_str(GOOD).unwrap();
    assert_eq!(s.gravity, [0.0, -9.8]);
    assert_eq!(s.grid.size, 1.0);
    assert!(s.material.plasticity);
    let c = s.curves();
    assert_eq!(c.len(), 1);
    assert_eq!(c[0].len(), 20);
    assert!((c[0][19].x - 0.7).abs() < 1e-12);
}

#[test]
fn every_builtin_round_trips_through_toml() {
    for (name, _) in builtin_names() {
        let s = builtin(name).unwrap();
        let text = s.to_toml_string();
        let back = Scene::from_toml_str(&text).unwrap_or_else(|e| panic!("{name}: {e}\n{text}"));
        assert_eq!(back, s, "{name}");
    }
}

#[test]
fn negative_value_names_field_and_line() {
    let e = err(&GOOD.replace("dt = 1e-4", "dt = -1e-4"));
    let m = e.to_string();
    assert_mentions(&m, &["line 6", "time.dt", "> 0"]);
}

#[test]
fn unknown_field_names_field_and_line() {
    let e = err(&GOOD.replace("gamma = 500.0", "gamma = 500.0\nstifness = 3"));
    let m = e.to_string();
    assert_mentions(&m, &["line 10", "stifness"]);
}

#[test]
fn wrong_type_and_syntax_errors_name_the_line() {
    let m = err(&GOOD.replace("resolution = 64", "resolution = \"big\"")).to_string();
    assert_mentions(&m, &["line 4", "grid.resolution"]);
    let m = err(&GOOD.replace("[material]", "[material")).to_string();
    assert_mentions(&m, &["line 7"]);
    let m = err(&GOOD.replace("resolution = 64", "resolution = 3")).to_string();
    assert_mentions(&m, &["line 4", "from 8"]);
}

#[test]
fn missing_field_is_named() {
    let m = err(&GOOD.replace("friction = 0.05\n", "")).to_string();
    assert_mentions(&m, &["friction"]);
}

#[test]
fn inconsistent_geometry_names_the_yarn_and_its_line() {
    let m = err(&GOOD.replace("length = 0.5", "length = 5.0")).to_string();
    assert_mentions(&m, &["yarns[0]", "line 12", "outside"]);
    let m = err(&GOOD.replace("direction = [1.0, 0.0]\n", "")).to_string();
    assert_mentions(&m, &["yarns[0]", "give either"]);
    let m = err(&GOOD.replace("direction = [1.0, 0.0]", "direction = [0.0, 0.0]")).to_string();
    assert_mentions(&m, &["direction", "zero"]);
}

#[test]
fn unknown_builtin_lists_the_known_ones() {
    match Scene::resolve("no-such-scene") {
        Err(SceneError::UnknownScene { known, .. }) => {
            assert!(known.contains(&"yarn-reference".to_string()))
        }
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        Scene::resolve("/nonexistent/x.toml"),
        Err(SceneError::Io { .. })
    ));
}

#[test]
fn integrator_defaults_to_explicit_and_is_left_out_of_the_toml() {
    let s = YarnScene::from_toml_str(GOOD).unwrap();
    assert_eq!(s.time.integrator, Integrator::Explicit);
    // Saying "explicit" is the same scene as leaving it out (so the same
    // substeps), and the default is not written back: scene files and
    // snapshots of today's scenes do not change.
    let said = YarnScene::from_toml_str(
        &GOOD.replace("dt = 1e-4", "dt = 1e-4\nintegrator = \"explicit\""),
    )
    .unwrap();
    assert_eq!(said, s);
    assert!(!s.to_toml_string().contains("integrator"));
    for (name, _) in builtin_names() {
        if let Scene::Yarn(y) = builtin(name).unwrap() {
            assert_eq!(y.time.integrator, Integrator::Explicit, "{name}");
        }
    }
}

#[test]
fn implicit_integrator_loads_and_an_unknown_one_is_refused_naming_the_field_and_line() {
    // The minimal scene (whole energy, plasticity, sticky walls) loads
    // under the implicit step, also with a free yarn beside a pinned one
    // (tests/implicit.rs covers the features).
    let implicit = GOOD.replace("dt = 1e-4", "dt = 1e-4\nintegrator = \"implicit\"");
    let s = YarnScene::from_toml_str(&implicit).unwrap();
    assert_eq!(s.time.integrator, yarnsim::scene::Integrator::Implicit);
    let mixed = format!(
        "{implicit}[[yarns]]\npoints = [[0.2, 0.3], [0.4, 0.3]]\nvertices = 5\n\
         [[pins]]\nyarn = 0\nend = \"start\"\n"
    );
    YarnScene::from_toml_str(&mixed).unwrap();
    // An unknown integrator is a field error too.
    let m = err(&GOOD.replace("dt = 1e-4", "dt = 1e-4\nintegrator = \"rk4\"")).to_string();
    assert_mentions(&m, &["line 7", "time.integrator", "rk4"]);
}

/// Every built-in is a file under `scenes/` (`scenes/yarn/NAME.toml`,
/// `scenes/massspring/NAME.toml`), the text the library embeds; it loads
/// through the loader of users' files, and its `scene show` text (and its
/// plain TOML) reads back to the same scene bit for bit (the `Debug` text
/// prints every float in its shortest round-trip form and tells -0.0 from
/// 0.0, which `==` does not). While the Rust constructors still existed, this
/// test compared each file with its constructor's scene.
#[test]
fn every_builtin_is_its_file_under_scenes() {
    for (name, _) in builtin_names() {
        let s = builtin(name).unwrap();
        let folder = match s {
            Scene::Yarn(_) => "yarn",
            Scene::MassSpring(_) => "massspring",
        };
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenes")
            .join(folder)
            .join(format!("{name}.toml"));
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(Some(text.as_str()), builtin_toml(name), "{name}");
        let file = Scene::from_file(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!(s.name(), name);
        for back in [s.to_commented_toml(), s.to_toml_string()] {
            let back = Scene::from_toml_str(&back).unwrap();
            assert_eq!(format!("{back:?}"), format!("{file:?}"), "{name}");
            assert_eq!(back, file, "{name}");
        }
    }
}
