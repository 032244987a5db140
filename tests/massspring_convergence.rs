//! Observed order of convergence of each integrator from three step sizes:
//! `p = log2(|x_h - x_{h/2}| / |x_{h/2} - x_{h/4}|)`, 1 for the Euler
//! schemes (forward, symplectic, backward, and backward Euler's
//! minimisation form), 2 for the trapezoidal rule.

mod common;

use common::solved_options;
use yarnsim::massspring::{scenes, Integrator, MassSpringScene, Simulation, V3};

/// Baraff and Witkin 1998's three particles with damped springs (so the damping force
/// and its Jacobian take part), in free flight under gravity.
fn damped_three_particle() -> MassSpringScene {
    let mut l = scenes::three_particle();
    for s in &mut l.springs {
        s.damping = 2.0;
    }
    l
}

/// Positions and velocities at `t_end` with step `h`.
fn end_state(layout: &MassSpringScene, integ: Integrator, h: f64, t_end: f64) -> Vec<f64> {
    // Chebyshev-Jacobi: each step's minimisation solved to round-off, so
    // that the error is the scheme's and not the iteration's.
    let o = solved_options(integ, h, 1e-14, 4000);
    let mut sim = Simulation::new(layout, integ, o).unwrap();
    let n = sim.run_to(t_end).unwrap();
    assert!(
        (n as f64 * h - t_end).abs() < 1e-9 * t_end,
        "{n} steps of {h}"
    );
    let x: Vec<V3> = sim.positions().to_vec();
    let v: Vec<V3> = sim.velocities().to_vec();
    x.iter().chain(&v).flat_map(|p| [p.x, p.y, p.z]).collect()
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

/// Observed order from the step sizes `h, h/2, h/4`.
fn observed_order(layout: &MassSpringScene, integ: Integrator, h: f64, t_end: f64) -> f64 {
    let a = end_state(layout, integ, h, t_end);
    let b = end_state(layout, integ, h / 2.0, t_end);
    let c = end_state(layout, integ, h / 4.0, t_end);
    let (d1, d2) = (distance(&a, &b), distance(&b, &c));
    assert!(
        d2 > 1e-11,
        "{integ}: differences {d1:e} {d2:e} too small to measure"
    );
    (d1 / d2).log2()
}

/// Asserts the observed order of each `(integrator, expected)` on `layout`
/// (step `h`, to `t_end`) within `tolerance`; `label` names the scene.
fn assert_orders(
    label: &str,
    layout: &MassSpringScene,
    (h, t_end): (f64, f64),
    cases: &[(Integrator, f64)],
    tolerance: f64,
) {
    for &(integ, expected) in cases {
        let p = observed_order(layout, integ, h, t_end);
        eprintln!(
            "{label}{integ}: observed order {p:.4} (h = {h}, {}, {})",
            h / 2.0,
            h / 4.0
        );
        assert!(
            (p - expected).abs() < tolerance,
            "{integ}: order {p}, expected {expected}"
        );
    }
}

#[test]
// Thousands of projection passes / Jacobi iterations: release only.
#[cfg_attr(debug_assertions, ignore)]
fn observed_order_is_one_for_the_euler_schemes_and_two_for_trapezoidal() {
    assert_orders(
        "",
        &damped_three_particle(),
        (0.004, 1.0),
        &[
            (Integrator::ForwardEuler, 1.0),
            (Integrator::SymplecticEuler, 1.0),
            (Integrator::BackwardEuler, 1.0),
            (Integrator::ChebyshevJacobi, 1.0),
            (Integrator::Trapezoidal, 2.0),
        ],
        0.1,
    );
}

#[test]
// Thousands of projection passes / Jacobi iterations: release only.
#[cfg_attr(debug_assertions, ignore)]
fn observed_order_on_the_driven_damped_wire() {
    // The stiff wire (damping rate up to about 4400 1/s; forward Euler's
    // bound is 4.7e-4 s): every scheme reaches its asymptotic order once h
    // resolves it. Driven end, damping and the Hessian clamp all take part.
    assert_orders(
        "wire ",
        &scenes::wire(),
        (2e-4, 0.2),
        &[
            (Integrator::BackwardEuler, 1.0),
            (Integrator::Trapezoidal, 2.0),
            (Integrator::SymplecticEuler, 1.0),
            (Integrator::ForwardEuler, 1.0),
        ],
        0.15,
    );
}
