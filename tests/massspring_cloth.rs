//! The cloth (Wang 2015; Müller et al. 2007; Provot 1995): sphere collision, strain limiting, pinned corners,
//! free fall against each scheme's own analytic trajectory.

mod common;

use common::solved_options;
use yarnsim::massspring::{
    scenes, Integrator, IntegratorOptions, MassSpringScene, Simulation, StrainSolver, V3,
};

/// Options under which every integrator runs the cloth (forward Euler has
/// no stable step without spring damping, so it gets a forced small one).
fn opts(integ: Integrator) -> IntegratorOptions {
    IntegratorOptions {
        dt: (integ == Integrator::ForwardEuler).then_some(1.0 / 3000.0),
        ..Default::default()
    }
}

#[test]
fn no_vertex_inside_the_sphere_after_any_step() {
    for integ in [
        Integrator::ChebyshevJacobi,
        Integrator::Pbd,
        Integrator::BackwardEuler,
    ] {
        let mut sim = Simulation::new(&scenes::cloth(), integ, opts(integ)).unwrap();
        let sph = sim.system().spheres[0];
        let frames = if cfg!(debug_assertions) { 40 } else { 90 };
        for _ in 0..frames {
            sim.step_frame().unwrap();
            let closest = sim
                .positions()
                .iter()
                .map(|p| (p - sph.center).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(
                closest >= sph.radius * (1.0 - 1e-12),
                "{integ}: a vertex at distance {closest} < {}",
                sph.radius
            );
        }
        let hits = sim.totals().collisions;
        eprintln!("{integ}: {hits} sphere projections in {frames} frames");
        // The test means something only if the cloth did reach the sphere.
        assert!(hits > 0, "{integ}: the cloth never touched the sphere");
    }
}

#[test]
// Thousands of projection passes / Jacobi iterations: release only.
#[cfg_attr(debug_assertions, ignore)]
fn strain_after_limiting_is_within_the_configured_limit() {
    let mut layout = scenes::cloth();
    layout.spheres.clear();
    let limit = 0.1;
    let run = |solver: StrainSolver, passes: usize| -> (f64, usize) {
        let o = IntegratorOptions {
            strain_limit: Some(limit),
            strain_iterations: passes,
            strain_solver: solver,
            ..Default::default()
        };
        let mut sim = Simulation::new(&layout, Integrator::Pbd, o).unwrap();
        let mut worst: f64 = 0.0;
        let mut most = 0;
        for _ in 0..15 {
            let st = sim.step(sim.dt()).unwrap();
            worst = worst.max(st.strain_after_limiting);
            most = most.max(st.strain_passes);
            // The reported figure is the state's.
            assert_eq!(st.strain_after_limiting, sim.max_strain());
        }
        eprintln!("pbd {solver}, limit {limit}, {passes} passes: worst strain {worst:.6}, most passes used {most}");
        (worst, most)
    };
    // Gauss-Seidel with enough passes meets the limit after every step.
    let (gs, used) = run(StrainSolver::GaussSeidel, 3000);
    assert!(gs <= limit + 1e-9, "{gs}");
    assert!(used > 1, "the limit was never active");
    // Without passes the falling sheet stretches far beyond it: the check
    // above can fail.
    let (none, _) = run(StrainSolver::GaussSeidel, 0);
    assert!(none > 2.0 * limit, "{none}");
    // The Unity cloth scripts' Jacobi averaging approaches the limit as passes are added.
    let j: Vec<f64> = [10, 100, 20_000]
        .iter()
        .map(|&p| run(StrainSolver::Jacobi, p).0)
        .collect();
    assert!(j[0] > j[1] && j[1] > j[2] && j[0] > limit, "{j:?}");
    assert!(j[2] <= limit + 1e-9, "{j:?}");

    // The same pass after an implicit step (Wang 2015's optimisation form).
    let o = IntegratorOptions {
        strain_limit: Some(0.02),
        strain_iterations: 3000,
        strain_solver: StrainSolver::GaussSeidel,
        ..Default::default()
    };
    let mut sim = Simulation::new(&layout, Integrator::ChebyshevJacobi, o).unwrap();
    let mut active = 0;
    for _ in 0..8 {
        let st = sim.step(sim.dt()).unwrap();
        assert!(st.strain_after_limiting <= 0.02 + 1e-9, "{st:?}");
        active += st.strain_passes;
    }
    assert!(active > 0);
}

#[test]
fn pinned_vertices_stay_bitwise_fixed() {
    for integ in Integrator::ALL {
        let mut sim = Simulation::new(&scenes::cloth(), integ, opts(integ)).unwrap();
        let pins: Vec<(usize, V3)> = sim
            .system()
            .kinematics
            .iter()
            .enumerate()
            .filter(|(_, k)| !k.is_free())
            .map(|(i, _)| (i, sim.positions()[i]))
            .collect();
        assert_eq!(pins.iter().map(|p| p.0).collect::<Vec<_>>(), vec![0, 20]);
        let frames = if integ == Integrator::ForwardEuler {
            1
        } else {
            5
        };
        for _ in 0..frames {
            sim.step_frame().unwrap();
        }
        for (i, p0) in &pins {
            let p = sim.positions()[*i];
            for c in 0..3 {
                assert_eq!(p[c].to_bits(), p0[c].to_bits(), "{integ} vertex {i}");
            }
            assert_eq!(sim.velocities()[*i], V3::zeros());
        }
        // The free vertices did move.
        assert!(sim.positions()[220].y < -1e-3, "{integ}");
    }
}

/// Height fallen after `n` steps of `h` from rest under gravity `g` with
/// velocity damping `d` per step, for each scheme: the velocities are
/// `v_k = h g (1 - d^k) / (1 - d)` for all of them, and the positions
/// `x_n = h sum_{k=1..n} v_k` (symplectic and backward Euler, their
/// minimisation form, PBD), `h d sum_{k=0..n-1} v_k` (forward Euler),
/// `h/2 sum_{k=0..n-1} (d v_k + v_{k+1})` (trapezoidal).
fn free_fall_drop(integ: Integrator, n: usize, h: f64, g: f64, d: f64) -> f64 {
    let v = |k: usize| h * g * (1.0 - d.powi(k as i32)) / (1.0 - d);
    let s_to = |n: usize| (1..=n).map(v).sum::<f64>();
    match integ {
        Integrator::ForwardEuler => h * d * (s_to(n) - v(n)),
        Integrator::Trapezoidal => 0.5 * h * (d * (s_to(n) - v(n)) + s_to(n)),
        _ => h * s_to(n),
    }
}

#[test]
fn free_fall_matches_each_schemes_analytic_trajectory() {
    let mut layout: MassSpringScene = scenes::cloth();
    layout.pinned.clear();
    layout.spheres.clear();
    let sys = layout.build().unwrap();
    let (h, g, d) = (sys.time_step, 9.8, 0.99);
    let n = 20;
    for integ in Integrator::ALL {
        // Chebyshev-Jacobi: the minimisation solved to convergence.
        let o = solved_options(integ, h, 1e-13, 3000);
        let mut sim = Simulation::new(&layout, integ, o).unwrap();
        for _ in 0..n {
            sim.step(h).unwrap();
        }
        let drop = free_fall_drop(integ, n, h, g, d);
        let err = sim
            .positions()
            .iter()
            .zip(&sys.positions)
            .map(|(p, p0)| (p - (p0 - V3::new(0.0, drop, 0.0))).norm())
            .fold(0.0, f64::max);
        eprintln!("{integ}: dropped {drop:.9} m in {n} steps, max error {err:.2e}");
        assert!(err < 1e-8 * drop, "{integ}: error {err}");
    }
    // The schemes' trajectories differ by far more than the tolerance.
    let fe = free_fall_drop(Integrator::ForwardEuler, n, h, g, d);
    let tr = free_fall_drop(Integrator::Trapezoidal, n, h, g, d);
    let be = free_fall_drop(Integrator::BackwardEuler, n, h, g, d);
    assert!(fe < tr && tr < be && (be - fe) > 0.1);
}
