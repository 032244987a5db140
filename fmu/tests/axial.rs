//! The stiff-yarn setting through parameters: `transfer.flip_time` (a
//! FLIP relaxation time, 0 for none) and `time.axial` (the fibre stretch
//! by backward Euler on each yarn's vertices) give the library's bits for
//! the same scene, travel in the FMU state, and refuse what the scene
//! file refuses, naming the variable.

mod common;

use common::*;
use yarnsim::mpm::YarnSim;
use yarnsim::scene::{Axial, StepSize, TransferScheme, YarnScene};
use yarnsim_fmu::fmi2::*;
use yarnsim_fmu::models::yarn::variables::*;

const H: f64 = 0.01;
const STEPS: u32 = 6;

/// The small scene with a stiff fibre (`k` x100: a wave 10 times faster
/// than the scene's own), where the axial step changes the answer, at a
/// substep below the explicit bound of that wave (5e-5 s against 6.6e-5
/// s), so that the default setting runs too.
fn stiff_scene() -> YarnScene {
    let mut s = small_scene();
    s.material.k *= 100.0;
    s.time.dt = StepSize::Fixed(5e-5);
    s
}

/// The library's yarn ends and energies after `STEPS` communication steps
/// of `H` (the small scene's fixed substep divides `H`).
fn library_run(scene: &YarnScene) -> Vec<f64> {
    scene.validate().unwrap();
    let mut sim = YarnSim::new(scene).unwrap();
    let per_step = (H / scene.time.dt.fixed().unwrap()).round() as u64;
    sim.steps_n(STEPS as u64 * per_step).unwrap();
    library_outputs(&sim)
}

/// An FMU of `scene` with `time.axial`, `transfer.scheme` and
/// `transfer.flip_time` set (where given) before initialization.
fn fmu_with(
    scene: &YarnScene,
    axial: Option<&str>,
    scheme: Option<&str>,
    flip_time: Option<f64>,
) -> Fmu {
    let f = Fmu::new(scene);
    if let Some(a) = axial {
        assert_eq!(f.set_string(VR_AXIAL, a), fmi2OK, "{:?}", f.lines());
    }
    if let Some(s) = scheme {
        assert_eq!(f.set_string(VR_TRANSFER_SCHEME, s), fmi2OK);
    }
    if let Some(t) = flip_time {
        assert_eq!(f.set_real(&[VR_FLIP_TIME], &[t]), fmi2OK, "{:?}", f.lines());
    }
    f
}

/// Every combination a user reaches the stiff setting by runs the
/// library's bits of the scene with the same fields, and each changes the
/// answer of the default setting.
#[test]
fn the_axial_and_flip_time_parameters_give_the_library_bits() {
    let scene = stiff_scene();
    let default = {
        let f = Fmu::initialized(&scene);
        assert_eq!(f.get_string(VR_AXIAL), "explicit");
        assert_eq!(f.get_real(&[VR_FLIP_TIME]), Ok(vec![0.0]));
        f.steps_ok(0..STEPS, H);
        f.outputs()
    };
    assert_eq!(bits(&default), bits(&library_run(&scene)));
    let cases = [
        (None, None, Some(0.002)),
        (Some("implicit"), None, Some(0.002)),
        (Some("implicit"), Some("apic"), None),
    ];
    for (axial, scheme, flip_time) in cases {
        let f = fmu_with(&scene, axial, scheme, flip_time);
        f.init();
        let mut lib = scene.clone();
        if axial == Some("implicit") {
            lib.time.axial = Axial::Implicit;
        }
        if scheme == Some("apic") {
            lib.transfer.scheme = TransferScheme::Apic;
        }
        lib.transfer.flip_time = flip_time;
        let want = axial.unwrap_or("explicit");
        assert_eq!(f.get_string(VR_AXIAL), want);
        assert_eq!(
            f.get_real(&[VR_FLIP_TIME]),
            Ok(vec![flip_time.unwrap_or(0.0)])
        );
        f.steps_ok(0..STEPS, H);
        let out = f.outputs();
        let case = format!("{axial:?} {scheme:?} {flip_time:?}");
        assert_eq!(bits(&out), bits(&library_run(&lib)), "{case}");
        assert_ne!(bits(&out), bits(&default), "{case}");
    }
}

/// The axial step changes no output before the first step: the outputs
/// read in initialization mode declare no initial dependency on
/// `time.axial` (`tests/dependencies.rs` cannot set it on its pure-FLIP
/// scenes).
#[test]
fn the_axial_step_changes_no_output_at_initialization() {
    let scene = stiff_scene();
    let read = |axial: Option<&str>| {
        let f = fmu_with(&scene, axial, Some("apic"), None);
        assert_eq!(f.setup(0.0, None), fmi2OK);
        // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops.
        assert_eq!(unsafe { fmi2EnterInitializationMode(f.c) }, fmi2OK);
        let outs = f.get_real(&f.yarn_vrs()).unwrap();
        let energies = f
            .get_real(&[VR_KINETIC_ENERGY, VR_ELASTIC_ENERGY, VR_MAX_STRETCH])
            .unwrap();
        bits(&[outs, energies].concat())
    };
    assert_eq!(read(Some("implicit")), read(None));
}

/// A scene file's own `flip_time` is the parameter's start value, and the
/// parameter 0 removes it (the scene without a relaxation time).
#[test]
fn a_scene_files_flip_time_is_the_start_and_zero_removes_it() {
    let mut scene = stiff_scene();
    scene.transfer.flip_time = Some(0.004);
    let f = Fmu::initialized(&scene);
    assert_eq!(f.get_real(&[VR_FLIP_TIME]), Ok(vec![0.004]));
    let g = fmu_with(&scene, None, None, Some(0.0));
    g.init();
    assert_eq!(g.get_real(&[VR_FLIP_TIME]), Ok(vec![0.0]));
    g.steps_ok(0..STEPS, H);
    let mut without = scene.clone();
    without.transfer.flip_time = None;
    assert_eq!(bits(&g.outputs()), bits(&library_run(&without)));
}

/// Bad values are refused when set, with a log line naming the variable;
/// settings that only the whole scene can judge are refused at the end of
/// initialization, naming the scene field as a scene file's error does.
#[test]
fn bad_axial_and_flip_time_values_are_refused_naming_the_variable() {
    let scene = stiff_scene();
    let f = Fmu::new(&scene);
    for bad in ["", "Implicit", "backward-euler"] {
        assert_eq!(f.set_string(VR_AXIAL, bad), fmi2Error, "{bad}");
        f.assert_error_contains("time.axial");
        f.assert_error_contains("\"explicit\" or \"implicit\"");
        // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops.
        unsafe { assert_eq!(fmi2Reset(f.c), fmi2OK) };
    }
    for bad in [-1e-3, f64::NAN, f64::INFINITY] {
        assert_eq!(f.set_real(&[VR_FLIP_TIME], &[bad]), fmi2Error, "{bad}");
        f.assert_error_contains("transfer.flip_time");
        // SAFETY: as above.
        unsafe { assert_eq!(fmi2Reset(f.c), fmi2OK) };
    }
    // Checked with the scene at the end of initialization: the axial step
    // under pure FLIP without a relaxation time, and a relaxation time
    // beside a FLIP ratio other than 1.
    let refused_at_init = |f: &Fmu, field: &str, words: &str| {
        assert_eq!(f.init_status(), fmi2Error, "{field}");
        f.assert_error_contains(field);
        f.assert_error_contains(words);
    };
    let pure_flip = fmu_with(&scene, Some("implicit"), None, None);
    refused_at_init(&pure_flip, "time.axial", "transfer.flip_time");
    let both = fmu_with(&scene, None, None, Some(0.002));
    assert_eq!(both.set_real(&[VR_FLIP_RATIO], &[0.9]), fmi2OK);
    refused_at_init(&both, "transfer.flip_time", "flip_ratio is 0.9");
    let not_explicit = fmu_with(&scene, Some("implicit"), Some("apic"), None);
    assert_eq!(not_explicit.set_string(VR_INTEGRATOR, "implicit"), fmi2OK);
    refused_at_init(&not_explicit, "time.axial", "integrator");
    // Fixed parameters: refused after initialization.
    let g = Fmu::initialized(&scene);
    assert_eq!(g.set_string(VR_AXIAL, "implicit"), fmi2Error);
    assert_eq!(g.set_real(&[VR_FLIP_TIME], &[0.002]), fmi2Error);
}

/// A state saved under the axial step travels to an instance with the
/// default parameters, which takes the state's and continues with the
/// same bits.
#[test]
fn the_axial_and_flip_time_parameters_travel_in_the_fmu_state() {
    let scene = stiff_scene();
    let f = fmu_with(&scene, Some("implicit"), None, Some(0.002));
    f.init();
    f.steps_ok(0..3, H);
    let bytes = f.state_bytes();
    f.steps_ok(3..STEPS, H);
    let end = f.outputs();
    let g = Fmu::initialized_from(&scene, &bytes);
    assert_eq!(g.get_string(VR_AXIAL), "implicit");
    assert_eq!(g.get_real(&[VR_FLIP_TIME]), Ok(vec![0.002]));
    g.steps_ok(3..STEPS, H);
    assert_eq!(bits(&g.outputs()), bits(&end));
}
