//! What the `yarnsim` binary says when a yarn scene cannot run as asked: a
//! fixed `time.dt` against the stable bound (warned, refused, forced with
//! `--allow-unstable` into the divergence, whose error carries the same
//! hint), the mass-spring flags on a yarn scene, field paths in the one
//! form `--set` takes and errors print, and a yarn diameter the contact
//! cannot carry (warned under shared fields, refused beyond the grid).

mod common;

use common::{on_small_scene, small_scene, stderr, stdout, tmp, yarnsim};
use yarnsim::scene::{Scene, YarnScene};
use yarnsim::YarnSim;

/// The user study's case: yarn-drape made stiff and light, at its own
/// dt 4e-5 s.
const STIFF: [&str; 4] = ["--set", "material.k=8e4", "--set", "material.density=0.02"];

/// The stable bound of `yarn-drape` with `STIFF`, from the library (the
/// number the FMU warns with): `YarnSim::stable_dt` at the start.
fn stiff_bound() -> f64 {
    let Scene::Yarn(s) = Scene::resolve_with(
        "yarn-drape",
        &["material.k=8e4".into(), "material.density=0.02".into()],
    )
    .unwrap() else {
        unreachable!()
    };
    YarnSim::new(&s).unwrap().stable_dt()
}

/// `record yarn-drape -d 0.01 -o <rrd>`.
fn record_drape(rrd: &std::path::Path) -> Vec<&str> {
    vec![
        "record",
        "yarn-drape",
        "-d",
        "0.01",
        "-o",
        rrd.to_str().unwrap(),
    ]
}

fn args<'a>(head: &[&'a str], tail: &[&'a str]) -> Vec<&'a str> {
    head.iter().chain(tail).copied().collect()
}

#[test]
fn a_fixed_dt_far_above_the_bound_is_refused_naming_the_bound() {
    let bound = stiff_bound();
    let rrd = tmp("refused.rrd");
    // dx / c = (1/256 m) / sqrt(8e4 Pa / 0.02 kg/m) = 1.953125e-6 s.
    assert!((bound - 1.953125e-6).abs() < 1e-15, "{bound}");
    let expected = format!(
        "error: substep dt = 0.00004 s exceeds the stability bound {bound:.6e} s of this yarn \
         scene (20.5x), more than 2x: it would diverge; set time.dt = \"auto\" (--set \
         time.dt=auto) or a dt below the bound, or pass --allow-unstable to run it anyway\n"
    );
    for cmd in [
        vec!["run", "yarn-drape", "-d", "0.01"],
        record_drape(&rrd),
        vec!["bench", "yarn-drape", "--steps", "5"],
    ] {
        let out = yarnsim(&args(&cmd, &STIFF));
        assert_eq!(out.status.code(), Some(2), "{cmd:?}: {}", stderr(&out));
        assert_eq!(stderr(&out), expected, "{cmd:?}");
        assert!(stdout(&out).is_empty(), "{cmd:?}");
    }
    assert!(!rrd.exists());
}

#[test]
fn forced_it_diverges_and_the_divergence_says_why() {
    let bound = stiff_bound();
    let out = yarnsim(&args(
        &["run", "yarn-drape", "-d", "0.01", "--allow-unstable"],
        &STIFF,
    ));
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let err = stderr(&out);
    let mut lines = err.lines();
    assert_eq!(
        lines.next().unwrap(),
        format!(
            "warning: substep dt = 0.00004 s exceeds the stability bound {bound:.6e} s of this \
             yarn scene (20.5x); running anyway (--allow-unstable)"
        )
    );
    let failure = lines.next().unwrap();
    assert!(
        failure
            .starts_with("error: simulation diverged at step 6 (t = 0.000240 s): vertex 0 moves "),
        "{failure}"
    );
    assert!(
        failure.ends_with(&format!(
            "(CFL limit 97.656 m/s); the substep dt = 0.00004 s is 20.5x the stability bound \
             {bound:.6e} s of this yarn scene at rest; set time.dt = \"auto\" (--set \
             time.dt=auto), or a smaller dt"
        )),
        "{failure}"
    );
    assert!(stdout(&out).contains("stopped: the simulation failed"));

    // `record` and `bench` report the same divergence.
    let rrd = tmp("forced.rrd");
    for cmd in [
        record_drape(&rrd),
        vec!["bench", "yarn-drape", "--steps", "20", "--warmup", "0"],
    ] {
        let out = yarnsim(&args(&args(&cmd, &["--allow-unstable"]), &STIFF));
        assert_eq!(out.status.code(), Some(1), "{cmd:?}: {}", stderr(&out));
        let err = stderr(&out);
        assert!(
            err.contains("simulation diverged at step 6") && err.contains("set time.dt = \"auto\""),
            "{cmd:?}: {err}"
        );
    }

    // What the hint says works: the adaptive step runs the scene.
    let out = yarnsim(&args(
        &["run", "yarn-drape", "-d", "1ms", "--set", "time.dt=auto"],
        &STIFF,
    ));
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(stderr(&out), "");
}

/// Without the return mapping the built-in bundle diverges at its landing
/// (t = 0.126 s at dt 4e-5) and no smaller step helps: the hint names the
/// field to change instead of the step.
#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn a_divergence_without_plasticity_points_to_the_plasticity() {
    let out = yarnsim(&["run", "-d", "0.2", "--set", "material.plasticity=false"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(
        err.starts_with("error: simulation diverged at step "),
        "{err}"
    );
    assert!(
        err.contains("material.plasticity = false keeps every cross-section that has opened")
            && err
                .trim_end()
                .ends_with("set material.plasticity = true (--set material.plasticity=true)"),
        "{err}"
    );
    assert!(!err.contains("a smaller dt"), "{err}");
    // A fixed step above its bound is the step's fault, plasticity or not.
    let forced = args(
        &[
            "run",
            "yarn-drape",
            "-d",
            "0.01",
            "--allow-unstable",
            "--set",
            "material.plasticity=false",
        ],
        &STIFF,
    );
    let err = stderr(&yarnsim(&forced));
    assert!(err.contains("x the stability bound"), "{err}");
    assert!(!err.contains("keeps every cross-section"), "{err}");
}

#[test]
fn a_fixed_dt_a_little_above_the_bound_is_warned_about() {
    // The small scene's density lowered until its bound is dt / 1.3: the
    // bound is dx / (c + v), c = sqrt(stiffness / density), v = 1 m/s.
    let text = std::fs::read_to_string(small_scene()).unwrap();
    let base = YarnScene::from_toml_str(&text).unwrap();
    let bound = YarnSim::new(&base).unwrap().stable_dt();
    let dt = base.time.dt.fixed().unwrap();
    let v = 1.0;
    let c = base.dx() / bound - v;
    let c_new = base.dx() / (dt / 1.3) - v;
    let density = base.material.density * (c / c_new).powi(2);
    let set = format!("material.density={density}");
    let Scene::Yarn(s) =
        Scene::resolve_with(small_scene().to_str().unwrap(), std::slice::from_ref(&set)).unwrap()
    else {
        unreachable!()
    };
    let bound = YarnSim::new(&s).unwrap().stable_dt();
    assert!((dt / bound - 1.3).abs() < 1e-9, "{}", dt / bound);
    let out = on_small_scene("run", &["-d", "2ms", "--set", &set]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(
        stderr(&out),
        format!(
            "warning: substep dt = 0.00004 s exceeds the stability bound {bound:.6e} s of this \
             yarn scene (1.3x); the run may diverge; set time.dt = \"auto\" (--set \
             time.dt=auto) to step within the bound\n"
        )
    );
    // At the bound itself: not a word.
    let out = yarnsim(&["run", small_scene().to_str().unwrap(), "-d", "2ms"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(stderr(&out), "");
}

#[test]
fn mass_spring_flags_on_a_yarn_scene_point_to_the_scene_field() {
    let out = yarnsim(&["run", "yarn-drape", "--integrator", "implicit"]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        stderr(&out),
        "error: --integrator applies to mass-spring scenes; a yarn scene takes its integrator \
         from the scene field time.integrator: --set time.integrator=implicit (one of explicit, \
         implicit, implicit-vertices, midpoint-vertices)\n"
    );
    let out = yarnsim(&["record", "yarn-drape", "--option", "dt=1e-4"]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        stderr(&out),
        "error: --option dt=1e-4 applies to mass-spring scenes; set a yarn scene's fields with \
         --set KEY=VALUE, e.g. --set time.dt=auto or --set time.integrator=implicit\n"
    );
    // The pointer works: the scene field takes the integrator.
    let out = yarnsim(&[
        "run",
        "yarn-drape",
        "-d",
        "0.02",
        "--set",
        "time.integrator=implicit",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn set_takes_both_index_forms_and_errors_print_brackets() {
    let small = small_scene();
    let small = small.to_str().unwrap();
    let particles = |key: &str| {
        let out = yarnsim(&["run", small, "-d", "1ms", "--set", key]);
        assert!(out.status.success(), "{key}: {}", stderr(&out));
        let text = stdout(&out);
        text.lines()
            .find(|l| l.starts_with("particles"))
            .unwrap()
            .to_string()
    };
    let bracket = particles("yarns[0].vertices=40");
    assert_eq!(bracket, particles("yarns.0.vertices=40"));
    assert_ne!(bracket, particles("yarns[0].vertices=30"));
    assert!(bracket.contains("80 vertices"), "{bracket}");
    for key in ["yarns.0.vertices", "yarns[0].vertices"] {
        let out = yarnsim(&["run", small, "--set", &format!("{key}=many")]);
        assert_eq!(out.status.code(), Some(3));
        assert_eq!(
            stderr(&out),
            format!(
                "error: scene error in --set argument 1 (`{key}=many`): \
                 must be an integer, got the string \"many\"\n"
            )
        );
    }
    let out = yarnsim(&["run", small, "--set", "obstacles[1].radius=0.1"]);
    assert_eq!(out.status.code(), Some(3));
    assert_eq!(
        stderr(&out),
        "error: scene error in --set argument 1 (`obstacles[1].radius=0.1`): \
         index 1 is out of range: `obstacles` has 1 entry, `obstacles[0]`\n"
    );
    // A check on another entry's field than the one set names it.
    let out = yarnsim(&["run", small, "--set", "yarns.0.end=[1.5,0.65]"]);
    assert_eq!(out.status.code(), Some(3));
    assert_eq!(
        stderr(&out),
        "error: scene error in --set argument 1 (`yarns.0.end=[1.5,0.65]`): yarn 0 (copy 0 of \
         this entry's 2) ends at [1.5, 0.65], outside the \
         grid interior: x and y must be within [0.023438, 0.976562] m, 1.5 grid cells inside \
         the domain [0, 1] m\n"
    );
}

#[test]
fn a_yarn_outside_the_grid_is_named_in_the_file() {
    let text = std::fs::read_to_string(small_scene()).unwrap();
    let file = tmp("outside.toml");
    std::fs::write(
        &file,
        text.replace("spacing = [0.0, 0.03]", "spacing = [0.0, 0.4]"),
    )
    .unwrap();
    let out = yarnsim(&["run", file.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(3));
    assert_eq!(
        stderr(&out),
        "error: scene error at line 38 in field `yarns[0].start`: yarn 1 (copy 1 of this \
         entry's 2, shifted by 1 x spacing [0, 0.4]) starts at [0.2, 1], outside the grid \
         interior: x and y must be within [0.023438, 0.976562] m, 1.5 grid cells inside the \
         domain [0, 1] m\n"
    );
}

/// A yarn diameter with the free yarns in one field warns that it does not
/// act between them; per-yarn fields do not warn; a diameter beyond what
/// the grid carries between yarns is refused naming the field and the
/// resolution that carries it.
#[test]
fn a_yarn_diameter_warns_under_shared_fields_and_is_refused_beyond_the_grid() {
    let run = |sets: &[&str]| {
        let mut args = vec!["run", "yarn-reference", "--duration", "2ms"];
        for s in sets {
            args.extend(["--set", s]);
        }
        yarnsim(&args)
    };
    let out = run(&["material.diameter=0.002"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(
        err.contains("warning: material.diameter = 0.002 m does not act between free yarns"),
        "{err}"
    );
    let out = run(&["material.diameter=0.002", "contact.fields=per-yarn"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        !stderr(&out).contains("material.diameter"),
        "{}",
        stderr(&out)
    );
    // 0.02 m is 5.12 cells of 256^2 over 1 m; 1.75 cells of 87^2 carry it
    let out = run(&["material.diameter=0.02", "contact.fields=per-yarn"]);
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(
        err.contains("material.diameter") && err.contains("grid.resolution to at most 87"),
        "{err}"
    );
}
