//! The implicit (backward Euler) integrator, `[time] integrator =
//! "implicit"`: free fall, momentum, the hanging-chain oracle at 1x, 10x
//! and 100x the explicit substep, and what it refuses.

mod common;

use std::time::Instant;

use common::{bundle, momentum_scale, on_threads, straight, SceneBuilder};
use yarnsim::math::{perp, Vec2};
use yarnsim::scene::{Integrator, YarnScene};
use yarnsim::testing::{hanging_chain_period, hanging_chain_toml, ZeroCrossings, CHAIN_GRAVITY};
use yarnsim::YarnSim;

/// A bare scene of pure fibre stretch (the hanging chain's material).
fn stretch_only() -> SceneBuilder {
    SceneBuilder::bare().material(|m| {
        m.gamma = 0.0;
        m.youngs_modulus = 0.0;
        m.bending = 0.0;
        m.plasticity = false;
    })
}

fn implicit(mut s: YarnScene, dt: f64) -> YarnScene {
    s.time.integrator = Integrator::Implicit;
    s.time.dt = yarnsim::scene::StepSize::Fixed(dt);
    s
}

#[test]
fn free_fall_is_exact() {
    let s = stretch_only()
        .gravity([0.5, -9.8])
        .yarn(straight([0.2, 0.7], [0.7, 0.85], 60))
        .build();
    let dt = 1e-3;
    let mut sim = YarnSim::new(&implicit(s, dt)).unwrap();
    let g = Vec2::new(0.5, -9.8);
    let c0 = sim.diagnostics().center_of_mass;
    let n = 200u64;
    sim.steps_n(n).unwrap();
    // backward Euler with no elastic force is the same grid trajectory as
    // symplectic Euler: v_n = n dt g, x_n = x_0 + dt^2 g n (n + 1) / 2
    let (expected, v) = common::grid_free_fall(c0, g, dt, n);
    let err = (sim.diagnostics().center_of_mass - expected).norm();
    // tolerance 1e-12 m (round-off over 200 substeps)
    assert!(err < 1e-12, "centre of mass off by {err:.3e} m");
    let d = sim.diagnostics();
    assert!((d.momentum / d.total_mass - v).norm() < 1e-11);
    for st in sim.stretches() {
        assert!((st - 1.0).abs() < 1e-9, "stretch {st}");
    }
}

#[test]
fn linear_momentum_is_kept_to_round_off() {
    let s = stretch_only()
        .yarn(bundle([0.3, 0.5], [0.7, 0.52], 80, 3, [0.0, 0.012]))
        .yarn(straight([0.48, 0.3], [0.52, 0.7], 80))
        .build();
    let mut sim = YarnSim::new(&implicit(s, 1e-3)).unwrap();
    // spin about the centre of mass and drift; rows of vertices at
    // different speeds stretch the segments, so the solve has work to do
    let c = sim.diagnostics().center_of_mass;
    {
        let p = sim.particles_mut();
        for (x, v) in p.vert.x.iter().zip(p.vert.v.iter_mut()) {
            *v = perp(x - c) * 4.0 + Vec2::new(0.3, -0.2) + Vec2::new(0.0, 2.0 * (x.x - c.x));
        }
    }
    let d0 = sim.diagnostics();
    let scale = momentum_scale(&sim);
    sim.steps_n(300).unwrap();
    let d1 = sim.diagnostics();
    let dp = (d1.momentum - d0.momentum).norm() / scale;
    let st = sim.implicit_stats();
    eprintln!(
        "implicit momentum: relative drift {dp:.2e} after 300 substeps of 1e-3 s, \
         {:.2} Newton / {:.1} CG iterations per substep",
        st.newton as f64 / st.substeps as f64,
        st.cg as f64 / st.substeps as f64
    );
    assert!(st.newton > 0, "the solve never iterated");
    // tolerance 1e-12 relative (round-off)
    assert!(dp < 1e-12, "linear momentum drift {dp:.3e}");
}

/// The pinned chain at 10x the explicit step, with 1 and with 2 threads:
/// bit-identical states (the solve is serial, in a fixed order).
#[test]
fn bit_identical_for_one_and_two_threads() {
    let text = hanging_chain_toml(50, 32, "1e-3")
        .replace("dt = 1e-3\n", "dt = 1e-3\nintegrator = \"implicit\"\n");
    let s = YarnScene::from_toml_str(&text).unwrap();
    let run = |threads: usize| {
        on_threads(threads, || {
            let mut sim = YarnSim::new(&s).unwrap();
            sim.steps_n(50).unwrap();
            (
                sim.save_state(),
                sim.implicit_stats(),
                sim.pin_reactions().to_vec(),
            )
        })
    };
    let (a, sa, ra) = run(1);
    let (b, sb, rb) = run(2);
    assert_eq!(sa, sb);
    assert_eq!(ra, rb);
    assert!(sa.newton >= 50, "{sa:?}");
    assert!(a == b, "states differ");
}

/// The chain's figures at one substep.
struct Chain {
    period_error: f64,
    /// Amplitude ratio per period (1: no damping), from the free end's
    /// half-swing peaks (higher modes add to them).
    damping: f64,
    /// The free end's largest swing (m).
    max_swing: f64,
    /// The pin's mean vertical force between the first and last crossing
    /// over the chain's weight, minus 1.
    weight_error: f64,
    wall_per_sim_s: f64,
    newton: f64,
    cg: f64,
}

/// Runs the hanging chain (100 vertices, 64^2, `hanging_chain_toml`) for
/// 5 zero crossings of the free end (2 periods) with the integrator and `dt`.
fn chain(integrator: &str, dt: &str, crossings_wanted: usize) -> Chain {
    let text = hanging_chain_toml(100, 64, dt).replace(
        &format!("dt = {dt}\n"),
        &format!("dt = {dt}\nintegrator = \"{integrator}\"\n"),
    );
    let s = YarnScene::from_toml_str(&text).unwrap();
    assert_eq!(s.time.integrator.is_explicit(), integrator == "explicit");
    let mut sim = YarnSim::new(&s).unwrap();
    let period = hanging_chain_period();
    let mut crossings = ZeroCrossings::new(sim.yarn_endpoints(0).1.x - 0.5);
    // the largest |u| of each half swing
    let mut peaks = vec![0.0f64];
    let weight = sim.diagnostics().total_mass * CHAIN_GRAVITY;
    let (mut impulse, mut span) = (0.0, 0.0);
    let t0 = Instant::now();
    while crossings.times.len() < crossings_wanted {
        let before = sim.time();
        sim.step()
            .unwrap_or_else(|e| panic!("{integrator} dt {dt}: {e}"));
        let h = sim.time() - before;
        let u = sim.yarn_endpoints(0).1.x - 0.5;
        if !crossings.times.is_empty() {
            impulse += sim.pin_reactions()[0].y * h;
            span += h;
        }
        if crossings.push(sim.time(), h, u) {
            peaks.push(0.0);
        }
        let last = peaks.last_mut().unwrap();
        *last = last.max(u.abs());
        assert!(
            sim.time() < 5.0 * period,
            "{integrator} dt {dt}: no {crossings_wanted} zero crossings"
        );
    }
    let wall = t0.elapsed().as_secs_f64();
    // full half swings are peaks[1..]; per period = two half swings
    let full = &peaks[1..peaks.len() - 1];
    let damping = if full.len() >= 3 {
        (full[full.len() - 1] / full[0]).powf(2.0 / (full.len() - 1) as f64)
    } else {
        f64::NAN
    };
    let st = sim.implicit_stats();
    let per = |x: u64| x as f64 / st.substeps.max(1) as f64;
    Chain {
        period_error: (crossings.period() - period) / period,
        damping,
        max_swing: peaks.iter().cloned().fold(0.0, f64::max),
        weight_error: impulse / span / weight - 1.0,
        wall_per_sim_s: wall / sim.time(),
        newton: per(st.newton),
        cg: per(st.cg),
    }
}

/// The hanging chain under backward Euler at the explicit step's 1e-4 s,
/// 10x and 100x it: period within 3 % of the oracle at 1e-4 and 1e-3
/// (the explicit tolerance), stable at 1e-2 with its error and damping
/// printed; wall time per simulated second against the explicit step.
#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn hanging_chain_under_backward_euler_at_1x_10x_100x_the_explicit_step() {
    let ex = chain("explicit", "1e-4", 5);
    eprintln!(
        "explicit dt 1e-4: period error {:+.2} %, amplitude ratio per period {:.4}, \
         wall {:.3} s per simulated s",
        100.0 * ex.period_error,
        ex.damping,
        ex.wall_per_sim_s
    );
    for (dt, tol) in [("1e-4", Some(0.03)), ("1e-3", Some(0.03)), ("1e-2", None)] {
        let c = chain("implicit", dt, 5);
        eprintln!(
            "implicit dt {dt}: period error {:+.2} %, amplitude ratio per period {:.4}, \
             {:.2} Newton and {:.1} CG iterations per substep, wall {:.3} s per simulated s \
             ({:.2}x the explicit 1e-4), pin force {:+.2} % off the weight",
            100.0 * c.period_error,
            c.damping,
            c.newton,
            c.cg,
            c.wall_per_sim_s,
            c.wall_per_sim_s / ex.wall_per_sim_s,
            100.0 * c.weight_error
        );
        // the pin (the solve's multiplier) carries the weight: 2 %, as the
        // explicit oracle
        assert!(
            c.weight_error.abs() < 0.02,
            "dt {dt}: pin force {:+.4}",
            c.weight_error
        );
        assert!(c.newton >= 1.0, "dt {dt}: the solve never iterated");
        // stable: the free end's swing stays within twice its start (0.02 m)
        assert!(c.max_swing < 0.04, "dt {dt}: swing {} m", c.max_swing);
        if let Some(tol) = tol {
            assert!(
                c.period_error.abs() < tol,
                "dt {dt}: period error {:+.4}",
                c.period_error
            );
        } else {
            assert!(c.period_error.is_finite(), "dt {dt}: no period");
        }
    }
}

/// Each thing outside the implicit step's scope is refused at load,
/// naming the field; the chain itself (pure fibre stretch, a fixed pin)
/// loads.
#[test]
fn implicit_scenes_outside_its_scope_are_refused_naming_the_field() {
    let base = hanging_chain_toml(20, 32, "1e-3")
        .replace("dt = 1e-3\n", "dt = 1e-3\nintegrator = \"implicit\"\n");
    YarnScene::from_toml_str(&base).expect("the chain is in scope");
    let cases = [("dt = 1e-3\n", "dt = \"auto\"\n", "time.dt")];
    for (from, to, field) in cases {
        let text = base.replace(from, to);
        assert_ne!(text, base, "{field}: the edit did not apply");
        let m = YarnScene::from_toml_str(&text)
            .expect_err(field)
            .to_string();
        assert!(m.contains(field) && m.contains("implicit"), "{field}: {m}");
    }
    let with = |extra: &str| YarnScene::from_toml_str(&format!("{base}{extra}"));
    // the whole yarn energy, walls, moving pins and the attractor load
    for (from, to) in [
        ("gamma = 0.0", "gamma = 10.0"),
        ("youngs_modulus = 0.0", "youngs_modulus = 5.0"),
        ("bending = 0.0", "bending = 1e-4"),
        ("plasticity = false", "plasticity = true"),
        ("mode = \"none\"", "mode = \"sticky\""),
        (
            "end = \"start\"\n",
            "end = \"start\"\nmotion = \"line\"\nvelocity = [0.1, 0.0]\n",
        ),
    ] {
        let text = base.replace(from, to);
        assert_ne!(text, base, "{to}: the edit did not apply");
        YarnScene::from_toml_str(&text).unwrap_or_else(|e| panic!("{to}: {e}"));
    }
    with("[[obstacles]]\ncenter = [0.2, 0.2]\nradius = 0.05\n").expect("an obstacle is in scope");
    with("[attractor]\nactive = true\n").expect("the attractor is in scope");
    // a second, free yarn beside the pinned one: two velocity fields
    let m = with("[[yarns]]\npoints = [[0.2, 0.2], [0.3, 0.2]]\nvertices = 5\n")
        .expect_err("two fields")
        .to_string();
    assert!(
        m.contains("pins") && m.contains("two velocity fields"),
        "{m}"
    );
    // also when the scene is built in code
    let mut s = YarnScene::from_toml_str(&base).unwrap();
    let mut free = s.yarns[0].clone();
    free.points = Some(vec![[0.2, 0.2], [0.3, 0.2]]);
    s.yarns.push(free);
    let m = match YarnSim::new(&s) {
        Ok(_) => panic!("an out-of-scope implicit scene must be refused"),
        Err(e) => e.to_string(),
    };
    assert!(m.contains("two velocity fields"), "{m}");
}
