//! One yarn without the grid (`[time] integrator = "implicit-vertices"`,
//! backward Euler, and `"midpoint-vertices"`, the generalized midpoint rule
//! at theta 0.55): the hanging chain, the cantilever and the capstan
//! oracles, free fall against each scheme's recurrence, momentum, thread
//! bits, and the scope the scene validation holds.

mod common;

use common::{capstan_threshold, momentum_scale, on_threads, straight, SceneBuilder};
use yarnsim::math::Vec2;
use yarnsim::mpm::driver::THETA;
use yarnsim::scene::{Integrator, SceneError, StepSize, YarnScene};
use yarnsim::testing::{
    cantilever_setup, cantilever_toml, capstan_preset_scene, capstan_toml, hanging_chain_period,
    hanging_chain_toml, two_periods_about_mean, ZeroCrossings, CAPSTAN_PURE_STRING,
};
use yarnsim::YarnSim;

fn with(mut s: YarnScene, integ: Integrator, dt: f64) -> YarnScene {
    s.time.integrator = integ;
    s.time.dt = StepSize::Fixed(dt);
    s
}

/// The hanging chain (k = 2e5, nearly inextensible) over 3.4 s: the
/// period's relative error against the continuum's first mode.
fn chain_error(vertices: u32, integ: Integrator, dt: f64) -> f64 {
    let mut s = YarnScene::from_toml_str(&hanging_chain_toml(vertices, 16, "1e-3")).unwrap();
    s.material.k = 2e5;
    let mut sim = YarnSim::new(&with(s, integ, dt)).unwrap();
    let mut crossings = ZeroCrossings::new(sim.yarn_endpoints(0).1.x - 0.5);
    while sim.time() < 3.4 {
        let before = sim.time();
        sim.step().unwrap();
        let h = sim.time() - before;
        crossings.push(sim.time(), h, sim.yarn_endpoints(0).1.x - 0.5);
    }
    assert!(
        crossings.times.len() >= 5,
        "{} crossings",
        crossings.times.len()
    );
    let oracle = hanging_chain_period();
    (crossings.period() - oracle) / oracle
}

/// Measured 2026-12-04: midpoint at dt 1e-2 +0.081 / +0.046 / +0.038 %
/// for 25 / 50 / 100 vertices (the limit, about +0.02 %, is the 2 cm
/// amplitude's own shift and the window, which MuJoCo's rope shows too);
/// backward Euler at 50 vertices, dt 5e-3 +0.046 %, dt 1e-2 +0.090 %
/// (its +0.059 % phase lag at omega dt = 0.042 against the midpoint
/// rule's +0.015 %). Tolerances: 0.1 / 0.06 / 0.05 %, and falling.
#[test]
fn hanging_chain_period_converges_on_the_vertices() {
    let mp: Vec<f64> = [25, 50, 100]
        .iter()
        .map(|&v| chain_error(v, Integrator::MidpointVertices, 1e-2))
        .collect();
    for (e, tol) in mp.iter().zip([1e-3, 6e-4, 5e-4]) {
        assert!(*e > 0.0 && *e < tol, "midpoint errors {mp:?}");
    }
    assert!(mp[0] > mp[1] && mp[1] > mp[2], "not converging: {mp:?}");
    let be = chain_error(50, Integrator::ImplicitVertices, 5e-3);
    assert!(be > 0.0 && be < 6e-4, "backward Euler at dt 5e-3: {be}");
    let be_large = chain_error(50, Integrator::ImplicitVertices, 1e-2);
    // backward Euler's phase lag at dt 1e-2 shows against the midpoint rule
    assert!(be_large > mp[1] + 3e-4, "{be_large} vs {}", mp[1]);
}

/// The cantilever's tip, averaged over two periods of its first mode,
/// against q L_f^4 / (8 B) (L_f the free length past the clamp's
/// midpoint): measured -0.02 % (midpoint, 25 vertices, dt 1e-3), tolerance
/// 0.5 %; backward Euler's damping biases that mean (+0.60 % at dt 1e-3),
/// tolerance 2 %.
#[test]
fn cantilever_tip_matches_euler_bernoulli() {
    let (len, b, rho, g) = cantilever_setup();
    for (integ, tol) in [
        (Integrator::MidpointVertices, 5e-3),
        (Integrator::ImplicitVertices, 2e-2),
    ] {
        let vertices = 25;
        let s = YarnScene::from_toml_str(&cantilever_toml(vertices)).unwrap();
        let mut sim = YarnSim::new(&with(s, integ, 1e-3)).unwrap();
        let free = len - 0.5 * len / (vertices - 1) as f64;
        let oracle = rho * g * free.powi(4) / (8.0 * b);
        let omega1 = 1.8751f64.powi(2) * (b / (rho * free.powi(4))).sqrt();
        let steps = (2.5 * 2.0 * std::f64::consts::PI / omega1 / 1e-3).round() as usize;
        let y0 = sim.yarn_endpoints(0).1.y;
        let mut d = Vec::with_capacity(steps);
        for _ in 0..steps {
            sim.step().unwrap();
            d.push(y0 - sim.yarn_endpoints(0).1.y);
        }
        let (a, e) = two_periods_about_mean(&d).expect("two periods");
        let tip = d[a..e].iter().sum::<f64>() / (e - a) as f64;
        let err = (tip - oracle) / oracle;
        assert!(
            err.abs() < tol,
            "{integ:?}: tip {tip} vs {oracle} ({err:+e})"
        );
    }
}

/// Whether a capstan yarn hanging `l1` and `l2` slides: after `load` s,
/// a free end moves by more than 0.5 % of its hanging length before `load
/// + hold` s (dt 1e-2).
fn slides(s: YarnScene, integ: Integrator, (l1, l2): (f64, f64), load: f64, hold: f64) -> bool {
    let mut sim = YarnSim::new(&with(s, integ, 1e-2)).unwrap();
    sim.advance(load).unwrap();
    let (a0, b0) = sim.yarn_endpoints(0);
    while sim.time() < load + hold - 1e-9 {
        sim.step().unwrap_or_else(|e| panic!("{integ:?}: {e}"));
        let (a, b) = sim.yarn_endpoints(0);
        if ((a.y - a0.y).abs() / l1).max((b.y - b0.y).abs() / l2) > 5e-3 {
            return true;
        }
    }
    false
}

/// Whether the capstan yarn (r 0.1, hanging 0.1 and 0.3) slides at
/// friction `f mu*` within 1 s after 0.2 s of loading.
fn capstan_slides(integ: Integrator, f: f64) -> bool {
    let (r, l1, l2) = (0.1, 0.1, 0.3);
    // mu*: the heavy rope's threshold (its weight on the arc included)
    let mu = f * capstan_threshold(r, l1, l2);
    let s = YarnScene::from_toml_str(&capstan_toml(r, l1, l2, mu, &CAPSTAN_PURE_STRING)).unwrap();
    slides(s, integ, (l1, l2), 0.2, 1.0)
}

/// The heavy-rope capstan: the yarn slides at 0.9 mu* and holds at 1.1
/// mu* at dt 1e-2 (measured: slides at 0.97, holds at 1.03 under backward
/// Euler); tolerance 10 % of mu*.
#[test]
fn capstan_threshold_within_ten_percent() {
    for integ in [Integrator::ImplicitVertices, Integrator::MidpointVertices] {
        assert!(capstan_slides(integ, 0.9), "{integ:?} holds at 0.9 mu*");
        assert!(!capstan_slides(integ, 1.1), "{integ:?} slides at 1.1 mu*");
    }
}

/// A real yarn over the capstan, far from the origin: the nylon
/// monofilament preset (EA 177 N, 80.6 tex: an axial wave of 1.5 km/s)
/// over the capstan ten times longer (a 1 m drum 7.5 m up; its threshold
/// is the heavy rope's, the bending's share 1/500), loaded sqrt(10) x 0.2
/// s, then held sqrt(10) x 1 s at dt 1e-2: slid if a free end moved more
/// than 0.5 % of its hanging length.
fn nylon_capstan_slides(integ: Integrator, f: f64) -> bool {
    let scale: f64 = 10.0;
    let mu = f * capstan_threshold(0.1, 0.1, 0.3);
    let (s, l1, l2) = capstan_preset_scene("nylon66-mono-0.30mm", scale, mu, &CAPSTAN_PURE_STRING);
    slides(s, integ, (l1, l2), 0.2 * scale.sqrt(), scale.sqrt())
}

/// The capstan oracle with a real yarn metres from the origin: slides at
/// 0.9 mu*, holds at 1.1 and at 3 mu* under both schemes (tolerance 10 %
/// of mu*, as above). Before the step energy formed its segment vectors
/// from the start's (`Rod::edges`), the midpoint rule's line search found
/// no decrease at 2 and 3 mu*: rounding the end positions 7 m from the
/// origin outweighed the Newton step's predicted decrease on this stiff,
/// light yarn.
#[test]
fn capstan_threshold_with_a_real_yarn_far_from_the_origin() {
    for integ in [Integrator::ImplicitVertices, Integrator::MidpointVertices] {
        assert!(
            nylon_capstan_slides(integ, 0.9),
            "{integ:?} holds at 0.9 mu*"
        );
        for f in [1.1, 3.0] {
            assert!(
                !nylon_capstan_slides(integ, f),
                "{integ:?} slides at {f} mu*"
            );
        }
    }
}

fn free_yarn(bending: f64) -> YarnScene {
    SceneBuilder::bare()
        .material(|m| {
            m.gamma = 0.0;
            m.youngs_modulus = 0.0;
            m.bending = bending;
        })
        .yarn(straight([0.3, 0.6], [0.7, 0.62], 30))
        .build()
}

/// Free fall: with no internal force the schemes' recurrences, to 1e-12
/// m: backward Euler `x_n = x_0 - g h^2 n (n + 1) / 2`, the midpoint rule
/// `x_n = x_0 - g h^2 n (n - 1) / 2 - theta g h^2 n` (the velocity exact,
/// `v_n = -g n h`, in both).
#[test]
fn free_fall_follows_each_recurrence() {
    for integ in [Integrator::ImplicitVertices, Integrator::MidpointVertices] {
        let mut s = with(free_yarn(0.0), integ, 1e-3);
        s.gravity = [0.0, -9.81];
        let mut sim = YarnSim::new(&s).unwrap();
        let y0: Vec<f64> = sim.particles().vert.x.iter().map(|x| x.y).collect();
        let n = 200;
        for _ in 0..n {
            sim.step().unwrap();
        }
        let (h, g, nf) = (1e-3, 9.81, n as f64);
        let drop = match integ {
            Integrator::ImplicitVertices => g * h * h * nf * (nf + 1.0) / 2.0,
            _ => g * h * h * nf * (nf - 1.0) / 2.0 + THETA * g * h * h * nf,
        };
        for (x, y0) in sim.particles().vert.x.iter().zip(&y0) {
            assert!(
                (y0 - drop - x.y).abs() < 1e-12,
                "{integ:?}: {} vs {}",
                x.y,
                y0 - drop
            );
        }
        for v in &sim.particles().vert.v {
            assert!((v.y + g * nf * h).abs() < 1e-12 && v.x.abs() < 1e-12);
        }
    }
}

/// Without gravity and pins the internal forces sum to zero: the linear
/// momentum of a spinning, bending yarn is kept to round-off (1e-12 of
/// its scale), and the run's bits do not depend on the thread count.
#[test]
fn momentum_is_kept_and_threads_do_not_change_bits() {
    for integ in [Integrator::ImplicitVertices, Integrator::MidpointVertices] {
        let run = |threads: usize| {
            on_threads(threads, || {
                let mut sim = YarnSim::new(&with(free_yarn(1e-3), integ, 2e-3)).unwrap();
                {
                    let p = yarnsim::testing::particles_mut(&mut sim);
                    for (i, (x, v)) in p.vert.x.iter().zip(p.vert.v.iter_mut()).enumerate() {
                        let r = x - Vec2::new(0.5, 0.61);
                        *v = Vec2::new(-r.y, r.x) * 3.0
                            + Vec2::new(0.2, (i as f64 * 0.7).sin() * 0.3);
                    }
                    // the quadrature particles move with their vertices
                    for q in 0..p.quad.v.len() {
                        let l = p.quad.left[q] as usize;
                        p.quad.v[q] = (p.vert.v[l] + p.vert.v[l + 1]) * 0.5;
                    }
                }
                let momentum = |sim: &YarnSim| {
                    let p = sim.particles();
                    let sum = |m: &[f64], v: &[Vec2]| {
                        m.iter().zip(v).fold(Vec2::zeros(), |a, (m, v)| a + v * *m)
                    };
                    sum(&p.vert.m, &p.vert.v) + sum(&p.quad.m, &p.quad.v)
                };
                let (p0, scale) = (momentum(&sim), momentum_scale(&sim));
                for _ in 0..150 {
                    sim.step().unwrap();
                }
                let p1 = momentum(&sim);
                assert!(
                    (p1 - p0).norm() < 1e-12 * scale,
                    "{integ:?}: {p0:?} -> {p1:?}"
                );
                sim.particles().vert.x.clone()
            })
        };
        assert_eq!(run(1), run(2), "{integ:?}");
    }
}

fn refusal(s: &YarnScene) -> String {
    match YarnSim::new(s) {
        Err(SceneError::Invalid { field, .. }) => field,
        other => panic!("expected a refusal, got {:?}", other.map(|_| ())),
    }
}

/// The scope: one yarn, no shear or cross-section stiffness, no walls;
/// each refusal names its field.
#[test]
fn scenes_outside_the_scope_are_refused_naming_the_field() {
    let base = with(free_yarn(0.0), Integrator::ImplicitVertices, 1e-3);
    YarnSim::new(&base).expect("in scope");
    let mut two = base.clone();
    two.yarns.push(straight([0.3, 0.3], [0.7, 0.3], 10));
    assert_eq!(refusal(&two), "yarns");
    let mut g = base.clone();
    g.material.gamma = 500.0;
    assert_eq!(refusal(&g), "material.gamma");
    let mut e = base.clone();
    e.material.youngs_modulus = 1000.0;
    assert_eq!(refusal(&e), "material.youngs_modulus");
    let mut w = base.clone();
    w.walls.mode = yarnsim::scene::WallMode::Slip;
    assert_eq!(refusal(&w), "walls.mode");
    let mut mp = base;
    mp.time.integrator = Integrator::MidpointVertices;
    mp.material.gamma = 1.0;
    assert_eq!(refusal(&mp), "material.gamma");
}

/// The capstan yarn on a frictionless circle slides: the free end's drop
/// after 0.3 s under the midpoint rule against backward Euler at dt 1e-3
/// (both first order in the contact, the same motion to the step's
/// order); a contact that lost its tangential momentum each step would
/// lag by tens of percent. Tolerance 2 %.
#[test]
fn midpoint_contacts_slide_as_backward_euler_without_friction() {
    let (r, l1, l2) = (0.1, 0.1, 0.3);
    let drop = |integ| {
        let s =
            YarnScene::from_toml_str(&capstan_toml(r, l1, l2, 0.0, &CAPSTAN_PURE_STRING)).unwrap();
        let mut sim = YarnSim::new(&with(s, integ, 1e-3)).unwrap();
        let y0 = sim.yarn_endpoints(0).1.y;
        sim.advance(0.3).unwrap();
        y0 - sim.yarn_endpoints(0).1.y
    };
    let (be, mp) = (
        drop(Integrator::ImplicitVertices),
        drop(Integrator::MidpointVertices),
    );
    eprintln!(
        "frictionless capstan, drop of the heavy end in 0.3 s: backward Euler {be}, midpoint {mp}"
    );
    assert!(be > 0.01, "no slide: {be}");
    assert!(
        (mp - be).abs() < 0.02 * be,
        "midpoint {mp} vs backward Euler {be}"
    );
}
