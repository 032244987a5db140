//! Adaptive substeps in the YarnBundle FMU: `dt = 0` (or a scene with
//! `dt = "auto"`) lands every communication step on its point with
//! substeps from the stability bound, gives the library's bits, and stays
//! inside `max_substeps_per_step`.

mod common;

use std::ffi::c_int;

use common::*;
use yarnsim::mpm::YarnSim;
use yarnsim::scene::{StepSize, YarnScene};
use yarnsim_fmu::fmi2::*;
use yarnsim_fmu::model_description::*;
use yarnsim_fmu::models::yarn::variables::*;

const H: f64 = 0.01;

fn set_int(f: &Fmu, vr: u32, v: c_int) -> fmi2Status {
    // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every pointer
    // argument is a local that outlives the call.
    unsafe { fmi2SetInteger(f.c, &vr, 1, &v) }
}

fn auto_scene() -> YarnScene {
    let mut s = small_scene();
    s.time.dt = StepSize::Auto;
    s
}

/// `dt = 0` set on the fixed-dt scene and a scene with `dt = "auto"` run the
/// same adaptive substeps as `YarnSim::advance_to` on every communication
/// point: bit-identical outputs and the same substep count, fewer than the
/// scene's fixed `dt` needs.
#[test]
fn dt_zero_runs_the_library_adaptive_substeps() {
    let fixed = small_scene();
    let by_parameter = Fmu::new(&fixed);
    assert_eq!(by_parameter.set_real(&[VR_DT], &[0.0]), fmi2OK);
    by_parameter.init();
    assert_eq!(by_parameter.get_real(&[VR_DT]).unwrap(), vec![0.0]);
    let by_scene = Fmu::initialized(&auto_scene());
    assert_eq!(by_scene.get_real(&[VR_DT]).unwrap(), vec![0.0]);
    let mut sim = YarnSim::new(&auto_scene()).unwrap();
    let steps = 10;
    for k in 0..steps {
        let t = k as f64 * H;
        for f in [&by_parameter, &by_scene] {
            assert_eq!(f.do_step(t, H), fmi2OK, "{:?}", f.lines());
        }
        // The FMU's point: t + h on its clock from the start time 0.
        sim.advance_to(t + H).unwrap();
        assert_eq!(sim.time(), t + H);
    }
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    let lib: Vec<f64> = (0..by_scene.yarns)
        .flat_map(|y| {
            let (l, r) = sim.yarn_endpoints(y);
            [l.x, l.y, r.x, r.y]
        })
        .collect();
    for f in [&by_parameter, &by_scene] {
        let out = f.outputs();
        assert_eq!(bits(&out[..lib.len()]), bits(&lib));
        assert_eq!(f.substeps() as u64, sim.steps());
    }
    let fixed_count = (steps as f64 * H / fixed.time.dt.fixed().unwrap()).round() as u64;
    eprintln!(
        "small scene, 0.1 s: {} adaptive substeps, {fixed_count} fixed",
        sim.steps()
    );
    assert!(sim.steps() < fixed_count);
}

/// The substep budget bounds adaptive steps too: a step whose estimate
/// exceeds it is refused before any substep (fmi2Error); a positive `dt`
/// set again gives fixed substeps.
#[test]
fn max_substeps_per_step_bounds_adaptive_steps() {
    let f = Fmu::new(&auto_scene());
    assert_eq!(set_int(&f, VR_MAX_SUBSTEPS, 3), fmi2OK);
    f.init();
    assert_eq!(f.do_step(0.0, H), fmi2Error);
    let e = f.last_error();
    assert!(
        e.contains("needs about") && e.contains("max_substeps_per_step = 3"),
        "{e}"
    );
    // A short step fits (a fresh instance: an fmi2Error ends the first).
    let f = Fmu::new(&auto_scene());
    assert_eq!(set_int(&f, VR_MAX_SUBSTEPS, 3), fmi2OK);
    f.init();
    assert_eq!(f.do_step(0.0, 1e-3), fmi2OK, "{:?}", f.lines());
    assert!((1..=3).contains(&f.substeps()), "{}", f.substeps());

    let g = Fmu::new(&auto_scene());
    assert_eq!(g.set_real(&[VR_DT], &[2e-4]), fmi2OK);
    g.init();
    assert_eq!(g.do_step(0.0, H), fmi2OK);
    assert_eq!(g.substeps(), 50);
}

/// A step whose estimate fits the budget but whose yarn speeds up (gravity
/// 2000 m/s^2 lowers the bound within the step) so that it needs more
/// substeps after all is undone with fmi2Error: the budget bounds the work
/// of every call.
#[test]
fn a_step_that_outgrows_its_estimate_is_undone() {
    let f = Fmu::new(&auto_scene());
    assert_eq!(set_int(&f, VR_MAX_SUBSTEPS, 10), fmi2OK);
    f.init();
    let dt0 = YarnSim::new(&auto_scene()).unwrap().dt();
    assert_eq!(
        f.set_real(&[VR_GRAVITY_X, VR_GRAVITY_Y], &[0.0, -2000.0]),
        fmi2OK
    );
    assert_eq!(f.do_step(0.0, 9.5 * dt0), fmi2Error);
    let e = f.last_error();
    assert!(
        e.contains("needed more than max_substeps_per_step = 10") && e.contains("undone"),
        "{e}"
    );
}

/// Under `dt = "auto"` the pin force output is the time average over the
/// communication step's substeps (weighted by their lengths), the same
/// bits as the library's reactions averaged that way.
#[test]
fn pin_force_is_the_time_average_of_the_adaptive_substeps() {
    let text = SMALL_SCENE
        .replace(
            "count = 3\nspacing = [0.0, 0.03]",
            "count = 2\nspacing = [0.0, 0.1]\n\n[[pins]]\nyarn = 0\nend = \"start\"\n",
        )
        .replace("dt = 2e-4", "dt = \"auto\"");
    let scene = YarnScene::from_toml_str(&text).unwrap();
    assert!(scene.time.dt.is_auto() && scene.pins.len() == 1);
    let f = Fmu::initialized(&scene);
    let mut sim = YarnSim::new(&scene).unwrap();
    let force = [VR_PIN_BASE + PIN_FORCE, VR_PIN_BASE + PIN_FORCE + 1];
    for k in 0..5 {
        let t = k as f64 * H;
        assert_eq!(f.do_step(t, H), fmi2OK, "{:?}", f.lines());
        let (mut sum, mut span) = (yarnsim::math::Vec2::zeros(), 0.0);
        loop {
            let before = sim.time();
            if !sim.step_toward(t + H).unwrap() {
                break;
            }
            let w = sim.time() - before;
            sum -= sim.pin_reactions()[0] * w;
            span += w;
        }
        let mean = sum / span;
        let fmu = f.get_real(&force).unwrap();
        assert_eq!(
            [fmu[0].to_bits(), fmu[1].to_bits()],
            [mean.x.to_bits(), mean.y.to_bits()],
            "step {k}"
        );
    }
}
