//! The heavy-rope capstan and the incline at a real yarn's measured EA
//! with `[time] axial = "implicit"`: the obstacle friction must see the
//! fibre tension, which the axial solve carries (`docs/obstacle-contact.md`,
//! "Under the axial split").

mod common;

use common::{capstan_slip, capstan_threshold, scene, CAPSTAN_BUILTIN};
use yarnsim::testing::capstan_drop_toml;
use yarnsim::YarnSim;

/// The axial solve's lines: `[time] axial = "implicit"` under APIC.
const AXIAL: &str = "axial = \"implicit\"\n[transfer]\nscheme = \"apic\"\n";

/// The heavy-rope capstan of [`capstan_drop_toml`] (R `r`, l1 0.1, l2 0.3,
/// released `drop` above the circle, friction `factor` times mu*) with
/// the preset `name` at its measured EA, the axial solve and `dt = "auto"`.
fn capstan_sim(name: &str, r: f64, drop: f64, factor: f64) -> YarnSim {
    let (l1, l2) = (0.1, 0.3);
    let mu = factor * capstan_threshold(r, l1, l2);
    let text = capstan_drop_toml(r, l1, l2, mu, drop, &CAPSTAN_BUILTIN);
    let (a, b) = (
        text.find("[material]\n").unwrap(),
        text.find("[walls]").unwrap(),
    );
    let text = format!(
        "{}[material]\npreset = \"{name}\"\nplasticity = true\n{}",
        &text[..a],
        &text[b..]
    )
    .replace("dt = 0.0001\n", &format!("dt = \"auto\"\n{AXIAL}"));
    YarnSim::new(&scene(&text)).unwrap()
}

/// The measurement of the cause: the normal force the grid's contact law
/// delivers to the drum (its normal impulse per substep over the substep)
/// against the rope's weight resting on it; `--ignored --nocapture`.
#[test]
#[ignore = "measurement: cargo test --release --test capstan_real_ea -- --ignored --nocapture"]
fn normal_force_the_grid_sees() {
    for name in ["polyester-167dtex", "nylon66-mono-0.30mm"] {
        let mut sim = capstan_sim(name, 0.1, 0.0, 1.4);
        let p = sim.particles();
        let mass: f64 = p.vert.m.iter().sum::<f64>() + p.quad.m.iter().sum::<f64>();
        let g = sim.gravity().norm();
        let (r, l1, l2) = (0.1, 0.1, 0.3);
        let w = mass * g / (l1 + l2 + std::f64::consts::PI * r);
        // the scalar normal force of a rope at rest on the upper half
        // circle: the tension over R along the arc (between w l1 and w l2
        // at its ends) plus the weight's normal part, 2 w R
        let (lo, hi) = (
            std::f64::consts::PI * w * l1 + 2.0 * w * r,
            std::f64::consts::PI * w * l2 + 2.0 * w * r,
        );
        let at = |sim: &YarnSim| {
            eprintln!(
                "{name} t {:.4}: normal force {:.4e} N/m, rest between {lo:.4e} and {hi:.4e}, weight {:.4e}",
                sim.time(),
                sim.obstacle_normal_impulse() / sim.dt(),
                mass * g
            );
        };
        for _ in 0..20 {
            sim.advance(0.01).unwrap();
            at(&sim);
        }
        let (slid, rel) = capstan_slip(&mut sim, l1, l2, |_| {});
        eprintln!("{name}: slid {slid} ({rel:.3e})");
    }
}
