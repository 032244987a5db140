//! Small dense math used by the solvers: 2x2 QR by a Givens rotation and the
//! quadratic B-spline weights of the MPM transfer.

pub mod bspline;
pub mod dual;
pub mod psd;
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

/// The 2D cross product `a.x b.y - a.y b.x`.
#[inline]
pub fn cross(a: Vec2, b: Vec2) -> f64 {
    a.x * b.y - a.y * b.x
}
