//! The reference bundle (`yarn-reference`) under the grid implicit
//! integrator at `dt = "auto"` with the fibre stiffness `k` given, on one
//! thread, to `T`: per outer substep, when a segment's stretch leaves the
//! band of the scene's `k` (`[0.9, 1.1]` at `k < 1e4`, `[0.99, 1.01]`
//! above) or the total energy rises above its start, a line with the
//! time, dt, the stretch range, the largest change of a segment's stretch
//! and the energy; at the end, the largest rise of the total energy over
//! the start, the stretch range, the implicit solver's counts and the wall
//! time.
//!
//! ```text
//! cargo run --release -p yarnsim-evidence --example implicit_bands -- K [T] [YARNS]
//! ```
//! `YARNS`: that many of the reference's 12 yarns (the lowest ones).
//! `OBSTACLE_FRICTION=MU` in the environment sets every circle's friction
//! (0.3), `YARN_FRICTION=MU` the yarns' (`material.friction`, 0.05),
//! `FLIP_RATIO=R` the transfer's (`transfer.flip_ratio`, 1).

use std::time::Instant;

use yarnsim::testing::implicit_pile_scene;
use yarnsim::YarnSim;

fn total(sim: &YarnSim) -> f64 {
    let d = sim.diagnostics();
    d.kinetic_energy + d.elastic_energy + d.potential_energy
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().collect();
    let k: f64 = a.get(1).map_or(Ok(1e3), |s| s.parse())?;
    let until: f64 = a.get(2).map_or(Ok(0.25), |s| s.parse())?;
    let yarns = a.get(3).map_or(Ok(12), |n| n.parse())?;
    let mut s = implicit_pile_scene(k, yarns);
    if let Ok(mu) = std::env::var("OBSTACLE_FRICTION") {
        let mu: f64 = mu.parse()?;
        s.obstacles.iter_mut().for_each(|o| o.friction = mu);
    }
    if let Ok(mu) = std::env::var("YARN_FRICTION") {
        s.material.friction = mu.parse()?;
    }
    if let Ok(r) = std::env::var("FLIP_RATIO") {
        s.transfer.flip_ratio = r.parse()?;
    }
    let band = if k < 1e4 { 0.1 } else { 0.01 };
    let mut sim = YarnSim::new(&s)?;
    let e0 = total(&sim);
    let t0 = Instant::now();
    let (mut lo, mut hi, mut rise) = (f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY);
    let mut outside = 0u64;
    let mut error = None;
    yarnsim::pool::on_pool(|| loop {
        let before = sim.stretches();
        let st0 = sim.implicit_stats();
        let t = sim.time();
        match sim.step_toward(until) {
            Ok(true) => {}
            Ok(false) => break,
            Err(e) => {
                error = Some(e);
                break;
            }
        }
        let d = sim.diagnostics();
        let e = total(&sim) - e0;
        let jump = (sim.stretches().iter().zip(&before))
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        rise = rise.max(e);
        lo = lo.min(d.min_stretch);
        hi = hi.max(d.max_stretch);
        let out = d.min_stretch < 1.0 - band || d.max_stretch > 1.0 + band;
        if out || e > 0.0 {
            outside += 1;
            let st = sim.implicit_stats();
            if outside <= 40 {
                println!(
                    "t {t:.5} dt {:.3e}: stretch {:.4}-{:.4}, largest change {:.2e}; \
                     total {e:+.4e} J over the start; cutbacks {} (energy {}), newton {}",
                    d.time - t,
                    d.min_stretch,
                    d.max_stretch,
                    jump,
                    st.cutbacks - st0.cutbacks,
                    st.energy_cuts - st0.energy_cuts,
                    st.newton - st0.newton
                );
            }
        }
    });
    let st = sim.implicit_stats();
    println!(
        "k {k:e} to t {:.4} s: start total {e0:.4} J, largest rise {rise:+.4e} J, stretch \
         {lo:.4}-{hi:.4} (band +-{band}), {outside} outer substeps out of band or above the \
         start; {} substeps; {st:?}; {:?}; wall {:.1} s",
        sim.time(),
        sim.steps(),
        error,
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}
