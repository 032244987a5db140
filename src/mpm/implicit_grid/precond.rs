//! A preconditioner for the implicit step's Newton systems that takes the
//! stiff fibre stretch exactly.
//!
//! The Newton matrix is `H = M + dt^2 W^T K W` on the grid nodes. Along a
//! yarn `K` is dominated by the fibre stretch (`k` of the yarn energy),
//! a rank-one term per segment: `c_s (b_s . v)^2` with `b_s` the change of
//! the segment's length per unit of grid velocity (nodal coefficient
//! vectors) and `c_s` its stiffness. Jacobi (`diag H`) sees none of that
//! coupling: its CG count grows with `sqrt(k) dt / dx`. This
//! preconditioner is
//!
//! ```text
//! P = D + B^T C B,        P^-1 = D^-1 - D^-1 B^T S^-1 B D^-1,   S = C^-1 + B D^-1 B^T
//! ```
//!
//! (Sherman-Morrison-Woodbury), `D` a positive diagonal (the rest of `H`),
//! `B` the rows `b_s`, `C = diag(c_s)`. `S` couples only segments that share
//! a grid node: along one yarn it is banded, and it is factored by a banded
//! Cholesky (Golub and Van Loan, "Matrix Computations", 4.3.5). Entries
//! outside the band (other yarns on the same nodes, a yarn folded onto
//! itself) are dropped and their absolute values added to the diagonal,
//! so the factored `S_a >= S` (Gershgorin) and `S_a - B D^-1 B^T >= C^-1 > 0`:
//! `P^-1` stays symmetric positive definite, as CG needs. On one yarn that
//! shares no nodes with another and within the band, `P^-1` is the exact
//! inverse of `D + B^T C B`.
//!
//! Building costs one pass over the node incidences and `O(n bw^2)` for the
//! factor; applying costs `O(nnz(B) + n bw)`. Serial, fixed order: the same
//! bits for any thread count.

use crate::math::Vec2;

/// Band half-width cap of `S` (rows of the same yarn farther apart than
/// this go to the diagonal compensation).
pub const MAX_BAND: usize = 16;

/// One stiff rank-one term `c (sum_n b_n . v_n)^2 / 2` of the Hessian.
#[derive(Clone, Debug, Default)]
pub struct StiffRow {
    /// Rows of one group (a yarn), in order along it, are consecutive.
    pub group: u32,
    /// `(unknown node, b_n)`, each node once.
    pub entries: Vec<(u32, Vec2)>,
    /// Stiffness `c > 0` (rows with `c <= 0` are left out).
    pub c: f64,
}

/// `P^-1` of the module documentation, factored.
#[derive(Clone, Debug)]
pub struct StiffPrecond {
    inv_d: Vec<Vec2>,
    start: Vec<usize>,
    node: Vec<u32>,
    coef: Vec<Vec2>,
    bw: usize,
    /// Lower band of the Cholesky factor of `S_a`: row `i`, entry
    /// `i * (MAX_BAND + 1) + (i - j)` holds `L[i][j]`.
    chol: Vec<f64>,
}

impl StiffPrecond {
    /// Builds and factors the preconditioner for the positive diagonal `d`
    /// (per node and component) and the stiff rows.
    pub fn new(d: &[Vec2], rows: &[StiffRow]) -> Self {
        let inv_d: Vec<Vec2> = d.iter().map(|d| Vec2::new(1.0 / d.x, 1.0 / d.y)).collect();
        let rows: Vec<&StiffRow> = rows.iter().filter(|r| r.c > 0.0).collect();
        let n = rows.len();
        let mut start = Vec::with_capacity(n + 1);
        let (mut node, mut coef) = (Vec::new(), Vec::new());
        start.push(0);
        for r in &rows {
            for &(i, b) in &r.entries {
                node.push(i);
                coef.push(b);
            }
            start.push(node.len());
        }
        // the rows at each node (counting sort: rows in increasing order)
        let mut count = vec![0usize; d.len() + 1];
        for &i in &node {
            count[i as usize + 1] += 1;
        }
        for i in 0..d.len() {
            count[i + 1] += count[i];
        }
        let mut inc = vec![(0u32, Vec2::zeros()); node.len()];
        let mut fill = count.clone();
        for s in 0..n {
            for e in start[s]..start[s + 1] {
                let i = node[e] as usize;
                inc[fill[i]] = (s as u32, coef[e]);
                fill[i] += 1;
            }
        }
        // G = B D^-1 B^T row by row: banded part within a group, the rest
        // compensated on the diagonal
        let mut acc = vec![0.0f64; n];
        let mut mark = vec![false; n];
        let mut touched: Vec<usize> = Vec::new();
        // `S_a` in a band of the full cap's width (the factor uses `bw`)
        let w = MAX_BAND + 1;
        let mut chol = vec![0.0; n * w];
        let mut bw = 0usize;
        for s in 0..n {
            let mut comp = 0.0;
            for e in start[s]..start[s + 1] {
                let i = node[e] as usize;
                let b = coef[e].component_mul(&inv_d[i]);
                for &(t, bt) in &inc[count[i]..count[i + 1]] {
                    let t = t as usize;
                    if !mark[t] {
                        mark[t] = true;
                        touched.push(t);
                    }
                    acc[t] += b.dot(&bt);
                }
            }
            for &t in &touched {
                let g = acc[t];
                acc[t] = 0.0;
                mark[t] = false;
                let near = rows[t].group == rows[s].group && s.abs_diff(t) <= MAX_BAND;
                if near {
                    if t <= s {
                        bw = bw.max(s - t);
                        chol[s * w + (s - t)] = g;
                    }
                } else {
                    comp += g.abs();
                }
            }
            touched.clear();
            chol[s * w] += 1.0 / rows[s].c + comp;
        }
        factor_band(&mut chol, n, bw, w);
        StiffPrecond {
            inv_d,
            start,
            node,
            coef,
            bw,
            chol,
        }
    }

    /// Band half-width of the factored `S_a`.
    #[cfg(test)]
    pub fn band(&self) -> usize {
        self.bw
    }

    /// `z = P^-1 r`.
    pub fn apply(&self, r: &[Vec2], z: &mut [Vec2]) {
        for ((z, r), d) in z.iter_mut().zip(r).zip(&self.inv_d) {
            *z = r.component_mul(d);
        }
        let n = self.start.len() - 1;
        let mut u: Vec<f64> = (0..n)
            .map(|s| {
                (self.start[s]..self.start[s + 1])
                    .map(|e| self.coef[e].dot(&z[self.node[e] as usize]))
                    .sum()
            })
            .collect();
        solve_band(&self.chol, n, self.bw, MAX_BAND + 1, &mut u);
        for (s, u) in u.iter().enumerate() {
            for e in self.start[s]..self.start[s + 1] {
                let i = self.node[e] as usize;
                z[i] -= self.coef[e].component_mul(&self.inv_d[i]) * *u;
            }
        }
    }
}

/// In-place banded Cholesky `A = L L^T` (lower band, half-width `bw`, row
/// `i` at `a[i * w..]`, `w > bw`, entry `i - j`). A pivot that round-off made
/// non-positive is replaced by a tiny positive one (the matrix is SPD by
/// construction).
fn factor_band(a: &mut [f64], n: usize, bw: usize, w: usize) {
    for i in 0..n {
        let j0 = i.saturating_sub(bw);
        for j in j0..=i {
            let mut sum = a[i * w + (i - j)];
            let k0 = j0.max(j.saturating_sub(bw));
            for k in k0..j {
                sum -= a[i * w + (i - k)] * a[j * w + (j - k)];
            }
            if j == i {
                a[i * w] = sum.max(1e-300).sqrt();
            } else {
                a[i * w + (i - j)] = sum / a[j * w];
            }
        }
    }
}

/// Solves `L L^T x = b` in place with the factor of [`factor_band`].
fn solve_band(l: &[f64], n: usize, bw: usize, w: usize, b: &mut [f64]) {
    for i in 0..n {
        let mut s = b[i];
        for k in i.saturating_sub(bw)..i {
            s -= l[i * w + (i - k)] * b[k];
        }
        b[i] = s / l[i * w];
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..(i + bw + 1).min(n) {
            s -= l[k * w + (k - i)] * b[k];
        }
        b[i] = s / l[i * w];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::Rng;

    /// `groups` yarns of `per` segments each over `nodes` nodes; segment
    /// `s` of a yarn touches the nodes `offset + 2 s .. + 6` (neighbours
    /// share nodes, as on the grid), yarn `g` starts at `g * shift`.
    fn rows(r: &mut Rng, groups: usize, per: usize, shift: usize) -> (Vec<StiffRow>, usize) {
        let mut out = Vec::new();
        let mut nodes = 0;
        for g in 0..groups {
            for s in 0..per {
                let entries: Vec<(u32, Vec2)> = (0..6)
                    .map(|k| {
                        let i = g * shift + 2 * s + k;
                        nodes = nodes.max(i + 1);
                        (i as u32, Vec2::new(r.unit() - 0.5, r.unit() - 0.5))
                    })
                    .collect();
                out.push(StiffRow {
                    group: g as u32,
                    entries,
                    c: 10f64.powf(4.0 * r.unit()),
                });
            }
        }
        (out, nodes)
    }

    /// Dense `D + B^T C B` (2 nodes-components).
    fn dense(d: &[Vec2], rows: &[StiffRow]) -> Vec<Vec<f64>> {
        let m = 2 * d.len();
        let mut a = vec![vec![0.0; m]; m];
        for (i, d) in d.iter().enumerate() {
            a[2 * i][2 * i] = d.x;
            a[2 * i + 1][2 * i + 1] = d.y;
        }
        for r in rows {
            let mut b = vec![0.0; m];
            for &(i, v) in &r.entries {
                b[2 * i as usize] += v.x;
                b[2 * i as usize + 1] += v.y;
            }
            for p in 0..m {
                for q in 0..m {
                    a[p][q] += r.c * b[p] * b[q];
                }
            }
        }
        a
    }

    fn mat_vec(a: &[Vec<f64>], x: &[Vec2]) -> Vec<Vec2> {
        let flat: Vec<f64> = x.iter().flat_map(|v| [v.x, v.y]).collect();
        let y: Vec<f64> = a
            .iter()
            .map(|row| row.iter().zip(&flat).map(|(a, b)| a * b).sum())
            .collect();
        y.chunks(2).map(|c| Vec2::new(c[0], c[1])).collect()
    }

    fn setup(seed: u64, groups: usize, shift: usize) -> (Vec<Vec2>, Vec<StiffRow>) {
        let mut r = Rng::new(seed);
        let (rows, nodes) = rows(&mut r, groups, 12, shift);
        let d = (0..nodes)
            .map(|_| Vec2::new(0.1 + r.unit(), 0.1 + r.unit()))
            .collect();
        (d, rows)
    }

    /// One yarn within the band: `P^-1 (D + B^T C B) x = x` to round-off
    /// (relative 1e-10, stiffness ratios up to 1e4).
    #[test]
    fn exact_inverse_on_one_yarn() {
        let (d, rows) = setup(3, 1, 0);
        let p = StiffPrecond::new(&d, &rows);
        let a = dense(&d, &rows);
        let mut r = Rng::new(9);
        let x: Vec<Vec2> = (0..d.len())
            .map(|_| Vec2::new(r.unit() - 0.5, r.unit() - 0.5))
            .collect();
        let ax = mat_vec(&a, &x);
        let mut z = vec![Vec2::zeros(); d.len()];
        p.apply(&ax, &mut z);
        let err: f64 = z.iter().zip(&x).map(|(z, x)| (z - x).norm_squared()).sum();
        let norm: f64 = x.iter().map(|x| x.norm_squared()).sum();
        assert!(
            (err / norm).sqrt() < 1e-10,
            "relative error {}",
            (err / norm).sqrt()
        );
        assert!(p.band() >= 2 && p.band() <= MAX_BAND);
    }

    /// Yarns on shared nodes (dropped couplings): `P^-1` is symmetric and
    /// positive definite.
    #[test]
    fn symmetric_positive_definite_with_shared_nodes() {
        let (d, rows) = setup(5, 3, 3);
        let p = StiffPrecond::new(&d, &rows);
        let mut r = Rng::new(11);
        let mut vecs = Vec::new();
        for _ in 0..20 {
            let x: Vec<Vec2> = (0..d.len())
                .map(|_| Vec2::new(r.unit() - 0.5, r.unit() - 0.5))
                .collect();
            let mut z = vec![Vec2::zeros(); d.len()];
            p.apply(&x, &mut z);
            let q: f64 = x.iter().zip(&z).map(|(x, z)| x.dot(z)).sum();
            assert!(q > 0.0, "x^T P^-1 x = {q}");
            vecs.push((x, z));
        }
        for a in 0..vecs.len() {
            for b in 0..a {
                let ab: f64 = vecs[a]
                    .0
                    .iter()
                    .zip(&vecs[b].1)
                    .map(|(x, z)| x.dot(z))
                    .sum();
                let ba: f64 = vecs[b]
                    .0
                    .iter()
                    .zip(&vecs[a].1)
                    .map(|(x, z)| x.dot(z))
                    .sum();
                assert!((ab - ba).abs() <= 1e-10 * (ab.abs() + ba.abs() + 1e-300));
            }
        }
    }
}
