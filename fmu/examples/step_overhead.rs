//! Measures the FMU's communication-step overhead: what an `fmi2DoStep`
//! costs beyond the substeps it runs.
//!
//! ```text
//! cargo run --release -p yarnsim-fmu --example step_overhead [SCENE] [CALLS]
//! ```
//!
//! 1. `fmi2DoStep` with h = 1e-9 dt: the substep grid is not reached, so no
//!    substep runs and the call is pure overhead (pointer and state checks,
//!    catch_unwind, time and substep bookkeeping).
//! 2. The fmpy-like cycle: `fmi2SetReal` of the inputs + that `fmi2DoStep` +
//!    `fmi2GetReal` of as many outputs (YarnBundle: attractor and gravity,
//!    4 yarn-end coordinates; MassSpring: gravity x/y/z, the last particle).
//! 3. For scale: `fmi2DoStep` with h = dt (one substep) against the
//!    library's step called directly, interleaved, alternating which goes
//!    first (each evicts the other's data from the caches).
//! 4. The end-of-step work of a step that runs substeps: the finite check
//!    of every output (for the yarn bundle with its diagnostics, computed
//!    anew after a substep) and the checkpoint of the last good state (the
//!    yarn's dynamic state, a clone of the mass-spring model), each against
//!    one substep (3.).
//!
//! SCENE is a yarn scene (default `fmu/scenes/small.toml`) or a mass-spring
//! one (`wire`, `cloth`, a file), which measures the MassSpring FMU.

use std::hint::black_box;
use std::time::Instant;

use yarnsim::massspring::Simulation;
use yarnsim::mpm::YarnSim;
use yarnsim::scene::Scene;
use yarnsim_fmu::fmi2::*;
use yarnsim_fmu::model_description::*;
use yarnsim_fmu::models::massspring::{self as ms, MsModel};
use yarnsim_fmu::models::model::FmuModel;
use yarnsim_fmu::models::yarn::variables::*;

mod common;

/// The library's own stepper, for the comparison in part 3.
enum Library {
    Yarn(Box<YarnSim>),
    MassSpring(Box<Simulation>),
}

impl Library {
    /// Substep `k`, as the FMU runs it.
    fn step(&mut self, k: u64) {
        match self {
            Library::Yarn(sim) => sim.step().unwrap(),
            Library::MassSpring(sim) => {
                let dt = sim.dt();
                sim.state_mut().t = k as f64 * dt;
                sim.step(dt).unwrap();
            }
        }
    }
}

/// Seconds per call, over `reps` calls after 20 substeps of `m`, of the
/// check of every output (with `reset` before each, inside the timing) and
/// of the last-good checkpoint.
fn end_of_step_costs<M: FmuModel>(mut m: M, reps: usize, reset: impl Fn(&mut M)) -> (f64, f64) {
    for k in 0..20 {
        m.substep(k).unwrap();
    }
    let t0 = Instant::now();
    for _ in 0..reps {
        reset(&mut m);
        assert!(black_box(&mut m).outputs_finite());
    }
    let check = t0.elapsed().as_secs_f64() / reps as f64;
    let t0 = Instant::now();
    for _ in 0..reps {
        black_box(FmuModel::checkpoint(&m));
    }
    (check, t0.elapsed().as_secs_f64() / reps as f64)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let scene_arg = args
        .first()
        .cloned()
        .unwrap_or_else(|| concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/small.toml").to_string());
    let calls: usize = args.get(1).map(|s| s.parse().unwrap()).unwrap_or(2_000_000);
    let fx = common::Fixture::new(&scene_arg, "bench");
    let scene = &fx.scene;
    let new_library = || match scene {
        Scene::Yarn(s) => Library::Yarn(Box::new(YarnSim::new(s).unwrap())),
        Scene::MassSpring(l) => Library::MassSpring(Box::new(MsModel::new(l.clone()).unwrap().sim)),
    };
    let dt = match new_library() {
        Library::Yarn(sim) => sim.dt(),
        Library::MassSpring(sim) => sim.dt(),
    };
    // Inputs to set and outputs to get in part 2, and the input values.
    let (in_vr, out_vr): (Vec<u32>, Vec<u32>) = match scene {
        Scene::Yarn(_) => (
            vec![VR_ATTRACTOR_X, VR_ATTRACTOR_Y, VR_GRAVITY_X, VR_GRAVITY_Y],
            (VR_YARN_BASE..VR_YARN_BASE + 4).collect(),
        ),
        Scene::MassSpring(l) => {
            let last = ms::num_particles(l).unwrap() as u32 - 1;
            let first = ms::VR_PARTICLE_BASE + 3 * last;
            (
                vec![ms::VR_GRAVITY_X, ms::VR_GRAVITY_Y, ms::VR_GRAVITY_Z],
                (first..first + 3).collect(),
            )
        }
    };
    let inputs = |k: usize| -> Vec<f64> {
        let wobble = 1e-3 * (k & 7) as f64;
        match scene {
            Scene::Yarn(_) => vec![0.5, 0.5 + wobble, 0.0, -9.8],
            Scene::MassSpring(_) => vec![0.0, -9.81 + wobble, 0.0],
        }
    };
    let ports = in_vr.len();
    // SAFETY: `c` is the fixture's initialized instance, alive for the whole block; every
    // value-reference and value array passed below has the length given with it.
    unsafe {
        let c = fx.instance();

        // 1. Bare DoStep: h = 1e-9 dt, so 5 x CALLS steps stay far below the
        // first substep's grid point and no substep runs.
        let h = dt * 1e-9;
        let mut t = 0.0;
        let mut best = f64::INFINITY;
        for _round in 0..5 {
            let t0 = Instant::now();
            for _ in 0..calls {
                let s = fmi2DoStep(c, t, h, 1);
                debug_assert_eq!(s, fmi2OK);
                black_box(s);
                t += h;
            }
            best = best.min(t0.elapsed().as_secs_f64() / calls as f64);
        }
        let mut n = 0;
        assert_eq!(fmi2GetInteger(c, &VR_SUBSTEPS, 1, &mut n), fmi2OK);
        assert_eq!(n, 0, "a substep ran during the overhead loop");
        println!(
            "fmi2DoStep without substeps:            {:.1} ns per call (best of 5 x {calls})",
            best * 1e9
        );

        // 2. set n inputs + DoStep + get n outputs.
        let mut out = vec![0.0; ports];
        let mut best = f64::INFINITY;
        for _round in 0..5 {
            let t0 = Instant::now();
            for k in 0..calls {
                let v = inputs(k);
                assert_eq!(fmi2SetReal(c, in_vr.as_ptr(), ports, v.as_ptr()), fmi2OK);
                assert_eq!(fmi2DoStep(c, t, h, 1), fmi2OK);
                assert_eq!(
                    fmi2GetReal(c, out_vr.as_ptr(), ports, out.as_mut_ptr()),
                    fmi2OK
                );
                black_box(&out);
                t += h;
            }
            best = best.min(t0.elapsed().as_secs_f64() / calls as f64);
        }
        println!(
            "SetReal({ports}) + DoStep + GetReal({ports}):       {:.1} ns per cycle",
            best * 1e9
        );
        fmi2FreeInstance(c);

        // 3. One substep per DoStep against the library's step, interleaved.
        let c = fx.instance();
        let mut sim = new_library();
        let steps = 2000.min(calls);
        let (mut fmu_s, mut lib_s) = (0.0, 0.0);
        for k in 0..steps {
            for first in [k % 2 == 0, k % 2 == 1] {
                let t0 = Instant::now();
                if first {
                    assert_eq!(fmi2DoStep(c, k as f64 * dt, dt, 1), fmi2OK);
                    fmu_s += t0.elapsed().as_secs_f64();
                } else {
                    sim.step(k as u64);
                    lib_s += t0.elapsed().as_secs_f64();
                }
            }
        }
        println!(
            "one substep: fmi2DoStep {:.2} us, library step {:.2} us (mean of {steps})",
            fmu_s / steps as f64 * 1e6,
            lib_s / steps as f64 * 1e6
        );
        fmi2FreeInstance(c);
        let one_substep = fmu_s / steps as f64;

        // 4. What a communication step that runs substeps adds: the check
        // of every output (the yarn's diagnostics are recomputed after a
        // substep) and the clone of the last good state.
        let reps = 200.min(calls).max(1);
        let (check_s, clone_s) = match scene {
            // The yarn's diagnostics are cleared before each check, as a
            // substep does; its checkpoint is the library's dynamic state.
            Scene::Yarn(s) => end_of_step_costs(
                yarnsim_fmu::models::yarn::YarnModel::new(s.clone()).unwrap(),
                reps,
                |m| m.diag = None,
            ),
            Scene::MassSpring(l) => {
                end_of_step_costs(MsModel::new(l.clone()).unwrap(), reps, |_| {})
            }
        };
        println!(
            "end of a step with substeps: output check {:.2} us ({:.1} % of one substep), last-good checkpoint {:.2} us ({:.1} %)",
            check_s * 1e6,
            100.0 * check_s / one_substep,
            clone_s * 1e6,
            100.0 * clone_s / one_substep
        );
    }
    let _ = std::fs::remove_dir_all(&fx.dir);
}
