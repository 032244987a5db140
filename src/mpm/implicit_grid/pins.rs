//! The fixed pins as exact linear constraints `sum_i w_ip v_i = target` on
//! the grid velocities (the explicit step's constraint,
//! [`crate::mpm::laws::pins::constrain_grid`], solved exactly): the mass-weighted
//! projection onto the velocities that keep them.

use super::problem::Weights;
use super::Problem;
use crate::math::Vec2;
use crate::mpm::machinery::particles::NONE;

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
                s[b * n + a] = sum;
            }
        }
        self.chol = PinFactor::new(s, n);
    }

    /// `S^-1 b` per component (on the independent rows; see [`PinFactor`]).
    fn solve_s(&self, b: &mut [Vec2]) {
        self.chol.solve(b);
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

/// Cholesky factor of `S = A M^-1 A^T` with diagonal pivoting (Golub and
/// Van Loan, "Matrix Computations", 4.2.8): rows that depend on the others
/// (more pinned vertices than the nodes under them can tell apart, e.g. a
/// bed pinned at every vertex, two vertices per cell) are left out once
/// the largest remaining pivot is round-off (1e-10 of the largest
/// diagonal), and get a multiplier of 0; the independent rows get the exact
/// solution (the rows are consistent: every pinned vertex follows its
/// pin's one motion).
#[derive(Clone, Debug, Default)]
pub struct PinFactor {
    /// `L` (lower, row-major, `n x n`) of the permuted `S`.
    l: Vec<f64>,
    /// Row `k` of the factor is row `perm[k]` of `S`.
    perm: Vec<usize>,
    /// Independent rows (the first `rank` of the permutation).
    rank: usize,
}

impl PinFactor {
    fn new(mut s: Vec<f64>, n: usize) -> Self {
        let mut perm: Vec<usize> = (0..n).collect();
        let top = (0..n).map(|i| s[i * n + i]).fold(0.0, f64::max);
        let mut rank = n;
        for j in 0..n {
            // the largest remaining pivot
            let (mut best, mut bd) = (j, f64::NEG_INFINITY);
            for i in j..n {
                let d = s[i * n + i];
                if d > bd {
                    (best, bd) = (i, d);
                }
            }
            if bd <= 1e-10 * top {
                rank = j;
                break;
            }
            if best != j {
                perm.swap(j, best);
                for c in 0..n {
                    s.swap(j * n + c, best * n + c);
                }
                for r in 0..n {
                    s.swap(r * n + j, r * n + best);
                }
            }
            let d = s[j * n + j].sqrt();
            s[j * n + j] = d;
            for i in j + 1..n {
                s[i * n + j] /= d;
            }
            // the trailing block less the new column's outer product
            for i in j + 1..n {
                let lij = s[i * n + j];
                for k in j + 1..n {
                    s[i * n + k] -= lij * s[k * n + j];
                }
            }
        }
        PinFactor { l: s, perm, rank }
    }

    /// `b <- S^+ b` on the independent rows (the others 0).
    fn solve(&self, b: &mut [Vec2]) {
        let n = self.perm.len();
        let (l, r) = (&self.l, self.rank);
        let mut y: Vec<Vec2> = self.perm.iter().map(|&p| b[p]).collect();
        for i in 0..r {
            for k in 0..i {
                let t = y[k] * l[i * n + k];
                y[i] -= t;
            }
            y[i] /= l[i * n + i];
        }
        for y in &mut y[r..] {
            *y = Vec2::zeros();
        }
        for i in (0..r).rev() {
            for k in i + 1..r {
                let t = y[k] * l[k * n + i];
                y[i] -= t;
            }
            y[i] /= l[i * n + i];
        }
        for (k, &p) in self.perm.iter().enumerate() {
            b[p] = y[k];
        }
    }
}
