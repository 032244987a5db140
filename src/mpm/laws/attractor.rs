//! The attractor: a point `p` that pulls the yarn with a settable strength
//! `s` (the FMU's and the CLI's run-time input), its law and its one input
//! check.
//!
//! The law, per unit mass, at distance `r = |x - p|`: the potential
//! `phi(r) = s (r - e ln(r + e))` with the softening length `e =`
//! [`SOFTENING`] m, whose force is the acceleration
//!
//! ```text
//! -grad phi = s (p - x) / (|p - x| + e)
//! ```
//!
//! (about `s` towards `p` far from it, vanishing at it). Every integrator
//! takes it from here: the explicit grid update the acceleration
//! ([`pull`]), the grid implicit solve the potential ([`potential`]), the
//! gradient ([`pull`]) and the Hessian ([`pull_jacobian`]), the vertex
//! implicit step the potential and its radial derivatives
//! ([`radial_derivatives`]). Each form is written once; the forms differ
//! only in the order of their floating-point operations, which each
//! integrator keeps (its results stay the same bits).

use crate::math::Vec2;
use crate::mpm::error::SimError;

/// Softening length `e` of the attractor's law in m: the pull is about
/// its full strength beyond a few `e` and falls linearly to zero within.
pub const SOFTENING: f64 = 0.01;

/// `phi(r) = s (r - e ln(r + e))`: the attractor's potential per unit mass
/// at distance `r` from it, strength `s`.
#[inline]
pub fn potential(r: f64, s: f64) -> f64 {
    s * (r - SOFTENING * (r + SOFTENING).ln())
}

/// `phi(r)`, `phi'(r) = s (1 - e / (r + e))` and `phi''(r) = s e / (r +
/// e)^2`: the potential and its first two radial derivatives.
#[inline]
pub fn radial_derivatives(r: f64, s: f64) -> (f64, f64, f64) {
    let e = SOFTENING;
    (
        potential(r, s),
        s * (1.0 - e / (r + e)),
        s * e / ((r + e) * (r + e)),
    )
}

/// `y c / (|y| + e)`: with `y = p - x` and `c = dt s`, the velocity the
/// attractor adds in `dt` (`-dt grad phi`); with `y = x - p` and `c = m dt
/// s`, the gradient `m dt grad phi` of the implicit grid solve.
#[inline(always)]
pub fn pull(y: Vec2, c: f64) -> Vec2 {
    y * (c / (y.norm() + SOFTENING))
}

/// The Jacobian of [`pull`] in `y`, times `c`: `c [I / (r + e) - y y^T /
/// (r (r + e)^2)]`, positive definite (eigenvalues `c / (r + e)` and `c e
/// / (r + e)^2`); `c I / e` at `y = 0`.
#[inline]
pub fn pull_jacobian(y: Vec2, c: f64) -> [[f64; 2]; 2] {
    let r = y.norm();
    let h = 1.0 / (r + SOFTENING);
    let t = if r > 0.0 { h * h / r } else { 0.0 };
    [
        [c * (h - t * y.x * y.x), -c * t * y.x * y.y],
        [-c * t * y.x * y.y, c * (h - t * y.y * y.y)],
    ]
}

/// The attractor as the simulation sees it (settable at run time).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Attractor {
    /// The point it pulls towards, in m.
    pub position: Vec2,
    /// `s`: its pull far from the point, in m/s^2.
    pub strength: f64,
    /// Whether it acts.
    pub active: bool,
}

impl Attractor {
    /// Largest accepted |coordinate| of the position in m: far outside any
    /// domain, yet small enough that `strength * distance` stays finite.
    pub const MAX_POSITION: f64 = 1e6;
    /// Largest accepted strength in m/s^2.
    pub const MAX_STRENGTH: f64 = 1e6;

    /// The attractor inputs' limits, the one check every caller (the
    /// simulation, the FMU) applies: a finite position within
    /// [`Self::MAX_POSITION`] m of the origin in each coordinate, a strength
    /// in `[0, MAX_STRENGTH]` m/s^2. The error names the input.
    pub fn check(&self) -> Result<(), SimError> {
        let p = self.position;
        if !(p.x.is_finite() && p.y.is_finite()) {
            return Err(SimError::BadInput(format!(
                "attractor position ({}, {}) must be finite",
                p.x, p.y
            )));
        }
        if p.x.abs() > Self::MAX_POSITION || p.y.abs() > Self::MAX_POSITION {
            return Err(SimError::BadInput(format!(
                "attractor position ({}, {}) is absurd (beyond 1e6 m)",
                p.x, p.y
            )));
        }
        if !(self.strength.is_finite() && (0.0..=Self::MAX_STRENGTH).contains(&self.strength)) {
            return Err(SimError::BadInput(format!(
                "attractor strength {} must be in [0, 1e6] m/s2",
                self.strength
            )));
        }
        Ok(())
    }
}
