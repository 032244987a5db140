//! `E(v)`, its gradient, the per-element Hessian blocks (exact by dual
//! numbers or, for a pure fibre stretch, in closed form; optionally
//! projected onto PSD) and the matrix-free `H d` and Jacobi diagonal from
//! them.

use super::precond::StiffRow;
use super::problem::{BendElem, QuadElem};
use super::Problem;
use crate::math::dual::jacobian;
use crate::math::psd::{mul, project_psd, symmetrize};
use crate::math::{Mat2, Vec2};
use crate::mpm::laws::attractor;
use crate::mpm::laws::bending::{bend_gradient_edges, project_bend};
use crate::mpm::laws::constitutive::quad_gradient;

/// The Hessian of `Psi` in element coordinates at one `v`: per quadrature
/// particle in `(d1, d2)`, per bending vertex in its edges `(e1, e2)`,
/// per node the attractor's (times `m dt^2`, in `v`).
#[derive(Clone, Debug, Default)]
pub struct Blocks {
    pub quad: Vec<[[f64; 4]; 4]>,
    pub bend: Vec<[[f64; 4]; 4]>,
    pub attr: Vec<[[f64; 2]; 2]>,
    /// Per contact term its weight `w` where it acts (`v . n < 0`), else 0:
    /// the block `w n n^T`.
    pub contact: Vec<f64>,
}

/// The exact block of a pure fibre stretch (`gamma = normal = 0`: `psi =
/// k/2 (|d1| / l0 - 1)^2`, nothing in `d2`), in closed form: `vol k / l0^2
/// [u u^T + (1 - l0 / L) (I - u u^T)]` in `d1` (`L = |d1|`, `u = d1 / L`),
/// the transverse coefficient clamped at 0 when `psd` (its eigenvalues are
/// the two coefficients). `None` where the stress clamps `r11` (then the
/// dual-number path).
#[inline]
pub(super) fn spring_block(
    k: f64,
    d: [f64; 4],
    l0: f64,
    vol: f64,
    psd: bool,
) -> Option<[[f64; 4]; 4]> {
    let il = 1.0 / l0;
    let (a, b) = (d[0] * il, d[1] * il);
    let r11 = (a * a + b * b).sqrt();
    if r11 < crate::mpm::laws::constitutive::R11_MIN {
        return None;
    }
    let (ux, uy) = (a / r11, b / r11);
    let s = vol * k * il * il;
    let t = 1.0 - 1.0 / r11;
    let t = if psd { t.max(0.0) } else { t };
    let mut h = [[0.0; 4]; 4];
    h[0][0] = s * (ux * ux + t * uy * uy);
    h[1][1] = s * (uy * uy + t * ux * ux);
    h[0][1] = s * (1.0 - t) * ux * uy;
    h[1][0] = h[0][1];
    Some(h)
}

impl Problem {
    /// `(d1, d2)` of quadrature particle `q` at `v`.
    #[inline]
    fn quad_d(&self, q: &QuadElem, v: &[Vec2]) -> [f64; 4] {
        let (mut d1, mut d2) = (q.d1, q.d2);
        for t in &self.quad_terms[q.start as usize..q.end as usize] {
            let vn = v[t.node as usize];
            d1 += vn * t.c1;
            d2 += vn * t.c2;
        }
        [d1.x, d1.y, d2.x, d2.y]
    }

    /// The edges `(e1, e2)` of bending vertex `b` at `v`.
    #[inline]
    fn bend_e(&self, b: &BendElem, v: &[Vec2]) -> [f64; 4] {
        let [mut e1, mut e2] = b.e;
        for t in &self.bend_terms[b.start as usize..b.end as usize] {
            let vn = v[t.node as usize];
            e1 += vn * t.a[0];
            e2 += vn * t.a[1];
        }
        [e1.x, e1.y, e2.x, e2.y]
    }

    /// The frames `(d1, d2)` of the quadrature particles at `v`.
    #[cfg(test)]
    pub fn frames(&self, v: &[Vec2]) -> Vec<[f64; 4]> {
        self.quads.iter().map(|q| self.quad_d(q, v)).collect()
    }

    /// `E(v)`: kinetic, elastic (`vol psi(G)`, [`crate::mpm::laws::constitutive`]),
    /// bending and attractor energy (relative to `v = 0`).
    pub fn energy(&self, v: &[Vec2]) -> f64 {
        let kinetic: f64 = (0..v.len())
            .map(|i| 0.5 * self.mass[i] * (v[i] - self.vstar[i]).norm_squared())
            .sum();
        let elastic: f64 = self
            .quads
            .iter()
            .map(|q| {
                let [a, b, c, d] = self.quad_d(q, v);
                let il = 1.0 / q.l0;
                q.vol * self.energy.psi(&(Mat2::new(a, c, b, d) * il))
            })
            .sum();
        let bend: f64 = self
            .bends
            .iter()
            .map(|b| {
                let e = self.bend_e(b, v);
                let (e1, e2) = (Vec2::new(e[0], e[1]), Vec2::new(e[2], e[3]));
                let dk = crate::mpm::laws::bending::curvature(e1, e2) - b.kappa0;
                0.5 * self.bending * dk * dk * b.inv_len
            })
            .sum();
        let attr: f64 = self.attractor.as_ref().map_or(0.0, |a| {
            (0..v.len())
                .map(|i| {
                    let x = a.x[i] - a.position;
                    let y = x + v[i] * self.dt;
                    self.mass[i]
                        * (attractor::potential(y.norm(), a.strength)
                            - attractor::potential(x.norm(), a.strength))
                })
                .sum()
        });
        let contact: f64 = self
            .contacts
            .iter()
            .map(|c| {
                let a = v[c.node as usize].dot(&c.n).min(0.0);
                0.5 * c.w * a * a
            })
            .sum();
        kinetic + elastic + bend + attr + contact
    }

    /// `dE/dv = M (v - v*) + dPsi/dv`: through each element's list, the
    /// explicit force laws ([`crate::math::dual`]).
    pub fn gradient(&self, v: &[Vec2]) -> Vec<Vec2> {
        let mut g: Vec<Vec2> = (0..v.len())
            .map(|i| (v[i] - self.vstar[i]) * self.mass[i])
            .collect();
        for q in &self.quads {
            let t = quad_gradient(&self.energy, self.quad_d(q, v), q.l0, q.vol);
            let (t1, t2) = (Vec2::new(t[0], t[1]), Vec2::new(t[2], t[3]));
            for term in &self.quad_terms[q.start as usize..q.end as usize] {
                g[term.node as usize] += t1 * term.c1 + t2 * term.c2;
            }
        }
        for b in &self.bends {
            let f = bend_gradient_edges(self.bend_e(b, v), self.bending, b.kappa0, b.inv_len);
            let (f1, f2) = (Vec2::new(f[0], f[1]), Vec2::new(f[2], f[3]));
            for term in &self.bend_terms[b.start as usize..b.end as usize] {
                g[term.node as usize] += f1 * term.a[0] + f2 * term.a[1];
            }
        }
        if let Some(a) = &self.attractor {
            for (i, g) in g.iter_mut().enumerate() {
                let y = a.x[i] + v[i] * self.dt - a.position;
                *g += attractor::pull(y, self.mass[i] * self.dt * a.strength);
            }
        }
        for c in &self.contacts {
            let a = v[c.node as usize].dot(&c.n).min(0.0);
            g[c.node as usize] += c.n * (c.w * a);
        }
        g
    }

    /// The Hessian blocks at `v`: exact (dual numbers), each projected
    /// onto the PSD cone when `psd`.
    pub fn blocks(&self, v: &[Vec2], psd: bool) -> Blocks {
        let e = self.energy;
        let spring = e.gamma == 0.0 && e.normal == 0.0;
        let quad = self
            .quads
            .iter()
            .map(|q| {
                let d = self.quad_d(q, v);
                if spring {
                    if let Some(h) = spring_block(e.k, d, q.l0, q.vol, psd) {
                        return h;
                    }
                }
                let mut h = jacobian(d, |d| quad_gradient(&e, d, q.l0, q.vol));
                symmetrize(&mut h);
                if psd {
                    project_psd(&h)
                } else {
                    h
                }
            })
            .collect();
        let bs = self.bending;
        let bend = self
            .bends
            .iter()
            .map(|b| {
                let e = self.bend_e(b, v);
                let mut h = jacobian(e, |e| bend_gradient_edges(e, bs, b.kappa0, b.inv_len));
                symmetrize(&mut h);
                if psd {
                    project_bend(&h, e, bend_gradient_edges(e, bs, b.kappa0, b.inv_len))
                } else {
                    h
                }
            })
            .collect();
        // m dt^2 s [I / (r + e) - y y^T / (r (r + e)^2)]: positive
        // definite
        let attr = self.attractor.as_ref().map_or(Vec::new(), |a| {
            (0..v.len())
                .map(|i| {
                    let y = a.x[i] + v[i] * self.dt - a.position;
                    attractor::pull_jacobian(y, self.mass[i] * self.dt * self.dt * a.strength)
                })
                .collect()
        });
        let contact = (self.contacts.iter())
            .map(|c| {
                if v[c.node as usize].dot(&c.n) < 0.0 {
                    c.w
                } else {
                    0.0
                }
            })
            .collect();
        Blocks {
            quad,
            bend,
            attr,
            contact,
        }
    }

    /// `H d = M d + sum_e J_e^T K_e J_e d` from the blocks.
    #[cfg(test)]
    pub fn hess_vec_blocks(&self, k: &Blocks, d: &[Vec2]) -> Vec<Vec2> {
        let mut y = vec![Vec2::zeros(); d.len()];
        self.hess_vec_into(k, d, &mut y);
        y
    }

    /// [`Problem::hess_vec_blocks`] into `y` (overwritten).
    pub fn hess_vec_into(&self, k: &Blocks, d: &[Vec2], y: &mut [Vec2]) {
        for ((y, d), m) in y.iter_mut().zip(d).zip(&self.mass) {
            *y = d * *m;
        }
        for (q, kq) in self.quads.iter().zip(&k.quad) {
            let terms = &self.quad_terms[q.start as usize..q.end as usize];
            let (mut d1, mut d2) = (Vec2::zeros(), Vec2::zeros());
            for t in terms {
                let dn = d[t.node as usize];
                d1 += dn * t.c1;
                d2 += dn * t.c2;
            }
            let f = mul(kq, &[d1.x, d1.y, d2.x, d2.y]);
            let (f1, f2) = (Vec2::new(f[0], f[1]), Vec2::new(f[2], f[3]));
            for t in terms {
                y[t.node as usize] += f1 * t.c1 + f2 * t.c2;
            }
        }
        for (b, kb) in self.bends.iter().zip(&k.bend) {
            let terms = &self.bend_terms[b.start as usize..b.end as usize];
            let (mut d1, mut d2) = (Vec2::zeros(), Vec2::zeros());
            for t in terms {
                let dn = d[t.node as usize];
                d1 += dn * t.a[0];
                d2 += dn * t.a[1];
            }
            let f = mul(kb, &[d1.x, d1.y, d2.x, d2.y]);
            let (f1, f2) = (Vec2::new(f[0], f[1]), Vec2::new(f[2], f[3]));
            for t in terms {
                y[t.node as usize] += f1 * t.a[0] + f2 * t.a[1];
            }
        }
        for ((y, a), d) in y.iter_mut().zip(&k.attr).zip(d) {
            *y += Vec2::new(a[0][0] * d.x + a[0][1] * d.y, a[1][0] * d.x + a[1][1] * d.y);
        }
        for (c, &w) in self.contacts.iter().zip(&k.contact) {
            let i = c.node as usize;
            y[i] += c.n * (w * c.n.dot(&d[i]));
        }
    }

    /// The exact `H d` at `v` (unprojected blocks).
    #[cfg(test)]
    pub fn hess_vec(&self, v: &[Vec2], d: &[Vec2]) -> Vec<Vec2> {
        self.hess_vec_blocks(&self.blocks(v, false), d)
    }

    /// The diagonal of `H` from the blocks, per component (positive for
    /// PSD blocks: the Jacobi preconditioner; entries clamped at the mass).
    pub fn diagonal(&self, k: &Blocks) -> Vec<Vec2> {
        let mut out: Vec<Vec2> = self.mass.iter().map(|&m| Vec2::new(m, m)).collect();
        for (q, kq) in self.quads.iter().zip(&k.quad) {
            for t in &self.quad_terms[q.start as usize..q.end as usize] {
                let o = &mut out[t.node as usize];
                for c in 0..2 {
                    let (i, j) = (c, c + 2);
                    o[c] += t.c1 * t.c1 * kq[i][i]
                        + 2.0 * t.c1 * t.c2 * kq[i][j]
                        + t.c2 * t.c2 * kq[j][j];
                }
            }
        }
        for (b, kb) in self.bends.iter().zip(&k.bend) {
            for t in &self.bend_terms[b.start as usize..b.end as usize] {
                let o = &mut out[t.node as usize];
                for c in 0..2 {
                    let (i, j) = (c, c + 2);
                    o[c] += t.a[0] * t.a[0] * kb[i][i]
                        + 2.0 * t.a[0] * t.a[1] * kb[i][j]
                        + t.a[1] * t.a[1] * kb[j][j];
                }
            }
        }
        for (o, a) in out.iter_mut().zip(&k.attr) {
            o.x += a[0][0];
            o.y += a[1][1];
        }
        for (c, &w) in self.contacts.iter().zip(&k.contact) {
            out[c.node as usize] += c.n.component_mul(&c.n) * w;
        }
        for (o, m) in out.iter_mut().zip(&self.mass) {
            o.x = o.x.max(*m);
            o.y = o.y.max(*m);
        }
        out
    }

    /// The fibre stretch of each segment at `v` as a stiff row for
    /// [`super::precond`]: `b_n = c1_n u` (`u` the unit fibre direction,
    /// so `b . v` is the rate of the segment's length) and `c = u^T K11 u`
    /// from the segment's block `k` (the `d1 d1` part), grouped by yarn.
    pub fn stiff_rows(&self, v: &[Vec2], k: &Blocks) -> Vec<StiffRow> {
        let mut rows = Vec::with_capacity(self.quads.len());
        let mut group = 0u32;
        let mut prev: Option<u32> = None;
        for (q, kq) in self.quads.iter().zip(&k.quad) {
            if prev.is_some_and(|p| p + 1 != q.left) {
                group += 1;
            }
            prev = Some(q.left);
            let [a, b, _, _] = self.quad_d(q, v);
            let l = (a * a + b * b).sqrt();
            if l <= 0.0 {
                continue;
            }
            let u = Vec2::new(a / l, b / l);
            let c =
                u.x * (kq[0][0] * u.x + kq[0][1] * u.y) + u.y * (kq[1][0] * u.x + kq[1][1] * u.y);
            let entries = self.quad_terms[q.start as usize..q.end as usize]
                .iter()
                .filter(|t| t.c1 != 0.0)
                .map(|t| (t.node, u * t.c1))
                .collect();
            rows.push(StiffRow { group, entries, c });
        }
        rows
    }

    /// [`Problem::diagonal`] without the part the stiff rows carry
    /// (`c b_n b_n^T` on the diagonal), clamped at the mass.
    pub fn diagonal_rest(&self, k: &Blocks, rows: &[StiffRow]) -> Vec<Vec2> {
        let mut out = self.diagonal(k);
        for r in rows.iter().filter(|r| r.c > 0.0) {
            for &(i, b) in &r.entries {
                out[i as usize] -= b.component_mul(&b) * r.c;
            }
        }
        for (o, m) in out.iter_mut().zip(&self.mass) {
            o.x = o.x.max(*m);
            o.y = o.y.max(*m);
        }
        out
    }
}
