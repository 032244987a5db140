//! The FMUs' log messages name the variable (`attractor.x = NaN refused:
//! inputs must be finite`, `material.k is a fixed parameter: ...`), in FMI
//! 2.0 and FMI 3.0 words, for the yarn bundle and the mass-spring model;
//! and a rejected input leaves the instance in the error state, where every
//! step is refused until a state restore (or a reset), after which the run
//! continues with the bits of a run that never saw the bad value (FMI 2.0.4
//! section 4.2.4, FMI 3.0 section 4.2.1: fmi2Error / fmi3Error leaves only
//! reset, the FMU-state functions and freeing).

mod common;
mod common3;

use std::ffi::{c_int, CString};

use common::*;
use common3::Fmu3;
use yarnsim_fmu::fmi2::*;
use yarnsim_fmu::fmi3::fmu_state::*;
use yarnsim_fmu::fmi3::unsupported::fmi3GetFloat32;
use yarnsim_fmu::fmi3::values::*;
use yarnsim_fmu::fmi3::*;
use yarnsim_fmu::model_description::*;
use yarnsim_fmu::models::yarn::arrays::array_vr;
use yarnsim_fmu::models::yarn::variables::*;

const H: f64 = 0.01;

/// Runs `call` on a fresh instance made by `make`: it must return
/// fmi2Error, and the last error logged must be `expected` exactly.
fn refused2(make: impl Fn() -> Fmu, call: impl FnOnce(&Fmu) -> c_int, expected: &str) {
    let f = make();
    assert_eq!(call(&f), fmi2Error, "{expected}");
    assert_eq!(f.last_error(), expected, "{:?}", f.lines());
    let logged = f.lines();
    let line = logged.iter().rev().find(|l| l.0 == fmi2Error).unwrap();
    assert_eq!(line.1, "logStatusError");
}

fn set_int(f: &Fmu, vr: u32, v: c_int) -> c_int {
    // SAFETY: `f.c` is a live instance; one value reference and one value.
    unsafe { fmi2SetInteger(f.c, &vr, 1, &v) }
}

fn get_bool(f: &Fmu, vr: u32) -> c_int {
    let mut v = 0;
    // SAFETY: as `set_int`.
    unsafe { fmi2GetBoolean(f.c, &vr, 1, &mut v) }
}

#[test]
fn fmi2_yarn_messages_name_the_variable() {
    let scene = small_scene();
    let new = || Fmu::new(&scene);
    let init = || Fmu::initialized(&scene);
    refused2(
        init,
        |f| f.set_real(&[VR_ATTRACTOR_X], &[f64::NAN]),
        "fmi2SetReal: attractor.x = NaN refused: inputs must be finite",
    );
    refused2(
        init,
        |f| f.set_real(&[VR_GRAVITY_X, VR_GRAVITY_Y], &[0.0, f64::NEG_INFINITY]),
        "fmi2SetReal: gravity.y = -inf refused: inputs must be finite",
    );
    refused2(
        new,
        |f| f.set_real(&[VR_DENSITY], &[f64::INFINITY]),
        "fmi2SetReal: material.density = inf refused: parameters must be finite",
    );
    refused2(
        init,
        |f| f.set_real(&[VR_K], &[2e3]),
        "fmi2SetReal: material.k is a fixed parameter: it can be set only before \
         fmi2ExitInitializationMode (state is \"step complete\")",
    );
    refused2(
        init,
        |f| f.set_bool(VR_PLASTICITY, false),
        "fmi2SetBoolean: material.plasticity is a fixed parameter: it can be set only before \
         fmi2ExitInitializationMode (state is \"step complete\")",
    );
    refused2(
        init,
        |f| f.set_string(VR_TRANSFER_SCHEME, "apic"),
        "fmi2SetString: transfer.scheme is a fixed parameter: it can be set only before \
         fmi2ExitInitializationMode (state is \"step complete\")",
    );
    refused2(
        init,
        |f| set_int(f, VR_THREADS, 2),
        "fmi2SetInteger: threads is a fixed parameter: it can be set only before \
         fmi2ExitInitializationMode (state is \"step complete\")",
    );
    refused2(
        new,
        |f| f.set_real(&[VR_BENDING], &[-1.0]),
        "fmi2SetReal: material.bending = -1 is out of range (must be >= 0 and at most 1000000000000)",
    );
    refused2(
        init,
        |f| f.set_real(&[VR_ATTRACTOR_STRENGTH], &[2e6]),
        "fmi2SetReal: attractor.strength = 2000000 refused: bad input: attractor strength \
         2000000 must be in [0, 1e6] m/s2",
    );
    refused2(
        init,
        |f| f.set_real(&[VR_GRAVITY_X], &[1e7]),
        "fmi2SetReal: gravity.x = 10000000 refused: bad input: gravity (10000000, -9.8) must be \
         finite and at most 1e6 m/s^2",
    );
    // a variable of another type or causality, and none at all
    refused2(
        init,
        |f| f.set_real(&[VR_YARN_BASE + 5], &[0.3]),
        "fmi2SetReal: yarn[1].left.y (value reference 1005) is not a Real input or parameter",
    );
    refused2(
        init,
        |f| f.set_bool(VR_K, true),
        "fmi2SetBoolean: material.k (value reference 10) is not a Boolean input or parameter",
    );
    refused2(
        init,
        |f| f.set_string(VR_DT, "0"),
        "fmi2SetString: dt (value reference 16) is not a String parameter",
    );
    refused2(
        init,
        |f| set_int(f, VR_SUBSTEPS, 3),
        "fmi2SetInteger: substeps (value reference 200) is not an Integer input or parameter",
    );
    refused2(
        init,
        |f| f.get_real(&[VR_ATTRACTOR_ACTIVE]).unwrap_err(),
        "fmi2GetReal: attractor.active (value reference 4) is not a Real variable",
    );
    refused2(
        init,
        |f| get_bool(f, VR_GRAVITY_Y),
        "fmi2GetBoolean: gravity.y (value reference 6) is not a Boolean variable",
    );
    refused2(
        init,
        |f| f.get_real(&[99_999]).unwrap_err(),
        "fmi2GetReal: no Real variable has value reference 99999",
    );
}

/// `fmu/scenes/driven.toml`: pin 0 driven (`motion = "input"`), pin 1 fixed.
const DRIVEN_SCENE: &str = include_str!("../scenes/driven.toml");

#[test]
fn fmi2_pin_and_mass_spring_messages_name_the_variable() {
    let driven = yarnsim::scene::YarnScene::from_toml_str(DRIVEN_SCENE).unwrap();
    let init = || Fmu::initialized(&driven);
    refused2(
        init,
        |f| f.set_real(&[VR_PIN_BASE + 2], &[f64::NAN]),
        "fmi2SetReal: pin[0].vx = NaN refused: inputs must be finite",
    );
    let pin1 = VR_PIN_BASE + 8;
    refused2(
        init,
        |f| f.set_real(&[pin1 + 1], &[0.3]),
        "fmi2SetReal: pin[1].y (value reference 2009) is not an input: pin 1 is not a \
         motion = \"input\" pin",
    );
    refused2(
        init,
        |f| f.set_real(&[VR_PIN_BASE, VR_PIN_BASE + 1], &[2e6, 0.5]),
        "fmi2SetReal: pin[0].x = 2000000, pin[0].y = 0.5 refused: bad input: pin 0 target \
         position (2000000, 0.5) m or velocity (0, 0) m/s is absurd: both must be finite, \
         within 1e6 m and 1e6 m/s",
    );

    use yarnsim_fmu::models::massspring as ms;
    let wire = yarnsim::massspring::scenes::wire();
    let init = || {
        let f = Fmu::mass_spring(&wire);
        f.init();
        f
    };
    refused2(
        init,
        |f| f.set_real(&[ms::VR_GRAVITY_Z], &[f64::NAN]),
        "fmi2SetReal: gravity.z = NaN refused: inputs must be finite",
    );
    refused2(
        init,
        |f| f.set_real(&[ms::VR_DT], &[1e-3]),
        "fmi2SetReal: dt is a fixed parameter: it can be set only before \
         fmi2ExitInitializationMode (state is \"step complete\")",
    );
    refused2(
        init,
        |f| f.set_real(&[ms::VR_GRAVITY_Y], &[-2e6]),
        "fmi2SetReal: gravity.y = -2000000 refused: gravity (0, -2000000, 0) must be finite \
         with |g| at most 1e6 m/s^2",
    );
    refused2(
        init,
        |f| f.set_real(&[ms::VR_PARTICLE_BASE + 4], &[0.0]),
        "fmi2SetReal: particle[1].y (value reference 1004) is not a Real input or parameter",
    );
    refused2(
        init,
        |f| f.set_bool(ms::VR_DT, true),
        "fmi2SetBoolean: dt (value reference 10) is not a Boolean input or parameter (this FMU \
         has none)",
    );
}

/// The controller loop of docs/fmu-masters.md in Rust: save the state before
/// setting the inputs; an input refused puts the instance in the error
/// state, where every step is refused; restoring the saved state leads
/// out, and the run goes on with the bits of a run that never saw it.
#[test]
fn fmi2_a_rejected_input_needs_a_state_restore_and_then_runs_on_bitwise() {
    let scene = small_scene();
    let f = Fmu::initialized(&scene);
    let reference = Fmu::initialized(&scene);
    let mut t = 0.0;
    for k in 0..6 {
        let x = 0.5 + 0.05 * k as f64;
        let saved = f.get_state();
        if k == 2 {
            assert_eq!(f.set_real(&[VR_ATTRACTOR_X], &[f64::NAN]), fmi2Error);
            f.assert_error_contains("attractor.x = NaN refused");
            // the error state: no step, no input, until the restore
            assert_eq!(f.do_step(t, H), fmi2Error);
            f.assert_error_contains("fmi2DoStep is not allowed in state \"error\"");
            assert_eq!(f.set_real(&[VR_ATTRACTOR_X], &[x]), fmi2Error);
            f.assert_error_contains("fmi2SetReal is not allowed in state \"error\"");
            f.set_state(saved);
        }
        f.free_state(saved);
        for g in [&f, &reference] {
            assert_eq!(g.set_real(&[VR_ATTRACTOR_X], &[x]), fmi2OK);
            assert_eq!(g.set_bool(VR_ATTRACTOR_ACTIVE, true), fmi2OK);
            assert_eq!(g.do_step(t, H), fmi2OK, "{:?}", g.lines());
        }
        t += H;
        let bits = |g: &Fmu| g.outputs().iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&f), bits(&reference), "step {k}");
    }
    // fmi2Reset leads out of the error state too (to the start).
    assert_eq!(f.set_real(&[VR_GRAVITY_Y], &[f64::NAN]), fmi2Error);
    // SAFETY: `f.c` is a live instance.
    assert_eq!(unsafe { fmi2Reset(f.c) }, fmi2OK);
    f.init();
    assert_eq!(f.do_step(0.0, H), fmi2OK);
}

fn refused3(call: impl FnOnce(&Fmu3) -> fmi3Status, expected: &str) {
    let f = Fmu3::small();
    f.init();
    assert_eq!(f.step(0.0, H).0, fmi3OK);
    assert_eq!(call(&f), fmi3Error, "{expected}");
    assert_eq!(f.last_error(), expected, "{:?}", f.lines());
}

#[test]
fn fmi3_messages_name_the_variable_in_fmi3_words() {
    refused3(
        |f| f.set(&[VR_ATTRACTOR_Y], &[f64::NAN]),
        "fmi3SetFloat64: attractor.y = NaN refused: inputs must be finite",
    );
    refused3(
        |f| f.set(&[VR_FRICTION], &[0.2]),
        "fmi3SetFloat64: material.friction is a fixed parameter: it can be set only before \
         fmi3ExitInitializationMode (state is \"step complete\")",
    );
    refused3(
        |f| f.set(&[array_vr(1, true)], &[0.0; 48]),
        "fmi3SetFloat64: yarn[1].velocities (value reference 1073741827) is an output or the \
         independent variable, not an input or parameter",
    );
    refused3(
        |f| f.set(&[VR_TIME], &[0.0]),
        "fmi3SetFloat64: time (value reference 0) is an output or the independent variable, \
         not an input or parameter",
    );
    refused3(
        |f| f.set_bool(VR_GAMMA, true),
        "fmi3SetBoolean: material.gamma (value reference 11) is not a Boolean input or parameter",
    );
    refused3(
        |f| {
            let mut v = [0f32; 1];
            // SAFETY: a live instance; one value reference, one value.
            unsafe { fmi3GetFloat32(f.c, &VR_GRAVITY_X, 1, v.as_mut_ptr(), 1) }
        },
        "fmi3GetFloat32: gravity.x (value reference 5) is not a Float32 variable (this FMU has \
         Float64, Int32, Boolean and String variables)",
    );
    refused3(
        |f| {
            let s = CString::new("x").unwrap();
            let p = s.as_ptr();
            // SAFETY: a live instance; one value reference and one live C string.
            unsafe { fmi3SetString(f.c, &VR_SCENE, 1, &p, 1) }
        },
        "fmi3SetString: scene is a fixed parameter: it can be set only before \
         fmi3ExitInitializationMode (state is \"step complete\")",
    );
    refused3(
        |f| {
            let mut n = 0;
            // SAFETY: a live instance; `n` is a local.
            unsafe { fmi3GetNumberOfVariableDependencies(f.c, VR_K, &mut n) }
        },
        "fmi3GetNumberOfVariableDependencies: material.k (value reference 10) is not an output \
         (ModelStructure lists the dependencies of outputs only)",
    );
}

/// FMI 3.0: after a refused input every fmi3DoStep is refused until
/// fmi3SetFMUState, which continues with the bits of an undisturbed run.
#[test]
fn fmi3_a_rejected_input_needs_a_state_restore_and_then_runs_on_bitwise() {
    let f = Fmu3::small();
    let reference = Fmu3::small();
    let outs = [
        VR_KINETIC_ENERGY,
        VR_ELASTIC_ENERGY,
        VR_YARN_BASE,
        VR_YARN_BASE + 3,
    ];
    f.init();
    reference.init();
    let mut t = 0.0;
    for k in 0..4 {
        let saved = f.get_state();
        if k == 1 {
            assert_eq!(f.set(&[VR_GRAVITY_X], &[f64::INFINITY]), fmi3Error);
            f.assert_error_contains("gravity.x = inf refused: inputs must be finite");
            assert_eq!(f.step(t, H).0, fmi3Error);
            f.assert_error_contains("fmi3DoStep is not allowed in state \"Error\"");
            // SAFETY: `saved` is a live state of this instance.
            assert_eq!(unsafe { fmi3SetFMUState(f.c, saved) }, fmi3OK);
        }
        f.free_state(saved);
        for g in [&f, &reference] {
            assert_eq!(g.set(&[VR_GRAVITY_X], &[0.5 * k as f64]), fmi3OK);
            assert_eq!(g.step(t, H).0, fmi3OK, "{:?}", g.lines());
        }
        t += H;
        let (sf, a) = f.get(&outs, outs.len());
        let (sr, b) = reference.get(&outs, outs.len());
        assert_eq!((sf, sr), (fmi3OK, fmi3OK));
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a), bits(&b), "step {k}");
    }
}

/// A divergence of the small scene without the return mapping
/// (`material.plasticity = false`, at its own dt within the bound; it
/// diverges at t = 0.3064 s) gives fmi2Discard with the log naming the
/// parameter to change, as the CLI's message does; with plasticity on the
/// same run passes.
#[test]
fn a_divergence_without_plasticity_names_the_parameter() {
    let scene = small_scene();
    let f = Fmu::new(&scene);
    assert_eq!(f.set_bool(VR_PLASTICITY, false), fmi2OK);
    f.init();
    let mut t = 0.0;
    let status = loop {
        let s = f.do_step(t, H);
        if s != fmi2OK || t > 1.0 {
            break s;
        }
        t += H;
    };
    assert_eq!(status, fmi2Discard, "no divergence by t = {t}");
    f.assert_discarded_at(t);
    let e = last_error_in(&f.lines(), fmi2Discard);
    assert!(
        e.contains("simulation diverged")
            && e.contains("material.plasticity = false keeps every cross-section")
            && e.contains("set material.plasticity = true; the simulation is terminated"),
        "{e}"
    );
    let g = Fmu::initialized(&scene);
    for k in 0..=(t / H).round() as u32 {
        assert_eq!(
            g.do_step(k as f64 * H, H),
            fmi2OK,
            "with plasticity, t = {}",
            k as f64 * H
        );
    }
}
