//! Small dense math used by the solvers: 2x2 QR by a Givens rotation and the
//! quadratic B-spline weights of the MPM transfer.

pub mod bspline;
pub mod qr;

/// A 2-vector of `f64` (nalgebra).
pub type Vec2 = nalgebra::Vector2<f64>;
/// A 2x2 matrix of `f64` (nalgebra, column major).
pub type Mat2 = nalgebra::Matrix2<f64>;

/// `(x, y)` rotated by +90 degrees: `(-y, x)`.
#[inline]
pub fn perp(v: Vec2) -> Vec2 {
    Vec2::new(-v.y, v.x)
}

/// `J0(x)`, the Bessel function of the first kind of order 0, by its power
/// series `sum_k (-1)^k (x/2)^(2k) / (k!)^2` (to round-off for `|x| <= 10`):
/// the mode shapes of the hanging chain, the oracle of the yarn tests and of
/// the work-precision study.
pub fn bessel_j0(x: f64) -> f64 {
    let q = -(x * x) / 4.0;
    let mut term = 1.0;
    let mut sum = 1.0;
    for k in 1..60 {
        term *= q / (k * k) as f64;
        sum += term;
        if term.abs() < 1e-17 * sum.abs().max(1e-300) {
            break;
        }
    }
    sum
}

/// The 2D cross product `a.x b.y - a.y b.x`.
#[inline]
pub fn cross(a: Vec2, b: Vec2) -> f64 {
    a.x * b.y - a.y * b.x
}
