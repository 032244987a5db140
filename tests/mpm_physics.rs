//! Physics of the MPM yarn solver: force assembly against the energy,
//! free fall, momentum conservation, rotation invariance, determinism.

mod common;

use common::{
    bundle, momentum_scale, pin_end, polyline, straight, straight_yarn_sim, Rng, SceneBuilder,
};
use yarnsim::math::{perp, Mat2, Vec2};
use yarnsim::testing::internals::{self as grid, quad_stress, scatter, Grid};

use yarnsim::scene::{TransferScheme, WallMode, YarnEnd, YarnScene, YarnSpec};
use yarnsim::testing::internals as simd;
use yarnsim::YarnSim;

/// Weight of grid node `(i, j)` in a stencil (0 outside it).
fn weight_at(st: &yarnsim::math::bspline::Stencil, i: usize, j: usize) -> f64 {
    let (a, b) = (i as i64 - st.base[0] as i64, j as i64 - st.base[1] as i64);
    if (0..3).contains(&a) && (0..3).contains(&b) {
        st.weight(a as usize, b as usize)
    } else {
        0.0
    }
}

#[test]
fn grid_forces_are_minus_the_energy_gradient() {
    // A deformed diagonal yarn (the orientation that exposes assembly bugs).
    let scene = SceneBuilder::bare()
        .yarn(straight([0.3, 0.35], [0.55, 0.6], 40))
        .build();
    let mut sim = YarnSim::new(&scene).unwrap();
    let geom = sim.grid_geom();
    let energy = *sim.energy_model();
    let kb = scene.material.bending;
    let mut rng = Rng::new(7);
    {
        let p = yarnsim::testing::particles_mut(&mut sim);
        let l0 = p.quad.l0[0];
        for x in p.vert.x.iter_mut() {
            *x += Vec2::new(rng.uniform(-0.15, 0.15), rng.uniform(-0.15, 0.15)) * l0;
        }
        for q in 0..p.quad.x.len() {
            let l = p.quad.left[q] as usize;
            let d1 = p.vert.x[l + 1] - p.vert.x[l];
            let n = perp(d1 / d1.norm()) * p.quad.l0[q];
            let d2 = n * rng.uniform(0.7, 0.98) + d1 * rng.uniform(-0.2, 0.2);
            p.quad.d[q] = Mat2::from_columns(&[d1, d2]);
            p.quad.x[q] = (p.vert.x[l] + p.vert.x[l + 1]) * 0.5;
        }
    }
    let p = yarnsim::testing::particles_mut(&mut sim);
    p.quad.refresh_frames(); // d was set by hand
    quad_stress(&mut p.quad, &geom, &energy);
    let mut grid = Grid::new(geom);
    scatter(p, &mut grid, 1.0, kb, &[]); // v = 0, C = 0: momentum = 1 * force
    let p = sim.particles();

    let total_energy = |node: (usize, usize), axis: usize, eps: f64| -> f64 {
        let mut x = p.vert.x.clone();
        let mut dir = Vec2::zeros();
        dir[axis] = eps;
        for (k, xk) in x.iter_mut().enumerate() {
            *xk += dir * weight_at(&p.vert.stencil[k], node.0, node.1);
        }
        let mut e = 0.0;
        for q in 0..p.quad.x.len() {
            let st = &p.quad.stencil[q];
            let l = p.quad.left[q] as usize;
            let d2 = p.quad.d[q].column(1).into_owned();
            let xi = Vec2::new(node.0 as f64, node.1 as f64) * geom.dx;
            let grad = (xi - p.quad.x[q])
                * (4.0 * weight_at(st, node.0, node.1) * geom.inv_dx * geom.inv_dx);
            let d2n = d2 + dir * grad.dot(&d2);
            let d = Mat2::from_columns(&[x[l + 1] - x[l], d2n]);
            e += p.quad.vol[q] * energy.psi(&(d / p.quad.l0[q]));
        }
        let mut moved = p.vert.clone();
        moved.x = x;
        e + yarnsim::mpm::laws::bending::bending_energy(&moved, kb)
    };

    let mut max_f: f64 = 0.0;
    let mut checked = 0;
    let mut worst: f64 = 0.0;
    let mut forces = Vec::new();
    let win = grid.geom;
    for &b in &grid.active {
        for idx in win.block_nodes(b as usize) {
            let f: Vec2 = grid
                .buffers
                .iter()
                .map(|buf| Vec2::new(buf.node[idx][grid::PX], buf.node[idx][grid::PY]))
                .sum();
            let m: f64 = grid.buffers.iter().map(|buf| buf.node[idx][grid::M]).sum();
            if m > 0.0 {
                forces.push((win.node(idx), f));
                max_f = max_f.max(f.norm());
            }
        }
    }
    let eps = 1e-7;
    for (node, f) in forces {
        for axis in 0..2 {
            let fd =
                -(total_energy(node, axis, eps) - total_energy(node, axis, -eps)) / (2.0 * eps);
            worst = worst.max((fd - f[axis]).abs());
            checked += 1;
        }
    }
    assert!(checked > 200, "{checked}");
    assert!(max_f > 1.0, "the deformation must load the grid ({max_f})");
    assert!(
        worst < 1e-5 * max_f,
        "worst |f - f_fd| = {worst:.3e} against max |f| = {max_f:.3e}"
    );
}

#[test]
fn free_fall_follows_the_schemes_trajectory() {
    let scene = SceneBuilder::bare()
        .gravity([0.5, -9.8])
        .yarn(straight([0.2, 0.7], [0.7, 0.85], 60))
        .yarn(polyline(&[[0.3, 0.6], [0.5, 0.62], [0.6, 0.5]], 50))
        .build();
    let mut sim = YarnSim::new(&scene).unwrap();
    let g = Vec2::from(scene.gravity);
    let dt = sim.dt();
    // symplectic Euler on the grid: v_n = n dt g, x_n = x_0 + dt^2 g n (n + 1) / 2
    common::assert_grid_free_fall(&mut sim, g, dt, 1500, Some(1e-5));
}

#[test]
fn linear_momentum_is_conserved_and_angular_drift_is_small() {
    // the bundle spun rigidly about its centre of mass (velocity gradient
    // C = omega [[0, -1], [1, 0]]) with a drift
    let mut sim = common::spinning_bundle(4.0, Vec2::new(0.3, -0.2));
    let d0 = sim.diagnostics();
    let scale = momentum_scale(&sim);
    sim.steps_n(1000).unwrap();
    let d1 = sim.diagnostics();
    let dp = (d1.momentum - d0.momentum).norm() / scale;
    assert!(dp < 1e-10, "linear momentum drift {dp:.3e}");
    let dl = (d1.angular_momentum - d0.angular_momentum).abs() / d0.angular_momentum.abs();
    // measured 1.9e-8 over 1000 substeps: quadrature positions are
    // re-interpolated from the vertices, which APIC does not account for.
    assert!(dl < 1e-6, "angular momentum drift {dl:.3e}");
    eprintln!("relative drift after 1000 substeps: linear {dp:.2e}, angular {dl:.2e}");
}

/// Rotates a point by +90 degrees about `c`.
fn rot90(x: Vec2, c: f64) -> Vec2 {
    Vec2::new(2.0 * c - x.y, x.x)
}

fn rotated_scene(scene: &YarnScene, c: f64) -> YarnScene {
    let mut s = scene.clone();
    let g = Vec2::from(s.gravity);
    s.gravity = [-g.y, g.x];
    for y in &mut s.yarns {
        let pts: Vec<[f64; 2]> = y.curves().unwrap()[0]
            .iter()
            .map(|&p| rot90(p, c).into())
            .collect();
        y.points = Some(pts);
        y.start = None;
        y.end = None;
        y.direction = None;
        y.length = None;
        let sp = Vec2::from(y.spacing);
        y.spacing = [-sp.y, sp.x];
        let v = Vec2::from(y.velocity);
        y.velocity = [-v.y, v.x];
    }
    s
}

#[test]
fn rotating_the_scene_by_90_degrees_rotates_the_trajectory() {
    let scene = SceneBuilder::bare()
        .gravity([0.0, -9.8])
        .walls(WallMode::Sticky)
        .material(|m| m.plasticity = true)
        .yarn(YarnSpec {
            velocity: [0.5, -1.0],
            ..bundle([0.25, 0.12], [0.7, 0.22], 70, 2, [0.0, 0.01])
        })
        .build();
    let geom_n = scene.grid.resolution as f64;
    // the node set 0..n-1 is symmetric about (n - 1) dx / 2
    let c = (geom_n - 1.0) / (2.0 * geom_n);
    let rscene = rotated_scene(&scene, c);
    let mut a = YarnSim::new(&scene).unwrap();
    let mut b = YarnSim::new(&rscene).unwrap();
    for _ in 0..4 {
        a.steps_n(250).unwrap();
        b.steps_n(250).unwrap();
        let mut worst: f64 = 0.0;
        for (xa, xb) in a.particles().vert.x.iter().zip(&b.particles().vert.x) {
            worst = worst.max((rot90(*xa, c) - xb).norm());
        }
        assert!(
            worst < 1e-11,
            "rotated trajectory differs by {worst:.3e} m at t = {}",
            a.time()
        );
    }
    // the yarns moved and deformed, so the comparison means something
    let d = a.diagnostics();
    assert!(
        d.kinetic_energy > 0.1 && d.max_stretch > 1.0 + 1e-5,
        "{d:?}"
    );
}

#[test]
fn two_runs_give_identical_bits() {
    let scene = yarnsim::scene::builtin::yarn_reference();
    let run = || {
        let mut s = YarnSim::new(&scene).unwrap();
        s.steps_n(if cfg!(debug_assertions) { 20 } else { 2000 })
            .unwrap();
        s.save_state()
    };
    assert!(run() == run(), "two identical runs differ");
}

#[test]
fn state_round_trip_reproduces_the_run() {
    let mut sim = straight_yarn_sim([0.2, 0.6], [0.8, 0.65], 60);
    sim.set_gravity(Vec2::new(0.0, -9.8)).unwrap();
    sim.steps_n(100).unwrap();
    let saved = sim.save_state();
    assert_eq!(saved.len(), sim.state_size());
    sim.steps_n(100).unwrap();
    let end1 = sim.save_state();
    sim.load_state(&saved).unwrap();
    sim.steps_n(100).unwrap();
    assert!(sim.save_state() == end1);
    // corrupt, truncated and foreign bytes are rejected and change nothing
    let before = sim.save_state();
    let mut bad = saved.clone();
    let k = bad.len() - 9;
    bad[k] ^= 1;
    assert!(sim.load_state(&bad).is_err());
    assert!(sim.load_state(&saved[..saved.len() - 1]).is_err());
    assert!(sim
        .load_state(b"not a state at all, clearly not one")
        .is_err());
    assert!(sim.save_state() == before);
}

#[test]
fn state_restored_into_a_new_instance_continues_bitwise_through_plastic_contact() {
    // Two yarns thrown onto an obstacle: the return mapping projects states
    // every step, and the frame factorisations the stepper caches between
    // steps must be exactly those a restore recomputes from `d`.
    let falling = |y: f64| YarnSpec {
        velocity: [0.0, -3.0],
        ..straight([0.25, y], [0.75, y], 80)
    };
    let scene = SceneBuilder::bare()
        .gravity([0.0, -9.8])
        .material(|m| m.plasticity = true)
        .obstacle([0.5, 0.45], 0.1, 0.3)
        .yarn(falling(0.56))
        .yarn(falling(0.575))
        .build();
    let mut a = YarnSim::new(&scene).unwrap();
    let e = *a.energy_model();
    let mut saved = Vec::new();
    let mut steps_with_yield = 0;
    for step in 0..300 {
        let before: Vec<_> = a.particles().quad.frame.clone();
        a.step().unwrap();
        if step == 150 {
            saved = a.save_state();
        }
        let q = &a.particles().quad;
        let mut yielding = false;
        for (k, (r, b)) in q.frame.iter().zip(&before).enumerate() {
            let fresh = yarnsim::math::qr::qr(&(q.d[k] * (1.0 / q.l0[k])));
            assert!(fresh == *r, "cached frame {k} differs from qr(d / l0)");
            yielding |= r.r22 < 1.0
                && r.r12 != b.r12
                && e.yield_function(r.r12, r.r22).abs() <= 1e-9 * e.normal;
        }
        steps_with_yield += yielding as u32;
    }
    assert!(
        steps_with_yield > 10,
        "the return mapping projected in only {steps_with_yield} steps"
    );
    let mut b = YarnSim::new(&scene).unwrap();
    b.load_state(&saved).unwrap();
    b.steps_n(149).unwrap();
    assert!(a.save_state() == b.save_state());
}

#[test]
fn divergence_is_reported_with_its_step_and_blocks_further_steps() {
    let scene = SceneBuilder::bare()
        .dt(2e-3) // far above the stable step
        .yarn(straight([0.3, 0.5], [0.7, 0.5], 60))
        .build();
    let mut sim = YarnSim::new(&scene).unwrap();
    {
        let p = yarnsim::testing::particles_mut(&mut sim);
        for (k, x) in p.vert.x.iter_mut().enumerate() {
            x.y += if k % 2 == 0 { 0.002 } else { -0.002 };
        }
    }
    let mut failed_at = None;
    for k in 1..=2000u64 {
        if let Err(e) = sim.step() {
            failed_at = Some((k, e));
            break;
        }
    }
    let (k, e) = failed_at.expect("an unstable step size must be reported");
    match &e {
        yarnsim::SimError::NonFinite { step, .. } => assert_eq!(*step, k),
        other => panic!("unexpected {other}"),
    }
    assert!(e.to_string().contains(&format!("step {k}")), "{e}");
    assert_eq!(sim.step(), Err(e));
    let d = sim.diagnostics();
    assert!(d.center_of_mass.x.is_finite());
}

#[test]
fn bad_inputs_are_rejected() {
    let mut sim = straight_yarn_sim([0.3, 0.5], [0.7, 0.5], 10);
    assert!(sim.set_gravity(Vec2::new(f64::NAN, 0.0)).is_err());
    assert!(sim.set_gravity(Vec2::new(0.0, 1e9)).is_err());
    let a = sim.attractor();
    assert!(sim
        .set_attractor(yarnsim::mpm::Attractor {
            strength: f64::INFINITY,
            ..a
        })
        .is_err());
    assert!(sim
        .set_attractor(yarnsim::mpm::Attractor {
            position: Vec2::new(f64::NAN, 0.0),
            ..a
        })
        .is_err());
    // The bound the FMU needs, in the library: |x| <= 1e6 m per coordinate.
    let far = sim
        .set_attractor(yarnsim::mpm::Attractor {
            position: Vec2::new(0.5, 2e6),
            ..a
        })
        .unwrap_err()
        .to_string();
    assert!(
        far.contains("attractor position") && far.contains("1e6"),
        "{far}"
    );
    assert!(sim.step_dt(-1.0).is_err());
    assert_eq!(sim.attractor(), a);
}

#[test]
fn every_kernel_width_gives_the_same_bits() {
    // The reference scene's setting (obstacles, walls, plasticity, bending),
    // smaller: the AVX-512, AVX2 and portable kernels must agree exactly,
    // under both transfer schemes (widths the CPU lacks fall back to the
    // next narrower, so they compare equal trivially).
    let mut scene = match yarnsim::scene::builtin("yarn-reference") {
        Some(yarnsim::Scene::Yarn(s)) => s,
        _ => unreachable!(),
    };
    scene.yarns.truncate(1);
    scene.yarns[0].count = 3;
    scene.attractor.active = true;
    for transfer in [
        yarnsim::scene::TransferScheme::Flip,
        yarnsim::scene::TransferScheme::Apic,
    ] {
        scene.transfer.scheme = transfer;
        let run = |k: simd::Kernels| {
            simd::set_widest_kernels(k);
            let mut sim = YarnSim::new(&scene).unwrap();
            sim.steps_n(300).unwrap();
            simd::set_widest_kernels(simd::Kernels::Avx512);
            sim.save_state()
        };
        let portable = run(simd::Kernels::Portable);
        assert!(portable == run(simd::Kernels::Avx2), "{transfer:?}: AVX2");
        assert!(
            portable == run(simd::Kernels::Avx512),
            "{transfer:?}: AVX-512"
        );
    }
    eprintln!("widest kernels on this CPU: {:?}", simd::kernels());
}

/// A yarn hanging from a pinned top vertex under FLIP stays bounded: the
/// pinned vertex's internal force is not scattered (the pin takes it) and its
/// `C` is reset with its velocity. Before both, this scene diverged at
/// t = 0.02 s (the pinned vertex's `C` and the top segments' velocity grew
/// every substep).
#[test]
fn pinned_hanging_yarn_stays_bounded_under_flip() {
    let scene = SceneBuilder::bare()
        .resolution(32)
        .dt(2e-4)
        .gravity([0.0, -9.8])
        .material(|m| {
            m.bending = 0.0;
            m.k = 4900.0;
        })
        .scheme(TransferScheme::Flip)
        .yarn(polyline(&[[0.5, 0.8], [0.505, 0.3]], 33))
        .pin(pin_end(0, YarnEnd::Start, 1))
        .build();
    let mut sim = YarnSim::new(&scene).unwrap();
    sim.advance(0.1).unwrap();
    // the reaction averaged over 0.2 s (many periods of the yarn's
    // longitudinal ringing, 4 L / c = 29 ms)
    let mut mean = Vec2::zeros();
    let n = 1000;
    for _ in 0..n {
        sim.step().unwrap();
        mean += sim.pin_reactions()[0] / n as f64;
    }
    let p = sim.particles();
    assert_eq!(p.vert.x[0], Vec2::new(0.5, 0.8));
    assert_eq!(p.vert.c[0], Mat2::zeros());
    let vmax = p.vert.v.iter().map(|v| v.norm()).fold(0.0, f64::max);
    // a 0.5 m chain from near rest: far below free-fall speed g t = 3 m/s
    // (measured 0.029 m/s)
    assert!(vmax < 0.1, "{vmax}");
    // the pin carries the yarn's weight (rho g L = 4.9 N/m) within 2 %
    // (measured 4.896)
    assert!(
        (mean.y - 4.9).abs() < 0.098 && mean.x.abs() < 0.05,
        "{mean:?}"
    );
}
