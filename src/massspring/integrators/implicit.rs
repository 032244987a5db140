//! Backward Euler and the trapezoidal rule with the velocity system solved by
//! preconditioned CG (course notes; Baraff and Witkin 1998).
//!
//! Both schemes solve, for the velocity change `dv` of the free particles,
//! `M dv = h [(1 - theta) f(x, v) + theta f(x + dx, v + dv)]` with
//! `dx = h v + c dv` (`theta = 1, c = h` for backward Euler;
//! `theta = 1/2, c = h/2` for the trapezoidal rule, so that
//! `x' = x + h/2 (v + v')`). Kinematic particles move to their prescribed
//! state at `t + h` inside `f(x + dx, v + dv)`.
//!
//! Linearising `f` about `(x, v)` with the clamped spring Hessian `H` and the
//! damping block `B` gives the symmetric positive definite system
//! `(M + theta h B + theta h c H) dv = h f - theta h (H a + B dv_k)`, `a` being
//! `h v` on free and the prescribed displacement on kinematic particles. One
//! solve is Baraff-Witkin's step; for backward Euler without damping it is
//! exactly Baraff-Witkin's `(M - h^2 K) v' = M v + h f`. The trapezoidal rule
//! keeps the same (clamped, SPD) matrix but multiplies `a` by the exact
//! position Jacobian (unclamped Hessian plus the position derivative of the
//! damping force): with the clamped one `f(x + a) - f(x) + H a = O(h)`
//! wherever a spring is compressed or damped, and the rule would be only
//! first order. (Evaluating `f(x + a)` exactly instead is also second order
//! but blows up on the stiff cloth at h = 1/30 s.) With
//! `newton_iterations > 1`, chord-Newton corrections with the same matrix
//! solve the nonlinear equations to `newton_tolerance`.

use nalgebra::Matrix3;

use super::{set_kinematics, IntegratorOptions, State, StepStats};
use crate::massspring::forces::{add_block_product, damping_block, hessian_block, total_forces};
use crate::massspring::linear::{assemble_block_system, pcg, CsrMatrix, DofMap, Preconditioner};
use crate::massspring::MassSpringError;
use crate::scene::massspring::{System, V3};

/// Which implicit scheme.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scheme {
    /// Backward Euler (Baraff and Witkin 1998): forces at the end of the step.
    BackwardEuler,
    /// The trapezoidal rule: the mean of the forces at both ends of the step.
    Trapezoidal,
}

impl Scheme {
    /// `(theta, c / h)`.
    fn weights(self) -> (f64, f64) {
        match self {
            Scheme::BackwardEuler => (1.0, 1.0),
            Scheme::Trapezoidal => (0.5, 0.5),
        }
    }
}

/// The linear system of one implicit step (its unit tests check it against a direct solve).
#[derive(Clone, Debug)]
pub struct StepSystem {
    /// Which particle dofs are free and where they sit in the system.
    pub map: DofMap,
    /// `M + theta h B + theta h c H` over the free dofs.
    pub matrix: CsrMatrix,
    /// Right-hand side of the first (linearised) solve.
    pub rhs: Vec<f64>,
}

/// Builds the linearised system of an implicit step at state `s`.
pub fn step_system(sys: &System, s: &State, h: f64, scheme: Scheme) -> StepSystem {
    let n = sys.len();
    let (theta, cf) = scheme.weights();
    let c = cf * h;
    let map = DofMap::new(n, |i| sys.is_free(i));
    let mut f = vec![V3::zeros(); n];
    total_forces(sys, &s.x, &s.v, &mut f);
    let (a, dvk) = known_parts(sys, s, h);
    let hb: Vec<Matrix3<f64>> = sys
        .springs
        .iter()
        .map(|sp| hessian_block(&s.x, sp, true))
        .collect();
    let bb: Vec<Matrix3<f64>> = sys
        .springs
        .iter()
        .map(|sp| damping_block(&s.x, sp))
        .collect();
    let blocks: Vec<Matrix3<f64>> = hb
        .iter()
        .zip(&bb)
        .map(|(hs, bs)| hs * (theta * h * c) + bs * (theta * h))
        .collect();
    let matrix = assemble_block_system(&map, &sys.masses, &sys.springs, &blocks);
    // f(x + a, v + dv_k) ~ f - corr, corr = J a + B dv_k.
    let mut corr = vec![V3::zeros(); n];
    match scheme {
        Scheme::BackwardEuler => {
            // Baraff-Witkin 1998: the clamped Hessian for J.
            add_block_product(&sys.springs, &hb, &a, &mut corr);
        }
        Scheme::Trapezoidal => {
            // The exact position Jacobian (unclamped Hessian and the
            // position derivative of the damping force): with the clamped
            // one the O(h) displacement a would carry an O(h^2) error into
            // every step and the rule would be first order.
            let exact: Vec<Matrix3<f64>> = sys
                .springs
                .iter()
                .map(|sp| hessian_block(&s.x, sp, false) + damping_position_block(&s.x, &s.v, sp))
                .collect();
            add_block_product(&sys.springs, &exact, &a, &mut corr);
        }
    }
    add_block_product(&sys.springs, &bb, &dvk, &mut corr);
    let mut rhs = vec![0.0; map.dofs()];
    for (fi, &p) in map.particle.iter().enumerate() {
        let r = f[p] * h - corr[p] * (theta * h);
        rhs[3 * fi..3 * fi + 3].copy_from_slice(r.as_slice());
    }
    StepSystem { map, matrix, rhs }
}

/// `G = -df_a/dx_a = df_a/dx_b` of the damping force
/// `f_a = b d (d . u)`, `u = v_b - v_a`: `G = b/l [(d . u) P + d (P u)^T]`,
/// `P = I - d d^T` (not symmetric; used only in products).
fn damping_position_block(
    x: &[V3],
    v: &[V3],
    sp: &crate::scene::massspring::Spring,
) -> Matrix3<f64> {
    let dx = x[sp.b] - x[sp.a];
    let l = dx.norm();
    if sp.damping == 0.0 || l == 0.0 {
        return Matrix3::zeros();
    }
    let d = dx / l;
    let u = v[sp.b] - v[sp.a];
    let p = Matrix3::identity() - d * d.transpose();
    (p * d.dot(&u) + d * (p * u).transpose()) * (sp.damping / l)
}

/// `a` (explicit part of the displacement) and the kinematic velocity change.
fn known_parts(sys: &System, s: &State, h: f64) -> (Vec<V3>, Vec<V3>) {
    let n = sys.len();
    let mut a = vec![V3::zeros(); n];
    let mut dvk = vec![V3::zeros(); n];
    for i in 0..n {
        match sys.kinematics[i].at(s.t + h) {
            None => a[i] = s.v[i] * h,
            Some((x1, v1)) => {
                a[i] = x1 - s.x[i];
                dvk[i] = v1 - s.v[i];
            }
        }
    }
    (a, dvk)
}

/// One implicit step.
pub fn step(
    sys: &System,
    s: &mut State,
    h: f64,
    scheme: Scheme,
    opt: &IntegratorOptions,
) -> Result<StepStats, MassSpringError> {
    let n = sys.len();
    let (theta, cf) = scheme.weights();
    let c = cf * h;
    let mut stats = StepStats::new(h);
    let ss = step_system(sys, s, h, scheme);
    let pre = Preconditioner::new(opt.preconditioner, &ss.matrix);
    let nd = ss.map.dofs();
    // One CG solve of the step's matrix, counted in the statistics.
    let solve = |rhs: &[f64], x: &mut [f64], stats: &mut StepStats| {
        let r = pcg(
            &ss.matrix,
            rhs,
            x,
            &pre,
            opt.cg_tolerance,
            opt.cg_max_iterations,
        );
        stats.cg_iterations += r.iterations;
        stats.cg_residual = r.relative_residual;
        stats.linear_solves += 1;
        r
    };
    let mut dv = vec![0.0; nd];
    let r = solve(&ss.rhs, &mut dv, &mut stats);
    // A solve stopped by the iteration cap is accepted when it got close
    // (the step then carries that residual in its statistics).
    let close = r.relative_residual < 1e-3;
    if !r.converged && !close {
        return Err(MassSpringError::Solver {
            time: s.t,
            message: format!(
                "CG did not converge: relative residual {:.3e} after {} iterations",
                r.relative_residual, r.iterations
            ),
        });
    }
    let (a, dvk) = known_parts(sys, s, h);
    let mut f0 = vec![V3::zeros(); n];
    total_forces(sys, &s.x, &s.v, &mut f0);
    let scale = f0
        .iter()
        .enumerate()
        .filter(|(i, _)| sys.is_free(*i))
        .map(|(_, f)| (f * h).norm_squared())
        .sum::<f64>()
        .sqrt()
        .max(f64::MIN_POSITIVE);
    // Trial state for a given dv.
    let trial = |dv: &[f64]| -> (Vec<V3>, Vec<V3>) {
        let mut x1 = s.x.clone();
        let mut v1 = s.v.clone();
        for i in 0..n {
            match ss.map.index[i] {
                Some(fi) => {
                    let d = V3::new(dv[3 * fi], dv[3 * fi + 1], dv[3 * fi + 2]);
                    x1[i] = s.x[i] + a[i] + d * c;
                    v1[i] = s.v[i] + d;
                }
                None => {
                    x1[i] = s.x[i] + a[i];
                    v1[i] = s.v[i] + dvk[i];
                }
            }
        }
        (x1, v1)
    };
    for _ in 1..opt.newton_iterations {
        let (x1, v1) = trial(&dv);
        let mut f1 = vec![V3::zeros(); n];
        total_forces(sys, &x1, &v1, &mut f1);
        let mut res = vec![0.0; nd];
        let mut rn = 0.0;
        for (fi, &p) in ss.map.particle.iter().enumerate() {
            let d = V3::new(dv[3 * fi], dv[3 * fi + 1], dv[3 * fi + 2]);
            let rv = (f0[p] * (1.0 - theta) + f1[p] * theta) * h - d * sys.masses[p];
            rn += rv.norm_squared();
            res[3 * fi..3 * fi + 3].copy_from_slice(rv.as_slice());
        }
        stats.newton_residual = rn.sqrt() / scale;
        if stats.newton_residual <= opt.newton_tolerance {
            break;
        }
        let mut delta = vec![0.0; nd];
        solve(&res, &mut delta, &mut stats);
        for (d, e) in dv.iter_mut().zip(&delta) {
            *d += e;
        }
    }
    let (x1, v1) = trial(&dv);
    s.x = x1;
    s.v = v1;
    set_kinematics(sys, s.t + h, &mut s.x, &mut s.v);
    Ok(stats)
}
