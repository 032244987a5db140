//! The fixed pins as exact linear constraints `sum_i w_ip v_i = target` on
//! the grid velocities (the explicit step's constraint,
//! [`crate::mpm::pins::constrain_grid`], solved exactly): the mass-weighted
//! projection onto the velocities that keep them.

use super::super::particles::NONE;
use super::problem::Weights;
use super::Problem;
use crate::math::Vec2;

impl Problem {
    /// Factors `S = A M^-1 A^T` of the pin rows (dense Cholesky; the pins
    /// of a scene are a few vertices).
    pub(super) fn factor(&mut self) {
        let n = self.rows.len();
        let mut s = vec![0.0; n * n];
        for a in 0..n {
            for b in 0..=a {
                let (ra, rb) = (&self.rows[a].0, &self.rows[b].0);
                let mut sum = 0.0;
                for i in 0..9 {
                    for j in 0..9 {
                        if ra.node[i] != NONE && ra.node[i] == rb.node[j] {
                            sum += ra.w[i] * rb.w[j] / self.mass[ra.node[i] as usize];
                        }
                    }
                }
                s[a * n + b] = sum;
            }
        }
        for j in 0..n {
            let mut d = s[j * n + j];
            for k in 0..j {
                d -= s[j * n + k] * s[j * n + k];
            }
            let d = d.max(1e-300).sqrt();
            s[j * n + j] = d;
            for i in j + 1..n {
                let mut v = s[i * n + j];
                for k in 0..j {
                    v -= s[i * n + k] * s[j * n + k];
                }
                s[i * n + j] = v / d;
            }
        }
        self.chol = s;
    }

    /// `S^-1 b` per component.
    fn solve_s(&self, b: &mut [Vec2]) {
        let (n, l) = (self.rows.len(), &self.chol);
        for i in 0..n {
            for k in 0..i {
                let t = b[k] * l[i * n + k];
                b[i] -= t;
            }
            b[i] /= l[i * n + i];
        }
        for i in (0..n).rev() {
            for k in i + 1..n {
                let t = b[k] * l[k * n + i];
                b[i] -= t;
            }
            b[i] /= l[i * n + i];
        }
    }

    /// `A x` (each pinned vertex's interpolated value).
    pub(super) fn apply_a(&self, x: &[Vec2]) -> Vec<Vec2> {
        self.rows.iter().map(|(w, _, _)| interp(w, x)).collect()
    }

    /// `out += A^T l`, each term scaled by `1/m` when `inv_m`.
    fn add_at(&self, l: &[Vec2], inv_m: bool, out: &mut [Vec2]) {
        for ((w, _, _), l) in self.rows.iter().zip(l) {
            for n in 0..9 {
                if w.node[n] != NONE {
                    let i = w.node[n] as usize;
                    let s = if inv_m { w.w[n] / self.mass[i] } else { w.w[n] };
                    out[i] += l * s;
                }
            }
        }
    }

    /// The feasible point nearest to `v` in the mass norm: every pinned
    /// vertex's interpolated velocity at its target.
    pub fn make_feasible(&self, v: &mut [Vec2]) {
        if self.rows.is_empty() {
            return;
        }
        let mut r: Vec<Vec2> = self.apply_a(v);
        for (r, (_, t, _)) in r.iter_mut().zip(&self.rows) {
            *r = t - *r;
        }
        self.solve_s(&mut r);
        self.add_at(&r, true, v);
    }

    /// `Pi x = x - M^-1 A^T S^-1 A x`: onto the velocity changes that keep
    /// the pins (mass-orthogonal projection).
    pub fn project(&self, x: &mut [Vec2]) {
        if self.rows.is_empty() {
            return;
        }
        let mut l = self.apply_a(x);
        self.solve_s(&mut l);
        l.iter_mut().for_each(|l| *l = -*l);
        self.add_at(&l, true, x);
    }

    /// `Pi^T g = g - A^T S^-1 A M^-1 g`, and the multipliers
    /// `S^-1 A M^-1 g` (each pinned vertex's impulse on the grid at the
    /// solution).
    pub fn project_dual(&self, g: &mut [Vec2]) -> Vec<Vec2> {
        if self.rows.is_empty() {
            return Vec::new();
        }
        // A M^-1 g without the scaled copy of g
        let mut l: Vec<Vec2> = self
            .rows
            .iter()
            .map(|(w, _, _)| {
                let mut s = Vec2::zeros();
                for n in 0..9 {
                    if w.node[n] != NONE {
                        let i = w.node[n] as usize;
                        s += (g[i] / self.mass[i]) * w.w[n];
                    }
                }
                s
            })
            .collect();
        self.solve_s(&mut l);
        let neg: Vec<Vec2> = l.iter().map(|l| -l).collect();
        self.add_at(&neg, false, g);
        l
    }

    /// Whether any pin constrains the grid.
    pub fn has_pins(&self) -> bool {
        !self.rows.is_empty()
    }

    /// Pin index of each constraint row.
    pub fn row_pins(&self) -> impl Iterator<Item = usize> + '_ {
        self.rows.iter().map(|r| r.2)
    }
}

/// `sum_i w_i v_i` over a stencil.
#[inline]
pub(super) fn interp(w: &Weights, v: &[Vec2]) -> Vec2 {
    let mut s = Vec2::zeros();
    for n in 0..9 {
        if w.node[n] != NONE {
            s += v[w.node[n] as usize] * w.w[n];
        }
    }
    s
}
