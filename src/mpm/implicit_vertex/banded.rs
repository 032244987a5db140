//! Symmetric positive definite banded systems: the Cholesky factor
//! `A = L L^T` of a matrix of half-bandwidth `w` in `O(n w^2)` and the two
//! triangular solves (the banded factorisation of Golub and Van Loan,
//! "Matrix Computations", 4th ed., section 4.3.5).

/// A symmetric `n x n` matrix of half-bandwidth `w`, stored by its lower
/// band: `band[i * (w + 1) + k] = A[i][i - k]` for `k <= min(i, w)`.
#[derive(Clone, Debug)]
pub struct Banded {
    pub n: usize,
    pub w: usize,
    band: Vec<f64>,
}

impl Banded {
    /// The zero matrix.
    pub fn zeros(n: usize, w: usize) -> Self {
        Banded {
            n,
            w,
            band: vec![0.0; n * (w + 1)],
        }
    }

    /// Sets every entry to zero, keeping the size.
    pub fn clear(&mut self) {
        self.band.iter_mut().for_each(|a| *a = 0.0);
    }

    /// Adds `a` to `A[i][j]` (and so to `A[j][i]`), `|i - j| <= w`; the
    /// caller adds each off-diagonal pair once.
    #[inline]
    pub fn add(&mut self, i: usize, j: usize, a: f64) {
        let (i, j) = if i >= j { (i, j) } else { (j, i) };
        debug_assert!(i - j <= self.w, "entry ({i}, {j}) outside the band");
        self.band[i * (self.w + 1) + (i - j)] += a;
    }

    /// `A x`.
    #[cfg(test)]
    pub fn mul(&self, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; self.n];
        for i in 0..self.n {
            for k in 0..=self.w.min(i) {
                let a = self.band[i * (self.w + 1) + k];
                y[i] += a * x[i - k];
                if k > 0 {
                    y[i - k] += a * x[i];
                }
            }
        }
        y
    }

    /// Overwrites the band with the Cholesky factor `L` (`A = L L^T`).
    /// `Err(i)`: the pivot of row `i` is not positive (`A` is not positive
    /// definite to working precision).
    pub fn factor(&mut self) -> Result<(), usize> {
        let (n, w) = (self.n, self.w);
        let s = w + 1;
        for j in 0..n {
            // L[j][j]
            let lo = j.saturating_sub(w);
            let mut d = self.band[j * s];
            for p in lo..j {
                let l = self.band[j * s + (j - p)];
                d -= l * l;
            }
            if d.is_nan() || d <= 0.0 {
                return Err(j);
            }
            let d = d.sqrt();
            self.band[j * s] = d;
            // L[i][j] for the rows below within the band
            for i in j + 1..n.min(j + w + 1) {
                let lo = i.saturating_sub(w);
                let mut a = self.band[i * s + (i - j)];
                for p in lo..j {
                    a -= self.band[i * s + (i - p)] * self.band[j * s + (j - p)];
                }
                self.band[i * s + (i - j)] = a / d;
            }
        }
        Ok(())
    }

    /// Solves `L L^T x = b` in place with the factor of [`Banded::factor`].
    // the band's index arithmetic reads best as index loops
    #[allow(clippy::needless_range_loop)]
    pub fn solve(&self, b: &mut [f64]) {
        let (n, w) = (self.n, self.w);
        let s = w + 1;
        for i in 0..n {
            let mut a = b[i];
            for p in i.saturating_sub(w)..i {
                a -= self.band[i * s + (i - p)] * b[p];
            }
            b[i] = a / self.band[i * s];
        }
        for i in (0..n).rev() {
            let mut a = b[i];
            for r in i + 1..n.min(i + w + 1) {
                a -= self.band[r * s + (r - i)] * b[r];
            }
            b[i] = a / self.band[i * s];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::Rng;

    /// A random SPD band matrix (diagonally dominant) solved against its
    /// own product: the residual to 1e-12 relative.
    #[test]
    fn factor_and_solve_reproduce_the_right_hand_side() {
        let (n, w) = (37, 5);
        let mut a = Banded::zeros(n, w);
        let mut r = Rng::new(12345);
        let mut rnd = || r.unit() - 0.5;
        for i in 0..n {
            for j in i.saturating_sub(w)..i {
                a.add(i, j, rnd());
            }
            a.add(i, i, 4.0 + rnd());
        }
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut b = a.mul(&x);
        let mut l = a.clone();
        l.factor().unwrap();
        l.solve(&mut b);
        for (got, want) in b.iter().zip(&x) {
            assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        }
    }

    #[test]
    fn an_indefinite_matrix_is_refused_at_its_row() {
        let mut a = Banded::zeros(3, 1);
        a.add(0, 0, 1.0);
        a.add(1, 0, 2.0);
        a.add(1, 1, 1.0);
        a.add(2, 2, 1.0);
        assert_eq!(a.factor(), Err(1));
    }
}
