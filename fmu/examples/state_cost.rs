//! Measures the FMU state functions through the C ABI: the time of
//! `fmi2GetFMUstate` (a new state, and into an existing one),
//! `fmi2SetFMUstate`, `fmi2SerializedFMUstateSize` + `fmi2SerializeFMUstate`
//! (of a state not serialized before), `fmi2DeSerializeFMUstate` and
//! `fmi2FreeFMUstate`, and the bytes: the serialized size and the heap
//! bytes a call allocates (a counting global allocator).
//!
//! ```text
//! cargo run --release -p yarnsim-fmu --example state_cost [SCENE] [REPEATS] [SUBSTEPS]
//! ```
//!
//! SCENE defaults to the reference scene (`yarn-reference`, the YarnBundle
//! FMU's default); the instance first runs SUBSTEPS substeps (default 250,
//! 0.01 s) so the state is not the one at rest. Every figure is the median
//! (and the minimum) of REPEATS calls (default 200). With
//! `STATE_COST_DUMP=FILE` the serialized state is written to FILE.

use std::alloc::{GlobalAlloc, Layout, System};
use std::ffi::c_void;
use std::hint::black_box;
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};
use std::time::Instant;

use yarnsim::scene::{Scene, DEFAULT_SCENE};
use yarnsim_fmu::fmi2::*;
use yarnsim_fmu::models::yarn::variables::*;

mod common;

/// Counts the bytes allocated (not freed) through the global allocator.
struct Counting;

static ALLOCATED: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every method forwards to `System` with the caller's arguments, so `System`'s guarantees
// are the allocator's; the counter only adds.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        ALLOCATED.fetch_add(l.size(), Relaxed);
        // SAFETY: forwarded with the caller's layout.
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        // SAFETY: forwarded with the caller's pointer and layout.
        unsafe { System.dealloc(p, l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, new: usize) -> *mut u8 {
        ALLOCATED.fetch_add(new.saturating_sub(l.size()), Relaxed);
        // SAFETY: forwarded with the caller's pointer and layout.
        unsafe { System.realloc(p, l, new) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Median and minimum of `samples` in microseconds.
fn stats(mut samples: Vec<f64>) -> (f64, f64) {
    samples.sort_by(|a, b| a.partial_cmp(b).unwrap());
    (samples[samples.len() / 2] * 1e6, samples[0] * 1e6)
}

fn report(what: &str, samples: Vec<f64>, allocated: usize) {
    let (median, min) = stats(samples);
    println!(
        "{what:<44} median {median:>9.1} us  min {min:>9.1} us  allocates {allocated:>9} bytes"
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let scene_arg = args.first().cloned().unwrap_or(DEFAULT_SCENE.to_string());
    let repeats: usize = args.get(1).map(|s| s.parse().unwrap()).unwrap_or(200);
    let substeps: u64 = args.get(2).map(|s| s.parse().unwrap()).unwrap_or(250);
    let fx = common::Fixture::new(&scene_arg, "state");
    let scene = &fx.scene;
    let alloc_of = |f: &mut dyn FnMut()| {
        let a = ALLOCATED.load(Relaxed);
        f();
        ALLOCATED.load(Relaxed) - a
    };
    // SAFETY: the FMI calling sequence of the standard, on a live instance
    // and states this program made and frees.
    unsafe {
        let instantiate = || fx.instance();
        let c = instantiate();
        let mut dt = 0.0;
        let vr_dt = match scene {
            Scene::Yarn(_) => VR_DT,
            Scene::MassSpring(_) => yarnsim_fmu::models::massspring::VR_DT,
        };
        assert_eq!(fmi2GetReal(c, &vr_dt, 1, &mut dt), fmi2OK);
        // MassSpring's dt = 0 means the integrator's own step.
        let h = if dt > 0.0 { dt * substeps as f64 } else { 0.01 };
        let t0 = Instant::now();
        assert_eq!(fmi2DoStep(c, 0.0, h, 1), fmi2OK);
        println!(
            "scene {:?}: {substeps} substeps of {dt} s in {:.3} s; {repeats} calls each",
            scene.name(),
            t0.elapsed().as_secs_f64()
        );

        let free = |s: &mut *mut c_void| {
            assert_eq!(fmi2FreeFMUstate(c, s), fmi2OK);
        };

        // GetFMUstate, a new state each time.
        let mut times = Vec::new();
        let mut bytes = 0;
        for _ in 0..repeats {
            let mut s: *mut c_void = std::ptr::null_mut();
            let t = Instant::now();
            bytes = alloc_of(&mut || assert_eq!(fmi2GetFMUstate(c, &mut s), fmi2OK));
            times.push(t.elapsed().as_secs_f64());
            free(&mut s);
        }
        report("fmi2GetFMUstate (new state)", times, bytes);

        // GetFMUstate into an existing state.
        let mut s: *mut c_void = std::ptr::null_mut();
        assert_eq!(fmi2GetFMUstate(c, &mut s), fmi2OK);
        let mut times = Vec::new();
        for _ in 0..repeats {
            let t = Instant::now();
            bytes = alloc_of(&mut || assert_eq!(fmi2GetFMUstate(c, &mut s), fmi2OK));
            times.push(t.elapsed().as_secs_f64());
        }
        report("fmi2GetFMUstate (into an existing state)", times, bytes);

        // SetFMUstate.
        let mut times = Vec::new();
        for _ in 0..repeats {
            let t = Instant::now();
            bytes = alloc_of(&mut || assert_eq!(fmi2SetFMUstate(c, s), fmi2OK));
            times.push(t.elapsed().as_secs_f64());
        }
        report("fmi2SetFMUstate", times, bytes);

        // Size + Serialize of a state not serialized before.
        let mut size = 0usize;
        let mut buf: Vec<u8> = Vec::new();
        let mut times = Vec::new();
        for _ in 0..repeats {
            let mut s: *mut c_void = std::ptr::null_mut();
            assert_eq!(fmi2GetFMUstate(c, &mut s), fmi2OK);
            let t = Instant::now();
            bytes = alloc_of(&mut || {
                assert_eq!(fmi2SerializedFMUstateSize(c, s, &mut size), fmi2OK);
                buf.resize(size, 0);
                assert_eq!(
                    fmi2SerializeFMUstate(c, s, buf.as_mut_ptr() as *mut _, size),
                    fmi2OK
                );
            });
            times.push(t.elapsed().as_secs_f64());
            black_box(&buf);
            free(&mut s);
        }
        report("fmi2SerializedFMUstateSize + Serialize", times, bytes);
        if let Some(path) = std::env::var_os("STATE_COST_DUMP") {
            std::fs::write(path, &buf).unwrap();
        }
        println!("serialized FMU state: {size} bytes");

        // DeSerialize, into this instance and into a fresh one.
        for (what, d) in [
            ("fmi2DeSerializeFMUstate", c),
            ("fmi2DeSerializeFMUstate (fresh instance)", instantiate()),
        ] {
            let mut times = Vec::new();
            for _ in 0..repeats {
                let mut s2: *mut c_void = std::ptr::null_mut();
                let t = Instant::now();
                bytes = alloc_of(&mut || {
                    assert_eq!(
                        fmi2DeSerializeFMUstate(d, buf.as_ptr() as *const _, size, &mut s2),
                        fmi2OK
                    )
                });
                times.push(t.elapsed().as_secs_f64());
                assert_eq!(fmi2FreeFMUstate(d, &mut s2), fmi2OK);
            }
            report(what, times, bytes);
            if d != c {
                fmi2FreeInstance(d);
            }
        }

        // FreeFMUstate.
        let mut times = Vec::new();
        for _ in 0..repeats {
            let mut s2: *mut c_void = std::ptr::null_mut();
            assert_eq!(fmi2GetFMUstate(c, &mut s2), fmi2OK);
            let t = Instant::now();
            free(&mut s2);
            times.push(t.elapsed().as_secs_f64());
        }
        report("fmi2FreeFMUstate", times, 0);
        free(&mut s);
        fmi2FreeInstance(c);
    }
    let _ = std::fs::remove_dir_all(&fx.dir);
}
