//! What the FMI 3.0 front end costs beside the FMI 2.0 one, on the same
//! scene and instance code.
//!
//! ```text
//! cargo run --release -p yarnsim-fmu --example fmi3_overhead [SCENE] [CALLS]
//! ```
//!
//! 1. A bare communication step (h = 1e-9 dt: no substep runs) through
//!    `fmi2DoStep` and through `fmi3DoStep` (which also writes its four
//!    flags), interleaved.
//! 2. One substep (h = dt) through each: the FMI 3.0 step also checks
//!    every array element finite (every vertex position and velocity).
//! 3. `fmi3GetFloat64` of all arrays at once (nValues checked against
//!    their sizes) against `fmi2GetReal` of the yarn-end scalars.
//!
//! SCENE is a yarn scene (default `fmu/scenes/small.toml`) or a
//! mass-spring one (`wire`, `cloth`, a file).

use std::ffi::CString;
use std::hint::black_box;
use std::time::Instant;

use yarnsim_fmu::fmi2::*;
use yarnsim_fmu::fmi3::common::*;
use yarnsim_fmu::fmi3::cosim::fmi3DoStep;
use yarnsim_fmu::fmi3::values::fmi3GetFloat64;
use yarnsim_fmu::fmi3::*;
use yarnsim_fmu::model_description::{ArrayVariable, VarType};
use yarnsim_fmu::SceneFmu;

mod common;

/// Median seconds per call of `a` and of `b` over 7 alternating rounds of
/// `n` calls each (which goes first alternates too).
fn per_call(n: usize, mut a: impl FnMut(), mut b: impl FnMut()) -> (f64, f64) {
    let time = |f: &mut dyn FnMut()| {
        let t0 = Instant::now();
        for _ in 0..n {
            f();
        }
        t0.elapsed().as_secs_f64() / n as f64
    };
    let (mut ta, mut tb) = (Vec::new(), Vec::new());
    for r in 0..7 {
        if r % 2 == 0 {
            ta.push(time(&mut a));
            tb.push(time(&mut b));
        } else {
            tb.push(time(&mut b));
            ta.push(time(&mut a));
        }
    }
    ta.sort_by(f64::total_cmp);
    tb.sort_by(f64::total_cmp);
    (ta[3], tb[3])
}

fn main() {
    let mut args = std::env::args().skip(1);
    let scene_arg = args
        .next()
        .unwrap_or_else(|| "fmu/scenes/small.toml".into());
    let calls: usize = args.next().map_or(20_000, |s| s.parse().unwrap());
    let fx = common::Fixture::new(&scene_arg, "fmi3-overhead");
    let d = fx.scene.description().unwrap();
    let arrays: Vec<&ArrayVariable> = d.arrays.iter().collect();
    let avrs: Vec<u32> = arrays.iter().map(|a| a.vr).collect();
    let alen: usize = arrays.iter().map(|a| a.len()).sum();
    let scalars: Vec<u32> = d
        .variables
        .iter()
        .filter(|v| v.causality == "output" && v.ty == VarType::Real)
        .map(|v| v.vr)
        .collect();
    let res = CString::new(format!("{}/", fx.dir.display())).unwrap();
    let (name, token) = (
        CString::new("bench3").unwrap(),
        CString::new(fx.scene.guid()).unwrap(),
    );
    // SAFETY: live strings and no callbacks; the standard calling sequence
    // on instances freed at the end; every array is a local of the given
    // length.
    unsafe {
        let two = fx.instance();
        let three = fmi3InstantiateCoSimulation(
            name.as_ptr(),
            token.as_ptr(),
            res.as_ptr(),
            false,
            false,
            false,
            false,
            std::ptr::null(),
            0,
            std::ptr::null_mut(),
            None,
            None,
        );
        assert!(!three.is_null());
        assert_eq!(
            fmi3EnterInitializationMode(three, false, 0.0, 0.0, false, 0.0),
            fmi3OK
        );
        assert!(fmi3ExitInitializationMode(three) <= fmi3Warning);
        let dt = yarnsim_fmu::new_model(&fx.scene).unwrap().dt();
        let (mut ev, mut term, mut early, mut last) = (false, false, false, 0.0);
        let mut t2 = 0.0;
        let mut t3 = 0.0;
        let tiny = 1e-9 * dt;
        let (bare2, bare3) = per_call(
            calls,
            || {
                assert_eq!(fmi2DoStep(two, t2, tiny, 1), fmi2OK);
                t2 += tiny;
            },
            || {
                let s = fmi3DoStep(
                    three, t3, tiny, true, &mut ev, &mut term, &mut early, &mut last,
                );
                assert_eq!(s, fmi3OK);
                t3 += tiny;
            },
        );
        println!(
            "bare step (no substep): fmi2DoStep {:.0} ns, fmi3DoStep {:.0} ns",
            bare2 * 1e9,
            bare3 * 1e9
        );
        // one substep each: both land on the next grid point
        let n = (calls / 100).max(20);
        let (sub2, sub3) = per_call(
            n,
            || {
                let next = ((t2 / dt).round() + 1.0) * dt;
                assert_eq!(fmi2DoStep(two, t2, next - t2, 1), fmi2OK);
                t2 = next;
            },
            || {
                let next = ((t3 / dt).round() + 1.0) * dt;
                let h = next - t3;
                let s = fmi3DoStep(
                    three, t3, h, true, &mut ev, &mut term, &mut early, &mut last,
                );
                assert_eq!(s, fmi3OK);
                t3 = next;
            },
        );
        println!(
            "one substep: fmi2DoStep {:.1} us, fmi3DoStep {:.1} us ({:+.1} %; it also checks {alen} array values finite)",
            sub2 * 1e6,
            sub3 * 1e6,
            100.0 * (sub3 / sub2 - 1.0)
        );
        let mut out = vec![0.0; alen];
        let mut sc = vec![0.0; scalars.len()];
        let (get3, get2) = per_call(
            calls,
            || {
                let s = fmi3GetFloat64(three, avrs.as_ptr(), avrs.len(), out.as_mut_ptr(), alen);
                assert_eq!(s, fmi3OK);
                black_box(&out);
            },
            || {
                let s = fmi2GetReal(two, scalars.as_ptr(), scalars.len(), sc.as_mut_ptr());
                assert_eq!(s, fmi2OK);
                black_box(&sc);
            },
        );
        println!(
            "reads: fmi3GetFloat64 of {} arrays ({alen} values) {:.2} us; fmi2GetReal of {} scalar outputs {:.2} us",
            avrs.len(),
            get3 * 1e6,
            scalars.len(),
            get2 * 1e6
        );
        fmi2FreeInstance(two);
        fmi3FreeInstance(three);
    }
    let _ = std::fs::remove_dir_all(&fx.dir);
}
