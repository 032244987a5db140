//! The bending law: discrete elastic rods (Bergou et al. 2008) in 2D. At an
//! interior vertex with edges `e1`, `e2` the curvature is `kappa = 2 tan(theta
//! / 2) = 2 (e1 x e2) / (|e1| |e2| + e1 . e2)` and the energy `B / 2 (kappa -
//! kappa0)^2 / l` (`kappa0` the rest curvature, `l` the rest Voronoi length).
//!
//! Here, once each: the rest state ([`curvature`], [`rest_of_curve`],
//! `BendRest::new`; the particle store keeps one [`BendRest`] per vertex),
//! the energy ([`bending_energy`]), its gradient in the edges over plain
//! `f64`s, branch-free so that it vectorizes across vertices (`bend_gradients`,
//! which `super::vertex_forces` turns into forces), the same gradient over
//! the dual-number scalar ([`bend_gradient_edges`], [`bend_gradient`]) whose
//! Jacobian is the exact Hessian block of the implicit integrators, and
//! that block's projection onto the PSD cone in closed form
//! ([`project_bend`]).

use crate::math::dual::Real;
use crate::math::psd::{mul, symmetrize};
use crate::math::{cross, Vec2};
pub use crate::mpm::machinery::particles::BendRest;
use crate::mpm::machinery::particles::Vertices;

impl BendRest {
    /// Rest data at a vertex between edges `e1` (incoming) and `e2` (outgoing).
    pub fn new(e1: Vec2, e2: Vec2) -> Self {
        BendRest {
            kappa0: curvature(e1, e2),
            inv_len: 2.0 / (e1.norm() + e2.norm()),
        }
    }
}

/// `2 tan(theta / 2)` of the turning angle from edge `e1` to edge `e2`.
#[inline(always)]
pub fn curvature(e1: Vec2, e2: Vec2) -> f64 {
    let d = e1.norm() * e2.norm() + e1.dot(&e2);
    if d > 0.0 {
        2.0 * cross(e1, e2) / d
    } else {
        0.0
    }
}

/// Rest bending data of a yarn's vertices `curve`: interior vertices get
/// their rest curvature and Voronoi length, the two ends none.
pub fn rest_of_curve(curve: &[Vec2]) -> Vec<BendRest> {
    let n = curve.len();
    (0..n)
        .map(|i| {
            if i == 0 || i + 1 == n {
                BendRest::default()
            } else {
                BendRest::new(curve[i] - curve[i - 1], curve[i + 1] - curve[i])
            }
        })
        .collect()
}

/// `(B (kappa - kappa0) / l) dkappa/de1` and `... dkappa/de2` at every
/// vertex `j` of `lo..hi` (`[g1.x, g1.y, g2.x, g2.y]`, entry `j - lo`),
/// zero where `j` is not an interior vertex of its yarn or out of range.
///
/// Written without branches over plain `f64`s so that it vectorizes across
/// vertices (the chain of two `sqrt` and three divisions per vertex is the
/// cost); `sqrt` and division are correctly rounded in every SIMD width, so
/// each vertex gets the same bits as one at a time.
#[inline(always)]
pub(crate) fn bend_gradients(
    x: &[Vec2],
    bend: &[BendRest],
    b: f64,
    lo: isize,
    hi: isize,
) -> Vec<[f64; 4]> {
    let mut out = vec![[0.0; 4]; (hi - lo) as usize];
    let n = x.len() as isize;
    // interior vertices of the whole array (its two ends are yarn ends)
    let (a, z) = (lo.clamp(1, (n - 1).max(1)), hi.clamp(1, (n - 1).max(1)));
    if a >= z {
        return out;
    }
    let (a, z) = (a as usize, z as usize);
    let o = &mut out[(a as isize - lo) as usize..(z as isize - lo) as usize];
    let xs = &x[a - 1..z + 1];
    let rest = &bend[a..z];
    for (k, g) in o.iter_mut().enumerate() {
        let (xm, x0, xp) = (xs[k], xs[k + 1], xs[k + 2]);
        let (e1x, e1y) = (x0.x - xm.x, x0.y - xm.y);
        let (e2x, e2y) = (xp.x - x0.x, xp.y - x0.y);
        let n1 = (e1x * e1x + e1y * e1y).sqrt();
        let n2 = (e2x * e2x + e2y * e2y).sqrt();
        let c = e1x * e2y - e1y * e2x;
        let d = n1 * n2 + (e1x * e2x + e1y * e2y);
        let kappa = 2.0 * c / d;
        let tau = b * (kappa - rest[k].kappa0) * rest[k].inv_len;
        let s = 2.0 * tau / (d * d);
        let (r1, r2) = (n2 / n1, n1 / n2);
        let g1x = (e2y * d - (e1x * r1 + e2x) * c) * s;
        let g1y = (-e2x * d - (e1y * r1 + e2y) * c) * s;
        let g2x = (-e1y * d - (e2x * r2 + e1x) * c) * s;
        let g2y = (e1x * d - (e2y * r2 + e1y) * c) * s;
        // a yarn end (no rest length), or a fully folded joint (theta = pi):
        // no finite curvature gradient
        let ok = rest[k].inv_len != 0.0 && d > 0.0 && n1 > 0.0 && n2 > 0.0;
        *g = if ok { [g1x, g1y, g2x, g2y] } else { [0.0; 4] };
    }
    out
}

/// Total bending energy `sum_j B / 2 (kappa_j - kappa0_j)^2 / l_j`.
pub fn bending_energy(v: &Vertices, bending: f64) -> f64 {
    if bending <= 0.0 {
        return 0.0;
    }
    let mut e = 0.0;
    for j in 0..v.x.len() {
        let rest = v.bend[j];
        if rest.inv_len == 0.0 {
            continue;
        }
        let kappa = curvature(v.x[j] - v.x[j - 1], v.x[j + 1] - v.x[j]);
        let dk = kappa - rest.kappa0;
        e += 0.5 * bending * dk * dk * rest.inv_len;
    }
    e
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

/// The PSD projection of a bending block in edge coordinates `e = (e1,
/// e2)` in closed form. The exact block is `H = B inv_len [g g^T + (kappa -
/// kappa0) K]`, `g = dkappa/de`, `K` its Hessian. `kappa` is invariant
/// under a rotation and a scaling of both edges, so with `s = e`, `r = J e`
/// (`J` the quarter turn of each edge), `g . s = g . r = 0` and `K s = -g`,
/// `K r = J g`: in the orthonormal basis `(s, g, J g, r)` normalised, `H s`
/// lies along `g`, `H r` along `J g`, with the same coefficient `-beta`,
/// `beta`. The `2x2` part in `(g, J g)` has eigenvectors `(c, s)` and
/// values `nu`; each `y = c g + s J g` pairs with `z = -c s + s r` into an
/// invariant plane where `H = [[nu, beta], [beta, 0]]` (one eigenvalue of
/// each sign unless `beta = 0`). The projection keeps the positive one of
/// each plane. `f` is the energy's gradient `B inv_len (kappa - kappa0)
/// g`, the direction of `g`; where it is zero `H` is the rank-one `B
/// inv_len g g^T` (PSD) and is returned as it is.
pub fn project_bend(h: &[[f64; 4]; 4], e: [f64; 4], f: [f64; 4]) -> [[f64; 4]; 4] {
    let norm = |x: &[f64; 4]| x.iter().map(|x| x * x).sum::<f64>().sqrt();
    let turn = |x: &[f64; 4]| [-x[1], x[0], -x[3], x[2]];
    let (se, sf) = (norm(&e), norm(&f));
    if !(se > 0.0 && sf > 0.0 && se.is_finite() && sf.is_finite()) {
        return *h;
    }
    let qs: [f64; 4] = std::array::from_fn(|i| e[i] / se);
    let qg: [f64; 4] = std::array::from_fn(|i| f[i] / sf);
    let (qj, qr) = (turn(&qg), turn(&qs));
    let quad = |a: &[f64; 4], b: &[f64; 4]| -> f64 {
        let hb = mul(h, b);
        (0..4).map(|i| a[i] * hb[i]).sum()
    };
    let (alpha, delta, gamma) = (quad(&qg, &qg), quad(&qg, &qj), quad(&qj, &qj));
    let beta = 0.5 * (quad(&qj, &qr) - quad(&qs, &qg));
    // the 2x2 [[alpha, delta], [delta, gamma]]: angle of its first
    // eigenvector
    let theta = 0.5 * (2.0 * delta).atan2(alpha - gamma);
    let (c, s) = (theta.cos(), theta.sin());
    let mut out = [[0.0; 4]; 4];
    for (c, s) in [(c, s), (-s, c)] {
        let nu = alpha * c * c + 2.0 * delta * c * s + gamma * s * s;
        // the positive root of l^2 - nu l - beta^2, without cancellation
        let root = (0.25 * nu * nu + beta * beta).sqrt();
        let l = if nu >= 0.0 {
            0.5 * nu + root
        } else {
            beta * beta / (root - 0.5 * nu)
        };
        if l.is_nan() || l <= 0.0 {
            continue;
        }
        let w = 1.0 / (l * l + beta * beta).sqrt();
        let (a, b) = (l * w, beta * w);
        let v: [f64; 4] =
            std::array::from_fn(|i| a * (c * qg[i] + s * qj[i]) + b * (-c * qs[i] + s * qr[i]));
        for i in 0..4 {
            for j in 0..4 {
                out[i][j] += l * v[i] * v[j];
            }
        }
    }
    symmetrize(&mut out);
    out
}
