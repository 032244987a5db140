//! Physical oracles of the MPM yarn model (issue 12, item 5), release-only:
//! the heavy-rope capstan threshold, the Euler-Bernoulli cantilever, the
//! hanging chain's first pendulum mode, conservation (free fall, linear and
//! angular momentum), self-convergence in dt, and pins. Every assertion
//! states its tolerance; measured errors are printed (`--nocapture`).

mod common;

use common::scene;
use yarnsim::math::Vec2;
use yarnsim::scene::YarnScene;
use yarnsim::YarnSim;

// ---- capstan ---------------------------------------------------------------

/// Heavy-rope capstan: tension at the heavy end of the wrapped half circle
/// for friction `mu`, from dT/ds = mu T / R + w (mu sin psi - cos psi),
/// psi = pi - s / R, T(0) = w l1 (RK4 in 2000 steps).
fn capstan_tension(mu: f64, r: f64, w: f64, l1: f64) -> f64 {
    let f = |s: f64, t: f64| {
        let psi = std::f64::consts::PI - s / r;
        mu * t / r + w * (mu * psi.sin() - psi.cos())
    };
    let n = 2000;
    let h = std::f64::consts::PI * r / n as f64;
    let mut t = w * l1;
    for i in 0..n {
        let s = i as f64 * h;
        let k1 = f(s, t);
        let k2 = f(s + h / 2.0, t + h / 2.0 * k1);
        let k3 = f(s + h / 2.0, t + h / 2.0 * k2);
        let k4 = f(s + h, t + h * k3);
        t += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    }
    t
}

/// The friction coefficient at which the heavy-rope capstan just holds
/// hanging lengths `l1` and `l2` over a half circle of radius `r`
/// (bisection on `T(pi R) = w l2`; independent of `w`).
fn capstan_threshold(r: f64, l1: f64, l2: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 5.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if capstan_tension(mid, r, 1.0, l1) < l2 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Grid of the capstan scenes.
const CAPSTAN_RES: u32 = 128;
/// Gravity of the capstan scenes (the threshold does not depend on it; a
/// small one keeps the elastic stretch and the time step small and large).
const CAPSTAN_G: f64 = 2.0;

/// Material: a pure string. Bending 0 (all the resistance is friction),
/// k = 1000 (strain below 0.1 %), plasticity off, and no cross-section
/// energy (gamma = 0, E = 0). Measured on this contact law with the
/// cross-section on: gamma 500, E 1000 holds at 1.1 mu* but the free end's
/// cross-section grows without bound (r22 > 1 has no energy) until the shear
/// stiffness, which scales with it, diverges (t = 1.19 s at 1.4 mu*, R 0.1,
/// l2 0.3); gamma 0, E 1000 creeps at 1.4 mu* (3e-3 l1 in 1 s, kinetic energy
/// growing): the cross-section pressure pushes the outer grid nodes of the
/// yarn outward, where the Coulomb law (on inward velocity only) gives them
/// no friction, and without shear nothing ties that layer to the held one.
/// With E = 0 it holds firmly at 1.1 mu* (kinetic energy 3e-8).
///
/// A bending-free yarn over a half circle of radius `r` centred at
/// (0.5, 0.75), hanging `l1` on the left and `l2` on the right, on a
/// circle with friction `mu`.
fn capstan_scene(r: f64, l1: f64, l2: f64, mu: f64) -> YarnScene {
    let (cx, cy) = (0.5, 0.75);
    let mut pts = vec![[cx - r, cy - l1]];
    let arc = 64;
    for i in 0..=arc {
        let psi = std::f64::consts::PI * (1.0 - i as f64 / arc as f64);
        pts.push([cx + r * psi.cos(), cy + r * psi.sin()]);
    }
    pts.push([cx + r, cy - l2]);
    let length = l1 + l2 + std::f64::consts::PI * r;
    let dx = 1.0 / CAPSTAN_RES as f64;
    // vertex spacing about dx / 2
    let vertices = (length / (0.5 * dx)).round() as u32 + 1;
    let points = pts
        .iter()
        .map(|p| format!("[{:.12}, {:.12}]", p[0], p[1]))
        .collect::<Vec<_>>()
        .join(", ");
    scene(&format!(
        r#"
gravity = [0.0, -{CAPSTAN_G}]
[grid]
resolution = {CAPSTAN_RES}
[time]
dt = 1e-4
[material]
k = 1000.0
gamma = 0.0
youngs_modulus = 0.0
friction = 0.0
bending = 0.0
plasticity = false
[walls]
mode = "none"
[[obstacles]]
center = [{cx}, {cy}]
radius = {r}
friction = {mu}
[[yarns]]
points = [{points}]
vertices = {vertices}
"#
    ))
}

/// Time the capstan runs load before the slip is measured: the yarn starts
/// unstretched at rest, and until the tension wave has loaded it (a few
/// 0.01 s) the friction that needs that tension is missing and it slips
/// by up to about 1e-3 m even far above the threshold.
const CAPSTAN_LOAD: f64 = 0.2;

/// Runs the capstan scene for `CAPSTAN_LOAD` and then up to 1 s more;
/// returns whether it slid in that second (a free end moved vertically by
/// more than 0.5 % of its hanging length; the lateral pendulum swing of the
/// hanging strands that the loading excites is not a slip) and the largest
/// relative vertical end displacement. Stops as soon as it slid.
fn capstan_slides(r: f64, l1: f64, l2: f64, mu: f64) -> (bool, f64) {
    let s = capstan_scene(r, l1, l2, mu);
    let mut sim = YarnSim::new(&s).unwrap();
    let half_dx = 0.5 * s.dx();
    let c = Vec2::from(s.obstacles[0].center);
    sim.advance(CAPSTAN_LOAD).unwrap();
    let (a0, b0) = sim.yarn_endpoints(0);
    let steps = (1.0 / sim.dt()).round() as u64;
    let mut worst: f64 = 0.0;
    for k in 0..steps {
        sim.step().unwrap();
        if k % 50 == 49 || k + 1 == steps {
            let (a, b) = sim.yarn_endpoints(0);
            let rel = ((a.y - a0.y).abs() / l1).max((b.y - b0.y).abs() / l2);
            worst = worst.max(rel);
            // non-penetration: no particle deeper than dx / 2 in the circle
            let p = sim.particles();
            for x in p.vert.x.iter().chain(&p.quad.x) {
                let depth = r - (x - c).norm();
                assert!(depth <= half_dx, "particle {x} is {depth} m inside");
            }
            if rel > 0.005 {
                return (true, rel);
            }
        }
    }
    (false, worst)
}

#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn heavy_rope_capstan_ode_matches_the_documented_threshold() {
    let mu = capstan_threshold(0.1, 0.1, 0.3);
    eprintln!("capstan mu*(R 0.1, l1 0.1, l2 0.3) = {mu:.5} (documented 0.2015)");
    // tolerance 5e-4: the documented value has four digits
    assert!((mu - 0.2015).abs() < 5e-4, "mu* = {mu}");
    // weightless limit (R << l): ln(l2 / l1) / pi
    let mu0 = capstan_threshold(1e-4, 0.1, 0.3);
    assert!(
        (mu0 - 3f64.ln() / std::f64::consts::PI).abs() < 1e-3,
        "{mu0}"
    );
}

#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn capstan_yarn_slides_below_and_holds_above_the_heavy_rope_threshold() {
    let l1 = 0.1;
    let mut failures = Vec::new();
    for &r in &[0.1, 0.05] {
        for &ratio in &[2.0, 3.0, 5.0] {
            let l2 = ratio * l1;
            let mu_star = capstan_threshold(r, l1, l2);
            let (slid_low, m_low) = capstan_slides(r, l1, l2, 0.7 * mu_star);
            let (slid_high, m_high) = capstan_slides(r, l1, l2, 1.4 * mu_star);
            // bisection on mu between 0.7 and 1.4 mu* (3 steps: bracket 0.0875 mu*)
            let (mut lo, mut hi) = (0.7 * mu_star, 1.4 * mu_star);
            for _ in 0..3 {
                let mid = 0.5 * (lo + hi);
                if capstan_slides(r, l1, l2, mid).0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let mu_meas = 0.5 * (lo + hi);
            let err = (mu_meas - mu_star) / mu_star;
            eprintln!(
                "capstan R {r} l1 {l1} l2 {l2:.2}: mu* {mu_star:.4}, 0.7 mu* slid {slid_low} (moved {m_low:.2e}), \
                 1.4 mu* slid {slid_high} (moved {m_high:.2e}), measured threshold {mu_meas:.4} in [{lo:.4}, {hi:.4}], error {:+.1} %",
                100.0 * err
            );
            // must slide at 0.7 mu*, hold at 1.4 mu* (< 0.5 % of the hanging
            // length in 1 s), threshold within 15 % of mu*
            if !slid_low || slid_high || err.abs() > 0.15 {
                failures.push(format!("R {r} l2/l1 {ratio}: err {err:+.3}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}
