//! Cost of the implicit step against the explicit one on the same scene:
//! Newton and CG iterations and wall time per substep, and wall time per
//! simulated second, for the cantilever of `tests/yarn_oracles.rs` (200
//! vertices, B = 1 N m) and the built-in material (k 1000, gamma 500,
//! E 1000, bending 1e-3, plasticity) on two falling yarns pressed together
//! (3 m/s toward each other, spinning at 2 rad/s). Runs alternate
//! (explicit, implicit 1e-4, implicit 1e-3, repeated `RUNS` times) and the
//! medians are printed.
//!
//! ```text
//! cargo run --release -p yarnsim-evidence --example implicit_cost [RUNS]
//! ```

use std::time::Instant;

use yarnsim::math::{perp, Vec2};
use yarnsim::scene::builtin::yarn_reference;
use yarnsim::scene::{Integrator, StepSize, WallMode, YarnScene, YarnSpec};
use yarnsim::testing::cantilever_toml;
use yarnsim::YarnSim;

/// The built-in material (the reference scene's) on two straight yarns of
/// 60 vertices, 1 cm apart, on 64^2 at dt 1e-4 with gravity, without walls,
/// obstacles or pins.
fn two_yarns() -> YarnScene {
    let mut s = yarn_reference();
    s.grid.resolution = 64;
    s.time.dt = StepSize::Fixed(1e-4);
    s.walls.mode = WallMode::None;
    s.obstacles.clear();
    s.yarns = vec![YarnSpec {
        count: 2,
        spacing: [0.0, 0.01],
        ..YarnSpec::straight([0.3, 0.5], [0.7, 0.5], 60)
    }];
    s
}

/// One run of `duration` simulated seconds: (wall s per substep, Newton
/// and CG per substep).
fn run(base: &YarnScene, implicit: Option<f64>, duration: f64, press: bool) -> (f64, f64, f64) {
    let mut s = base.clone();
    if let Some(dt) = implicit {
        s.time.integrator = Integrator::Implicit;
        s.time.dt = StepSize::Fixed(dt);
    }
    let mut sim = YarnSim::new(&s).unwrap();
    if press {
        let c = sim.diagnostics().center_of_mass;
        let p = yarnsim::testing::particles_mut(&mut sim);
        for (x, v) in p.vert.x.iter().zip(p.vert.v.iter_mut()) {
            let toward = if x.y > c.y { -3.0 } else { 3.0 };
            *v = perp(x - c) * 2.0 + Vec2::new(0.0, toward);
        }
    }
    let n = (duration / sim.dt()).round() as u64;
    let t0 = Instant::now();
    sim.steps_n(n).unwrap();
    let wall = t0.elapsed().as_secs_f64() / n as f64;
    let st = sim.implicit_stats();
    let per = |x: u64| x as f64 / st.substeps.max(1) as f64;
    (wall, per(st.newton), per(st.cg))
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v[v.len() / 2]
}

fn main() {
    let runs: usize = std::env::args()
        .nth(1)
        .map_or(3, |a| a.parse().expect("RUNS"));
    let scenes = [
        (
            "cantilever 200 vertices",
            YarnScene::from_toml_str(&cantilever_toml(200)).unwrap(),
            0.1,
            false,
        ),
        ("built-in material, two yarns", two_yarns(), 0.1, true),
    ];
    for (name, scene, duration, press) in scenes {
        let modes = [None, Some(1e-4), Some(1e-3)];
        let mut t: Vec<Vec<(f64, f64, f64)>> = vec![Vec::new(); modes.len()];
        for _ in 0..runs {
            for (k, m) in modes.iter().enumerate() {
                t[k].push(run(&scene, *m, duration, press));
            }
        }
        let dt_ex = scene.time.dt.fixed().unwrap();
        for (k, m) in modes.iter().enumerate() {
            let wall = median(t[k].iter().map(|r| r.0).collect());
            let (newton, cg) = (t[k][0].1, t[k][0].2);
            let dt = m.unwrap_or(dt_ex);
            let label = match m {
                None => format!("explicit dt {dt:e}"),
                Some(_) => format!("implicit dt {dt:e}"),
            };
            println!(
                "{name}: {label}: {newton:.2} Newton / {cg:.1} CG per substep, \
                 {:.3} ms per substep, {:.2} s per simulated s (median of {runs})",
                1e3 * wall,
                wall / dt
            );
        }
    }
}
