//! Bad input to the FMI 3.0 front end: illegal call orders, NaN and inf
//! inputs, wrong `nValues` to the getters and setters, foreign and truncated
//! serialized states, an FMI 2.0 instance passed to fmi3 functions, and
//! parallel instances on threads. Every refusal is logged with a clear
//! message, and the refused call changes nothing but the state machine's
//! state (checked through the serialized FMU state).

mod common;
mod common3;

use common::assert_refused_state;
use common3::*;
use yarnsim_fmu::fmi3::common::*;
use yarnsim_fmu::fmi3::cosim::*;
use yarnsim_fmu::fmi3::fmu_state::*;
use yarnsim_fmu::fmi3::unsupported::*;
use yarnsim_fmu::fmi3::values::*;
use yarnsim_fmu::fmi3::*;
use yarnsim_fmu::instance::{Instance, Phase};
use yarnsim_fmu::model_description::*;
use yarnsim_fmu::models::yarn::arrays::array_vr;
use yarnsim_fmu::models::yarn::variables::*;

const H: f64 = 0.01;

/// The serialized FMU state of `f` as if it were in Step Mode (the phase
/// byte aside, what a refused call must leave unchanged).
fn state_bytes(f: &Fmu3) -> Vec<u8> {
    // SAFETY: `f.c` is a live instance of this FMU.
    let inst = unsafe { Instance::from_ptr(f.c) }.unwrap();
    let phase = inst.phase;
    inst.phase = Phase::StepComplete;
    let s = f.get_state();
    let bytes = f.serialize(s);
    f.free_state(s);
    // SAFETY: as above.
    unsafe { Instance::from_ptr(f.c) }.unwrap().phase = phase;
    bytes
}

fn phase(f: &Fmu3) -> Phase {
    // SAFETY: `f.c` is a live instance of this FMU.
    unsafe { Instance::from_ptr(f.c) }.unwrap().phase
}

/// Runs `call` on a fresh instance in Step Mode after two steps: it must
/// return fmi3Error with a log line containing `what`, and change nothing
/// but the state (now Error); fmi3Reset recovers.
fn refused(what: &str, call: impl FnOnce(&Fmu3) -> fmi3Status) {
    let f = Fmu3::small();
    f.init();
    assert_eq!(f.step(0.0, H).0, fmi3OK);
    assert_eq!(f.step(H, H).0, fmi3OK);
    let before = state_bytes(&f);
    assert_eq!(call(&f), fmi3Error, "{what}");
    let msg = f.last_error();
    assert!(msg.contains(what), "expected {what:?} in {msg:?}");
    assert!(!msg.contains("fmi2"), "FMI 2.0 words in {msg:?}");
    assert!(
        f.lines()
            .iter()
            .any(|l| l.0 == fmi3Error && l.1 == "logStatusError"),
        "{:?}",
        f.lines()
    );
    assert_eq!(phase(&f), Phase::Error);
    assert_eq!(
        state_bytes(&f),
        before,
        "{what}: the refused call changed the state"
    );
    // SAFETY: a live instance.
    assert_eq!(unsafe { fmi3Reset(f.c) }, fmi3OK);
    assert_eq!(phase(&f), Phase::Instantiated);
}

#[test]
fn illegal_call_orders_are_refused_with_the_fmi3_state_names() {
    let f = Fmu3::small();
    // SAFETY: a live instance throughout.
    unsafe {
        assert_eq!(f.step(0.0, H).0, fmi3Error);
        f.assert_error_contains("fmi3DoStep is not allowed in state \"Instantiated\"");
        // only Reset (and the state functions) leave the Error state
        assert_eq!(fmi3ExitInitializationMode(f.c), fmi3Error);
        f.assert_error_contains("\"Error\"");
        assert_eq!(fmi3Reset(f.c), fmi3OK);
        assert_eq!(fmi3EnterStepMode(f.c), fmi3Error);
        assert_eq!(fmi3Reset(f.c), fmi3OK);
        // reading in Instantiated is allowed (as Reference-FMUs), in Error not
        assert_eq!(
            f.get(&[VR_KINETIC_ENERGY, VR_GRAVITY_Y], 2),
            (fmi3OK, vec![0.0, -9.8])
        );
        assert_eq!(f.step(0.0, H).0, fmi3Error);
        assert_eq!(f.get(&[VR_KINETIC_ENERGY], 1).0, fmi3Error);
        f.assert_error_contains("fmi3GetFloat64 is not allowed in state \"Error\"");
        assert_eq!(fmi3Reset(f.c), fmi3OK);
        f.init();
        assert_eq!(fmi3EnterStepMode(f.c), fmi3OK);
        assert_eq!(
            fmi3EnterInitializationMode(f.c, false, 0.0, 0.0, false, 0.0),
            fmi3Error
        );
        assert_eq!(fmi3Reset(f.c), fmi3OK);
        f.init();
        assert_eq!(fmi3Terminate(f.c), fmi3OK);
        assert_eq!(f.step(0.0, H).0, fmi3Error);
        f.assert_error_contains("\"Terminated\"");
        // the unsupported interfaces say why
        assert_eq!(fmi3Reset(f.c), fmi3OK);
        assert_eq!(fmi3EnterEventMode(f.c), fmi3Error);
        assert!(f.last_error().contains("no event mode"));
        // a NULL instance is a no-op for fmi3FreeInstance, an error elsewhere
        fmi3FreeInstance(std::ptr::null_mut());
        assert_eq!(fmi3Reset(std::ptr::null_mut()), fmi3Error);
    }
}

#[test]
fn instantiation_refuses_what_the_fmu_cannot_do() {
    let bad = Fmu3::try_new(SMALL_SCENE, "{not-the-token}", false)
        .err()
        .unwrap();
    assert!(bad[0].2.contains("instantiationToken"), "{bad:?}");
    let scene = yarnsim::scene::Scene::from_toml_str(SMALL_SCENE).unwrap();
    let token = yarnsim_fmu::SceneFmu::guid(&scene);
    let ev = Fmu3::try_new(SMALL_SCENE, &token, true).err().unwrap();
    assert!(ev[0].2.contains("eventModeUsed"), "{ev:?}");
    assert_eq!(ev[0].0, fmi3Error);
}

#[test]
fn nan_and_inf_inputs_are_refused_and_change_nothing() {
    for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        refused(
            &format!("attractor.x = {v} refused: inputs must be finite"),
            |f| f.set(&[VR_ATTRACTOR_X], &[v]),
        );
        refused(&format!("gravity.y = {v} refused"), |f| {
            f.set(&[VR_GRAVITY_X, VR_GRAVITY_Y], &[1.0, v])
        });
    }
    // a step of a non-finite size
    refused("must be finite", |f| f.step(2.0 * H, f64::NAN).0);
}

#[test]
fn wrong_value_counts_are_refused_without_reading_past_the_arrays() {
    let n0 = 2 * 24;
    refused("nValues = 47", |f| f.get(&[array_vr(0, false)], n0 - 1).0);
    refused("nValues = 49", |f| f.get(&[array_vr(0, false)], n0 + 1).0);
    refused("nValues = 1", |f| {
        f.get(&[VR_KINETIC_ENERGY, array_vr(1, true)], 1).0
    });
    refused("nValues = 2", |f| f.get(&[VR_KINETIC_ENERGY], 2).0);
    refused("nValues = 1", |f| {
        let vals = [0.0];
        // SAFETY: a live instance; two value references, one value.
        unsafe {
            fmi3SetFloat64(
                f.c,
                [VR_GRAVITY_X, VR_GRAVITY_Y].as_ptr(),
                2,
                vals.as_ptr(),
                1,
            )
        }
    });
    refused("is an output", |f| f.set(&[array_vr(0, true)], &[0.0; 48]));
    refused("nValues = 2", |f| {
        let mut v = [0i32; 2];
        // SAFETY: a live instance; one value reference, two values.
        unsafe { fmi3GetInt32(f.c, &VR_SUBSTEPS, 1, v.as_mut_ptr(), 2) }
    });
    refused("nValues = 0", |f| {
        let mut v = [false; 1];
        // SAFETY: as above.
        unsafe { fmi3GetBoolean(f.c, &VR_ATTRACTOR_ACTIVE, 1, v.as_mut_ptr(), 0) }
    });
    refused(
        "gravity.x (value reference 5) is not a Float32 variable",
        |f| {
            let mut v = [0f32; 1];
            // SAFETY: as above.
            unsafe { fmi3GetFloat32(f.c, &VR_GRAVITY_X, 1, v.as_mut_ptr(), 1) }
        },
    );
    // the right count of all arrays at once works
    let f = Fmu3::small();
    f.init();
    let vrs: Vec<u32> = (0..3)
        .flat_map(|y| [array_vr(y, false), array_vr(y, true)])
        .collect();
    let (s, v) = f.get(&vrs, 3 * 4 * 24);
    assert_eq!(s, fmi3OK);
    assert!(v.iter().all(|x| x.is_finite()));
}

#[test]
fn foreign_and_truncated_states_are_refused() {
    let f = Fmu3::small();
    f.init();
    assert_eq!(f.step(0.0, H).0, fmi3OK);
    let s = f.get_state();
    let bytes = f.serialize(s);
    f.free_state(s);
    for (what, b) in [
        ("truncated", bytes[..bytes.len() / 2].to_vec()),
        ("empty", Vec::new()),
        (
            "foreign",
            b"not a yarnsim state at all, just bytes".to_vec(),
        ),
        ("flipped", {
            let mut b = bytes.clone();
            let k = b.len() - 9;
            b[k] ^= 0x40;
            b
        }),
    ] {
        let before = state_bytes(&f);
        let func = "fmi3DeserializeFMUState";
        assert_refused_state(what, f.deserialize(&b), fmi3Error, &f.last_error(), func);
        assert!(f.last_error().starts_with(func), "{what}");
        assert_eq!(state_bytes(&f), before, "{what}");
        // SAFETY: a live instance.
        assert_eq!(unsafe { fmi3Reset(f.c) }, fmi3OK);
        f.init();
        assert_eq!(f.step(0.0, H).0, fmi3OK);
    }
    // a mass-spring state is foreign to the yarn FMU
    let wire = yarnsim::massspring::scenes::wire().to_toml_string();
    let g = Fmu3::new(&wire);
    g.init();
    let s = g.get_state();
    let wbytes = g.serialize(s);
    g.free_state(s);
    assert_eq!(f.deserialize(&wbytes).0, fmi3Error);
    // a state pointer of another instance kind is refused, not read
    let mut junk = [0u64; 8];
    // SAFETY: a live instance; the pointer is checked by its magic number.
    let st = unsafe { fmi3SetFMUState(g.c, junk.as_mut_ptr() as fmi3FMUState) };
    assert_eq!(st, fmi3Error);
}

#[test]
fn an_fmi2_instance_is_refused_by_the_fmi3_functions() {
    let two = common::Fmu::new(&common::small_scene());
    // SAFETY: `two.c` is a live FMI 2.0 instance of this FMU.
    let s = unsafe { fmi3Reset(two.c) };
    assert_eq!(s, fmi3Error);
    assert!(two
        .last_error()
        .contains("made by fmi2Instantiate, not fmi3InstantiateCoSimulation"));
}

#[test]
fn parallel_instances_on_threads_give_the_same_bits() {
    let run = || {
        let f = Fmu3::small();
        f.init();
        let vrs: Vec<u32> = (0..3).map(|y| array_vr(y, false)).collect();
        let mut bits = Vec::new();
        for k in 0..8 {
            assert_eq!(f.set(&[VR_GRAVITY_X], &[k as f64 * 0.5]), fmi3OK);
            assert_eq!(f.step(k as f64 * H, H).0, fmi3OK);
            bits.extend(f.get(&vrs, 3 * 48).1.iter().map(|v| v.to_bits()));
        }
        bits
    };
    let alone = run();
    let threads: Vec<_> = (0..4).map(|_| std::thread::spawn(run)).collect();
    for t in threads {
        assert_eq!(t.join().unwrap(), alone);
    }
}

#[test]
fn a_diverging_step_discards_with_terminate_simulation() {
    let f = Fmu3::small();
    // a substep far beyond the stability bound and a huge gravity diverge
    assert_eq!(f.set(&[VR_DT], &[5e-3]), fmi3OK);
    // SAFETY: a live instance.
    unsafe {
        assert_eq!(
            fmi3EnterInitializationMode(f.c, false, 0.0, 0.0, false, 0.0),
            fmi3OK
        );
        assert_eq!(fmi3ExitInitializationMode(f.c), fmi3Warning);
    }
    assert_eq!(f.set(&[VR_GRAVITY_Y], &[-9.0e5]), fmi3OK);
    let mut t = 0.0;
    let mut last = (fmi3OK, false, false, false, 0.0);
    let mut before = f.get(&[array_vr(0, false), array_vr(0, true)], 96).1;
    for _ in 0..50 {
        last = f.step(t, H);
        if last.0 != fmi3OK {
            break;
        }
        before = f.get(&[array_vr(0, false), array_vr(0, true)], 96).1;
        t += H;
    }
    let (s, term, early, ev, lst) = last;
    assert_eq!(
        (s, term, early, ev),
        (fmi3Discard, true, false, false),
        "{:?}",
        f.lines()
    );
    assert_eq!(lst, t);
    // the outputs are those of lastSuccessfulTime, bit for bit
    let (s, v) = f.get(&[array_vr(0, false), array_vr(0, true)], 96);
    assert_eq!(s, fmi3OK);
    assert_eq!(v, before);
    // no further step (fmi3Error), but after restoring the state Terminate
    assert_eq!(phase(&f), Phase::StepFailed);
    let saved = f.get_state();
    assert_eq!(f.step(t, H).0, fmi3Error);
    f.assert_error_contains("Step Mode after terminateSimulation");
    // SAFETY: a live instance and a state it made.
    unsafe {
        assert_eq!(fmi3SetFMUState(f.c, saved), fmi3OK);
        assert_eq!(phase(&f), Phase::StepFailed);
        assert_eq!(fmi3Terminate(f.c), fmi3OK);
    }
    f.free_state(saved);
}

/// The `scene` parameter may load a scene with other vertex counts (same
/// yarns, same pins): the arrays then have the new sizes, and a read with
/// the bundled scene's sizes is refused with the counts in the message.
#[test]
fn arrays_follow_a_scene_parameter_with_other_vertex_counts() {
    let f = Fmu3::small();
    let other = SMALL_SCENE.replace("vertices = 24", "vertices = 30");
    assert_ne!(other, SMALL_SCENE);
    std::fs::write(f.dir.join("other.toml"), other).unwrap();
    let name = std::ffi::CString::new("other.toml").unwrap();
    let p = name.as_ptr();
    // SAFETY: a live instance; one value reference and one live C string.
    assert_eq!(unsafe { fmi3SetString(f.c, &VR_SCENE, 1, &p, 1) }, fmi3OK);
    f.init();
    assert_eq!(f.step(0.0, H).0, fmi3OK);
    let (s, v) = f.get(&[array_vr(0, false)], 60);
    assert_eq!(s, fmi3OK, "{:?}", f.lines());
    assert!(v.iter().all(|x| x.is_finite()));
    assert_eq!(f.get(&[array_vr(0, false)], 48).0, fmi3Error);
    f.assert_error_contains("nValues = 48");
    f.assert_error_contains("have 60 values");
}
