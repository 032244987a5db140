//! Per-substep energy ledger of the implicit integrator (`dt = "auto"`)
//! through a landing: a small bundle (3 yarns of 0.3 m, 75 vertices, the
//! built-in material with `k` given) dropped 6.5 cm onto one circle of
//! the reference scene (R 0.08, friction 0.3, 256^2), landing at about
//! 1.1 m/s as the reference bundle does. Prints, per substep: time, dt,
//! kinetic, elastic, potential and total energy, the stretch range.
//!
//! ```text
//! cargo run --release -p yarnsim-evidence --example implicit_landing -- K [DURATION] [SAFETY|-] [FRICTION]
//! ```

use yarnsim::testing::implicit_landing_scene;
use yarnsim::YarnSim;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let k: f64 = a.get(1).map_or(1e3, |s| s.parse().unwrap());
    let dur: f64 = a.get(2).map_or(0.2, |s| s.parse().unwrap());
    let mut s = implicit_landing_scene(k, 0.3);
    if let Some(sf) = a.get(3).filter(|x| *x != "-") {
        s.time.safety = Some(sf.parse().unwrap());
    }
    if let Some(mu) = a.get(4) {
        s.obstacles[0].friction = mu.parse().unwrap();
    }
    let mut sim = YarnSim::new(&s).unwrap();
    let d0 = sim.diagnostics();
    let e0 = d0.kinetic_energy + d0.elastic_energy + d0.potential_energy;
    println!("k {k}: start total {e0:.6} J");
    let t0 = std::time::Instant::now();
    let mut emax: f64 = f64::NEG_INFINITY;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    while sim.time() < dur - 1e-12 {
        let t = sim.time();
        let dt = sim.substep_toward(dur).unwrap();
        let before = sim.diagnostics();
        let eb = before.kinetic_energy + before.elastic_energy + before.potential_energy;
        if let Err(e) = sim.step_toward(dur) {
            println!("t {t:.5}: {e}");
            break;
        }
        let d = sim.diagnostics();
        let e = d.kinetic_energy + d.elastic_energy + d.potential_energy;
        emax = emax.max(e - e0);
        lo = lo.min(d.min_stretch);
        hi = hi.max(d.max_stretch);
        if t > 0.08 {
            println!(
                "t {:.5} dt {dt:.3e} ke {:.5} el {:.5} pe {:.5} tot {:+.5} dE {:+.2e} stretch {:.4}-{:.4}",
                d.time, d.kinetic_energy, d.elastic_energy, d.potential_energy, e - e0, e - eb,
                d.min_stretch, d.max_stretch
            );
        }
    }
    let st = sim.implicit_stats();
    println!(
        "k {k}: max total over start {emax:+.4} J, stretch {lo:.4}-{hi:.4}, {} substeps, {st:?}, wall {:.1} s",
        sim.steps(),
        t0.elapsed().as_secs_f64()
    );
}
