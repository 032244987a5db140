//! Spring, damping and gravity forces, their energies, and the per-spring
//! 3x3 Hessian blocks the implicit integrators assemble.
//!
//! Conventions: for a spring between `a` and `b` with `d = (x_b - x_a) / l`,
//! the elastic force on `a` is `k (l - l0) d` (course notes: `E (l/l0 - 1)` with
//! `k = E / l0`; Baraff-Witkin: `E (l - L)/l dx`), the damping force on `a` is
//! `b d d^T (v_b - v_a)`, and `b` gets the opposite of both.
//! The energy Hessian block is
//! `H = k [d d^T + max(0, 1 - l0/l) (I - d d^T)]`: Baraff and Witkin 1998's `K^s` with the
//! transverse term clamped at 0 under compression so that `H` stays positive
//! semi-definite; the force Jacobian is `df_a/dx_a = -H`, `df_a/dx_b = +H`.

use nalgebra::Matrix3;

use crate::scene::massspring::{Spring, System, V3};

/// Unit direction and length of a spring, `None` when its ends coincide.
#[inline]
pub fn direction(x: &[V3], s: &Spring) -> Option<(V3, f64)> {
    let dx = x[s.b] - x[s.a];
    let l = dx.norm();
    if l > 0.0 {
        Some((dx / l, l))
    } else {
        None
    }
}

/// Unit direction of every spring at positions `x` (zero for a spring whose
/// ends coincide).
pub fn unit_directions(springs: &[Spring], x: &[V3]) -> Vec<V3> {
    springs
        .iter()
        .map(|s| direction(x, s).map_or(V3::zeros(), |(d, _)| d))
        .collect()
}

/// Adds the elastic spring forces at positions `x` to `f`.
pub fn add_elastic_forces(springs: &[Spring], x: &[V3], f: &mut [V3]) {
    for s in springs {
        if let Some((d, l)) = direction(x, s) {
            let fa = d * (s.k * (l - s.rest_length));
            f[s.a] += fa;
            f[s.b] -= fa;
        }
    }
}

/// Adds the spring damping forces `b d d^T (v_b - v_a)` (on `a`) to `f`.
pub fn add_damping_forces(springs: &[Spring], x: &[V3], v: &[V3], f: &mut [V3]) {
    for s in springs {
        if s.damping == 0.0 {
            continue;
        }
        if let Some((d, _)) = direction(x, s) {
            let fa = d * (s.damping * d.dot(&(v[s.b] - v[s.a])));
            f[s.a] += fa;
            f[s.b] -= fa;
        }
    }
}

/// Total force (elastic + damping + gravity) at `(x, v)`, written into `f`.
pub fn total_forces(sys: &System, x: &[V3], v: &[V3], f: &mut [V3]) {
    for (fi, &m) in f.iter_mut().zip(&sys.masses) {
        *fi = sys.gravity * m;
    }
    add_elastic_forces(&sys.springs, x, f);
    add_damping_forces(&sys.springs, x, v, f);
}

/// Energy Hessian block `k [d d^T + max(0, 1 - l0/l)(I - d d^T)]` (positive
/// semi-definite). `clamp = false` gives Baraff-Witkin's unclamped `K^s`.
pub fn hessian_block(x: &[V3], s: &Spring, clamp: bool) -> Matrix3<f64> {
    match direction(x, s) {
        Some((d, l)) => {
            let ddt = d * d.transpose();
            let mut t = 1.0 - s.rest_length / l;
            if clamp {
                t = t.max(0.0);
            }
            (ddt + (Matrix3::identity() - ddt) * t) * s.k
        }
        // Coincident ends: no direction; the isotropic part of the clamped form.
        None => Matrix3::zeros(),
    }
}

/// Damping Jacobian block `b d d^T` (`df_a/dv_a = -B`, `df_a/dv_b = +B`).
pub fn damping_block(x: &[V3], s: &Spring) -> Matrix3<f64> {
    match direction(x, s) {
        Some((d, _)) if s.damping != 0.0 => d * d.transpose() * s.damping,
        _ => Matrix3::zeros(),
    }
}

/// `out += sum_s blocks_s (u_a - u_b)` on `a` (and the opposite on `b`): the
/// product of the assembled Laplacian-like matrix with `u`.
pub fn add_block_product(springs: &[Spring], blocks: &[Matrix3<f64>], u: &[V3], out: &mut [V3]) {
    for (s, h) in springs.iter().zip(blocks) {
        let y = h * (u[s.a] - u[s.b]);
        out[s.a] += y;
        out[s.b] -= y;
    }
}

/// Elastic energy `sum 1/2 k (l - l0)^2` in J.
pub fn elastic_energy(springs: &[Spring], x: &[V3]) -> f64 {
    springs
        .iter()
        .map(|s| {
            let l = (x[s.b] - x[s.a]).norm();
            0.5 * s.k * (l - s.rest_length).powi(2)
        })
        .sum()
}

/// Gravitational potential `-sum m g . x` in J.
pub fn gravity_energy(sys: &System, x: &[V3]) -> f64 {
    x.iter()
        .zip(&sys.masses)
        .map(|(xi, &m)| -m * sys.gravity.dot(xi))
        .sum()
}

/// Kinetic energy `sum 1/2 m |v|^2` in J.
pub fn kinetic_energy(sys: &System, v: &[V3]) -> f64 {
    v.iter()
        .zip(&sys.masses)
        .map(|(vi, &m)| 0.5 * m * vi.norm_squared())
        .sum()
}

/// Largest relative stretch `|l / l0 - 1|` over all springs (0 without springs).
pub fn max_strain(springs: &[Spring], x: &[V3]) -> f64 {
    springs
        .iter()
        .map(|s| ((x[s.b] - x[s.a]).norm() / s.rest_length - 1.0).abs())
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spring(k: f64, l0: f64) -> Spring {
        Spring {
            a: 0,
            b: 1,
            k,
            damping: 0.0,
            rest_length: l0,
        }
    }

    /// The Hessian block is minus the finite-difference Jacobian of the force.
    #[test]
    fn hessian_is_force_jacobian_when_stretched() {
        let s = spring(7.0, 0.8);
        let x = vec![V3::new(0.1, 0.2, -0.3), V3::new(1.0, -0.4, 0.5)];
        let h = hessian_block(&x, &s, true);
        let eps = 1e-6;
        for c in 0..3 {
            let mut xp = x.clone();
            let mut xm = x.clone();
            xp[0][c] += eps;
            xm[0][c] -= eps;
            let (mut fp, mut fm) = (vec![V3::zeros(); 2], vec![V3::zeros(); 2]);
            add_elastic_forces(&[s], &xp, &mut fp);
            add_elastic_forces(&[s], &xm, &mut fm);
            let col = (fp[0] - fm[0]) / (2.0 * eps);
            for r in 0..3 {
                assert!((col[r] + h[(r, c)]).abs() < 1e-6, "{r} {c}");
            }
        }
    }

    /// Under compression the unclamped block is indefinite, the clamped one is not.
    #[test]
    fn clamp_keeps_hessian_semidefinite_under_compression() {
        let s = spring(10.0, 2.0);
        let x = vec![V3::zeros(), V3::new(1.0, 0.0, 0.0)];
        let raw = hessian_block(&x, &s, false).symmetric_eigenvalues();
        let clamped = hessian_block(&x, &s, true).symmetric_eigenvalues();
        assert!(raw.min() < -1.0, "{raw}");
        assert!(clamped.min() >= 0.0, "{clamped}");
        // The axial stiffness k survives the clamp.
        assert!((clamped.max() - 10.0).abs() < 1e-12);
    }

    #[test]
    fn energies_of_a_stretched_spring() {
        let s = spring(4.0, 1.0);
        let x = vec![V3::zeros(), V3::new(0.0, 1.5, 0.0)];
        assert!((elastic_energy(&[s], &x) - 0.5).abs() < 1e-15);
        assert!((max_strain(&[s], &x) - 0.5).abs() < 1e-15);
    }
}
