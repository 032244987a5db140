//! Adaptive substeps (`[time] dt = "auto"`) on the reference scene, the
//! figures of the README section "Adaptive substeps":
//!
//! `cargo run --release -p yarnsim-evidence --example auto_dt -- [ROUNDS] [--safety S...]`
//!
//! * speed: the reference scene to t = 0.5 s with the fixed 4e-5 s and with
//!   `"auto"` (default safety), alternately `ROUNDS` times (default 3), so
//!   both see the same host load; prints substeps, wall times (stepping
//!   only) and their ratios;
//! * `--safety S...`: one `"auto"` run per safety factor (stable or where it
//!   diverged), the measurement behind the default.

use std::time::Instant;

use yarnsim::scene::{builtin, Scene, StepSize, YarnScene};
use yarnsim::YarnSim;

const T_END: f64 = 0.5;

fn reference() -> YarnScene {
    let Some(Scene::Yarn(s)) = builtin("yarn-reference") else {
        panic!("yarn-reference is a yarn scene")
    };
    s
}

/// Runs `scene` to [`T_END`]; (substeps, wall s, outcome).
fn run(scene: &YarnScene) -> (u64, f64, String) {
    let mut sim = YarnSim::new(scene).unwrap();
    let t0 = Instant::now();
    let r = sim.advance_to(T_END);
    let wall = t0.elapsed().as_secs_f64();
    let s = sim.stretches();
    let lo = s.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = s.iter().copied().fold(0.0, f64::max);
    let d = sim.dt_stats();
    let outcome = match r {
        Ok(()) => format!(
            "t = {}, dt min / mean / max {:.3e} / {:.3e} / {:.3e} s, stretch {lo:.4} to {hi:.4}",
            sim.time(),
            d.min,
            d.mean(),
            d.max
        ),
        Err(e) => format!("{e}"),
    };
    (sim.steps(), wall, outcome)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let base = reference();
    let mut auto = base.clone();
    auto.time.dt = StepSize::Auto;
    if let Some(i) = args.iter().position(|a| a == "--safety") {
        for s in &args[i + 1..] {
            let mut sc = auto.clone();
            sc.time.safety = Some(s.parse().expect("a safety factor"));
            let (n, wall, out) = run(&sc);
            println!("safety {s}: {n} substeps, {wall:.2} s: {out}");
        }
        return;
    }
    let rounds: usize = args.first().map_or(3, |a| a.parse().expect("ROUNDS"));
    let threads = rayon::current_num_threads();
    println!("reference scene to {T_END} s, {threads} threads, {rounds} alternate rounds");
    let (mut wf, mut wa) = (Vec::new(), Vec::new());
    for k in 0..rounds {
        let (nf, f, of) = run(&base);
        let (na, a, oa) = run(&auto);
        println!("round {k}: fixed 4e-5: {nf} substeps {f:.2} s ({of})");
        println!(
            "round {k}: auto:       {na} substeps {a:.2} s ({oa}); speed-up {:.2}",
            f / a
        );
        wf.push(f);
        wa.push(a);
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (mf, ma) = (median(&mut wf), median(&mut wa));
    println!(
        "median wall: fixed {mf:.2} s, auto {ma:.2} s, speed-up {:.2} (substeps ratio {:.2})",
        mf / ma,
        12500.0 / run(&auto).0 as f64
    );
}
