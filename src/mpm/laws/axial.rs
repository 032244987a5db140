//! The fibre-stretch (axial) term of the yarn energy on one segment, as a
//! spring between its two vertices: energy, gradient and the PSD Hessian
//! block that the vertex solves use.
//!
//! In the energy of Jiang, Gast, Teran 2017 ([`super::constitutive`]) the
//! `k` term `k / 2 (r11 - 1)^2` depends on the fibre edge `d1` alone:
//! `r11 = |d1| / l0` for `G = d / l0`, so on a segment of volume `vol` it
//! is the spring energy
//!
//! ```text
//! E(e) = a / 2 (|e| / l0 - 1)^2,   a = vol k,   e = x_right - x_left
//! ```
//!
//! with `dE/de = a (|e| / l0 - 1) / (l0 |e|) e`, the `k` part of the
//! constitutive law's `t1 = dE/dd1` (checked in the tests below). Its
//! Hessian `a / l0^2 u u^T + a (|e| / l0 - 1) / (l0 |e|) (I - u u^T)`
//! (`u = e / |e|`) is indefinite under compression; [`hessian`] drops the
//! negative transverse part (as Choi and Ko 2002, "Stable but responsive
//! cloth", do for a compressed spring), so a Newton system built from it
//! is positive definite.

use crate::math::Vec2;

/// A 2x2 block, row major.
pub type Block = [[f64; 2]; 2];

/// `E(e)` of a segment of stiffness `a = vol k` and rest length `l0`.
#[inline]
pub fn energy(a: f64, l0: f64, e: Vec2) -> f64 {
    let r = e.norm() / l0 - 1.0;
    0.5 * a * r * r
}

/// `dE/de` (zero at `|e| = 0`, where the direction is undefined).
#[inline]
pub fn gradient(a: f64, l0: f64, e: Vec2) -> Vec2 {
    let len = e.norm();
    if len > 0.0 {
        e * (a * (len / l0 - 1.0) / (l0 * len))
    } else {
        Vec2::zeros()
    }
}

/// `d^2E/de^2` with its transverse part clamped at zero (PSD); `None` at
/// `|e| = 0`.
#[inline]
pub fn hessian(a: f64, l0: f64, e: Vec2) -> Option<Block> {
    let len = e.norm();
    if len <= 0.0 {
        return None;
    }
    let u = e / len;
    let axial = a / (l0 * l0);
    let transverse = (a * (len / l0 - 1.0) / (l0 * len)).max(0.0);
    let mut k = [[0.0; 2]; 2];
    for (r, row) in k.iter_mut().enumerate() {
        for (c, k) in row.iter_mut().enumerate() {
            let uu = u[r] * u[c];
            let id = (r == c) as u8 as f64;
            *k = axial * uu + transverse * (id - uu);
        }
    }
    Some(k)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Mat2;
    use crate::mpm::laws::constitutive::{frame_gradient, YarnEnergy};

    /// The spring is the `k` term of the constitutive law: the law's `t1`
    /// with only `k` set equals [`gradient`], and the `k` part of the full
    /// law's `t1` (full minus `k = 0`) too, to 1e-12 relative, for a
    /// stretched and a compressed, sheared frame.
    #[test]
    fn gradient_is_the_k_term_of_the_constitutive_law() {
        let (k, l0, vol) = (1e7, 0.01, 0.01);
        for (stretch, shear) in [(1.003, 0.0), (0.97, 0.2)] {
            let d1 = Vec2::new(0.6, 0.8) * (l0 * stretch);
            let d2 = Vec2::new(-0.8 + shear, 0.6) * (l0 * 0.9);
            let d = Mat2::from_columns(&[d1, d2]);
            let full = YarnEnergy {
                k,
                gamma: 500.0,
                normal: 1400.0,
                friction: 0.3,
            };
            let rest = YarnEnergy { k: 0.0, ..full };
            let only_k = YarnEnergy {
                gamma: 0.0,
                normal: 0.0,
                ..full
            };
            let want = gradient(vol * k, l0, d1);
            let (t_k, _) = frame_gradient(&only_k, &d, l0, vol);
            let (t_full, _) = frame_gradient(&full, &d, l0, vol);
            let (t_rest, _) = frame_gradient(&rest, &d, l0, vol);
            let scale = want.norm();
            assert!((t_k - want).norm() < 1e-12 * scale, "{t_k:?} vs {want:?}");
            let diff = t_full - t_rest;
            assert!((diff - want).norm() < 1e-12 * scale, "{diff:?} vs {want:?}");
        }
    }

    /// [`gradient`] against central differences of [`energy`], and
    /// [`hessian`] against central differences of [`gradient`] in tension
    /// (where no projection acts), 1e-6 relative.
    #[test]
    fn derivatives_match_finite_differences() {
        let (a, l0) = (3.0, 0.02);
        let e = Vec2::new(0.013, -0.016);
        let h = 1e-7;
        let g = gradient(a, l0, e);
        let hs = hessian(a, l0, e).unwrap();
        for i in 0..2 {
            let mut p = e;
            let mut m = e;
            p[i] += h;
            m[i] -= h;
            let fd = (energy(a, l0, p) - energy(a, l0, m)) / (2.0 * h);
            assert!((fd - g[i]).abs() < 1e-6 * g.norm(), "{fd} vs {}", g[i]);
            let fdg = (gradient(a, l0, p) - gradient(a, l0, m)) / (2.0 * h);
            for r in 0..2 {
                assert!((fdg[r] - hs[r][i]).abs() < 1e-6 * a / (l0 * l0));
            }
        }
    }
}
