//! Symmetric positive definite block tridiagonal systems of 2x2 blocks: a
//! yarn's Newton system without bending, where the stretch springs couple
//! each vertex to its two neighbours only. Block `LDL^T` (the block
//! tridiagonal elimination of Golub and Van Loan, "Matrix Computations",
//! 4th ed., section 4.5.1, for an SPD matrix without pivoting):
//!
//! ```text
//! D_0 = A_00,   G_i = D_{i-1}^-1 B_{i-1},   D_i = A_ii - B_{i-1}^T G_i
//! ```
//!
//! with `B_i = A(i, i + 1)`, and the solve `y_i = b_i - G_i^T y_{i-1}`,
//! `x_i = D_i^-1 y_i - G_{i+1} x_{i+1}`. Each vertex's step depends on the
//! last through one 2x2 product and one division (the inverse of `D_i`),
//! where the scalar band factorisation of [`super::banded`] chains two
//! rows' square roots and divisions per vertex. The explicit inverses of
//! the 2x2 blocks lose about the system's condition times the round-off
//! (1.7e-9 relative at a condition of 4e4, where the band's Cholesky
//! solve keeps 1.8e-12; the test below): Newton, which measures its
//! convergence on the exact gradient, takes it as a search direction, and
//! took the same iterations with it on the stiff reference bundle
//! (38,398 over its first 0.3 s) in three quarters of the axial solves' time
//! (`docs/performance/cost.md`).

use super::energy::Block;

/// A symmetric matrix of `n x n` 2x2 blocks, tridiagonal by blocks: the
/// diagonal blocks `A(i, i)` and the blocks `A(i, i + 1)` above them
/// (`A(i + 1, i)` their transposes). After [`BlockTridiagonal::factor`]
/// it holds `D_i^-1` and `G_{i+1}` in their place.
#[derive(Clone, Debug)]
pub struct BlockTridiagonal {
    diag: Vec<Block>,
    off: Vec<Block>,
}

const ZERO: Block = [[0.0; 2]; 2];

impl BlockTridiagonal {
    /// The zero matrix of `n` block rows.
    pub fn zeros(n: usize) -> Self {
        BlockTridiagonal {
            diag: vec![ZERO; n],
            off: vec![ZERO; n.saturating_sub(1)],
        }
    }

    /// Sets every block to zero.
    pub fn clear(&mut self) {
        self.diag.fill(ZERO);
        self.off.fill(ZERO);
    }

    /// Adds `b` to the diagonal block `A(i, i)`; its lower entry `b[1][0]`
    /// stands for both off-diagonal entries (the symmetric matrix's lower
    /// triangle, as [`super::banded::Banded::add`] stores it).
    #[inline]
    pub fn add_diag(&mut self, i: usize, b: &Block) {
        let d = &mut self.diag[i];
        d[0][0] += b[0][0];
        d[1][0] += b[1][0];
        d[0][1] += b[1][0];
        d[1][1] += b[1][1];
    }

    /// Adds `b` to `A(i, i + 1)` (and its transpose to `A(i + 1, i)`).
    #[inline]
    pub fn add_off(&mut self, i: usize, b: &Block) {
        let o = &mut self.off[i];
        for r in 0..2 {
            for c in 0..2 {
                o[r][c] += b[r][c];
            }
        }
    }

    /// Overwrites the blocks with the factors: `D_i^-1` on the diagonal,
    /// `G_{i+1} = D_i^-1 B_i` above it. `Err(i)`: `D_i` is not positive
    /// definite (nor is `A`, to working precision), at block row `i`.
    pub fn factor(&mut self) -> Result<(), usize> {
        let n = self.diag.len();
        for i in 0..n {
            let mut d = self.diag[i];
            if i > 0 {
                // D_i = A_ii - B^T G with G = D_{i-1}^-1 B (symmetric: the
                // lower entry computed once)
                let (b, g) = (&self.off[i - 1], &self.diag_g(i));
                d[0][0] -= b[0][0] * g[0][0] + b[1][0] * g[1][0];
                d[1][0] -= b[0][1] * g[0][0] + b[1][1] * g[1][0];
                d[1][1] -= b[0][1] * g[0][1] + b[1][1] * g[1][1];
                self.off[i - 1] = *g;
            }
            let det = d[0][0] * d[1][1] - d[1][0] * d[1][0];
            if d[0][0].is_nan() || d[0][0] <= 0.0 || det.is_nan() || det <= 0.0 {
                return Err(i);
            }
            let inv = 1.0 / det;
            let off = -d[1][0] * inv;
            self.diag[i] = [[d[1][1] * inv, off], [off, d[0][0] * inv]];
        }
        Ok(())
    }

    /// `G_i = D_{i-1}^-1 B_{i-1}` from the inverse already in place.
    #[inline(always)]
    fn diag_g(&self, i: usize) -> Block {
        let (e, b) = (&self.diag[i - 1], &self.off[i - 1]);
        let mut g = ZERO;
        for r in 0..2 {
            for c in 0..2 {
                g[r][c] = e[r][0] * b[0][c] + e[r][1] * b[1][c];
            }
        }
        g
    }

    /// Solves `A x = b` in place with the factors of
    /// [`BlockTridiagonal::factor`]; `b` holds `x_i` at `[2 i, 2 i + 1]`.
    pub fn solve(&self, b: &mut [f64]) {
        let n = self.diag.len();
        assert_eq!(b.len(), 2 * n, "one pair of entries per block row");
        // y_i = b_i - G_i^T y_{i-1}, then z_i = D_i^-1 y_i
        let mut prev = [0.0; 2];
        for i in 0..n {
            let mut y = [b[2 * i], b[2 * i + 1]];
            if i > 0 {
                let g = &self.off[i - 1];
                y[0] -= g[0][0] * prev[0] + g[1][0] * prev[1];
                y[1] -= g[0][1] * prev[0] + g[1][1] * prev[1];
            }
            prev = y;
            let e = &self.diag[i];
            b[2 * i] = e[0][0] * y[0] + e[0][1] * y[1];
            b[2 * i + 1] = e[1][0] * y[0] + e[1][1] * y[1];
        }
        // x_i = z_i - G_{i+1} x_{i+1}
        for i in (0..n.saturating_sub(1)).rev() {
            let g = &self.off[i];
            let (x0, x1) = (b[2 * i + 2], b[2 * i + 3]);
            b[2 * i] -= g[0][0] * x0 + g[0][1] * x1;
            b[2 * i + 1] -= g[1][0] * x0 + g[1][1] * x1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mpm::implicit_vertex::banded::Banded;
    use crate::testing::Rng;

    /// A random SPD block tridiagonal matrix (diagonally dominant, with
    /// the stiff direction of a stretched spring: condition about 1e4, as
    /// the axial step's `M + dt^2 K`), in both forms.
    // the 2x2 blocks' entries read best as index loops
    #[allow(clippy::needless_range_loop)]
    fn random(n: usize, seed: u64) -> (BlockTridiagonal, Banded) {
        let mut t = BlockTridiagonal::zeros(n);
        let mut a = Banded::zeros(2 * n, 3);
        let mut r = Rng::new(seed);
        let mut rnd = || r.unit() - 0.5;
        let mut diag = vec![[[1.0, 0.0], [0.0, 1.0]]; n];
        for i in 0..n - 1 {
            // a spring between i and i + 1 along a random direction
            let (c, s) = (rnd(), rnd());
            let l = (c * c + s * s).sqrt();
            let u = [c / l, s / l];
            let k = 1e4 * (1.0 + rnd());
            let kk: Block = std::array::from_fn(|p| std::array::from_fn(|q| k * u[p] * u[q]));
            for p in 0..2 {
                for q in 0..2 {
                    diag[i][p][q] += kk[p][q];
                    diag[i + 1][p][q] += kk[p][q];
                }
            }
            let o: Block = std::array::from_fn(|p| std::array::from_fn(|q| -kk[p][q]));
            t.add_off(i, &o);
            for p in 0..2 {
                for q in 0..2 {
                    a.add(2 * i + p, 2 * (i + 1) + q, o[p][q]);
                }
            }
        }
        for (i, d) in diag.iter().enumerate() {
            t.add_diag(i, d);
            for p in 0..2 {
                for q in 0..=p {
                    a.add(2 * i + p, 2 * i + q, d[p][q]);
                }
            }
        }
        (t, a)
    }

    /// The solve reproduces the right-hand side of a known solution: to
    /// 1e-8 of its largest entry at a condition of about 4e4 (measured:
    /// 1.7e-9 at n = 200, where the band's Cholesky solve reaches 1.8e-12;
    /// the explicit 2x2 inverses lose about the condition times the
    /// round-off, see the module docs).
    #[test]
    fn solves_a_stiff_yarn_system_as_the_band_does() {
        for (n, seed) in [(1, 3), (2, 5), (7, 11), (200, 12345)] {
            let (mut t, a) = random(n, seed);
            let x: Vec<f64> = (0..2 * n).map(|i| (i as f64 * 0.37).sin()).collect();
            let b = a.mul(&x);
            let (mut xt, mut xb) = (b.clone(), b.clone());
            t.factor().unwrap();
            t.solve(&mut xt);
            let mut l = a.clone();
            l.factor().unwrap();
            l.solve(&mut xb);
            let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for ((got, band), want) in xt.iter().zip(&xb).zip(&x) {
                assert!((got - want).abs() < 1e-8 * scale, "n {n}: {got} vs {want}");
                assert!(
                    (band - want).abs() < 1e-11 * scale,
                    "n {n}: {band} vs {want}"
                );
            }
        }
    }

    /// An indefinite matrix is refused at the block row where it shows.
    #[test]
    fn an_indefinite_matrix_is_refused_at_its_block_row() {
        let mut t = BlockTridiagonal::zeros(3);
        let one = [[1.0, 0.0], [0.0, 1.0]];
        for i in 0..3 {
            t.add_diag(i, &one);
        }
        // B_0 = 2 I: D_1 = I - 4 I
        t.add_off(0, &[[2.0, 0.0], [0.0, 2.0]]);
        assert_eq!(t.factor(), Err(1));
        // a non-finite entry is refused too
        let mut t = BlockTridiagonal::zeros(2);
        t.add_diag(0, &one);
        t.add_diag(1, &[[f64::NAN, 0.0], [0.0, 1.0]]);
        assert_eq!(t.factor(), Err(1));
    }
}
