//! The anisotropic yarn energy of Jiang, Gast, Teran 2017 and its
//! Mohr-Coulomb return mapping, in the fiber frame.
//!
//! Each quadrature particle has a material frame `d = [d1 | d2]` (fiber edge
//! and normal) with rest frame `D = [D1 | R90 D1]`, `|D1| = l0`. The energy is
//! evaluated on `G = d / l0`, the deformation gradient seen in the fiber frame,
//! so that a yarn's response does not depend on its orientation in the world:
//! with `G = Q R` (Givens QR, `det Q = +1`, `r11 >= 0`)
//!
//! ```text
//! psi(R) = 1/2 k (r11 - 1)^2 + 1/2 gamma r12^2 + 1/2 (2 mu + lambda) (log r22)^2 [r22 < 1]
//! ```
//!
//! and `P = dpsi/dG = Q A R^-T` with `A = (dpsi/dR) R^T` whose upper triangle
//! is mirrored: `A00 = f' r11 + g' r12`, `A01 = A10 = g' r22`, `A11 = h' r22`.
//! In world terms, with `F = d D^-1` and `D = Q_D l0`, `dpsi/dF D^-T = P / l0`.
//!
//! The same stress over the dual-number scalar ([`stress`], [`quad_gradient`])
//! gives the implicit integrators' exact Hessian blocks; `frames.rs` evaluates
//! the law over batches of quadrature particles (vectorized).

pub(crate) mod frames;

use crate::math::dual::Real;
use crate::math::qr::{qr, Qr2};
use crate::math::{Mat2, Vec2};
use crate::scene::Material;

/// `r22` is clamped to at least this before `log r22` and `1 / r22`, so a
/// crushed or inverted cross-section gives a large finite restoring stress
/// instead of NaN.
pub const R22_MIN: f64 = 1e-3;
/// `r11` is clamped to at least this before `1 / r11`.
pub const R11_MIN: f64 = 1e-6;

/// Material constants of the energy.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct YarnEnergy {
    /// Fiber stretch stiffness.
    pub k: f64,
    /// Fiber shear stiffness.
    pub gamma: f64,
    /// Normal (cross-section) stiffness `2 mu + lambda = 1.4 E`.
    pub normal: f64,
    /// Mohr-Coulomb friction coefficient `c_f`.
    pub friction: f64,
}

impl YarnEnergy {
    /// The energy of a scene's material.
    pub fn from_material(m: &Material) -> Self {
        YarnEnergy {
            k: m.k,
            gamma: m.gamma,
            normal: 2.0 * m.mu() + m.lambda(),
            friction: m.friction,
        }
    }

    /// `psi` at the factor `R` (entries `r11, r12, r22`).
    pub fn psi_r(&self, r11: f64, r12: f64, r22: f64) -> f64 {
        let f = 0.5 * self.k * (r11 - 1.0) * (r11 - 1.0);
        let g = 0.5 * self.gamma * r12 * r12;
        let h = if r22 < 1.0 {
            let l = r22.max(R22_MIN).ln();
            0.5 * self.normal * l * l
        } else {
            0.0
        };
        f + g + h
    }

    /// The cross-section's stiffness against further compression at `r22`,
    /// Pa: `d2psi/dr22^2 = (2 mu + lambda) (1 - log r22) / r22^2` for
    /// `r22 < 1` (`r22` clamped to [`R22_MIN`]), and the rest value
    /// `2 mu + lambda` otherwise. A crushed cross-section is stiffer than
    /// the one at rest (6.8x at `r22 = 0.5`, 65x at 0.2): its waves are
    /// faster, and the explicit step's elastic bound shrinks with it.
    pub fn normal_tangent(&self, r22: f64) -> f64 {
        if r22 >= 1.0 {
            return self.normal;
        }
        let r = r22.max(R22_MIN);
        self.normal * (1.0 - r.ln()) / (r * r)
    }

    /// `psi(G)` for a fiber-frame deformation gradient `G`.
    pub fn psi(&self, g: &Mat2) -> f64 {
        let d = qr(g);
        self.psi_r(d.r11, d.r12, d.r22)
    }

    /// First Piola-Kirchhoff stress `P = dpsi/dG = Q A R^-T` from a QR factorisation.
    #[inline]
    pub fn stress_qr(&self, d: &Qr2) -> Mat2 {
        let r11 = d.r11.max(R11_MIN);
        let r22 = d.r22.max(R22_MIN);
        let ln22 = if r22 < 1.0 { r22.ln() } else { 0.0 };
        self.stress_clamped(d.c, d.s, r11, d.r12, r22, ln22)
    }

    /// [`YarnEnergy::stress_qr`] from the rotation `(c, s)`, the clamped
    /// `r11 >= R11_MIN`, `r22 >= R22_MIN`, `r12`, and `ln22 = ln r22` (read
    /// only where `r22 < 1`): the arithmetic after the `ln`, shared with the
    /// batched frame update (`crate::mpm::laws::constitutive::frames`).
    #[inline(always)]
    pub fn stress_clamped(&self, c: f64, s: f64, r11: f64, r12: f64, r22: f64, ln22: f64) -> Mat2 {
        let fp = self.k * (r11 - 1.0);
        let gp = self.gamma * r12;
        // h'(r22) r22 = normal * log r22 for r22 < 1, else 0.
        let hr = if r22 < 1.0 { self.normal * ln22 } else { 0.0 };
        let a00 = fp * r11 + gp * r12;
        let a01 = gp * r22;
        let a11 = hr;
        // A R^-T with R^-T = [[1/r11, 0], [-r12/(r11 r22), 1/r22]]
        let i11 = 1.0 / r11;
        let i22 = 1.0 / r22;
        let i21 = -r12 * i11 * i22;
        let b00 = a00 * i11 + a01 * i21;
        let b01 = a01 * i22;
        let b10 = a01 * i11 + a11 * i21;
        let b11 = a11 * i22;
        // Q B
        Mat2::new(
            c * b00 - s * b10,
            c * b01 - s * b11,
            s * b00 + c * b10,
            s * b01 + c * b11,
        )
    }

    /// `P = dpsi/dG`.
    pub fn stress(&self, g: &Mat2) -> Mat2 {
        self.stress_qr(&qr(g))
    }

    /// Mohr-Coulomb return mapping on `(r12, r22)`, in stress units.
    ///
    /// * `r22 > 1` (cross-section in tension, yarns separated): `r12 = 0`, `r22 = 1`.
    /// * otherwise the shear stress `|A01| = gamma |r12| r22` may not exceed
    ///   `c_f` times the normal pressure `-A11 = -(2 mu + lambda) log r22`;
    ///   `r12` is scaled back onto that yield surface. `r22` is raised to at
    ///   least [`R22_MIN`] so an inverted cross-section is reset.
    #[inline]
    pub fn return_map(&self, r12: f64, r22: f64) -> (f64, f64) {
        if r22 > 1.0 {
            return (0.0, 1.0);
        }
        let r22 = r22.max(R22_MIN);
        // -log r22 >= 1 - r22: a state inside the cone of that lower bound is
        // inside the yield surface, no logarithm needed (the common case).
        if self.gamma * r12.abs() * r22 <= self.friction * self.normal * (1.0 - r22) {
            return (r12, r22);
        }
        let pressure = -self.normal * r22.ln(); // >= 0
        let limit = self.friction * pressure;
        let shear = self.gamma * r12.abs() * r22;
        if shear > limit {
            let r12_max = if self.gamma > 0.0 {
                limit / (self.gamma * r22)
            } else {
                0.0
            };
            (r12.signum() * r12_max, r22)
        } else {
            (r12, r22)
        }
    }

    /// Yield function `gamma |r12| r22 - c_f (-(2 mu + lambda) log r22)`:
    /// `<= 0` inside the elastic region, `0` on the yield surface.
    pub fn yield_function(&self, r12: f64, r22: f64) -> f64 {
        self.gamma * r12.abs() * r22 - self.friction * (-self.normal * r22.ln())
    }
}

/// The fiber-frame force vectors of one quadrature particle: `dE/dd1` and
/// `dE/dd2` for energy `E = V psi(d / l0)`.
#[inline]
pub fn frame_gradient(energy: &YarnEnergy, d: &Mat2, l0: f64, volume: f64) -> (Vec2, Vec2) {
    frame_gradient_qr(energy, &qr(&(d * (1.0 / l0))), l0, volume)
}

/// [`frame_gradient`] from the QR factorisation of `G = d / l0`.
#[inline]
pub fn frame_gradient_qr(energy: &YarnEnergy, g: &Qr2, l0: f64, volume: f64) -> (Vec2, Vec2) {
    let p = energy.stress_qr(g);
    let s = volume / l0;
    (p.column(0) * s, p.column(1) * s)
}

/// Plastic state of a quadrature particle after the Mohr-Coulomb return
/// mapping ([`YarnEnergy::return_map`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlasticState {
    /// Inside the yield surface.
    Elastic = 0,
    /// On the yield surface: the return mapping limits the shear (sliding).
    Yielding = 1,
    /// `r22 = 1`: the cross-section is in tension and carries no stress.
    Separated = 2,
}

impl YarnEnergy {
    /// Classifies `(r12, r22)` of a frame after the return mapping:
    /// separated at `r22 >= 1`, yielding where the yield function is 0 (to a
    /// relative `1e-6` of `c_f (2 mu + lambda) |log r22|`, the size of its
    /// terms) with some shear, elastic otherwise.
    pub fn plastic_state(&self, r12: f64, r22: f64) -> PlasticState {
        if r22 >= 1.0 - 1e-9 {
            return PlasticState::Separated;
        }
        let f = self.yield_function(r12, r22);
        let scale = self.friction * self.normal * (-r22.ln()).abs();
        if f >= -1e-6 * scale && r12 != 0.0 {
            PlasticState::Yielding
        } else {
            PlasticState::Elastic
        }
    }
}

// ---- the same law over dual numbers (the implicit integrators' Hessian)

/// `P = dpsi/dG` ([`YarnEnergy::stress_qr`] of the Givens QR of `G`), row
/// major `[P00, P01, P10, P11]` from `G = [G00, G01, G10, G11]`: the same
/// operations as the explicit model, clamped entries constant.
#[inline(always)]
pub fn stress<T: Real>(e: &YarnEnergy, g: [T; 4]) -> [T; 4] {
    let [a, b, cc, d] = g;
    let r11 = (a * a + cc * cc).sqrt();
    let (c, s) = if r11.val() > 0.0 {
        (a / r11, cc / r11)
    } else {
        (T::cst(1.0), T::cst(0.0))
    };
    let r12 = c * b + s * d;
    let r22 = -s * b + c * d;
    let r11 = if r11.val() >= R11_MIN {
        r11
    } else {
        T::cst(R11_MIN)
    };
    let r22 = if r22.val() >= R22_MIN {
        r22
    } else {
        T::cst(R22_MIN)
    };
    let zero = T::cst(0.0);
    let (ln22, below) = if r22.val() < 1.0 {
        (r22.ln(), true)
    } else {
        (zero, false)
    };
    let fp = T::cst(e.k) * (r11 - T::cst(1.0));
    let gp = T::cst(e.gamma) * r12;
    let hr = if below { T::cst(e.normal) * ln22 } else { zero };
    let a00 = fp * r11 + gp * r12;
    let a01 = gp * r22;
    let a11 = hr;
    let i11 = T::cst(1.0) / r11;
    let i22 = T::cst(1.0) / r22;
    let i21 = -r12 * i11 * i22;
    let b00 = a00 * i11 + a01 * i21;
    let b01 = a01 * i22;
    let b10 = a01 * i11 + a11 * i21;
    let b11 = a11 * i22;
    [
        c * b00 - s * b10,
        c * b01 - s * b11,
        s * b00 + c * b10,
        s * b01 + c * b11,
    ]
}

/// `dE/d(d1, d2)` of one quadrature particle, `E = vol psi(d / l0)`, as
/// `[d1.x, d1.y, d2.x, d2.y]` (the explicit `t1`, `t2` of
/// [`crate::mpm::laws::constitutive::frame_gradient_qr`]).
#[inline(always)]
pub fn quad_gradient<T: Real>(e: &YarnEnergy, d: [T; 4], l0: f64, vol: f64) -> [T; 4] {
    let il = T::cst(1.0 / l0);
    let [d1x, d1y, d2x, d2y] = d;
    let p = stress(e, [d1x * il, d2x * il, d1y * il, d2y * il]);
    let s = T::cst(vol / l0);
    [p[0] * s, p[2] * s, p[1] * s, p[3] * s]
}

#[cfg(test)]
mod plastic_state_tests {
    use super::*;

    #[test]
    fn plastic_state_follows_the_return_mapping() {
        let e = YarnEnergy {
            k: 1000.0,
            gamma: 500.0,
            normal: 1400.0,
            friction: 0.3,
        };
        // Compressed, little shear: inside the yield surface.
        assert_eq!(e.plastic_state(1e-4, 0.95), PlasticState::Elastic);
        // Too much shear for the pressure: the return mapping puts it on the surface.
        let (r12, r22) = e.return_map(0.5, 0.95);
        assert!(r12 < 0.5);
        assert_eq!(e.plastic_state(r12, r22), PlasticState::Yielding);
        assert_eq!(e.plastic_state(-r12, r22), PlasticState::Yielding);
        // Just inside the surface (shear 1 % below the returned one): elastic.
        assert_eq!(e.plastic_state(0.99 * r12, r22), PlasticState::Elastic);
        // Cross-section in tension: separated.
        let (r12, r22) = e.return_map(0.1, 1.2);
        assert_eq!(e.plastic_state(r12, r22), PlasticState::Separated);
    }
}

#[cfg(test)]
mod normal_tangent_tests {
    use super::*;

    /// The crushed cross-section's stiffness is the second derivative of
    /// `psi` in `r22`: central differences of `psi_r` (step 1e-4, error
    /// O(h^2) ~ 1e-7 relative), tolerance 1e-5 relative.
    #[test]
    fn normal_tangent_is_the_second_derivative_of_psi() {
        let e = YarnEnergy {
            k: 1000.0,
            gamma: 500.0,
            normal: 1400.0,
            friction: 0.3,
        };
        for r22 in [0.2, 0.5, 0.9, 0.999] {
            let h = 1e-4 * r22;
            let fd = (e.psi_r(1.0, 0.0, r22 + h) - 2.0 * e.psi_r(1.0, 0.0, r22)
                + e.psi_r(1.0, 0.0, r22 - h))
                / (h * h);
            let t = e.normal_tangent(r22);
            assert!((fd - t).abs() <= 1e-5 * t, "r22 {r22}: {fd} against {t}");
        }
        // at and above rest: the rest stiffness, 6.8x it at r22 = 0.5
        assert_eq!(e.normal_tangent(1.0), 1400.0);
        assert_eq!(e.normal_tangent(1.3), 1400.0);
        assert!((e.normal_tangent(0.5) / 1400.0 - 6.77).abs() < 0.01);
    }
}
