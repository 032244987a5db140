//! The energy of one yarn's backward Euler step in its vertex velocities,
//! its gradient and its block-banded Hessian (each element block projected
//! onto the PSD cone).
//!
//! ```text
//! E(v) = sum_i m_i |v_i - v*_i|^2 / 2 + Psi(x + dt v)
//! (the segment vectors of y = x + dt v formed as (x_{s+1} - x_s) + dt (v_{s+1} - v_s): Rod::edges)
//! Psi(y) = sum_s a_s / 2 (|y_{s+1} - y_s| / l0_s - 1)^2
//!        + sum_j B / 2 (kappa_j - kappa0_j)^2 inv_len_j
//!        + sum_i m_i phi(|y_i - p|)
//! ```
//!
//! `a_s = vol_s k` is the segment's stretch term of the yarn energy of
//! Jiang, Gast, Teran 2017 with no shear and no cross-section term
//! (`psi = k / 2 (r11 - 1)^2`, `r11 = |d1| / l0`, [`crate::mpm::laws::axial`]), the bending is the
//! discrete-elastic-rod energy of [`crate::mpm::laws::vertex_forces`], `phi` the
//! attractor's potential of the grid solver ([`crate::mpm::implicit_grid`]).
//! The friction of the contacts ([`super::contacts`]) adds its own term.

use crate::math::dual::jacobian;
use crate::math::psd::symmetrize;
use crate::math::Vec2;
use crate::mpm::laws::bending::{bend_gradient_edges, curvature, project_bend, BendRest};
use crate::mpm::laws::{attractor, axial};

/// A 2x2 block, row major.
pub use crate::mpm::laws::axial::Block;

/// One yarn's step: the state it starts from and its energy terms.
#[derive(Clone, Debug)]
pub struct Rod {
    /// Positions at the start of the step.
    pub x: Vec<Vec2>,
    /// Lumped masses (a vertex and half of each adjacent segment).
    pub m: Vec<f64>,
    /// `v*`: the start velocity plus `dt g`.
    pub vstar: Vec<Vec2>,
    pub dt: f64,
    /// Segment `s` joins vertices `s` and `s + 1`: `(a_s, l0_s)`.
    pub segments: Vec<(f64, f64)>,
    /// Bending stiffness `B` (0: no bending term).
    pub bending: f64,
    /// Rest curvature and inverse Voronoi length per vertex.
    pub bend: Vec<BendRest>,
    /// Attractor position and strength.
    pub attractor: Option<(Vec2, f64)>,
}

/// The Hessian's blocks: `diag[i] = H(i, i)`, `off1[i] = H(i, i + 1)`,
/// `off2[i] = H(i, i + 2)`.
#[derive(Clone, Debug)]
pub struct Hessian {
    pub diag: Vec<Block>,
    pub off1: Vec<Block>,
    pub off2: Vec<Block>,
}

fn add(b: &mut Block, a: &Block, sign: f64) {
    for r in 0..2 {
        for c in 0..2 {
            b[r][c] += sign * a[r][c];
        }
    }
}

fn sub_block(h: &[[f64; 4]; 4], p: usize, q: usize) -> Block {
    [
        [h[2 * p][2 * q], h[2 * p][2 * q + 1]],
        [h[2 * p + 1][2 * q], h[2 * p + 1][2 * q + 1]],
    ]
}

impl Rod {
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// End-of-step positions `x + dt v` (the attractor's term only: the
    /// yarn's own terms read [`Rod::edges`]).
    pub fn positions(&self, v: &[Vec2]) -> Vec<Vec2> {
        self.x.iter().zip(v).map(|(x, v)| x + v * self.dt).collect()
    }

    /// End-of-step segment vectors `(x_{s+1} - x_s) + dt (v_{s+1} - v_s)`:
    /// formed from the start's segment vectors, not as differences of the
    /// end positions `x + dt v`. Both are the same vectors, but rounding
    /// `x + dt v` costs each trial of the line search an error of the
    /// vertices' distance from the origin times the machine epsilon, which
    /// on a stiff yarn metres from the origin (a real nylon monofilament
    /// over a 1 m drum, 7 m up) outweighed the Newton step's predicted
    /// decrease: the line search found none. Here the start's segment
    /// vectors are the same in every trial and the rest is rounded at the
    /// segment's length.
    pub fn edges(&self, v: &[Vec2]) -> Vec<Vec2> {
        (0..self.len().saturating_sub(1))
            .map(|s| (self.x[s + 1] - self.x[s]) + (v[s + 1] - v[s]) * self.dt)
            .collect()
    }

    /// Whether vertex `j` carries a bending term.
    fn bends(&self, j: usize) -> bool {
        self.bending > 0.0 && j > 0 && j + 1 < self.len() && self.bend[j].inv_len != 0.0
    }

    /// `Psi` at the end of the step with velocities `v`.
    pub fn potential(&self, v: &[Vec2]) -> f64 {
        let d = self.edges(v);
        let mut e = 0.0;
        for (s, &(a, l0)) in self.segments.iter().enumerate() {
            e += axial::energy(a, l0, d[s]);
        }
        for j in 0..self.len() {
            if self.bends(j) {
                let b = &self.bend[j];
                let dk = curvature(d[j - 1], d[j]) - b.kappa0;
                e += 0.5 * self.bending * dk * dk * b.inv_len;
            }
        }
        if let Some((p, s)) = self.attractor {
            for (y, m) in self.positions(v).iter().zip(&self.m) {
                e += m * attractor::potential((y - p).norm(), s);
            }
        }
        e
    }

    /// `E(v)` without the friction term.
    pub fn energy(&self, v: &[Vec2]) -> f64 {
        let kinetic: f64 = v
            .iter()
            .zip(&self.vstar)
            .zip(&self.m)
            .map(|((v, vs), m)| 0.5 * m * (v - vs).norm_squared())
            .sum();
        kinetic + self.potential(v)
    }

    /// `dPsi/dy` at the end of the step with velocities `v`.
    pub fn potential_gradient(&self, v: &[Vec2]) -> Vec<Vec2> {
        let d = self.edges(v);
        let mut g = vec![Vec2::zeros(); self.len()];
        for (s, &(a, l0)) in self.segments.iter().enumerate() {
            let f = axial::gradient(a, l0, d[s]);
            g[s] -= f;
            g[s + 1] += f;
        }
        for j in 0..self.len() {
            if self.bends(j) {
                let b = &self.bend[j];
                let (e1, e2) = (d[j - 1], d[j]);
                let [g1x, g1y, g2x, g2y] = bend_gradient_edges(
                    [e1.x, e1.y, e2.x, e2.y],
                    self.bending,
                    b.kappa0,
                    b.inv_len,
                );
                let (g1, g2) = (Vec2::new(g1x, g1y), Vec2::new(g2x, g2y));
                g[j - 1] -= g1;
                g[j] += g1 - g2;
                g[j + 1] += g2;
            }
        }
        if let Some((p, s)) = self.attractor {
            for ((g, y), m) in g.iter_mut().zip(&self.positions(v)).zip(&self.m) {
                let r = y - p;
                let d = r.norm();
                if d > 0.0 {
                    *g += r * (m * attractor::radial_derivatives(d, s).1 / d);
                }
            }
        }
        g
    }

    /// `dE/dv` without the friction term.
    pub fn gradient(&self, v: &[Vec2]) -> Vec<Vec2> {
        let gp = self.potential_gradient(v);
        v.iter()
            .zip(&self.vstar)
            .zip(&self.m)
            .zip(&gp)
            .map(|(((v, vs), m), g)| (v - vs) * *m + g * self.dt)
            .collect()
    }

    /// `d^2 E / dv^2` without the friction term: `M + dt^2 K` with every
    /// element block of `K` projected onto the PSD cone (the stretch block
    /// without its negative transverse part under compression, the
    /// bending block by [`project_bend`]).
    pub fn hessian(&self, v: &[Vec2]) -> Hessian {
        let n = self.len();
        let d = self.edges(v);
        let z = [[0.0; 2]; 2];
        let mut h = Hessian {
            diag: vec![z; n],
            off1: vec![z; n],
            off2: vec![z; n],
        };
        let dt2 = self.dt * self.dt;
        for (s, &(a, l0)) in self.segments.iter().enumerate() {
            if let Some(k) = axial::hessian(a, l0, d[s]) {
                add(&mut h.diag[s], &k, dt2);
                add(&mut h.diag[s + 1], &k, dt2);
                add(&mut h.off1[s], &k, -dt2);
            }
        }
        for j in 0..n {
            if !self.bends(j) {
                continue;
            }
            let b = &self.bend[j];
            let (e1, e2) = (d[j - 1], d[j]);
            let e = [e1.x, e1.y, e2.x, e2.y];
            let bs = self.bending;
            let mut he = jacobian(e, |e| bend_gradient_edges(e, bs, b.kappa0, b.inv_len));
            symmetrize(&mut he);
            let he = project_bend(&he, e, bend_gradient_edges(e, bs, b.kappa0, b.inv_len));
            let (h11, h12, h21, h22) = (
                sub_block(&he, 0, 0),
                sub_block(&he, 0, 1),
                sub_block(&he, 1, 0),
                sub_block(&he, 1, 1),
            );
            // e1 = x_j - x_{j-1}, e2 = x_{j+1} - x_j
            add(&mut h.diag[j - 1], &h11, dt2);
            let mut d = [[0.0; 2]; 2];
            add(&mut d, &h11, 1.0);
            add(&mut d, &h12, -1.0);
            add(&mut d, &h21, -1.0);
            add(&mut d, &h22, 1.0);
            add(&mut h.diag[j], &d, dt2);
            add(&mut h.diag[j + 1], &h22, dt2);
            let mut o = [[0.0; 2]; 2];
            add(&mut o, &h11, -1.0);
            add(&mut o, &h12, 1.0);
            add(&mut h.off1[j - 1], &o, dt2);
            let mut o = [[0.0; 2]; 2];
            add(&mut o, &h12, 1.0);
            add(&mut o, &h22, -1.0);
            add(&mut h.off1[j], &o, dt2);
            add(&mut h.off2[j - 1], &h12, -dt2);
        }
        if let Some((p, s)) = self.attractor {
            for (i, (y, m)) in self.positions(v).iter().zip(&self.m).enumerate() {
                let r = y - p;
                let d = r.norm();
                if d <= 0.0 {
                    continue;
                }
                let u = r / d;
                let (_, d1, d2) = attractor::radial_derivatives(d, s);
                for a in 0..2 {
                    for c in 0..2 {
                        let uu = u[a] * u[c];
                        let id = (a == c) as u8 as f64;
                        h.diag[i][a][c] += dt2 * m * (d2 * uu + d1 / d * (id - uu));
                    }
                }
            }
        }
        for (d, m) in h.diag.iter_mut().zip(&self.m) {
            d[0][0] += m;
            d[1][1] += m;
        }
        h
    }
}

impl Hessian {
    /// `H d`.
    #[cfg(test)]
    pub fn mul(&self, d: &[Vec2]) -> Vec<Vec2> {
        let n = d.len();
        let m = |b: &Block, x: &Vec2| {
            Vec2::new(b[0][0] * x.x + b[0][1] * x.y, b[1][0] * x.x + b[1][1] * x.y)
        };
        let mt = |b: &Block, x: &Vec2| {
            Vec2::new(b[0][0] * x.x + b[1][0] * x.y, b[0][1] * x.x + b[1][1] * x.y)
        };
        let mut y: Vec<Vec2> = (0..n).map(|i| m(&self.diag[i], &d[i])).collect();
        for i in 0..n {
            if i + 1 < n {
                y[i] += m(&self.off1[i], &d[i + 1]);
                y[i + 1] += mt(&self.off1[i], &d[i]);
            }
            if i + 2 < n {
                y[i] += m(&self.off2[i], &d[i + 2]);
                y[i + 2] += mt(&self.off2[i], &d[i]);
            }
        }
        y
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bent, stretched yarn of 8 vertices with the attractor on.
    fn rod(stretch: f64, bent: bool) -> (Rod, Vec<Vec2>) {
        let n = 8;
        let rest: Vec<Vec2> = (0..n)
            .map(|i| {
                let s = i as f64 * 0.05;
                Vec2::new(0.3 + s, 0.5 + if bent { 0.4 * s * s } else { 0.0 })
            })
            .collect();
        let bend = crate::mpm::laws::bending::rest_of_curve(&rest);
        let segments = (0..n - 1)
            .map(|s| (0.05 * 1e3, (rest[s + 1] - rest[s]).norm()))
            .collect();
        // the current shape: the rest shape scaled by `stretch` about its
        // first vertex and rotated by 0.3 rad, plus (if bent) a wiggle
        let (c, s) = (0.3f64.cos(), 0.3f64.sin());
        let x: Vec<Vec2> = rest
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let d = (p - rest[0]) * stretch;
                let w = if bent {
                    0.004 * (i as f64 * 1.7).sin()
                } else {
                    0.0
                };
                rest[0] + Vec2::new(c * d.x - s * d.y, s * d.x + c * d.y + w)
            })
            .collect();
        let v: Vec<Vec2> = (0..n)
            .map(|i| Vec2::new((i as f64).cos() * 0.1, (i as f64 * 0.3).sin() * 0.2))
            .collect();
        let r = Rod {
            x,
            m: vec![0.05; n],
            vstar: v.iter().map(|v| v + Vec2::new(0.0, -0.01)).collect(),
            dt: 2e-3,
            segments,
            bending: 1e-3,
            bend,
            attractor: Some((Vec2::new(0.5, 0.8), 3.0)),
        };
        (r, v)
    }

    /// `dE/dv` against central differences of `E`, 1e-6 relative.
    #[test]
    fn gradient_matches_finite_differences() {
        let (r, v) = rod(1.01, true);
        let g = r.gradient(&v);
        let h = 1e-6;
        for i in 0..r.len() {
            for a in 0..2 {
                let (mut p, mut m) = (v.clone(), v.clone());
                p[i][a] += h;
                m[i][a] -= h;
                let fd = (r.energy(&p) - r.energy(&m)) / (2.0 * h);
                let scale = g.iter().map(|g| g.norm()).fold(0.0, f64::max);
                assert!(
                    (fd - g[i][a]).abs() < 1e-6 * scale,
                    "({i}, {a}): {fd} vs {}",
                    g[i][a]
                );
            }
        }
    }

    /// `H d` against central differences of the gradient along `d`, 1e-6
    /// relative, where no projection acts (every segment in tension,
    /// every joint at its rest curvature: the shape a stretched, rotated
    /// copy of the rest shape).
    #[test]
    fn hessian_matches_finite_differences_of_the_gradient() {
        let (r, v) = rod(1.02, false);
        let h = r.hessian(&v);
        let d: Vec<Vec2> = (0..r.len())
            .map(|i| Vec2::new((i as f64 * 1.3).sin(), (i as f64 * 0.4).cos()))
            .collect();
        let hd = h.mul(&d);
        let e = 1e-6;
        let p: Vec<Vec2> = v.iter().zip(&d).map(|(v, d)| v + d * e).collect();
        let m: Vec<Vec2> = v.iter().zip(&d).map(|(v, d)| v - d * e).collect();
        let (gp, gm) = (r.gradient(&p), r.gradient(&m));
        let scale = hd.iter().map(|x| x.norm()).fold(0.0, f64::max);
        for i in 0..r.len() {
            let fd = (gp[i] - gm[i]) / (2.0 * e);
            assert!(
                (fd - hd[i]).norm() < 1e-6 * scale,
                "{i}: {fd:?} vs {:?}",
                hd[i]
            );
        }
    }
}
