//! Real time: the YarnBundle FMU of a preset bundle (`[material] preset =
//! "polyester-167dtex"`, the measured EA) with `[time] axial = "implicit"`
//! (APIC, `dt = "auto"`, the FMU's `dt` 0: adaptive substeps), stepped at
//! 1/60 s communication steps on one thread (`threads` = 1): the wall time
//! per simulated second for bundles from the reference size down, and the
//! same scene explicit (short, extrapolated). The measurement of
//! `docs/performance/fmu.md`, "Real time" (ignored: `cargo test --workspace
//! --release --test real_time -- --ignored --nocapture`).

mod common;

use std::time::Instant;

use common::Fmu;
use yarnsim::scene::YarnScene;
use yarnsim_fmu::fmi2::fmi2OK;
use yarnsim_fmu::model_description::{VR_MAX_SUBSTEPS, VR_THREADS};

/// One communication step: 1/60 s.
const H: f64 = 1.0 / 60.0;

/// `yarns` polyester yarns of 0.8 m and `vertices` vertices, 1 cm apart,
/// falling onto the reference bundle's three circles on a `res`^2 grid,
/// `dt = "auto"`, APIC, with the axial solve or explicit.
fn bundle(yarns: u32, vertices: u32, res: u32, axial: bool) -> YarnScene {
    let axial = if axial { "implicit" } else { "explicit" };
    let mut text = format!(
        "kind = \"yarn\"\ngravity = [0.0, -9.8]\n[grid]\nresolution = {res}\n[time]\n\
         dt = \"auto\"\naxial = \"{axial}\"\n[transfer]\nscheme = \"apic\"\n\
         [material]\npreset = \"polyester-167dtex\"\n"
    );
    for c in ["[0.25, 0.6]", "[0.5, 0.3]", "[0.75, 0.5]"] {
        text += &format!("[[obstacles]]\ncenter = {c}\nradius = 0.08\n");
    }
    text += &format!(
        "[[yarns]]\nstart = [0.1, 0.75]\ndirection = [1.0, 0.0]\nlength = 0.8\n\
         vertices = {vertices}\ncount = {yarns}\nspacing = [0.0, 0.01]\n"
    );
    YarnScene::from_toml_str(&text).unwrap()
}

/// Runs `steps` communication steps of `h` of the FMU for `scene` on one
/// thread; returns the wall time per simulated second and the mean
/// substeps per communication step (every step fmi2OK, or it panics with
/// the log).
fn run(scene: &YarnScene, steps: u32, h: f64) -> (f64, f64) {
    let f = Fmu::new(scene);
    assert_eq!(f.set_integer(VR_THREADS, 1), fmi2OK);
    assert_eq!(f.set_integer(VR_MAX_SUBSTEPS, 1_000_000), fmi2OK);
    // its diameter does not act between the yarns of one shared field: a
    // warning at initialization (`YarnScene::diameter_warning`)
    f.init_warned();
    let start = Instant::now();
    let mut substeps = 0;
    for k in 0..steps {
        assert_eq!(f.do_step(k as f64 * h, h), fmi2OK, "{:?}", f.lines());
        substeps += f.substeps();
    }
    let wall = start.elapsed().as_secs_f64();
    (wall / (steps as f64 * h), substeps as f64 / steps as f64)
}

#[test]
#[ignore = "measurement (minutes): --ignored --nocapture"]
fn real_time_of_a_preset_bundle() {
    for (yarns, vertices, res, steps) in [
        (12, 200, 256, 12),
        (12, 100, 128, 30),
        (6, 100, 128, 30),
        (3, 50, 64, 60),
        (3, 50, 32, 60),
    ] {
        let scene = bundle(yarns, vertices, res, true);
        // the substep `dt = "auto"` takes at rest (the cross-section wave)
        let at_rest = yarnsim::YarnSim::new(&scene).unwrap().auto_dt();
        let (ratio, per) = run(&scene, steps, H);
        eprintln!(
            "| {yarns} x {vertices} | {res}^2 | axial | {:.2} s | {ratio:.3} | {per:.0} | {:.0} |",
            steps as f64 * H,
            H / at_rest
        );
        assert!(ratio.is_finite() && ratio > 0.0);
    }
    // explicit at the real EA: 2 ms of simulated time in one step,
    // extrapolated to one second (the substep is fixed by the fibre wave)
    for (yarns, vertices, res) in [(12, 200, 256), (3, 50, 64)] {
        let (ratio, per) = run(&bundle(yarns, vertices, res, false), 1, 2e-3);
        eprintln!("| {yarns} x {vertices} | {res}^2 | explicit | 0.002 s | {ratio:.1} | {per:.0} per 2 ms |");
        assert!(ratio.is_finite() && ratio > 0.0);
    }
}
