//! Adaptive substeps, `[time] dt = "auto"`: each substep is the safety
//! factor times the stability bound of the state it starts from
//! ([`yarnsim::mpm::driver::timestep`]), the last one before a frame or
//! communication point shortened to land on it.

mod common;

use common::{bundle, SceneBuilder};
use yarnsim::mpm::Stepping;
use yarnsim::scene::{builtin, Scene, SceneError, StepSize, WallMode, YarnScene, DEFAULT_SAFETY};
use yarnsim::YarnSim;

fn reference() -> YarnScene {
    let Some(Scene::Yarn(s)) = builtin("yarn-reference") else {
        panic!("yarn-reference is a yarn scene")
    };
    s
}

fn auto(mut s: YarnScene) -> YarnScene {
    s.time.dt = StepSize::Auto;
    s
}

/// The reference scene under `"auto"` lands on the circles like the fixed
/// 4e-5 s run (the checks of `mpm_reference`: stretch within [0.97, 1.05]
/// at t = 0.5 s, finite state) in fewer substeps: measured 6513 against
/// 12500 (0.52); the bound asserted is 0.6.
#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn reference_scene_runs_stable_in_fewer_substeps() {
    let mut sim = YarnSim::new(&auto(reference())).unwrap();
    assert_eq!(
        sim.stepping(),
        Stepping::Auto {
            safety: DEFAULT_SAFETY,
            dt_max: f64::INFINITY
        }
    );
    sim.advance(0.5).unwrap();
    assert_eq!(sim.time(), 0.5);
    for (k, s) in sim.stretches().iter().enumerate() {
        assert!((0.97..=1.05).contains(s), "segment {k} stretch {s}");
    }
    let p = sim.particles();
    assert!(p
        .vert
        .x
        .iter()
        .chain(&p.vert.v)
        .chain(&p.quad.x)
        .chain(&p.quad.v)
        .all(|x| x.x.is_finite() && x.y.is_finite()));
    assert!(sim.diagnostics().center_of_mass.y < 0.7);
    let stats = sim.dt_stats();
    let fixed = (0.5f64 / 4e-5).round() as u64;
    eprintln!(
        "reference, dt = \"auto\": {} substeps (fixed 4e-5: {fixed}, ratio {:.3}), dt min / mean / max {:.3e} / {:.3e} / {:.3e} s",
        stats.substeps,
        stats.substeps as f64 / fixed as f64,
        stats.min,
        stats.mean(),
        stats.max
    );
    assert_eq!(stats.substeps, sim.steps());
    assert!((stats.substeps as f64) < 0.6 * fixed as f64);
}

/// A small, fast scene: the reference bundle's material on a 64^2 grid.
fn small() -> YarnScene {
    SceneBuilder::bare()
        .dt(StepSize::Auto)
        .frame_dt(0.01)
        .gravity([0.0, -9.8])
        .walls(WallMode::Sticky)
        .material(|m| {
            m.bending = 1e-3;
            m.plasticity = true;
        })
        .obstacle([0.5, 0.3], 0.1, 0.3)
        .yarn(bundle([0.2, 0.6], [0.8, 0.6], 60, 3, [0.0, 0.03]))
        .build()
}

/// Frame times are hit exactly (the clock reads `k * frame_dt`, no
/// overshoot), every substep is at most the bound of the state it starts
/// from, and no substep before a frame is a sliver: all are at least half
/// the smallest bound seen (the rest between one and two bounds is split
/// evenly).
#[test]
fn frames_are_hit_exactly_and_every_substep_respects_the_bound() {
    let mut sim = YarnSim::new(&small()).unwrap();
    let frame_dt = sim.scene().time.frame_dt;
    let frames = if cfg!(debug_assertions) { 3 } else { 20 };
    let mut min_bound = f64::INFINITY;
    let mut min_dt = f64::INFINITY;
    for k in 1..=frames {
        let until = k as f64 * frame_dt;
        loop {
            let bound = sim.auto_dt();
            assert!(bound <= DEFAULT_SAFETY * sim.stable_dt());
            let Some(dt) = sim.substep_toward(until) else {
                break;
            };
            assert!(dt <= bound, "substep {dt} above the bound {bound}");
            min_bound = min_bound.min(bound);
            min_dt = min_dt.min(dt);
            let before = sim.time();
            assert!(sim.step_toward(until).unwrap());
            assert!(sim.time() <= until, "overshoot: {} > {until}", sim.time());
            assert!(sim.time() > before);
        }
        assert_eq!(sim.time(), until, "frame {k}");
        assert!(!sim.step_toward(until).unwrap(), "nothing left to do");
    }
    assert!(min_dt >= 0.5 * min_bound, "{min_dt} vs {min_bound}");
    assert_eq!(sim.dt_stats().substeps, sim.steps());
}

/// `dt_max` caps the substep; a cap that divides the frame interval gives
/// equal substeps.
#[test]
fn dt_max_caps_the_substep() {
    let mut s = small();
    s.time.dt_max = Some(1e-4);
    let mut sim = YarnSim::new(&s).unwrap();
    sim.advance_to(0.01).unwrap();
    let st = sim.dt_stats();
    assert_eq!(sim.time(), 0.01);
    assert!(st.max <= 1e-4, "{st:?}");
    assert!((99..=101).contains(&st.substeps), "{st:?}");
}

/// The same run with 1 and with 2 threads: bit-identical state and
/// substeps (the largest particle speed is a maximum, whose value does not
/// depend on the order of the parallel reduction).
#[test]
fn bit_identical_for_one_and_two_threads() {
    let t_end = if cfg!(debug_assertions) { 0.01 } else { 0.1 };
    common::same_on_one_and_two_threads(|| {
        let mut sim = YarnSim::new(&small()).unwrap();
        sim.advance_to(t_end).unwrap();
        (sim.save_state(), sim.dt_stats())
    });
}

/// `dt = "auto"`, `safety` and `dt_max` read and write back; bad values
/// name the field and the line.
#[test]
fn scene_fields_read_back_and_bad_values_name_field_and_line() {
    let text = |time: &str| {
        format!(
            "[grid]\nresolution = 64\n[time]\n{time}\n[material]\nk = 1000.0\ngamma = 0.0\nyoungs_modulus = 0.0\nfriction = 0.0\n[[yarns]]\nstart = [0.2, 0.5]\nend = [0.8, 0.5]\nvertices = 20\n"
        )
    };
    let s = YarnScene::from_toml_str(&text("dt = \"auto\"\nsafety = 0.5\ndt_max = 1e-4")).unwrap();
    assert_eq!(s.time.dt, StepSize::Auto);
    assert_eq!((s.time.safety, s.time.dt_max), (Some(0.5), Some(1e-4)));
    assert_eq!(YarnScene::from_toml_str(&s.to_toml_string()).unwrap(), s);
    let f = YarnScene::from_toml_str(&text("dt = 2e-4")).unwrap();
    assert_eq!(f.time.dt, StepSize::Fixed(2e-4));
    assert_eq!(YarnScene::from_toml_str(&f.to_toml_string()).unwrap(), f);

    let err = |time: &str| -> String {
        let e: SceneError = YarnScene::from_toml_str(&text(time)).unwrap_err();
        e.to_string()
    };
    for (time, line, field, what) in [
        ("dt = \"fast\"", 4, "time.dt", "\"auto\""),
        ("dt = -1.0", 4, "time.dt", "\"auto\""),
        ("dt = 0.0", 4, "time.dt", "> 0"),
        ("dt = \"auto\"\nsafety = 0.0", 5, "time.safety", "(0, 2]"),
        ("dt = \"auto\"\nsafety = 3.0", 5, "time.safety", "(0, 2]"),
        ("dt = \"auto\"\ndt_max = -1e-4", 5, "time.dt_max", "> 0"),
        (
            "dt = 1e-4\nsafety = 0.5",
            5,
            "time.safety",
            "only to dt = \"auto\"",
        ),
        (
            "dt = 1e-4\n\ndt_max = 1e-3",
            6,
            "time.dt_max",
            "only to dt = \"auto\"",
        ),
    ] {
        let m = err(time);
        assert!(
            m.contains(&format!("line {line}")) && m.contains(field) && m.contains(what),
            "{time:?}: {m}"
        );
    }
}
