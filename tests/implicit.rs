//! The implicit (backward Euler) integrator, `[time] integrator =
//! "implicit"`: free fall, momentum, the hanging-chain oracle at 1x, 10x
//! and 100x the explicit substep, and what it refuses.

mod common;

use std::time::Instant;

use common::{bundle, momentum_scale, on_threads, straight, SceneBuilder};
use yarnsim::math::{perp, Vec2};
use yarnsim::scene::{Integrator, YarnScene};
use yarnsim::testing::{
    hanging_chain_floor_period, hanging_chain_period, hanging_chain_toml, ZeroCrossings,
    CHAIN_GRAVITY,
};
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
    // backward Euler with no elastic force is the same grid trajectory as
    // symplectic Euler: v_n = n dt g, x_n = x_0 + dt^2 g n (n + 1) / 2;
    // round-off over 200 substeps
    common::assert_grid_free_fall(&mut sim, Vec2::new(0.5, -9.8), dt, 200, Some(1e-9));
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
        let p = yarnsim::testing::particles_mut(&mut sim);
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

/// The chain's figures at one setting.
struct Chain {
    /// The measured period (s).
    period: f64,
    /// Against the oracle `hanging_chain_period()` (inextensible continuum).
    period_error: f64,
    /// Against the linearised discrete extensible chain with the run's own
    /// segments and `k` (`hanging_chain_floor_period`): the scheme's error
    /// without the model's stretch and segment-count bias.
    floor_error: f64,
    /// The floor against the oracle.
    floor_bias: f64,
    /// Amplitude ratio per period (1: no damping): the geometric mean of
    /// the ratios of successive half-swing peaks of the free end (higher
    /// modes add to them), squared.
    damping: f64,
    /// The free end's largest swing (m).
    max_swing: f64,
    /// The pin's mean vertical force between the first and last crossing
    /// over the chain's weight, minus 1.
    weight_error: f64,
    wall_per_sim_s: f64,
    newton: f64,
    cg: f64,
    /// Mean substep (s).
    mean_dt: f64,
}

/// Periods spanned by `CROSSINGS` zero crossings of the free end.
const PERIODS: usize = 4;
/// Zero crossings the chain runs for: four periods between the first and
/// the last (the first at a quarter period: 6.3 s simulated).
const CROSSINGS: usize = 2 * PERIODS + 1;

/// Runs the hanging chain (`hanging_chain_toml(vertices, grid, dt)`) for
/// `crossings_wanted` zero crossings of the free end with the integrator
/// and `dt` (a TOML value).
fn chain(vertices: u32, grid: u32, integrator: &str, dt: &str, crossings_wanted: usize) -> Chain {
    let text = hanging_chain_toml(vertices, grid, dt).replace(
        &format!("dt = {dt}\n"),
        &format!("dt = {dt}\nintegrator = \"{integrator}\"\n"),
    );
    let s = YarnScene::from_toml_str(&text).unwrap();
    assert_eq!(s.time.integrator.is_explicit(), integrator == "explicit");
    let mut sim = YarnSim::new(&s).unwrap();
    let period = hanging_chain_period();
    let floor = hanging_chain_floor_period(vertices as usize - 1, s.material.k, s.material.density);
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
            sim.time() < (crossings_wanted / 2 + 2) as f64 * period,
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
    let measured = crossings.period();
    let dts = sim.dt_stats();
    Chain {
        period: measured,
        period_error: (measured - period) / period,
        floor_error: (measured - floor) / floor,
        floor_bias: (floor - period) / period,
        damping,
        max_swing: peaks.iter().cloned().fold(0.0, f64::max),
        weight_error: impulse / span / weight - 1.0,
        wall_per_sim_s: wall / sim.time(),
        newton: per(st.newton),
        cg: per(st.cg),
        mean_dt: dts.sum / dts.substeps as f64,
    }
}

/// Backward Euler's amplitude ratio per period for an undamped mode of
/// period `T` (the oracle's): `|1 / (1 + i omega dt)|` per substep, over
/// `T / dt` substeps: `(1 + (omega dt)^2)^(-T / (2 dt))`, about
/// `exp(-pi omega dt)`.
fn backward_euler_damping(dt: f64) -> f64 {
    let t = hanging_chain_period();
    let w = 2.0 * std::f64::consts::PI / t;
    (1.0 + (w * dt).powi(2)).powf(-t / (2.0 * dt))
}

/// Backward Euler's period lengthening `atan(omega dt) / (omega dt) - 1`
/// inverted: the period of a mode of period `T` over `T` minus 1, about
/// `(omega dt)^2 / 3`.
fn backward_euler_period_error(dt: f64) -> f64 {
    let x = 2.0 * std::f64::consts::PI / hanging_chain_period() * dt;
    x / x.atan() - 1.0
}

fn report(what: &str, c: &Chain) {
    eprintln!(
        "{what}: period {:.5} s, error {:+.3} % (oracle), {:+.3} % (extensible floor, itself \
         {:+.3} %), amplitude ratio per period {:.4}, mean dt {:.3e} s, {:.2} Newton and {:.1} CG \
         per substep, wall {:.3} s per simulated s, pin force {:+.2} % off the weight",
        c.period,
        100.0 * c.period_error,
        100.0 * c.floor_error,
        100.0 * c.floor_bias,
        c.damping,
        c.mean_dt,
        c.newton,
        c.cg,
        c.wall_per_sim_s,
        100.0 * c.weight_error
    );
}

/// The period error within `tol`, or without one at least measured
/// (finite); `what` leads the messages.
fn assert_period_error(period_error: f64, tol: Option<f64>, what: &str) {
    if let Some(tol) = tol {
        assert!(
            period_error.abs() < tol,
            "{what}period error {period_error:+.4}"
        );
    } else {
        assert!(period_error.is_finite(), "{what}no period");
    }
}

/// The hanging chain (100 vertices, 64^2) under backward Euler at the
/// explicit step's 1e-4 s, 10x and 100x it, over four periods: period
/// within 3 % of the oracle at 1e-4 and 1e-3 (the explicit tolerance),
/// stable at 1e-2 with its error and damping printed; wall time per
/// simulated second against the explicit step.
#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn hanging_chain_under_backward_euler_at_1x_10x_100x_the_explicit_step() {
    let ex = chain(100, 64, "explicit", "1e-4", CROSSINGS);
    report("explicit dt 1e-4", &ex);
    for (dt, tol) in [("1e-4", Some(0.03)), ("1e-3", Some(0.03)), ("1e-2", None)] {
        let c = chain(100, 64, "implicit", dt, CROSSINGS);
        report(&format!("implicit dt {dt}"), &c);
        eprintln!(
            "  ({:.2}x the explicit 1e-4 wall time)",
            c.wall_per_sim_s / ex.wall_per_sim_s
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
        // backward Euler damps the first mode by (1 + (omega dt)^2)^(-T / 2 dt)
        // per period; at 1e-4 (prediction 0.9987) the higher modes in the
        // free end's peaks are larger than that, so only 1e-3 and 1e-2
        let be = backward_euler_damping(dt.parse().unwrap());
        eprintln!("  backward Euler's amplitude ratio per period {be:.4}");
        if dt != "1e-4" {
            assert!(
                (c.damping - be).abs() < DAMPING_TOL,
                "dt {dt}: amplitude ratio {} against {be}",
                c.damping
            );
        }
        assert_period_error(c.period_error, tol, &format!("dt {dt}: "));
    }
}

/// The implicit chain at dt 1e-3 at 25 / 50 / 100 vertices (16^2 / 32^2 /
/// 64^2, the peers benchmark's ladder) over four periods, against the
/// linearised discrete extensible chain with the same segments and `k`
/// (`hanging_chain_floor_period`): what is left is the scheme's error (the
/// grid transfer and backward Euler), FLOOR_TOL at most; the amplitude
/// ratio per period is backward Euler's damping of the first mode
/// ([`backward_euler_damping`], within [`DAMPING_TOL`]).
#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn implicit_chain_period_against_the_extensible_floor_at_three_resolutions() {
    let mut last = f64::INFINITY;
    // tolerances: about 1.5x to 2x the measured +0.28 / +0.09 / +0.04 %
    for (vertices, grid, tol) in [(25, 16, 5e-3), (50, 32, 2e-3), (100, 64, 1e-3)] {
        let c = chain(vertices, grid, "implicit", "1e-3", CROSSINGS);
        report(
            &format!("implicit dt 1e-3, {vertices} vertices, {grid}^2"),
            &c,
        );
        assert!(
            c.floor_error.abs() < tol,
            "{vertices} vertices: period {:+.4} off the extensible floor",
            c.floor_error
        );
        let be = backward_euler_damping(1e-3);
        assert!(
            (c.damping - be).abs() < DAMPING_TOL,
            "{vertices} vertices: amplitude ratio {} against backward Euler's {be}",
            c.damping
        );
        // the scheme's error falls with the resolution
        assert!(c.floor_error.abs() < last, "{vertices} vertices");
        last = c.floor_error.abs();
    }
}

/// Absolute tolerance of the free end's amplitude ratio per period against
/// backward Euler's damping of the first mode (the peaks carry the higher
/// modes too; measured within 0.002 at dt 1e-3 and 1e-2).
const DAMPING_TOL: f64 = 0.005;

/// `dt = "auto"` under the implicit integrator: the advection limit
/// capped by `dt_max` instead of the elastic-wave bound. With `dt_max =
/// 1e-2` the steps are far larger than the explicit auto step and the
/// period stays within 0.25 % of the oracle over four periods (the model's
/// extensible floor +0.11 %, the grid about +0.04 %, backward Euler
/// `(omega dt)^2 / 3` +0.06 %); with the default cap (the frame time
/// 1/60 s) backward Euler's period error and damping are the predicted ones.
#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn implicit_chain_under_dt_auto_steps_far_above_the_explicit_auto_step() {
    let auto = "\"auto\"";
    let ex = chain(100, 64, "explicit", auto, 3);
    report("explicit dt auto (one period)", &ex);
    // the advection limit (0.8 dx / |v|max, about 0.15 s here) is far
    // above both caps, so every step is the cap
    for (cap, dt_max, tol) in [("1e-2", 1e-2, Some(0.0025)), ("", 1.0 / 60.0, None)] {
        let dt = if cap.is_empty() {
            auto.to_string()
        } else {
            format!("{auto}\ndt_max = {cap}")
        };
        let im = chain(100, 64, "implicit", &dt, CROSSINGS);
        let ratio = im.mean_dt / ex.mean_dt;
        report(&format!("implicit dt auto, dt_max {dt_max:.4}"), &im);
        let be = backward_euler_period_error(dt_max);
        eprintln!(
            "  mean step {ratio:.1}x the explicit auto step; backward Euler's period error \
             {:+.3} %, damping {:.4}",
            100.0 * be,
            backward_euler_damping(dt_max)
        );
        assert!(
            (im.mean_dt - dt_max).abs() < 1e-9 * dt_max,
            "mean step {}",
            im.mean_dt
        );
        assert!(ratio > 30.0, "implicit step only {ratio:.1}x the explicit");
        assert!(
            (im.damping - backward_euler_damping(dt_max)).abs() < DAMPING_TOL,
            "amplitude ratio {}",
            im.damping
        );
        // period against the floor plus backward Euler's lengthening: the
        // 100-vertex grid error (+0.04 % at dt 1e-3) within 0.1 %
        let predicted = (1.0 + im.floor_bias) * (1.0 + be) - 1.0;
        assert!(
            (im.period_error - predicted).abs() < 1e-3,
            "period error {:+.4} against {predicted:+.4}",
            im.period_error
        );
        assert_period_error(im.period_error, tol, "");
    }
}

/// The implicit step runs every yarn scene: the chain with each feature
/// switched on loads, also with a free yarn beside the pinned one (two
/// velocity fields), from TOML and built in code.
#[test]
fn implicit_integrator_takes_every_scene_feature() {
    let base = hanging_chain_toml(20, 32, "1e-3")
        .replace("dt = 1e-3\n", "dt = 1e-3\nintegrator = \"implicit\"\n");
    YarnScene::from_toml_str(&base).expect("the chain is in scope");
    let with = |extra: &str| YarnScene::from_toml_str(&format!("{base}{extra}"));
    // the whole yarn energy, walls, moving pins, dt "auto" and the
    // attractor load
    for (from, to) in [
        ("dt = 1e-3\n", "dt = \"auto\"\n"),
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
    let two =
        with("[[yarns]]\npoints = [[0.2, 0.2], [0.3, 0.2]]\nvertices = 5\n").expect("two fields");
    let mut sim = YarnSim::new(&two).unwrap();
    assert!(sim.has_two_fields());
    sim.steps_n(3).unwrap();
    // also when the scene is built in code
    let mut s = YarnScene::from_toml_str(&base).unwrap();
    let mut free = s.yarns[0].clone();
    free.points = Some(vec![[0.2, 0.2], [0.3, 0.2]]);
    s.yarns.push(free);
    let mut sim = YarnSim::new(&s).unwrap();
    assert!(sim.has_two_fields());
    sim.steps_n(3).unwrap();
}
