//! Forward-mode dual numbers and the yarn's force laws written over a small
//! scalar trait ([`Real`]), so one generic body gives both the gradient
//! (`f64`) and, with `Dual`, one exact column of the Hessian per seed: the
//! explicit model's stress `P(G)` of [`crate::mpm::constitutive`] (QR,
//! clamps and the `r22 < 1` branch included) and the discrete-elastic-rod
//! bending gradient of [`crate::mpm::vertex_forces`].

// small dense blocks and stencils: index loops read as the formulas
#![allow(clippy::needless_range_loop)]

use std::ops::{Add, Div, Mul, Neg, Sub};

use crate::mpm::constitutive::{YarnEnergy, R11_MIN, R22_MIN};

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
    fn sqrt(self) -> Self;
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
    pub v: f64,
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
/// [`crate::mpm::constitutive::frame_gradient_qr`]).
#[inline(always)]
pub fn quad_gradient<T: Real>(e: &YarnEnergy, d: [T; 4], l0: f64, vol: f64) -> [T; 4] {
    let il = T::cst(1.0 / l0);
    let [d1x, d1y, d2x, d2y] = d;
    let p = stress(e, [d1x * il, d2x * il, d1y * il, d2y * il]);
    let s = T::cst(vol / l0);
    [p[0] * s, p[2] * s, p[1] * s, p[3] * s]
}

/// `dE/d(e1, e2)` of the bending energy `B / 2 (kappa - kappa0)^2 inv_len`
/// at one interior vertex in its edges `e1 = x_j - x_prev`, `e2 = x_next -
/// x_j` (`[e1.x, e1.y, e2.x, e2.y]`); zero at a fully folded joint or a
/// zero-length edge, as the explicit force.
#[inline(always)]
pub fn bend_gradient_edges<T: Real>(e: [T; 4], b: f64, kappa0: f64, inv_len: f64) -> [T; 4] {
    let [e1x, e1y, e2x, e2y] = e;
    let n1 = (e1x * e1x + e1y * e1y).sqrt();
    let n2 = (e2x * e2x + e2y * e2y).sqrt();
    let c = e1x * e2y - e1y * e2x;
    let d = n1 * n2 + (e1x * e2x + e1y * e2y);
    let zero = T::cst(0.0);
    if !(inv_len != 0.0 && d.val() > 0.0 && n1.val() > 0.0 && n2.val() > 0.0) {
        return [zero; 4];
    }
    let kappa = T::cst(2.0) * c / d;
    let tau = T::cst(b) * (kappa - T::cst(kappa0)) * T::cst(inv_len);
    let s = T::cst(2.0) * tau / (d * d);
    let (r1, r2) = (n2 / n1, n1 / n2);
    let g1x = (e2y * d - (e1x * r1 + e2x) * c) * s;
    let g1y = (-e2x * d - (e1y * r1 + e2y) * c) * s;
    let g2x = (-e1y * d - (e2x * r2 + e1x) * c) * s;
    let g2y = (e1x * d - (e2y * r2 + e1y) * c) * s;
    [g1x, g1y, g2x, g2y]
}

/// `dE/d(x_prev, x_j, x_next)` of the same energy (positions
/// `[x_prev.x, x_prev.y, x_j.x, ..., x_next.y]`): [`bend_gradient_edges`]
/// mapped through `e1 = x_j - x_prev`, `e2 = x_next - x_j`.
#[inline(always)]
pub fn bend_gradient<T: Real>(x: [T; 6], b: f64, kappa0: f64, inv_len: f64) -> [T; 6] {
    let e = [x[2] - x[0], x[3] - x[1], x[4] - x[2], x[5] - x[3]];
    let [g1x, g1y, g2x, g2y] = bend_gradient_edges(e, b, kappa0, inv_len);
    [-g1x, -g1y, g1x - g2x, g1y - g2y, g2x, g2y]
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
