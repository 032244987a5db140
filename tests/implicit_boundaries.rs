//! Boundaries under the implicit (backward Euler) integrator, release-only:
//! obstacles with Coulomb friction (the heavy-rope capstan threshold, a
//! yarn on an incline), the floor wall, free fall beside them, and a pin
//! driven on a line. The obstacle and wall laws act on the solved grid
//! velocities (`grid_update::boundaries`), the pins inside the solve.
//!
//! The material is a parameter of each scene (the pure string: gamma = E
//! = bending = 0, plasticity off; the capstan also with the built-in
//! material, with and without its bending).
//! Measured figures are printed (`--nocapture`).

mod common;

use std::time::Instant;

use common::{capstan_slip, capstan_threshold, pin_end, straight, SceneBuilder};
use yarnsim::math::Vec2;
use yarnsim::scene::{
    Integrator, Material, PinMotionKind, StepSize, TransferScheme, WallMode, YarnEnd, YarnScene,
};
use yarnsim::testing::{capstan_toml, Capstan, CAPSTAN_PURE_STRING};
use yarnsim::YarnSim;

/// The pure string: no cross-section energy, no bending, no plasticity.
fn pure_string(m: &mut Material) {
    m.gamma = 0.0;
    m.youngs_modulus = 0.0;
    m.bending = 0.0;
    m.plasticity = false;
}

fn with_integrator(mut s: YarnScene, integrator: Integrator, dt: f64) -> YarnScene {
    s.time.integrator = integrator;
    s.time.dt = StepSize::Fixed(dt);
    s.validate().unwrap_or_else(|e| panic!("{e}"));
    s
}

/// Newton and CG iterations per substep so far.
fn iterations(sim: &YarnSim) -> (f64, f64) {
    let st = sim.implicit_stats();
    let n = st.substeps.max(1) as f64;
    (st.newton as f64 / n, st.cg as f64 / n)
}

// ---- capstan ---------------------------------------------------------------

/// The capstan scene (`capstan_toml`) with the integrator and `setup.dt`;
/// runs it as the explicit oracle does ([`common::capstan_slip`]) and
/// returns whether it slid, the largest relative end displacement, the
/// deepest particle inside the circle (m) and the wall time per substep.
fn capstan_run(
    r: f64,
    l1: f64,
    l2: f64,
    mu: f64,
    setup: &Capstan,
    integrator: Integrator,
) -> (bool, f64, f64, f64, (f64, f64)) {
    let s = YarnScene::from_toml_str(&capstan_toml(r, l1, l2, mu, setup)).unwrap();
    let s = with_integrator(s, integrator, setup.dt);
    let mut sim = YarnSim::new(&s).unwrap();
    let c = Vec2::from(s.obstacles[0].center);
    let t0 = Instant::now();
    let mut depth: f64 = 0.0;
    let (slid, worst) = capstan_slip(&mut sim, l1, l2, |sim| {
        let p = sim.particles();
        for x in p.vert.x.iter().chain(&p.quad.x) {
            depth = depth.max(r - (x - c).norm());
        }
    });
    let per_step = t0.elapsed().as_secs_f64() / sim.steps() as f64;
    (slid, worst, depth, per_step, iterations(&sim))
}

/// The heavy-rope capstan (R 0.1, l1 0.1, l2 0.3, mu* = 0.2015) under
/// backward Euler at 10x the explicit oracle's dt: slides at 0.85 mu* and
/// holds at 1.15 mu* (so the threshold is within 15 % of mu*), no particle
/// deeper than one cell inside the circle (the solve does not see the
/// obstacle: its law acts after the solve, first order in dt).
fn capstan_holds_within_15_percent(setup: &Capstan) {
    let (r, l1, l2) = (0.1, 0.1, 0.3);
    let mu_star = capstan_threshold(r, l1, l2);
    let dx = 1.0 / setup.res as f64;
    let runs: Vec<_> = std::thread::scope(|sc| {
        let h: Vec<_> = [0.85, 1.15]
            .map(|f| {
                sc.spawn(move || capstan_run(r, l1, l2, f * mu_star, setup, Integrator::Implicit))
            })
            .into_iter()
            .collect();
        h.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for (f, (slid, moved, depth, per_step, (newton, cg))) in [0.85, 1.15].iter().zip(&runs) {
        eprintln!(
            "implicit capstan {}^2 dt {:.0e}: {f} mu* ({:.4}) slid {slid} (moved {moved:.2e}), \
             deepest particle {:.3} dx inside, {newton:.2} Newton / {cg:.1} CG per substep, \
             {:.2} ms per substep",
            setup.res,
            setup.dt,
            f * mu_star,
            depth / dx,
            1e3 * per_step
        );
    }
    assert!(runs[0].0, "0.85 mu*: held (moved {:.2e})", runs[0].1);
    assert!(!runs[1].0, "1.15 mu*: slid (moved {:.2e})", runs[1].1);
    for run in &runs {
        // tolerance: one cell (the explicit oracle allows dx / 2 at dt 1e-4)
        assert!(run.2 <= dx, "a particle is {:.3} dx inside", run.2 / dx);
    }
}

#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn capstan_threshold_under_backward_euler_at_10x_the_explicit_dt() {
    capstan_holds_within_15_percent(&Capstan {
        dt: 1e-3,
        ..CAPSTAN_PURE_STRING
    });
}

/// The built-in material (k 1000, gamma 500, E 1000, fibre friction 0.05,
/// plasticity; bending 0 as the explicit
/// `capstan_oracle_holds_for_the_builtin_yarn_material`, tests/yarn_oracles.rs)
/// at dt 1e-3, 128^2, g = 2.
const BUILTIN: Capstan = Capstan {
    dt: 1e-3,
    gamma: 500.0,
    youngs_modulus: 1000.0,
    friction: 0.05,
    bending: 0.0,
    plasticity: true,
    ..CAPSTAN_PURE_STRING
};

#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn capstan_threshold_under_backward_euler_with_the_builtin_material() {
    capstan_holds_within_15_percent(&BUILTIN);
}

/// With the built-in bending B = 1e-3 N m as well (the explicit
/// `capstan_oracle_holds_with_bending`) the threshold holds at dt 5e-4,
/// not at 1e-3: there the yarn creeps at 1.15 mu* and crosses the slip
/// criterion about 0.9 s after loading (measured end displacement over 1 s after
/// loading: 1.15 mu* 6.8e-3 at dt 1e-3, 1.6e-3 at 5e-4, 6.1e-4 at 2.5e-4;
/// 1.4 mu* 4.6e-3 and 2 mu* 3.3e-3 at 1e-3, still creeping; without
/// bending 7.8e-5 at 1e-3).
#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn capstan_threshold_under_backward_euler_with_the_builtin_material_and_bending() {
    capstan_holds_within_15_percent(&Capstan {
        dt: 5e-4,
        bending: 1e-3,
        ..BUILTIN
    });
}

/// The capstan with slip walls under the implicit integrator (the
/// boundary pass is serial, in block order): bit-identical states with 1
/// and 2 threads.
#[test]
fn boundaries_give_the_same_bits_for_one_and_two_threads() {
    let setup = Capstan {
        dt: 1e-3,
        ..CAPSTAN_PURE_STRING
    };
    let text =
        capstan_toml(0.1, 0.1, 0.3, 0.3, &setup).replace("mode = \"none\"", "mode = \"slip\"");
    let s = with_integrator(
        YarnScene::from_toml_str(&text).unwrap(),
        Integrator::Implicit,
        1e-3,
    );
    assert_eq!(s.walls.mode, WallMode::Slip);
    common::same_bits_on_one_and_two_threads(&s, 60);
}

// ---- incline ---------------------------------------------------------------

/// Gravity of the incline.
const G: f64 = 9.8;
/// Coulomb coefficient of the incline's obstacle.
const INCLINE_MU: f64 = 0.3;
/// Radius of the obstacle whose top is the incline: over the yarn's 0.1 m
/// and its slide the surface turns by at most 0.015 rad (the largest radius a
/// scene takes, 10 domain sizes).
const INCLINE_R: f64 = 10.0;

/// A 0.1 m yarn of `material` lying on the top of a circle of radius
/// [`INCLINE_R`] (a flat floor at y = 0.4 to 5e-4 m over the yarn) with
/// Coulomb friction [`INCLINE_MU`], gravity `G` tilted by `theta`
/// (downhill along +x), 128^2. The yarn's centre starts 0.03 m uphill of
/// the top, so that over the measured slide it lies about the top.
fn incline(theta: f64, material: fn(&mut Material), integrator: Integrator, dt: f64) -> YarnSim {
    let dx: f64 = 1.0 / 128.0;
    let n = (0.1 / (0.5 * dx)).round() as u32 + 1;
    let s = SceneBuilder::bare()
        .resolution(128)
        .material(material)
        .gravity([G * theta.sin(), -G * theta.cos()])
        .obstacle([0.48, 0.4 - INCLINE_R], INCLINE_R, INCLINE_MU)
        .yarn(straight([0.4, 0.4], [0.5, 0.4], n))
        .build();
    YarnSim::new(&with_integrator(s, integrator, dt)).unwrap()
}

/// Runs the incline: 0.1 s to settle, then 0.4 s; returns the yarn's mean
/// downhill acceleration over the 0.4 s (from its momentum) and the
/// distance it slid in them.
fn incline_run(
    theta: f64,
    material: fn(&mut Material),
    integrator: Integrator,
    dt: f64,
) -> (f64, f64, (f64, f64)) {
    let mut sim = incline(theta, material, integrator, dt);
    sim.advance(0.1).unwrap();
    let d0 = sim.diagnostics();
    let v0 = d0.momentum.x / d0.total_mass;
    sim.advance(0.4).unwrap();
    let d1 = sim.diagnostics();
    let v1 = d1.momentum.x / d1.total_mass;
    (
        (v1 - v0) / 0.4,
        d1.center_of_mass.x - d0.center_of_mass.x,
        iterations(&sim),
    )
}

/// The incline law: a yarn on a surface with Coulomb friction mu holds for
/// tan theta < mu and slides with acceleration g (sin theta - mu cos
/// theta) above it. Under backward Euler at dt 1e-3: at tan theta = 0.85 mu
/// it moves less than 1e-3 m in 0.4 s (sliding at 1.15 mu it moves 3.3e-2
/// m), at 1.15 mu its acceleration is within 5 % of the law.
fn incline_law_holds(material: fn(&mut Material), dt: f64) {
    for f in [0.85, 1.15] {
        let theta = (f * INCLINE_MU).atan();
        let (a, slid, (newton, cg)) = incline_run(theta, material, Integrator::Implicit, dt);
        let law = (G * (theta.sin() - INCLINE_MU * theta.cos())).max(0.0);
        eprintln!(
            "implicit incline dt {dt:.0e}: tan theta {:.3} = {f} mu: acceleration {a:.4} m/s^2 \
             (law {law:.4}), slid {slid:.2e} m in 0.4 s, {newton:.2} Newton / {cg:.1} CG per substep",
            f * INCLINE_MU
        );
        if f < 1.0 {
            // tolerance 1e-3 m (a slide would move g (sin - mu cos) t^2 / 2 > 0)
            assert!(slid.abs() < 1e-3, "tan theta {f} mu: slid {slid} m");
        } else {
            // tolerance 10 % of the law's acceleration
            assert!(
                (a - law).abs() < 0.1 * law,
                "tan theta {f} mu: a {a}, law {law}"
            );
        }
    }
}

#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn yarn_on_an_incline_holds_below_and_slides_above_tan_theta_mu() {
    incline_law_holds(pure_string, 1e-3);
}

// ---- walls -----------------------------------------------------------------

/// A horizontal 0.3 m yarn of `material` at height 0.3 moving at
/// `(vx, 0)`, dropped under g = 9.8 onto the floor of walls `mode` (3
/// cells), 64^2.
fn drop_on_floor(
    mode: WallMode,
    vx: f64,
    material: fn(&mut Material),
    scheme: TransferScheme,
    integrator: Integrator,
    dt: f64,
) -> YarnSim {
    let s = SceneBuilder::bare()
        .scheme(scheme)
        .material(material)
        .gravity([0.0, -9.8])
        .walls(mode)
        .yarn(straight([0.3, 0.3], [0.6, 0.3], 40))
        .build();
    let mut sim = YarnSim::new(&with_integrator(s, integrator, dt)).unwrap();
    for v in yarnsim::testing::particles_mut(&mut sim).vert.v.iter_mut() {
        *v = Vec2::new(vx, 0.0);
    }
    sim
}

/// Lowest particle height and largest vertex speed.
fn lowest_and_fastest(sim: &YarnSim) -> (f64, f64) {
    let p = sim.particles();
    let low = p
        .vert
        .x
        .iter()
        .chain(&p.quad.x)
        .map(|x| x.y)
        .fold(f64::INFINITY, f64::min);
    let fast = p.vert.v.iter().map(|v| v.norm()).fold(0.0, f64::max);
    (low, fast)
}

/// Sticky floor (the wall nodes, j < 3, at rest): a yarn that lands at
/// 2.2 m/s stops (every vertex slower than 1 cm/s 0.5 s after landing);
/// no particle gets below y = 1.5 dx, where its whole stencil lies on wall
/// nodes, and the lowest one lies within half a cell of the explicit
/// run's (dt 1e-4). Slip floor: only the normal velocity is removed, so the
/// horizontal momentum is kept to round-off through the landing.
fn walls_stop_the_yarn(material: fn(&mut Material), scheme: TransferScheme, dt: f64) {
    let dx = 1.0 / 64.0;
    let sticky = |integrator: Integrator, dt: f64| {
        let mut sim = drop_on_floor(WallMode::Sticky, 0.0, material, scheme, integrator, dt);
        let mut low: f64 = 1.0;
        while sim.time() < 0.8 {
            sim.step().unwrap();
            low = low.min(lowest_and_fastest(&sim).0);
        }
        (low, lowest_and_fastest(&sim).1)
    };
    let (low, fast) = sticky(Integrator::Implicit, dt);
    let (ex_low, ex_fast) = sticky(Integrator::Explicit, 1e-4);
    eprintln!(
        "implicit sticky floor {scheme:?} dt {dt:.0e}: lowest particle {:.3} dx (explicit 1e-4: {:.3} dx), \
         fastest vertex {fast:.2e} m/s at 0.8 s (explicit {ex_fast:.2e})",
        low / dx,
        ex_low / dx
    );
    assert!(low >= 1.5 * dx, "a particle reached {:.3} dx", low / dx);
    // tolerance: half a cell (at dt 1e-3 the yarn lands 0.14 dx per
    // substep, and the wall acts after the solve)
    assert!(
        (low - ex_low).abs() < 0.5 * dx,
        "lowest {:.3} dx, explicit {:.3} dx",
        low / dx,
        ex_low / dx
    );
    assert!(fast < 1e-2, "still moving at {fast} m/s");

    let mut sim = drop_on_floor(
        WallMode::Slip,
        0.2,
        material,
        scheme,
        Integrator::Implicit,
        dt,
    );
    let p0 = sim.diagnostics().momentum.x;
    sim.advance(0.6).unwrap();
    let d = sim.diagnostics();
    let (low, _) = lowest_and_fastest(&sim);
    let rel = (d.momentum.x - p0).abs() / p0;
    eprintln!(
        "implicit slip floor {scheme:?} dt {dt:.0e}: horizontal momentum kept to {rel:.2e}, lowest particle {:.3} dx, \
         vertical momentum {:.2e} at 0.6 s",
        low / dx,
        d.momentum.y
    );
    // tolerance 1e-12 relative (round-off)
    assert!(rel < 1e-12, "horizontal momentum changed by {rel:.3e}");
    assert!(low >= 1.5 * dx, "a particle reached {:.3} dx", low / dx);
}

#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn floor_wall_stops_a_dropped_yarn_under_backward_euler() {
    // FLIP: the particles take the grid's change, so a wall change missing
    // from it would keep them falling; APIC: the velocities themselves
    for scheme in [TransferScheme::Flip, TransferScheme::Apic] {
        walls_stop_the_yarn(pure_string, scheme, 1e-3);
    }
}

// ---- free fall -------------------------------------------------------------

/// Free fall beside an obstacle, inside sticky walls, is the grid scheme's
/// exact trajectory (the boundary pass leaves nodes out of reach alone).
#[test]
fn free_fall_beside_obstacles_and_walls_is_exact() {
    let s = SceneBuilder::bare()
        .material(pure_string)
        .gravity([0.5, -9.8])
        .walls(WallMode::Sticky)
        .obstacle([0.2, 0.3], 0.1, 0.5)
        .yarn(straight([0.4, 0.7], [0.8, 0.85], 60))
        .build();
    let dt = 1e-3;
    let mut sim = YarnSim::new(&with_integrator(s, Integrator::Implicit, dt)).unwrap();
    // round-off over 150 substeps
    common::assert_grid_free_fall(&mut sim, Vec2::new(0.5, -9.8), dt, 150, None);
}

// ---- driven pin ------------------------------------------------------------

/// Angular velocity of the circle-driven pin (rad/s).
const OMEGA: f64 = 3.0;

/// The prescribed path of the driven top vertex, from (0.4, 0.8): along x
/// at 0.2 m/s (`motion = "line"`), or about (0.4, 0.75) at [`OMEGA`]
/// (`motion = "circle"`).
fn pin_path(motion: PinMotionKind, t: f64) -> Vec2 {
    match motion {
        PinMotionKind::Line => Vec2::new(0.4 + 0.2 * t, 0.8),
        PinMotionKind::Circle => {
            let (s, c) = (OMEGA * t).sin_cos();
            Vec2::new(0.4 - 0.05 * s, 0.75 + 0.05 * c)
        }
        m => panic!("no path for {m:?}"),
    }
}

/// A 0.4 m yarn of `material` hanging from its top vertex, which is driven
/// on [`pin_path`], 64^2, g = 9.8.
fn driven_chain(
    material: fn(&mut Material),
    motion: PinMotionKind,
    integrator: Integrator,
    dt: f64,
) -> YarnSim {
    let mut pin = pin_end(0, YarnEnd::Start, 1);
    pin.motion = motion;
    match motion {
        PinMotionKind::Line => pin.velocity = Some([0.2, 0.0]),
        _ => {
            pin.center = Some([0.4, 0.75]);
            pin.angular_velocity = Some(OMEGA);
        }
    }
    let s = SceneBuilder::bare()
        .material(material)
        .gravity([0.0, -9.8])
        .yarn(straight([0.4, 0.8], [0.4, 0.4], 52))
        .pin(pin)
        .build();
    YarnSim::new(&with_integrator(s, integrator, dt)).unwrap()
}

/// The driven chain for 1 s: the free end sampled every 0.01 s, the pin's
/// mean vertical force over the second half over the weight, minus 1, the
/// pinned vertex's largest distance from its path, and the wall time per
/// substep.
fn driven_run(
    material: fn(&mut Material),
    motion: PinMotionKind,
    integrator: Integrator,
    dt: f64,
) -> (Vec<Vec2>, f64, f64, f64) {
    let mut sim = driven_chain(material, motion, integrator, dt);
    let weight = sim.diagnostics().total_mass * 9.8;
    let (mut ends, mut impulse, mut span, mut worst_pin) = (Vec::new(), 0.0, 0.0, 0.0f64);
    let t0 = Instant::now();
    for k in 1..=100 {
        let t = k as f64 * 0.01;
        while sim.time() < t - 1e-9 {
            let before = sim.time();
            sim.step().unwrap();
            if sim.time() > 0.5 {
                impulse += sim.pin_reactions()[0].y * (sim.time() - before);
                span += sim.time() - before;
            }
        }
        let (top, end) = sim.yarn_endpoints(0);
        worst_pin = worst_pin.max((top - pin_path(motion, sim.time())).norm());
        ends.push(end);
    }
    let per_step = t0.elapsed().as_secs_f64() / sim.steps() as f64;
    (ends, impulse / span / weight - 1.0, worst_pin, per_step)
}

/// A pin driven on a line or a circle under backward Euler at dt 1e-3
/// carries the yarn with it as the explicit step at 1e-4 does: the free
/// end within 2 cells of the explicit run's over 1 s, the pinned vertex on
/// its path to round-off; on the line (constant velocity) the pin's mean
/// vertical force is the weight to 2 %.
fn driven_pin_tracks(material: fn(&mut Material), motion: PinMotionKind) {
    let dx = 1.0 / 64.0;
    let (ex, ex_w, _, ex_t) = driven_run(material, motion, Integrator::Explicit, 1e-4);
    let (im, im_w, pin_err, im_t) = driven_run(material, motion, Integrator::Implicit, 1e-3);
    let gap = ex
        .iter()
        .zip(&im)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    let travel = (im[99] - im[0]).norm();
    eprintln!(
        "driven pin {motion:?}: free end within {:.3} dx of the explicit run (moved {travel:.3} m), \
         pin force {:+.2} % (explicit {:+.2} %) of the weight, pinned vertex off its path by {pin_err:.1e} m; \
         {:.3} ms per implicit substep (1e-3) vs {:.3} ms per explicit (1e-4)",
        gap / dx,
        100.0 * im_w,
        100.0 * ex_w,
        1e3 * im_t,
        1e3 * ex_t
    );
    // tolerances: 2 cells, 1e-12 m, 2 % (the hanging chain's)
    assert!(
        gap < 2.0 * dx,
        "free end {:.3} dx off the explicit run",
        gap / dx
    );
    assert!(pin_err < 1e-12, "pinned vertex {pin_err} m off its path");
    assert!(travel > 0.05, "the yarn did not follow the pin: {travel} m");
    if motion == PinMotionKind::Line {
        assert!(im_w.abs() < 0.02, "pin force {im_w:+.4}");
    }
}

#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn driven_pin_under_backward_euler_tracks_its_line_like_the_explicit_step() {
    driven_pin_tracks(pure_string, PinMotionKind::Line);
}

#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn driven_pin_under_backward_euler_tracks_its_circle_like_the_explicit_step() {
    driven_pin_tracks(pure_string, PinMotionKind::Circle);
}
