//! QR decomposition of a 2x2 matrix by one Givens rotation.
//!
//! `F = Q R` with `Q` a proper rotation (`det Q = +1`) and `R` upper
//! triangular with `r11 >= 0`. Because `Q` is never a reflection, an inverted
//! `F` (`det F < 0`) shows up as `r22 < 0` instead of being hidden, which is
//! what the Mohr-Coulomb return mapping needs to see (Gram-Schmidt would flip
//! the sign of the second column and hide the inversion).

use super::{Mat2, Vec2};

/// Result of [`qr`]: the rotation as `(cos, sin)` and the entries of `R`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Qr2 {
    /// cos of the rotation angle.
    pub c: f64,
    /// sin of the rotation angle.
    pub s: f64,
    /// `R[0][0]`, never negative.
    pub r11: f64,
    /// `R[0][1]`.
    pub r12: f64,
    /// `R[1][1]`; negative when `f` is inverted (`det f < 0`).
    pub r22: f64,
}

/// Givens QR of `f`: `f = Q(c, s) * [[r11, r12], [0, r22]]`.
#[inline]
pub fn qr(f: &Mat2) -> Qr2 {
    let (a, b, cc, d) = (f[(0, 0)], f[(0, 1)], f[(1, 0)], f[(1, 1)]);
    // plain sqrt: entries are O(1) deformation gradients, hypot's overflow care is not needed
    let r11 = (a * a + cc * cc).sqrt();
    let (c, s) = if r11 > 0.0 {
        (a / r11, cc / r11)
    } else {
        (1.0, 0.0)
    };
    // R = Q^T F
    Qr2 {
        c,
        s,
        r11,
        r12: c * b + s * d,
        r22: -s * b + c * d,
    }
}

impl Qr2 {
    /// The rotation `Q = [[c, -s], [s, c]]`.
    #[inline]
    pub fn q(&self) -> Mat2 {
        Mat2::new(self.c, -self.s, self.s, self.c)
    }

    /// The upper triangular factor `R`.
    #[inline]
    pub fn r(&self) -> Mat2 {
        Mat2::new(self.r11, self.r12, 0.0, self.r22)
    }

    /// `Q v`.
    #[inline]
    pub fn rotate(&self, v: Vec2) -> Vec2 {
        Vec2::new(self.c * v.x - self.s * v.y, self.s * v.x + self.c * v.y)
    }

    /// `Q * [[r11, r12], [0, r22]]` for replaced entries of `R`.
    #[inline]
    pub fn compose(&self, r11: f64, r12: f64, r22: f64) -> Mat2 {
        let c0 = self.rotate(Vec2::new(r11, 0.0));
        let c1 = self.rotate(Vec2::new(r12, r22));
        Mat2::from_columns(&[c0, c1])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reconstructs_and_is_proper_rotation() {
        let mats = [
            Mat2::new(1.0, 0.2, -0.3, 0.9),
            Mat2::new(-2.0, 0.5, 0.1, 3.0),
            Mat2::new(0.0, 1.0, 0.0, 2.0),
            Mat2::new(0.3, 0.2, 0.4, -0.7), // inverted
        ];
        for f in mats {
            let d = qr(&f);
            assert!((d.q() * d.r() - f).norm() < 1e-14, "{f}");
            assert!((d.q().determinant() - 1.0).abs() < 1e-14);
            assert!(d.r11 >= 0.0);
        }
    }

    #[test]
    fn inversion_shows_as_negative_r22() {
        let f = Mat2::new(1.0, 0.0, 0.0, -0.5);
        let d = qr(&f);
        assert!(d.r22 < 0.0);
        assert!((d.r11 - 1.0).abs() < 1e-15);
    }
}
