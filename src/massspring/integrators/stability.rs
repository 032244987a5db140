//! The explicit schemes' stability bound (the course notes' `Maximum_Dt`, computed
//! from the scene instead of estimated per spring).
//!
//! Linearised about a configuration, the axial spring forces give
//! `M x'' = -K x - B x'` with `K = sum k_s d d^T`, `B = sum b_s d d^T`
//! (Laplacian-like over the free particles). When every spring has the same
//! ratio `tau = b/k` ("proportional" damping, true of the built-in scenes),
//! each mode of `M^{-1} K` with frequency `w` obeys
//! `q'' = -w^2 q - tau w^2 q'`, and per mode:
//!
//! * forward Euler is stable iff `h <= tau` (underdamped, `tau w <= 2`) or
//!   `h <= 2 / lambda_fast`, `lambda_fast = (tau w^2 + sqrt(tau^2 w^4 - 4 w^2))/2`
//!   (overdamped); the bound is decided by the largest `w`;
//! * symplectic Euler is stable iff `h^2 w^2 + 2 h tau w^2 <= 4`, i.e.
//!   `h <= -tau + sqrt(tau^2 + 4/w^2)`.
//!
//! `w_max^2` is the largest eigenvalue of `M^{-1/2} K M^{-1/2}`, found by
//! Lanczos with full reorthogonalisation (exact when the free dofs are fewer
//! than the Lanczos steps). Without proportional damping the bounds use
//! `tau_min = min b/k` and the largest damping rate `beta_max` of
//! `M^{-1/2} B M^{-1/2}` instead: `min(tau_min, 2/beta_max)` for forward
//! Euler and `(-beta_max + sqrt(beta_max^2 + 4 w^2))/w^2` for symplectic
//! Euler (conservative estimates). Without damping forward Euler has no
//! stable step (`0`).

use nalgebra::{DMatrix, SymmetricEigen};

use crate::massspring::forces::unit_directions;
use crate::massspring::linear::DofMap;
use crate::scene::massspring::{Spring, System, V3};

/// Stability data of a system at a configuration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StabilityInfo {
    /// Largest squared axial angular frequency `w_max^2` in 1/s^2.
    pub omega_max_sq: f64,
    /// The common ratio `b/k` in s when damping is proportional.
    pub damping_ratio: Option<f64>,
    /// Forward Euler's largest stable step in s (infinite without springs).
    pub forward_euler: f64,
    /// Symplectic Euler's largest stable step in s.
    pub symplectic_euler: f64,
}

/// Lanczos steps used for `w_max` (all of them when the system is smaller).
pub const LANCZOS_STEPS: usize = 120;

/// Stability bounds of `sys` linearised at positions `x`.
pub fn analyze(sys: &System, x: &[V3]) -> StabilityInfo {
    let map = DofMap::new(sys.len(), |i| sys.is_free(i));
    let springs: Vec<&Spring> = sys.springs.iter().collect();
    let dirs = unit_directions(&sys.springs, x);
    let inv_sqrt_m: Vec<f64> = map
        .particle
        .iter()
        .map(|&p| 1.0 / sys.masses[p].sqrt())
        .collect();
    let op = |coef: &dyn Fn(&Spring) -> f64, u: &[f64], out: &mut [f64]| {
        out.iter_mut().for_each(|o| *o = 0.0);
        let get = |i: usize| -> V3 {
            match map.index[i] {
                Some(f) => V3::new(u[3 * f], u[3 * f + 1], u[3 * f + 2]) * inv_sqrt_m[f],
                None => V3::zeros(),
            }
        };
        for (s, d) in springs.iter().zip(&dirs) {
            let c = coef(s);
            if c == 0.0 {
                continue;
            }
            let y = d * (c * d.dot(&(get(s.a) - get(s.b))));
            if let Some(f) = map.index[s.a] {
                for k in 0..3 {
                    out[3 * f + k] += y[k] * inv_sqrt_m[f];
                }
            }
            if let Some(f) = map.index[s.b] {
                for k in 0..3 {
                    out[3 * f + k] -= y[k] * inv_sqrt_m[f];
                }
            }
        }
    };
    let dim = map.dofs();
    let w2 = lanczos_max(dim, |u, o| op(&|s: &Spring| s.k, u, o));
    let stiff: Vec<&&Spring> = springs.iter().filter(|s| s.k > 0.0).collect();
    let proportional = stiff.first().and_then(|s0| {
        let tau = s0.damping / s0.k;
        let same = springs.iter().all(|s| {
            if s.k > 0.0 {
                (s.damping / s.k - tau).abs() <= 1e-12 * tau.abs().max(1e-300)
            } else {
                s.damping == 0.0
            }
        });
        same.then_some(tau)
    });
    let (fe, se) = if w2 <= 0.0 {
        (f64::INFINITY, f64::INFINITY)
    } else if let Some(tau) = proportional {
        (fe_bound(tau, w2), -tau + (tau * tau + 4.0 / w2).sqrt())
    } else {
        let tau_min = stiff
            .iter()
            .map(|s| s.damping / s.k)
            .fold(f64::INFINITY, f64::min);
        let beta = lanczos_max(dim, |u, o| op(&|s: &Spring| s.damping, u, o));
        let fe = if tau_min == 0.0 || beta == 0.0 {
            0.0
        } else {
            tau_min.min(2.0 / beta)
        };
        (fe, (-beta + (beta * beta + 4.0 * w2).sqrt()) / w2)
    };
    StabilityInfo {
        omega_max_sq: w2,
        damping_ratio: proportional,
        forward_euler: fe,
        symplectic_euler: se,
    }
}

/// Forward Euler bound for proportional damping `tau` and `w_max^2 = w2`.
pub fn fe_bound(tau: f64, w2: f64) -> f64 {
    let w = w2.sqrt();
    if tau == 0.0 {
        0.0
    } else if tau * w <= 2.0 {
        tau
    } else {
        let lf = 0.5 * (tau * w2 + (tau * tau * w2 * w2 - 4.0 * w2).sqrt());
        2.0 / lf
    }
}

/// Largest eigenvalue of the symmetric positive semi-definite operator `op`
/// of dimension `dim`, by Lanczos with full reorthogonalisation from a fixed
/// start vector (deterministic).
pub fn lanczos_max(dim: usize, op: impl Fn(&[f64], &mut [f64])) -> f64 {
    if dim == 0 {
        return 0.0;
    }
    let steps = dim.min(LANCZOS_STEPS);
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let mut q: Vec<f64> = (0..dim)
        .map(|i| 1.0 + 0.5 * (1.7 * i as f64 + 0.3).sin())
        .collect();
    let qn = dot(&q, &q).sqrt();
    q.iter_mut().for_each(|v| *v /= qn);
    let mut basis: Vec<Vec<f64>> = vec![q];
    let mut alpha = Vec::new();
    let mut beta: Vec<f64> = Vec::new();
    let mut w = vec![0.0; dim];
    let mut scale: f64 = 0.0;
    for j in 0..steps {
        op(&basis[j], &mut w);
        let a = dot(&w, &basis[j]);
        alpha.push(a);
        scale = scale.max(a.abs());
        for _ in 0..2 {
            for qb in &basis {
                let c = dot(&w, qb);
                for (wi, qi) in w.iter_mut().zip(qb) {
                    *wi -= c * qi;
                }
            }
        }
        let b = dot(&w, &w).sqrt();
        if j + 1 == steps || b <= 1e-12 * scale.max(f64::MIN_POSITIVE) {
            break;
        }
        beta.push(b);
        scale = scale.max(b);
        basis.push(w.iter().map(|v| v / b).collect());
    }
    let m = alpha.len();
    let mut t = DMatrix::zeros(m, m);
    for i in 0..m {
        t[(i, i)] = alpha[i];
        if i + 1 < m {
            t[(i, i + 1)] = beta[i];
            t[(i + 1, i)] = beta[i];
        }
    }
    SymmetricEigen::new(t).eigenvalues.max().max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanczos_finds_largest_eigenvalue_of_a_path_laplacian() {
        // Fixed-free chain Laplacian (n x n): eigenvalues 4 sin^2((2j-1) pi / (2(2n+1))).
        let n = 30;
        let op = |u: &[f64], o: &mut [f64]| {
            for i in 0..n {
                let left = if i == 0 { 0.0 } else { u[i - 1] };
                let right = if i + 1 < n { u[i + 1] } else { 0.0 };
                let deg = if i + 1 < n { 2.0 } else { 1.0 };
                o[i] = deg * u[i] - left - right;
            }
        };
        let exact = 4.0
            * ((2 * n - 1) as f64 * std::f64::consts::PI / (2.0 * (2 * n + 1) as f64))
                .sin()
                .powi(2);
        assert!((lanczos_max(n, op) - exact).abs() < 1e-10);
    }

    #[test]
    fn forward_euler_bound_regimes() {
        // Underdamped: tau.
        assert_eq!(fe_bound(0.01, 100.0), 0.01);
        // Overdamped single mode: 2/lambda_fast makes |1 - h lambda_fast| = 1.
        let (tau, w2) = (0.1, 44000.0);
        let h = fe_bound(tau, w2);
        let lf = 0.5 * (tau * w2 + (tau * tau * w2 * w2 - 4.0 * w2).sqrt());
        assert!(((1.0 - h * lf).abs() - 1.0).abs() < 1e-12);
        assert_eq!(fe_bound(0.0, 1.0), 0.0);
    }
}
