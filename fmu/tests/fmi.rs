//! The FMU driven through its exported C functions: trajectories (insta
//! snapshots), the state machine, FMU states, bad input, threads.

mod common;

use std::ffi::{c_char, CString};

use common::*;
use yarnsim::scene::YarnScene;
use yarnsim_fmu::fmi2::*;
use yarnsim_fmu::model_description::*;
use yarnsim_fmu::models::yarn::variables::*;

const H: f64 = 0.01;

/// Attractor on a circle of radius 0.2 around (0.5, 0.5), one turn in 0.4 s,
/// gravity off: the yarns are pulled around.
#[test]
fn attractor_on_a_circle_trajectory() {
    let fmu = Fmu::initialized(&small_scene());
    assert_eq!(
        fmu.set_real(
            &[VR_GRAVITY_X, VR_GRAVITY_Y, VR_ATTRACTOR_STRENGTH],
            &[0.0, 0.0, 40.0]
        ),
        fmi2OK
    );
    assert_eq!(fmu.set_bool(VR_ATTRACTOR_ACTIVE, true), fmi2OK);
    let mut snap = Vec::new();
    let mut first = None;
    for k in 0..30 {
        let t = k as f64 * H;
        let w = 2.0 * std::f64::consts::PI * t / 0.4;
        let p = [0.5 + 0.2 * w.cos(), 0.5 + 0.2 * w.sin()];
        assert_eq!(fmu.set_real(&[VR_ATTRACTOR_X, VR_ATTRACTOR_Y], &p), fmi2OK);
        assert_eq!(fmu.do_step(t, H), fmi2OK, "{:?}", fmu.lines());
        let out = fmu.outputs();
        assert!(out.iter().all(|v| v.is_finite()));
        first.get_or_insert(out.clone());
        if k % 3 == 2 {
            snap.push(fmt_row(t + H, &out));
        }
    }
    assert_eq!(fmu.substeps(), 30 * 50);
    // The attractor moved the yarns: their centre of the ends moved and the
    // bundle is moving.
    let last = fmu.outputs();
    let ke = last[4 * fmu.yarns];
    assert!(ke > 0.0);
    let moved: f64 = (0..4 * fmu.yarns)
        .map(|i| (last[i] - first.as_ref().unwrap()[i]).abs())
        .sum();
    assert!(moved > 0.05, "yarn ends moved only {moved} m in total");
    insta::assert_snapshot!(snap.join("\n"));
}

/// Gravity down, then sideways to +x, then up: the yarn ends follow.
#[test]
fn gravity_switching_direction_trajectory() {
    let fmu = Fmu::initialized(&small_scene());
    let mut snap = Vec::new();
    let mut mean_x = Vec::new();
    let mut mean_y = Vec::new();
    for k in 0..30 {
        let t = k as f64 * H;
        let g = match k / 10 {
            0 => [0.0, -9.8],
            1 => [9.8, 0.0],
            _ => [0.0, 9.8],
        };
        assert_eq!(fmu.set_real(&[VR_GRAVITY_X, VR_GRAVITY_Y], &g), fmi2OK);
        assert_eq!(fmu.do_step(t, H), fmi2OK, "{:?}", fmu.lines());
        let out = fmu.outputs();
        let n = 2 * fmu.yarns;
        mean_x.push((0..n).map(|i| out[2 * i]).sum::<f64>() / n as f64);
        mean_y.push((0..n).map(|i| out[2 * i + 1]).sum::<f64>() / n as f64);
        if k % 3 == 2 {
            snap.push(fmt_row(t + H, &out));
        }
    }
    // Falling in the first phase, drifting to +x in the second, rising
    // relative to the second phase in the third.
    assert!(mean_y[9] < mean_y[0], "{mean_y:?}");
    assert!(mean_x[19] > mean_x[10], "{mean_x:?}");
    let vy_late = mean_y[29] - mean_y[26];
    assert!(vy_late > 0.0, "{mean_y:?}");
    insta::assert_snapshot!(snap.join("\n"));
}

/// The substeps done by a time are fixed by the time, not by how the master
/// partitions it: different step sizes give the same bits.
#[test]
fn results_do_not_depend_on_the_step_partition() {
    let scene = small_scene();
    let run = |steps: &[f64]| {
        let fmu = Fmu::initialized(&scene);
        let mut t = 0.0;
        for &h in steps {
            assert_eq!(fmu.do_step(t, h), fmi2OK, "{:?}", fmu.lines());
            t += h;
        }
        (fmu.substeps(), fmu.outputs())
    };
    let a = run(&[0.01; 10]);
    let b = run(&[0.02; 5]);
    let c = run(&[0.003, 0.007, 0.025, 0.015, 0.0101, 0.0399]);
    assert_eq!(a.0, 500);
    assert_eq!(a.0, b.0);
    assert_eq!(a.0, c.0);
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&a.1), bits(&b.1));
    assert_eq!(bits(&a.1), bits(&c.1));
}

/// The same run straight on the library gives the same bits as the FMU.
#[test]
fn fmu_matches_the_library() {
    let scene = small_scene();
    let fmu = Fmu::initialized(&scene);
    let mut sim = yarnsim::mpm::YarnSim::new(&scene).unwrap();
    for k in 0..8 {
        let g = [0.5 * k as f64, -9.8];
        assert_eq!(fmu.set_real(&[VR_GRAVITY_X, VR_GRAVITY_Y], &g), fmi2OK);
        sim.set_gravity(yarnsim::math::Vec2::from(g)).unwrap();
        assert_eq!(fmu.do_step(k as f64 * H, H), fmi2OK);
        sim.steps_n(50).unwrap();
    }
    assert_eq!(bits(&fmu.outputs()), bits(&library_outputs(&sim)));
}

fn run_on(fmu: &Fmu, t0: f64, n: usize) -> Vec<u64> {
    let mut bits = Vec::new();
    for k in 0..n {
        let t = t0 + k as f64 * H;
        let g = [3.0 * (7.0 * t).sin(), -9.8];
        assert_eq!(fmu.set_real(&[VR_GRAVITY_X, VR_GRAVITY_Y], &g), fmi2OK);
        assert_eq!(fmu.do_step(t, H), fmi2OK, "{:?}", fmu.lines());
        bits.extend(fmu.outputs().iter().map(|v| v.to_bits()));
    }
    bits
}

/// The small scene and its FMU, initialized and run for `n` steps of
/// [`run_on`] from t = 0.
fn small_fmu_after(n: usize) -> (YarnScene, Fmu) {
    let scene = small_scene();
    let fmu = Fmu::initialized(&scene);
    run_on(&fmu, 0.0, n);
    (scene, fmu)
}

/// Get and serialize the state at t1, run on, deserialize, restore, run on
/// again: identical bits, also in another instance.
#[test]
fn state_round_trip_gives_identical_bits() {
    let (scene, fmu) = small_fmu_after(5);
    let s = fmu.get_state();
    let bytes = fmu.serialize(s);
    assert_eq!(&bytes[..8], b"YBFMUST\0");
    let first = run_on(&fmu, 0.05, 6);

    // Restore the in-memory state (twice: a state survives being set).
    for _ in 0..2 {
        fmu.set_state(s);
        assert_eq!(run_on(&fmu, 0.05, 6), first);
    }
    // A state taken right after a restore serializes to the same bytes.
    fmu.set_state(s);
    let s2 = fmu.get_state();
    assert_eq!(fmu.serialize(s2), bytes);
    fmu.free_state(s2);
    fmu.free_state(s);

    // Restore the deserialized bytes, in this instance and in a new one.
    let d = fmu.set_state_from(&bytes);
    assert_eq!(fmu.substeps(), 250);
    assert_eq!(run_on(&fmu, 0.05, 6), first);
    fmu.free_state(d);

    let other = Fmu::new(&scene);
    let d = other.set_state_from(&bytes);
    let restored = other.get_state();
    assert_eq!(other.serialize(restored), bytes);
    other.free_state(restored);
    assert_eq!(run_on(&other, 0.05, 6), first);
    // Serializing the restored state gives the same bytes back.
    let again = other.get_state();
    assert_eq!(
        other.serialize(again).len(),
        bytes.len(),
        "state size changed after a round trip"
    );
    other.free_state(again);
    other.free_state(d);
}

/// fmi2GetFMUstate into an existing state overwrites it.
#[test]
fn get_fmu_state_reuses_an_existing_state() {
    let fmu = Fmu::initialized(&small_scene());
    let mut s = fmu.get_state();
    run_on(&fmu, 0.0, 3);
    let before = s;
    // SAFETY: `fmu.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every pointer
    // argument is a local that outlives the call.
    assert_eq!(unsafe { fmi2GetFMUstate(fmu.c, &mut s) }, fmi2OK);
    assert_eq!(s, before);
    let later = run_on(&fmu, 0.03, 2);
    fmu.set_state(s);
    assert_eq!(fmu.substeps(), 150);
    assert_eq!(run_on(&fmu, 0.03, 2), later);
    fmu.free_state(s);
}

/// Truncated, corrupt, foreign or empty state bytes give fmi2Error with a
/// log line, and never a state.
#[test]
fn corrupt_or_truncated_state_is_rejected() {
    let (scene, fmu) = small_fmu_after(2);
    let bytes = fmu.state_bytes();
    let mut cases: Vec<(&str, Vec<u8>)> = vec![
        ("empty", Vec::new()),
        ("header only", bytes[..20].to_vec()),
        ("truncated", bytes[..bytes.len() - 1].to_vec()),
        ("one byte longer", [bytes.clone(), vec![0]].concat()),
    ];
    for at in [0, 9, 13, 25, 40, bytes.len() / 2, bytes.len() - 3] {
        let mut b = bytes.clone();
        b[at] ^= 0x10;
        cases.push(("flipped byte", b));
    }
    for (what, b) in cases {
        let f = Fmu::new(&scene);
        let func = "fmi2DeSerializeFMUstate";
        assert_refused_state(what, f.deserialize(&b), fmi2Error, &f.last_error(), func);
    }
    // A state of a scene with another number of yarns.
    let mut two = scene.clone();
    two.yarns[0].count = 2;
    let f = Fmu::new(&two);
    let (st, _) = f.deserialize(&bytes);
    assert_eq!(st, fmi2Error);
    // A null FMUstate is not a state.
    assert_eq!(
        // SAFETY: `fmu.c` is a live instance; the FMU checks the state for null before using it,
        // which is what is checked.
        unsafe { fmi2SetFMUstate(fmu.c, std::ptr::null_mut()) },
        fmi2Error
    );
}

#[test]
fn illegal_call_order_is_an_error_with_a_log_line() {
    let scene = small_scene();
    // DoStep before initialization.
    let fmu = Fmu::new(&scene);
    assert_eq!(fmu.do_step(0.0, H), fmi2Error);
    fmu.assert_error_contains("fmi2DoStep is not allowed");
    // The instance is now in the error state: only reset / set state / free.
    assert_eq!(fmu.setup(0.0, None), fmi2Error);
    // SAFETY: `fmu.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every pointer
    // argument is a local that outlives the call.
    assert_eq!(unsafe { fmi2Reset(fmu.c) }, fmi2OK);
    fmu.init();
    assert_eq!(fmu.do_step(0.0, H), fmi2OK);

    // Exit initialization without entering it; setup after initialization.
    let f = Fmu::new(&scene);
    // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every pointer
    // argument is a local that outlives the call.
    assert_eq!(unsafe { fmi2ExitInitializationMode(f.c) }, fmi2Error);
    let f = Fmu::initialized(&scene);
    assert_eq!(f.setup(0.0, None), fmi2Error);
    assert!(f.last_error().contains("fmi2SetupExperiment"));

    // Fixed parameters cannot change after initialization.
    let f = Fmu::initialized(&scene);
    assert_eq!(f.set_real(&[VR_DT], &[1e-4]), fmi2Error);
    f.assert_error_contains("dt is a fixed parameter");

    // Terminate, then no more steps.
    let f = Fmu::initialized(&scene);
    // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every pointer
    // argument is a local that outlives the call.
    assert_eq!(unsafe { fmi2Terminate(f.c) }, fmi2OK);
    assert_eq!(f.do_step(0.0, H), fmi2Error);

    // Unsupported optional functions answer fmi2Error, not a crash.
    let f = Fmu::initialized(&scene);
    let mut v = 0.0;
    let order = 1;
    assert_eq!(
        // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
        // pointer argument is a local that outlives the call.
        unsafe { fmi2GetRealOutputDerivatives(f.c, &VR_YARN_BASE, 1, &order, &mut v) },
        fmi2Error
    );
}

#[test]
fn do_step_checks_time_step_and_stop_time() {
    let scene = small_scene();
    let new = |stop: Option<f64>| {
        let f = Fmu::new(&scene);
        assert_eq!(f.setup(0.0, stop), fmi2OK);
        f.init_mode();
        f
    };
    let f = new(None);
    assert_eq!(f.do_step(0.0, 0.0), fmi2Error);
    assert!(f.last_error().contains("> 0"), "{:?}", f.lines());
    let f = new(None);
    assert_eq!(f.do_step(0.0, -H), fmi2Error);
    let f = new(None);
    assert_eq!(f.do_step(0.0, f64::NAN), fmi2Error);
    // The communication point must be the FMU's time.
    let f = new(None);
    assert_eq!(f.do_step(0.001, H), fmi2Error);
    assert!(f.last_error().contains("does not match"), "{:?}", f.lines());
    // ... with a relative tolerance: t accumulated as t += h.
    let f = new(None);
    let mut t = 0.0;
    for _ in 0..10 {
        assert_eq!(f.do_step(t, 0.1 / 10.0), fmi2OK);
        t += 0.1 / 10.0;
    }
    assert_ne!(t, 0.1);
    assert_eq!(f.do_step(t, H), fmi2OK, "{:?}", f.lines());
    // Not past the stop time.
    let f = new(Some(0.02));
    assert_eq!(f.do_step(0.0, H), fmi2OK);
    assert_eq!(f.do_step(H, H), fmi2OK);
    assert_eq!(f.do_step(2.0 * H, H), fmi2Error);
    assert!(f.last_error().contains("stop time"), "{:?}", f.lines());
    // A start time other than 0.
    let f = Fmu::new(&scene);
    assert_eq!(f.setup(2.5, None), fmi2OK);
    f.init_mode();
    assert_eq!(f.do_step(0.0, H), fmi2Error);
    let f = Fmu::new(&scene);
    assert_eq!(f.setup(2.5, None), fmi2OK);
    f.init_mode();
    assert_eq!(f.do_step(2.5, H), fmi2OK);
    assert_eq!(f.substeps(), 50);
    let mut lst = 0.0;
    assert_eq!(
        // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
        // pointer argument is a local that outlives the call.
        unsafe { fmi2GetRealStatus(f.c, fmi2LastSuccessfulTime, &mut lst) },
        fmi2OK
    );
    assert_eq!(lst, 2.5 + H);
}

#[test]
fn reset_returns_to_the_instantiated_state() {
    let scene = small_scene();
    let fresh = Fmu::initialized(&scene);
    let expected = run_on(&fresh, 0.0, 4);

    let f = Fmu::new(&scene);
    assert_eq!(f.setup(1.0, Some(2.0)), fmi2OK);
    f.init_mode();
    assert_eq!(f.set_real(&[VR_GRAVITY_Y], &[3.0]), fmi2OK);
    assert_eq!(f.do_step(1.0, 0.05), fmi2OK);
    // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every pointer
    // argument is a local that outlives the call.
    assert_eq!(unsafe { fmi2Reset(f.c) }, fmi2OK);
    // Instantiated again: the inputs are back to their start values, the
    // time to 0 and no stop time.
    f.init();
    assert_eq!(f.get_real(&[VR_GRAVITY_Y]).unwrap(), vec![-9.8]);
    assert_eq!(f.substeps(), 0);
    assert_eq!(run_on(&f, 0.0, 4), expected);
}

#[test]
fn guid_mismatch_and_bad_arguments_fail_instantiation() {
    let scene = small_scene();
    let err = Fmu::try_new(&scene, "{00000000-0000-0000-0000-000000000000}", "x")
        .err()
        .unwrap();
    assert!(
        err.iter().any(|l| l.0 == fmi2Error && l.2.contains("GUID")),
        "{err:?}"
    );
    // The GUID of another scene.
    let mut other = scene.clone();
    other.material.k = 1001.0;
    assert!(Fmu::try_new(&scene, &guid(&other), "x").is_err());
    // An empty instance name.
    let err = Fmu::try_new(&scene, &guid(&scene), "").err().unwrap();
    assert!(err.iter().any(|l| l.2.contains("instance name")), "{err:?}");
    // Model exchange is not offered; null callbacks give null.
    // SAFETY: the strings are live `CString`s and `cb` outlives every call; the FMU refuses Model
    // Exchange and null callbacks before it uses them, which is what is checked.
    unsafe {
        let dir = resources(&scene);
        let uri = CString::new(format!("file://{}", dir.display())).unwrap();
        let g = CString::new(guid(&scene)).unwrap();
        let n = CString::new("me").unwrap();
        let cb = fmi2CallbackFunctions {
            logger: None,
            allocateMemory: None,
            freeMemory: None,
            stepFinished: None,
            componentEnvironment: std::ptr::null_mut(),
        };
        let c = instantiate_with(fmi2Instantiate, (&n, fmi2ModelExchange, &g, &uri), &cb);
        assert!(c.is_null());
        let c = instantiate_with(
            fmi2Instantiate,
            (&n, fmi2CoSimulation, &g, &uri),
            std::ptr::null(),
        );
        assert!(c.is_null());
        // Without a logger it still works; file:/ and %-escaped URIs too.
        let uri2 = CString::new(format!("file:{}", dir.display())).unwrap();
        let c = instantiate_with(fmi2Instantiate, (&n, fmi2CoSimulation, &g, &uri2), &cb);
        assert!(!c.is_null());
        fmi2FreeInstance(c);
        let spaced = std::env::temp_dir().join(format!("yarn bundle {}", std::process::id()));
        std::fs::create_dir_all(&spaced).unwrap();
        std::fs::write(spaced.join(SCENE_FILE), scene.to_toml_string()).unwrap();
        let uri3 =
            CString::new(format!("file://{}", spaced.display()).replace(' ', "%20")).unwrap();
        let c = instantiate_with(fmi2Instantiate, (&n, fmi2CoSimulation, &g, &uri3), &cb);
        assert!(!c.is_null());
        fmi2FreeInstance(c);
        std::fs::remove_dir_all(spaced).unwrap();
        std::fs::remove_dir_all(dir).unwrap();
        // Freeing null is a no-op.
        fmi2FreeInstance(std::ptr::null_mut());
    }
}

#[test]
fn null_pointers_and_bad_value_references_are_errors() {
    let scene = small_scene();
    let f = Fmu::initialized(&scene);
    // SAFETY: null arrays with a non-zero count: the FMU checks every pointer for null before
    // reading it, which is what is checked.
    unsafe {
        assert_eq!(
            fmi2GetReal(f.c, std::ptr::null(), 2, std::ptr::null_mut()),
            fmi2Error
        );
        assert!(f.last_error().contains("null pointer"));
    }
    let f = Fmu::initialized(&scene);
    assert_eq!(
        f.get_real(&[VR_YARN_BASE + 4 * f.yarns as u32]),
        Err(fmi2Error)
    );
    // Null components.
    // SAFETY: null components: the FMU checks the component for null before using it, which is
    // what is checked.
    unsafe {
        assert_eq!(fmi2DoStep(std::ptr::null_mut(), 0.0, H, 0), fmi2Error);
        assert_eq!(fmi2Reset(std::ptr::null_mut()), fmi2Error);
        let mut v = 0;
        assert_eq!(
            fmi2GetBooleanStatus(std::ptr::null_mut(), fmi2Terminated, &mut v),
            fmi2Error
        );
    }
    // Zero-length calls with null arrays are fine.
    let f = Fmu::initialized(&scene);
    // SAFETY: a zero-length call reads and writes nothing through its null arrays.
    unsafe {
        assert_eq!(
            fmi2GetReal(f.c, std::ptr::null(), 0, std::ptr::null_mut()),
            fmi2OK
        );
    }
}

#[test]
fn non_finite_and_absurd_inputs_are_rejected_with_a_log_line() {
    let scene = small_scene();
    for (vr, v) in [
        (VR_ATTRACTOR_X, f64::NAN),
        (VR_GRAVITY_Y, f64::INFINITY),
        (VR_GRAVITY_X, f64::NEG_INFINITY),
        (VR_ATTRACTOR_STRENGTH, -1.0),
        (VR_GRAVITY_X, 1e7),
    ] {
        let f = Fmu::initialized(&scene);
        assert_eq!(f.set_real(&[vr], &[v]), fmi2Error, "{vr} = {v}");
        assert!(f.last_error().contains("fmi2SetReal"), "{:?}", f.lines());
        // The instance is unusable until reset, then runs normally.
        assert_eq!(f.do_step(0.0, H), fmi2Error);
        // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
        // pointer argument is a local that outlives the call.
        assert_eq!(unsafe { fmi2Reset(f.c) }, fmi2OK);
        f.init();
        assert_eq!(f.do_step(0.0, H), fmi2OK);
        assert!(f.outputs().iter().all(|x| x.is_finite()));
    }
}

/// Messages go through the printf-style logger with % and # escaped.
#[test]
fn log_messages_escape_percent_and_hash() {
    let scene = small_scene();
    let f = Fmu::new(&scene);
    let name = CString::new("no%such#scene.toml").unwrap();
    let p = name.as_ptr();
    // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every pointer
    // argument is a local that outlives the call.
    assert_eq!(unsafe { fmi2SetString(f.c, &VR_SCENE, 1, &p) }, fmi2Error);
    let lines = f.lines();
    let err = lines
        .iter()
        .find(|l| l.0 == fmi2Error)
        .expect("an error line");
    assert_eq!(err.1, "logStatusError");
    assert!(err.2.contains("no%%such##scene.toml"), "{err:?}");
    // Debug logging: categories by name, unknown names rejected.
    let f = Fmu::new(&scene);
    let cats = [
        CString::new("logEvents").unwrap(),
        CString::new("logAll").unwrap(),
    ];
    let ptrs: Vec<*const c_char> = cats.iter().map(|c| c.as_ptr()).collect();
    assert_eq!(
        // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
        // pointer argument is a local that outlives the call.
        unsafe { fmi2SetDebugLogging(f.c, 1, 2, ptrs.as_ptr()) },
        fmi2OK
    );
    f.init();
    assert_eq!(f.do_step(0.0, H), fmi2OK);
    let lines = f.lines();
    assert!(
        lines
            .iter()
            .any(|l| l.1 == "logEvents" && l.2.contains("initialized")),
        "{lines:?}"
    );
    assert!(
        lines
            .iter()
            .any(|l| l.1 == "logAll" && l.2.contains("fmi2DoStep")),
        "{lines:?}"
    );
    let bad = CString::new("logNothing").unwrap();
    let p = bad.as_ptr();
    // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every pointer
    // argument is a local that outlives the call.
    assert_eq!(unsafe { fmi2SetDebugLogging(f.c, 1, 1, &p) }, fmi2Error);
}

/// A run that blows up ends in fmi2Discard with the terminated status set
/// and a log line; its outputs are never handed out as NaN: the failed step
/// puts back the state of its start (lastSuccessfulTime), whose outputs stay
/// readable.
#[test]
fn diverging_run_is_discarded_never_ok_with_nan() {
    let scene = small_scene();
    let f = Fmu::new(&scene);
    // A huge substep: the CFL guard or the stress update fails.
    assert_eq!(f.set_real(&[VR_DT], &[5e-3]), fmi2OK);
    assert_eq!(f.setup(0.0, None), fmi2OK);
    // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every pointer
    // argument is a local that outlives the call.
    unsafe {
        assert_eq!(fmi2EnterInitializationMode(f.c), fmi2OK);
        // Beyond the stability bound: a warning at initialization.
        assert_eq!(fmi2ExitInitializationMode(f.c), fmi2Warning);
    }
    assert_eq!(f.set_real(&[VR_GRAVITY_Y], &[-9.0e5]), fmi2OK);
    let mut t = 0.0;
    let mut status = fmi2OK;
    let mut before = f.outputs();
    let mut substeps = f.substeps();
    for _ in 0..50 {
        status = f.do_step(t, H);
        if status != fmi2OK {
            break;
        }
        before = f.outputs();
        substeps = f.substeps();
        assert!(before.iter().all(|v| v.is_finite()));
        t += H;
    }
    assert_eq!(status, fmi2Discard, "{:?}", f.lines());
    f.assert_discarded_at(t);
    // The last good state, bit for bit.
    assert_eq!(f.outputs(), before);
    assert_eq!(f.substeps(), substeps);
    assert!(f.do_step(t, H) >= fmi2Error);
}

fn independent_run(scene: &YarnScene, gx: f64) -> Vec<u64> {
    let f = Fmu::initialized(scene);
    assert_eq!(f.set_real(&[VR_GRAVITY_X], &[gx]), fmi2OK);
    f.output_bits(0..6, H)
}

/// Instances share nothing: interleaved in one thread and concurrent in
/// several threads, each gives the bits of a lone run.
#[test]
fn instances_are_independent_in_one_thread_and_in_parallel() {
    let scene = small_scene();
    let gx = [-4.0, 0.0, 2.5, 6.0];
    let alone: Vec<Vec<u64>> = gx.iter().map(|&g| independent_run(&scene, g)).collect();
    assert_ne!(alone[0], alone[1]);

    // Interleaved in one thread.
    let fmus: Vec<Fmu> = gx.iter().map(|_| Fmu::new(&scene)).collect();
    let mut bits = vec![Vec::new(); gx.len()];
    for (f, &g) in fmus.iter().zip(&gx) {
        f.init();
        assert_eq!(f.set_real(&[VR_GRAVITY_X], &[g]), fmi2OK);
    }
    for k in 0..6 {
        for (i, f) in fmus.iter().enumerate() {
            assert_eq!(f.do_step(k as f64 * H, H), fmi2OK);
            bits[i].extend(f.outputs().iter().map(|v| v.to_bits()));
        }
    }
    assert_eq!(bits, alone);

    // Concurrent threads.
    let threads: Vec<_> = gx
        .iter()
        .map(|&g| {
            let s = scene.clone();
            std::thread::spawn(move || independent_run(&s, g))
        })
        .collect();
    let par: Vec<Vec<u64>> = threads.into_iter().map(|t| t.join().unwrap()).collect();
    assert_eq!(par, alone);
}

/// Parameters set before initialization change the run; a second scene file
/// in the resources folder can be chosen by the `scene` parameter.
#[test]
fn parameters_and_scene_parameter() {
    let scene = small_scene();
    let base = independent_run(&scene, 0.0);
    let f = Fmu::new(&scene);
    assert_eq!(f.set_real(&[VR_DT], &[1e-4]), fmi2OK);
    assert_eq!(f.setup(0.0, None), fmi2OK);
    // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every pointer
    // argument is a local that outlives the call.
    unsafe { assert_eq!(fmi2EnterInitializationMode(f.c), fmi2OK) };
    assert_eq!(f.get_real(&[VR_DT]), Ok(vec![1e-4]));
    // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every pointer
    // argument is a local that outlives the call.
    unsafe { assert_eq!(fmi2ExitInitializationMode(f.c), fmi2OK) };
    let bits = f.output_bits(0..6, H);
    assert_ne!(bits, base);
    assert_eq!(f.substeps(), 600);
    // The same parameter change through a scene file.
    let mut stiff = scene.clone();
    stiff.time.dt = 1e-4.into();
    std::fs::write(f.dir.join("stiff.toml"), stiff.to_toml_string()).unwrap();
    let g = Fmu::new(&scene);
    std::fs::write(g.dir.join("stiff.toml"), stiff.to_toml_string()).unwrap();
    let name = CString::new("stiff.toml").unwrap();
    let p = name.as_ptr();
    assert_eq!(
        // SAFETY: `g.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
        // pointer argument is a local that outlives the call.
        unsafe { fmi2SetString(g.c, &VR_SCENE, 1, &p) },
        fmi2OK,
        "{:?}",
        g.lines()
    );
    g.init();
    let bits2 = g.output_bits(0..6, H);
    assert_eq!(bits2, bits);
    // Out-of-range parameters are rejected (dt = 0 is adaptive substeps,
    // tests/auto_dt.rs).
    let h = Fmu::new(&scene);
    assert_eq!(h.set_real(&[VR_DT], &[-1e-4]), fmi2Error);
}
