//! Forward-mode dual numbers and a small scalar trait ([`Real`]) over
//! `f64` and [`Dual`], so one generic body of a force law gives both the
//! gradient (`f64`) and, with `Dual`, one exact column of the Hessian per
//! seed ([`jacobian`]). The yarn's laws written over it are in
//! `crate::mpm::laws` (the constitutive stress and the bending gradient).

// small dense blocks and stencils: index loops read as the formulas
#![allow(clippy::needless_range_loop)]

use std::ops::{Add, Div, Mul, Neg, Sub};

/// The scalar operations the force laws use.
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// A constant.
    fn cst(v: f64) -> Self;
    /// The value (branches and clamps test it).
    fn val(self) -> f64;
    /// The square root.
    fn sqrt(self) -> Self;
    /// The natural logarithm.
    fn ln(self) -> Self;
}

impl Real for f64 {
    #[inline(always)]
    fn cst(v: f64) -> Self {
        v
    }
    #[inline(always)]
    fn val(self) -> f64 {
        self
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn ln(self) -> Self {
        f64::ln(self)
    }
}

/// `v + d eps` with `eps^2 = 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dual {
    /// The value.
    pub v: f64,
    /// The derivative along the seed.
    pub d: f64,
}

impl Dual {
    /// `v` seeded with derivative `d`.
    pub fn new(v: f64, d: f64) -> Self {
        Dual { v, d }
    }
}

impl Add for Dual {
    type Output = Dual;
    #[inline(always)]
    fn add(self, o: Dual) -> Dual {
        Dual::new(self.v + o.v, self.d + o.d)
    }
}
impl Sub for Dual {
    type Output = Dual;
    #[inline(always)]
    fn sub(self, o: Dual) -> Dual {
        Dual::new(self.v - o.v, self.d - o.d)
    }
}
impl Mul for Dual {
    type Output = Dual;
    #[inline(always)]
    fn mul(self, o: Dual) -> Dual {
        Dual::new(self.v * o.v, self.d * o.v + self.v * o.d)
    }
}
impl Div for Dual {
    type Output = Dual;
    #[inline(always)]
    fn div(self, o: Dual) -> Dual {
        let q = self.v / o.v;
        Dual::new(q, (self.d - q * o.d) / o.v)
    }
}
impl Neg for Dual {
    type Output = Dual;
    #[inline(always)]
    fn neg(self) -> Dual {
        Dual::new(-self.v, -self.d)
    }
}
impl Real for Dual {
    #[inline(always)]
    fn cst(v: f64) -> Self {
        Dual::new(v, 0.0)
    }
    #[inline(always)]
    fn val(self) -> f64 {
        self.v
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        let s = self.v.sqrt();
        Dual::new(s, self.d / (2.0 * s))
    }
    #[inline(always)]
    fn ln(self) -> Self {
        Dual::new(self.v.ln(), self.d / self.v)
    }
}

/// The Jacobian of a gradient `f: R^N -> R^N` at `x` by `N` dual
/// evaluations (column `j` the dual part at `x + eps e_j`), row major.
#[inline]
pub fn jacobian<const N: usize, F>(x: [f64; N], f: F) -> [[f64; N]; N]
where
    F: Fn([Dual; N]) -> [Dual; N],
{
    let mut h = [[0.0; N]; N];
    for j in 0..N {
        let seeded: [Dual; N] = std::array::from_fn(|i| Dual::new(x[i], (i == j) as u8 as f64));
        let col = f(seeded);
        for i in 0..N {
            h[i][j] = col[i].d;
        }
    }
    h
}
