//! Linear and iterative solvers of the mass-spring integrators: IC(0)-PCG on
//! the wire, Baraff and Witkin 1998's 3-particle system against a dense direct solve,
//! Chebyshev against plain Jacobi. Unit tests: they call the solvers, which
//! are the crate's machinery, not its API (moved from `tests/`).

use crate::massspring::integrators::chebyshev;
use crate::massspring::integrators::implicit::{step_system, Scheme};
use crate::massspring::linear::{dense_solve, pcg, Preconditioner};
use crate::massspring::{
    scenes, Integrator, IntegratorOptions, PreconditionerKind, Simulation, State, V3,
};
use nalgebra::{DMatrix, DVector, Matrix3};

#[test]
fn ic0_pcg_on_the_driven_wire_converges_in_one_iteration() {
    for integ in [Integrator::BackwardEuler, Integrator::Trapezoidal] {
        let mut iters = Vec::new();
        for pc in [PreconditionerKind::Ic0, PreconditionerKind::Jacobi] {
            let opts = IntegratorOptions {
                preconditioner: pc,
                cg_tolerance: 1e-10,
                ..Default::default()
            };
            let mut sim = Simulation::new(&scenes::wire(), integ, opts).unwrap();
            let mut per_step = Vec::new();
            for _ in 0..20 {
                let f = sim.step_frame().unwrap();
                per_step.push(f.cg_iterations as f64 / f.steps as f64);
                assert!(f.last_step.cg_residual <= 1e-10);
            }
            iters.push(per_step);
        }
        eprintln!(
            "{integ}: CG iterations per step, IC(0) {:?}, Jacobi mean {:.2}",
            &iters[0][..3],
            iters[1].iter().sum::<f64>() / iters[1].len() as f64
        );
        // Block-tridiagonal A: IC(0) is the exact Cholesky factor.
        assert!(
            iters[0].iter().all(|&n| n == 1.0),
            "{integ}: {:?}",
            iters[0]
        );
        assert!(iters[1].iter().all(|&n| n > 2.0), "{integ}: {:?}", iters[1]);
    }
}

/// Baraff and Witkin 1998's block `K^s_ij = E/l^2 ((l-L)/l dx^T dx I + (1 - (l-L)/l) dx dx^T)`.
fn baraff_witkin_block(e: f64, rest: f64, dx: V3) -> Matrix3<f64> {
    let l = dx.norm();
    let r = (l - rest) / l;
    (Matrix3::identity() * (r * dx.dot(&dx)) + dx * dx.transpose() * (1.0 - r)) * (e / (l * l))
}

#[test]
fn three_particle_backward_euler_matches_baraff_witkin_and_a_direct_solve() {
    let layout = scenes::three_particle();
    let sys = layout.build().unwrap();
    let st = State::initial(&sys);
    let h = 0.1;
    // Baraff and Witkin 1998, written out: f, K (force Jacobian), A = M - h^2 K, b = M v + h f.
    let x = &st.x;
    let v = &st.v;
    let g = sys.gravity;
    let m = &sys.masses;
    let e = 50.0;
    let (l01, l12) = (0.9, 0.8);
    let dx01 = x[1] - x[0];
    let dx12 = x[2] - x[1];
    let f01 = dx01 * (e * (dx01.norm() - l01) / dx01.norm());
    let f12 = dx12 * (e * (dx12.norm() - l12) / dx12.norm());
    let f = [g * m[0] + f01, g * m[1] - f01 + f12, g * m[2] - f12];
    let k01 = baraff_witkin_block(e, l01, dx01);
    let k12 = baraff_witkin_block(e, l12, dx12);
    let mut kk = DMatrix::<f64>::zeros(9, 9);
    let mut put = |i: usize, j: usize, b: Matrix3<f64>| {
        for r in 0..3 {
            for c in 0..3 {
                kk[(3 * i + r, 3 * j + c)] += b[(r, c)];
            }
        }
    };
    put(0, 0, -k01);
    put(0, 1, k01);
    put(1, 0, k01);
    put(1, 1, -k01 - k12);
    put(1, 2, k12);
    put(2, 1, k12);
    put(2, 2, -k12);
    let mut mm = DMatrix::<f64>::zeros(9, 9);
    for i in 0..9 {
        mm[(i, i)] = m[i / 3];
    }
    let a = &mm - &kk * (h * h);
    let mut b = DVector::<f64>::zeros(9);
    for i in 0..3 {
        for c in 0..3 {
            b[3 * i + c] = m[i] * v[i][c] + h * f[i][c];
        }
    }
    let direct = dense_solve(&a, &b).unwrap();

    // Our assembled system (for dv = v' - v) has the same matrix.
    let ss = step_system(&sys, &st, h, Scheme::BackwardEuler);
    let ours = ss.matrix.to_dense();
    assert!((&ours - &a).abs().max() < 1e-12, "{ours}\nvs\n{a}");
    assert!(ss.matrix.asymmetry() == 0.0);
    // CG (both preconditioners) agrees with the direct solve.
    for pc in [
        PreconditionerKind::None,
        PreconditionerKind::Jacobi,
        PreconditionerKind::Ic0,
    ] {
        let pre = Preconditioner::new(pc, &ss.matrix);
        let mut dv = vec![0.0; 9];
        let r = pcg(&ss.matrix, &ss.rhs, &mut dv, &pre, 1e-14, 100);
        assert!(r.converged && r.iterations <= 9, "{pc}: {r:?}");
        for i in 0..9 {
            let vnew = v[i / 3][i % 3] + dv[i];
            assert!((vnew - direct[i]).abs() < 1e-12, "{pc} {i}");
        }
        eprintln!("three-particle {pc}: {} CG iterations", r.iterations);
    }
    // And the integrator's step ends with exactly that velocity, x' = x + h v'.
    let opts = IntegratorOptions {
        dt: Some(h),
        cg_tolerance: 1e-14,
        ..Default::default()
    };
    let mut sim = Simulation::new(&layout, Integrator::BackwardEuler, opts).unwrap();
    sim.step(h).unwrap();
    for i in 0..9 {
        let (p, c) = (i / 3, i % 3);
        assert!((sim.velocities()[p][c] - direct[i]).abs() < 1e-12);
        assert!((sim.positions()[p][c] - (x[p][c] + h * direct[i])).abs() < 1e-12);
    }
}

#[test]
fn chebyshev_reduces_the_residual_faster_than_plain_jacobi() {
    // A deformed cloth state: a few frames of the cloth model.
    let mut sim = Simulation::new(
        &scenes::cloth(),
        Integrator::ChebyshevJacobi,
        IntegratorOptions::default(),
    )
    .unwrap();
    for _ in 0..5 {
        sim.step_frame().unwrap();
    }
    let sys = sim.system().clone();
    let h = sys.time_step;
    let mut results = Vec::new();
    for rho in [0.0, 0.995] {
        let mut s = sim.state().clone();
        let mut hist = Vec::new();
        chebyshev::step(&sys, &mut s, h, rho, 32, Some(&mut hist));
        results.push(hist);
    }
    let (jac, cheb) = (&results[0], &results[1]);
    eprintln!(
        "gradient norm: start {:.4e}; after 32 iterations Jacobi {:.4e}, Chebyshev {:.4e} (ratio {:.3})",
        jac[0],
        jac[32],
        cheb[32],
        cheb[32] / jac[32]
    );
    assert_eq!(jac[0], cheb[0]);
    assert!(cheb[32] < 0.5 * jac[32], "{} vs {}", cheb[32], jac[32]);
    // rho = 0 is plain Jacobi: every weight is 1.
    assert!(chebyshev::chebyshev_weights(0.0, 32)
        .iter()
        .all(|&w| w == 1.0));
}
