//! Adversarial cases: every case must end with a finite,
//! physically bounded state, or with a clear error naming the step where the
//! state went bad. A non-finite state is never reported as success.

mod common;

use common::straight_yarn_sim;
use yarnsim::massspring::{scenes, Integrator, IntegratorOptions, MassSpringError, Simulation};
use yarnsim::math::{Mat2, Vec2};
use yarnsim::mpm::laws::constitutive::{frame_gradient, YarnEnergy};
use yarnsim::mpm::{Attractor, SimError};
use yarnsim::scene::WallMode;
use yarnsim::testing::reference_material;
use yarnsim::YarnSim;

/// Every particle position and velocity finite.
fn all_finite(sim: &YarnSim) -> bool {
    let p = sim.particles();
    p.vert
        .x
        .iter()
        .chain(&p.vert.v)
        .chain(&p.quad.x)
        .chain(&p.quad.v)
        .all(|v| v.x.is_finite() && v.y.is_finite())
}

/// Outcome of running `steps` substeps: `Ok` with the state checked finite, or
/// the error, which must name a step within the run and stop the simulation.
fn run_checked(sim: &mut YarnSim, steps: u64) -> Result<(), SimError> {
    let start = sim.steps();
    match sim.steps_n(steps) {
        Ok(()) => {
            assert!(all_finite(sim), "non-finite state reported as success");
            Ok(())
        }
        Err(e) => {
            match &e {
                SimError::NonFinite { step, .. } => {
                    assert!(*step > start && *step <= start + steps, "{e}");
                    assert!(e.to_string().contains(&format!("step {step}")), "{e}");
                }
                SimError::Refused { what, .. } => panic!("unexpected refusal: {what}"),
                SimError::BadInput(m) => panic!("unexpected bad input: {m}"),
            }
            assert_eq!(sim.failure(), Some(&e));
            assert!(
                sim.step().is_err(),
                "a failed simulation must refuse to step"
            );
            Err(e)
        }
    }
}

/// Every particle inside the grid domain.
fn inside_domain(sim: &YarnSim) -> bool {
    let size = sim.scene().grid.size;
    let p = sim.particles();
    p.vert
        .x
        .iter()
        .chain(&p.quad.x)
        .all(|x| (0.0..=size).contains(&x.x) && (0.0..=size).contains(&x.y))
}

/// Deepest penetration of a vertex into any obstacle, in m.
fn max_penetration(sim: &YarnSim) -> f64 {
    let mut worst = 0.0f64;
    for o in &sim.scene().obstacles {
        let c = Vec2::from(o.center);
        for x in &sim.particles().vert.x {
            worst = worst.max(o.radius - (x - c).norm());
        }
    }
    worst
}

fn total_energy(sim: &YarnSim) -> f64 {
    let d = sim.diagnostics();
    d.kinetic_energy + d.elastic_energy
}

#[test]
fn yarn_stretched_to_three_times_its_length_snaps_back() {
    let mut sim = straight_yarn_sim([0.4, 0.5], [0.6, 0.5], 30);
    let l_rest: f64 = sim.stretches().iter().sum::<f64>();
    {
        let p = yarnsim::testing::particles_mut(&mut sim);
        let c = Vec2::new(0.5, 0.5);
        for x in p.vert.x.iter_mut() {
            *x = c + (*x - c) * 3.0;
        }
        for q in 0..p.quad.x.len() {
            let l = p.quad.left[q] as usize;
            let d1 = p.vert.x[l + 1] - p.vert.x[l];
            let d2 = p.quad.d[q].column(1).into_owned();
            p.quad.d[q] = Mat2::from_columns(&[d1, d2]);
            p.quad.x[q] = (p.vert.x[l] + p.vert.x[l + 1]) * 0.5;
        }
    }
    let s0 = sim.diagnostics();
    assert!((s0.max_stretch - 3.0).abs() < 1e-9 && l_rest > 0.0);
    let e0 = total_energy(&sim);
    assert!(e0 > 0.0);
    // 0.03 s: the yarn recoils; no gravity, walls or obstacles.
    match run_checked(&mut sim, 300) {
        Ok(()) => {
            let d = sim.diagnostics();
            assert!(inside_domain(&sim));
            // Released, the stretch relaxes: no segment stays at 3x.
            assert!(d.max_stretch < 2.5, "max stretch {}", d.max_stretch);
            // No energy is created (elastic + kinetic, nothing external).
            assert!(
                total_energy(&sim) <= 1.05 * e0,
                "{} > {e0}",
                total_energy(&sim)
            );
            // Momentum stays zero (symmetric release, APIC conserves it).
            assert!(d.momentum.norm() < 1e-8 * d.total_mass.max(1.0) * 100.0);
        }
        Err(e) => eprintln!("stretched yarn: clear failure: {e}"),
    }
}

#[test]
fn yarns_crushed_against_an_obstacle() {
    let mut sc = yarnsim_evidence::small_yarn_scene(4, 40, 64);
    sc.gravity = [0.0, -200.0];
    sc.time.dt = 5e-5.into();
    sc.obstacles[0].center = [0.5, 0.4];
    sc.obstacles[0].radius = 0.12;
    sc.yarns[0].start = Some([0.25, 0.6]);
    sc.yarns[0].length = Some(0.5);
    sc.yarns[0].velocity = [0.0, -5.0];
    let mut sim = YarnSim::new(&sc).unwrap();
    let dx = sim.grid_geom().dx;
    match run_checked(&mut sim, 2000) {
        Ok(()) => {
            assert!(inside_domain(&sim));
            let pen = max_penetration(&sim);
            assert!(pen <= dx, "penetration {pen} > dx {dx}");
            let d = sim.diagnostics();
            assert!(d.min_stretch > 0.2 && d.max_stretch < 3.0, "{d:?}");
        }
        Err(e) => eprintln!("crushed yarns: clear failure: {e}"),
    }
}

#[test]
fn degenerate_and_inverted_deformation_gradients_give_finite_stress() {
    let e = YarnEnergy::from_material(&reference_material());
    let cases = [
        Mat2::zeros(),
        Mat2::new(1.0, 0.0, 0.0, 0.0), // rank 1, cross-section collapsed
        Mat2::new(0.0, 0.0, 0.0, 1.0), // fibre collapsed
        Mat2::new(1.0, 0.0, 0.0, -1.0), // inverted cross-section
        Mat2::new(-1.0, 0.0, 0.0, 1.0), // inverted fibre
        Mat2::new(-1.0, 0.0, 0.0, -1.0), // rotation by pi
        Mat2::new(1.0, 1.0, 1.0, 1.0), // singular shear
        Mat2::new(1e-12, 0.0, 0.0, 1e-12), // nearly zero
        Mat2::new(1e6, 0.0, 0.0, 1e6), // huge
        Mat2::new(3.0, 0.0, 0.0, 1.0), // 3x stretch
        Mat2::new(1e-300, 1e-300, -1e-300, 1e-300), // subnormal scale
    ];
    for f in cases {
        let p = e.stress(&f);
        assert!(p.iter().all(|v| v.is_finite()), "P({f}) = {p}");
        let psi = e.psi(&f);
        assert!(psi.is_finite() && psi >= 0.0, "psi({f}) = {psi}");
        let (g1, g2) = frame_gradient(&e, &(f * 0.01), 0.01, 1e-4);
        assert!(g1.iter().chain(g2.iter()).all(|v| v.is_finite()), "{f}");
    }
    // The return mapping repairs inverted / collapsed cross-sections.
    for (r12, r22) in [
        (0.5, -1.0),
        (0.0, 0.0),
        (1e6, 1e-9),
        (-3.0, -1e300),
        (2.0, 5.0),
    ] {
        let (a, b) = e.return_map(r12, r22);
        assert!(
            a.is_finite() && b.is_finite() && b > 0.0 && b <= 1.0,
            "({r12},{r22}) -> ({a},{b})"
        );
        assert!(
            e.yield_function(a, b) <= 1e-9 * (1.0 + e.gamma * a.abs()),
            "({a},{b})"
        );
        assert_eq!(e.return_map(a, b), (a, b), "return mapping not idempotent");
    }
}

fn wall_scene(mode: WallMode, vx: f64) -> yarnsim::YarnScene {
    let mut sc = yarnsim_evidence::small_yarn_scene(3, 40, 64);
    sc.gravity = [0.0, 0.0];
    sc.obstacles.clear();
    sc.walls.mode = mode;
    sc.yarns[0].start = Some([0.5, 0.3]);
    sc.yarns[0].direction = Some([1.0, 1.0]);
    sc.yarns[0].length = Some(0.4);
    sc.yarns[0].velocity = [vx, 0.0];
    sc
}

#[test]
fn particles_driven_at_the_walls_at_high_speed_stay_on_the_grid() {
    for mode in [WallMode::Sticky, WallMode::Slip, WallMode::None] {
        // 100 m/s: 0.64 cells per substep, below the one-cell CFL guard.
        let mut sim = YarnSim::new(&wall_scene(mode, 100.0)).unwrap();
        match run_checked(&mut sim, 400) {
            Ok(()) => {
                assert!(inside_domain(&sim), "{mode:?}: a particle left the grid");
                let g = sim.grid_geom();
                let n = sim.scene().grid.resolution as f64;
                for x in &sim.particles().vert.x {
                    let cell = x / g.dx;
                    assert!(
                        (cell.x - 0.5).floor() >= 0.0 && (cell.x - 0.5).floor() <= n - 3.0,
                        "{mode:?}: stencil off the grid at {x:?}"
                    );
                }
                if mode != WallMode::None {
                    // Walls stop the bundle: it cannot keep its speed.
                    let ke = sim.diagnostics().kinetic_energy;
                    let m = sim.diagnostics().total_mass;
                    assert!(ke < 0.5 * m * 100.0 * 100.0, "{mode:?}: KE {ke}");
                }
            }
            Err(e) => eprintln!("{mode:?}: clear failure: {e}"),
        }
    }
    // 1000 m/s moves 6 cells per substep: the CFL guard must name step 1.
    let mut sim = YarnSim::new(&wall_scene(WallMode::Sticky, 1000.0)).unwrap();
    let e = run_checked(&mut sim, 10).expect_err("6 cells per substep must be refused");
    assert!(matches!(e, SimError::NonFinite { step: 1, .. }), "{e}");
}

#[test]
fn huge_gravity_is_bounded_or_refused() {
    let base = yarnsim_evidence::small_yarn_scene(3, 40, 64);
    let mut sim = YarnSim::new(&base).unwrap();
    // Beyond the documented limit: refused, state untouched.
    assert!(matches!(
        sim.set_gravity(Vec2::new(0.0, -1e7)),
        Err(SimError::BadInput(_))
    ));
    assert!(sim.set_gravity(Vec2::new(0.0, f64::NAN)).is_err());
    assert_eq!(sim.gravity(), Vec2::new(0.0, -9.8));
    // 1e4 m/s^2 (1000 g) is accepted; the bundle slams into the circle and walls.
    sim.set_gravity(Vec2::new(0.0, -1e4)).unwrap();
    let dx = sim.grid_geom().dx;
    match run_checked(&mut sim, 1000) {
        Ok(()) => {
            assert!(inside_domain(&sim));
            assert!(max_penetration(&sim) <= dx, "{}", max_penetration(&sim));
        }
        Err(e) => eprintln!("huge gravity: clear failure: {e}"),
    }
    // 1e6 m/s^2 at this dt moves far more than a cell per substep within a
    // few steps: bounded, or refused with the step named.
    let mut sim = YarnSim::new(&base).unwrap();
    sim.set_gravity(Vec2::new(0.0, -1e6)).unwrap();
    match run_checked(&mut sim, 200) {
        Ok(()) => assert!(inside_domain(&sim)),
        Err(e) => eprintln!("gravity 1e6: clear failure: {e}"),
    }
}

#[test]
fn attractor_inside_an_obstacle_cannot_pull_yarn_into_it() {
    let base = yarnsim_evidence::small_yarn_scene(3, 40, 64);
    let mut sim = YarnSim::new(&base).unwrap();
    let o = base.obstacles[0].clone();
    sim.set_attractor(Attractor {
        position: Vec2::from(o.center),
        strength: 1e3,
        active: true,
    })
    .unwrap();
    assert!(sim.passes().attractor);
    let dx = sim.grid_geom().dx;
    match run_checked(&mut sim, 1500) {
        Ok(()) => {
            let pen = max_penetration(&sim);
            assert!(pen <= dx, "penetration {pen} > dx {dx}");
            assert!(inside_domain(&sim));
            // The yarn did get pulled onto the circle.
            let c = Vec2::from(o.center);
            let closest = sim
                .particles()
                .vert
                .x
                .iter()
                .map(|x| (x - c).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(closest < o.radius + 3.0 * dx, "closest {closest}");
        }
        Err(e) => eprintln!("attractor in obstacle: clear failure: {e}"),
    }
    // Non-finite attractor inputs are refused.
    assert!(sim
        .set_attractor(Attractor {
            position: Vec2::new(f64::NAN, 0.5),
            strength: 1.0,
            active: true
        })
        .is_err());
}

/// The built-in cloth stretched 10x away from its pinned edge and released
/// for 30 frames (1 s).
fn cloth_stretched_ten_times_and_released(integ: Integrator) {
    {
        let mut sim =
            Simulation::new(&scenes::cloth(), integ, IntegratorOptions::default()).unwrap();
        // Stretch 10x away from the pinned edge (z = 5); pins stay put.
        for x in sim.state_mut().x.iter_mut() {
            x.z = 5.0 + (x.z - 5.0) * 10.0;
        }
        let strain0 = sim.max_strain();
        assert!(strain0 > 8.0, "{strain0}");
        let e0 = sim.energies().total();
        let mut outcome = Ok(());
        for _ in 0..30 {
            if let Err(e) = sim.step_frame() {
                outcome = Err(e);
                break;
            }
        }
        match outcome {
            Ok(()) => {
                assert!(sim
                    .positions()
                    .iter()
                    .chain(sim.velocities())
                    .all(|p| p.iter().all(|c| c.is_finite())));
                // Bounded: no energy created (kinetic + elastic + gravity;
                // 0.99 velocity damping per frame only removes energy) and
                // every particle within 10 stretched extents of the pins.
                let e = sim.energies().total();
                assert!(e <= e0 + 0.05 * e0.abs(), "{integ}: energy {e} > {e0}");
                assert!(
                    sim.positions()
                        .iter()
                        .all(|p| (p - sim.system().positions[0]).norm() < 1e3),
                    "{integ}: unbounded positions"
                );
                eprintln!(
                    "{integ}: max strain {strain0:.2} -> {:.2}, energy {e0:.4e} -> {e:.4e}",
                    sim.max_strain()
                );
            }
            Err(e) => {
                assert!(
                    integ != Integrator::BackwardEuler,
                    "backward Euler must survive: {e}"
                );
                match &e {
                    MassSpringError::Diverged { step, .. } => {
                        assert!(*step > 0 && e.to_string().contains("step"), "{e}")
                    }
                    MassSpringError::Solver { .. } => assert!(e.to_string().contains("t =")),
                    other => panic!("{integ}: unexpected error {other}"),
                }
                eprintln!("{integ}: clear failure: {e}");
            }
        }
    }
}

/// One test per integrator, each [`cloth_stretched_ten_times_and_released`]
/// (`name: Integrator variant;`, attributes before the name).
macro_rules! cloth_stretched_ten_times_tests {
    ($($(#[$attr:meta])* $name:ident: $integ:ident;)*) => {
        $(
            #[test]
            $(#[$attr])*
            fn $name() {
                cloth_stretched_ten_times_and_released(Integrator::$integ);
            }
        )*
    };
}

cloth_stretched_ten_times_tests! {
    cloth_stretched_ten_times_backward_euler: BackwardEuler;
    cloth_stretched_ten_times_chebyshev_jacobi: ChebyshevJacobi;
    cloth_stretched_ten_times_symplectic_euler: SymplecticEuler;
    cloth_stretched_ten_times_pbd: Pbd;
    #[ignore = "massspring (reported): trapezoidal at the cloth's h = 1/30 s gains energy on a 10x-stretched cloth (6.38e7 -> 6.90e7 J after 30 frames, +8%) and reports success; the stress study finds it stable on the cloth only up to dt ~ 0.020 s"]
    cloth_stretched_ten_times_trapezoidal: Trapezoidal;
}
