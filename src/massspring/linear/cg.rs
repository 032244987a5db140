//! Preconditioned conjugate gradients with Jacobi or incomplete-Cholesky
//! IC(0) preconditioning (course notes: "CG with an Incomplete Cholesky
//! preconditioner").

use std::fmt;
use std::str::FromStr;

use super::sparse::CsrMatrix;

/// Which preconditioner CG uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum PreconditionerKind {
    /// Plain CG.
    None,
    /// Inverse diagonal.
    Jacobi,
    /// Incomplete Cholesky with the pattern of `A` (default).
    #[default]
    Ic0,
}

impl FromStr for PreconditionerKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "none" | "cg" => Ok(PreconditionerKind::None),
            "jacobi" | "diagonal" => Ok(PreconditionerKind::Jacobi),
            "ic0" | "ic" | "ichol" | "incomplete-cholesky" => Ok(PreconditionerKind::Ic0),
            _ => Err(format!(
                "unknown preconditioner {s:?}; known: none, jacobi, ic0"
            )),
        }
    }
}

impl fmt::Display for PreconditionerKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            PreconditionerKind::None => "none",
            PreconditionerKind::Jacobi => "jacobi",
            PreconditionerKind::Ic0 => "ic0",
        })
    }
}

/// Incomplete Cholesky factor `L` (lower triangle, pattern of `A`), with
/// `A + shift diag(A) ~= L L^T`.
#[derive(Clone, Debug)]
pub struct Ic0 {
    n: usize,
    /// Row pointers of the strictly lower part.
    row_ptr: Vec<usize>,
    col: Vec<usize>,
    val: Vec<f64>,
    diag: Vec<f64>,
}

impl Ic0 {
    /// Factors `A` (symmetric positive definite). Retries with a growing
    /// diagonal shift if a pivot is not positive.
    pub fn new(a: &CsrMatrix) -> Ic0 {
        let mut shift = 0.0;
        loop {
            if let Some(f) = Ic0::try_factor(a, shift) {
                return f;
            }
            shift = if shift == 0.0 { 1e-3 } else { shift * 4.0 };
        }
    }

    fn try_factor(a: &CsrMatrix, shift: f64) -> Option<Ic0> {
        let n = a.n;
        let mut row_ptr = vec![0usize; n + 1];
        let mut col = Vec::new();
        let mut val = Vec::new();
        let mut diag = vec![0.0; n];
        for i in 0..n {
            let start = col.len();
            let mut aii = 0.0;
            for k in a.row_ptr[i]..a.row_ptr[i + 1] {
                let j = a.col[k];
                if j < i {
                    col.push(j);
                    val.push(a.val[k]);
                } else if j == i {
                    aii = a.val[k];
                }
            }
            // Row i of L: L_ik = (a_ik - sum_{j<k} L_ij L_kj) / L_kk.
            for p in start..col.len() {
                let k = col[p];
                let (mut q, qe) = (row_ptr[k], row_ptr[k + 1]);
                let mut s = val[p];
                let mut r = start;
                while r < p && q < qe {
                    match col[r].cmp(&col[q]) {
                        std::cmp::Ordering::Less => r += 1,
                        std::cmp::Ordering::Greater => q += 1,
                        std::cmp::Ordering::Equal => {
                            s -= val[r] * val[q];
                            r += 1;
                            q += 1;
                        }
                    }
                }
                val[p] = s / diag[k];
            }
            let d = aii * (1.0 + shift) - val[start..].iter().map(|v| v * v).sum::<f64>();
            if d.partial_cmp(&(1e-14 * aii.abs())) != Some(std::cmp::Ordering::Greater) {
                return None;
            }
            diag[i] = d.sqrt();
            row_ptr[i + 1] = col.len();
        }
        Some(Ic0 {
            n,
            row_ptr,
            col,
            val,
            diag,
        })
    }

    /// `z = (L L^T)^{-1} r`.
    pub fn apply(&self, r: &[f64], z: &mut [f64]) {
        // Forward: L y = r.
        for i in 0..self.n {
            let mut s = r[i];
            for p in self.row_ptr[i]..self.row_ptr[i + 1] {
                s -= self.val[p] * z[self.col[p]];
            }
            z[i] = s / self.diag[i];
        }
        // Backward: L^T z = y, column by column from the end.
        for i in (0..self.n).rev() {
            z[i] /= self.diag[i];
            let zi = z[i];
            for p in self.row_ptr[i]..self.row_ptr[i + 1] {
                z[self.col[p]] -= self.val[p] * zi;
            }
        }
    }
}

/// A ready-to-apply preconditioner.
#[derive(Clone, Debug)]
pub enum Preconditioner {
    /// No preconditioning.
    None,
    /// Jacobi: the inverse of the diagonal (1 where it is 0).
    Jacobi(Vec<f64>),
    /// Incomplete Cholesky without fill-in.
    Ic0(Ic0),
}

impl Preconditioner {
    /// Builds the preconditioner of `kind` for `a`.
    pub fn new(kind: PreconditionerKind, a: &CsrMatrix) -> Preconditioner {
        match kind {
            PreconditionerKind::None => Preconditioner::None,
            PreconditionerKind::Jacobi => Preconditioner::Jacobi(
                a.diagonal()
                    .into_iter()
                    .map(|d| if d != 0.0 { 1.0 / d } else { 1.0 })
                    .collect(),
            ),
            PreconditionerKind::Ic0 => Preconditioner::Ic0(Ic0::new(a)),
        }
    }

    /// `z = P^{-1} r`.
    pub fn apply(&self, r: &[f64], z: &mut [f64]) {
        match self {
            Preconditioner::None => z.copy_from_slice(r),
            Preconditioner::Jacobi(inv) => {
                for ((zi, ri), di) in z.iter_mut().zip(r).zip(inv) {
                    *zi = ri * di;
                }
            }
            Preconditioner::Ic0(f) => f.apply(r, z),
        }
    }
}

/// Outcome of a CG solve.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct CgResult {
    /// Iterations taken (matrix-vector products after the initial residual).
    pub iterations: usize,
    /// Final `|b - A x| / |b|` (0 when `b = 0`).
    pub relative_residual: f64,
    /// Whether the residual reached the tolerance.
    pub converged: bool,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Below this largest entry of the right-hand side [`pcg`] solves the
/// system scaled by its inverse: the squares in its dot products would
/// underflow.
const TINY_RHS: f64 = 1e-100;

/// Solves `A x = b` by preconditioned CG from the initial guess in `x`,
/// until `|r| <= tol |b|` or `max_iter` iterations.
pub fn pcg(
    a: &CsrMatrix,
    b: &[f64],
    x: &mut [f64],
    pre: &Preconditioner,
    tol: f64,
    max_iter: usize,
) -> CgResult {
    let n = a.n;
    let bmax = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if bmax > 0.0 && bmax < TINY_RHS {
        // Squares of so small a residual underflow (a chain at rest to
        // round-off after a long backward Euler run: |b| ~ 1e-162), which would
        // stop CG at its first step with zero curvature: solve for `x /
        // max |b_i|` with that scaled right-hand side, then scale back.
        // Above this size nothing changes (same bits).
        let s = 1.0 / bmax;
        let scaled: Vec<f64> = b.iter().map(|v| v * s).collect();
        for v in x.iter_mut() {
            *v *= s;
            if !v.is_finite() {
                *v = 0.0;
            }
        }
        let r = pcg(a, &scaled, x, pre, tol, max_iter);
        x.iter_mut().for_each(|v| *v *= bmax);
        return r;
    }
    let bnorm = dot(b, b).sqrt();
    if bnorm == 0.0 {
        x.iter_mut().for_each(|v| *v = 0.0);
        return CgResult {
            iterations: 0,
            relative_residual: 0.0,
            converged: true,
        };
    }
    let mut r = vec![0.0; n];
    a.matvec(x, &mut r);
    for (ri, bi) in r.iter_mut().zip(b) {
        *ri = bi - *ri;
    }
    let mut rnorm = dot(&r, &r).sqrt();
    if rnorm <= tol * bnorm {
        return CgResult {
            iterations: 0,
            relative_residual: rnorm / bnorm,
            converged: true,
        };
    }
    let mut z = vec![0.0; n];
    pre.apply(&r, &mut z);
    let mut p = z.clone();
    let mut rz = dot(&r, &z);
    let mut ap = vec![0.0; n];
    let mut it = 0;
    while it < max_iter {
        it += 1;
        a.matvec(&p, &mut ap);
        let pap = dot(&p, &ap);
        if pap <= 0.0 || !pap.is_finite() {
            break;
        }
        let alpha = rz / pap;
        for i in 0..n {
            x[i] += alpha * p[i];
            r[i] -= alpha * ap[i];
        }
        rnorm = dot(&r, &r).sqrt();
        if rnorm <= tol * bnorm {
            break;
        }
        pre.apply(&r, &mut z);
        let rz_new = dot(&r, &z);
        let beta = rz_new / rz;
        rz = rz_new;
        for i in 0..n {
            p[i] = z[i] + beta * p[i];
        }
    }
    CgResult {
        iterations: it,
        relative_residual: rnorm / bnorm,
        converged: rnorm <= tol * bnorm,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 1D Laplacian plus identity, tridiagonal.
    fn tridiag(n: usize) -> CsrMatrix {
        let mut row_ptr = vec![0];
        let mut col = vec![];
        let mut val = vec![];
        for i in 0..n {
            if i > 0 {
                col.push(i - 1);
                val.push(-1.0);
            }
            col.push(i);
            val.push(3.0);
            if i + 1 < n {
                col.push(i + 1);
                val.push(-1.0);
            }
            row_ptr.push(col.len());
        }
        CsrMatrix {
            n,
            row_ptr,
            col,
            val,
        }
    }

    #[test]
    fn ic0_of_tridiagonal_is_exact_and_pcg_takes_one_iteration() {
        let a = tridiag(50);
        let b: Vec<f64> = (0..50).map(|i| (i as f64 * 0.37).sin()).collect();
        let pre = Preconditioner::new(PreconditionerKind::Ic0, &a);
        let mut x = vec![0.0; 50];
        let res = pcg(&a, &b, &mut x, &pre, 1e-12, 100);
        assert_eq!(res.iterations, 1, "{res:?}");
        let mut none = vec![0.0; 50];
        let plain = pcg(&a, &b, &mut none, &Preconditioner::None, 1e-12, 100);
        assert!(plain.iterations > 5, "{plain:?}");
        for (u, w) in x.iter().zip(&none) {
            assert!((u - w).abs() < 1e-10);
        }
    }

    #[test]
    fn pcg_solves_against_dense() {
        let a = tridiag(8);
        let b = vec![1.0; 8];
        let mut x = vec![0.0; 8];
        let pre = Preconditioner::new(PreconditionerKind::Jacobi, &a);
        let r = pcg(&a, &b, &mut x, &pre, 1e-13, 100);
        assert!(r.converged);
        let d = crate::massspring::linear::dense_solve(
            &a.to_dense(),
            &nalgebra::DVector::from_vec(b.clone()),
        )
        .unwrap();
        for i in 0..8 {
            assert!((x[i] - d[i]).abs() < 1e-12);
        }
    }

    /// A right-hand side whose squares underflow (|b| ~ 1e-162, a chain at
    /// rest to round-off) is solved as well as a unit one, to the same
    /// relative residual, where plain CG stopped at its first step with zero
    /// curvature (relative residual 1).
    #[test]
    fn pcg_solves_a_right_hand_side_whose_squares_underflow() {
        let a = tridiag(8);
        let pre = Preconditioner::new(PreconditionerKind::Jacobi, &a);
        let unit: Vec<f64> = (0..8).map(|i| (i as f64 * 0.37).sin() + 0.5).collect();
        let mut xu = vec![0.0; 8];
        let ru = pcg(&a, &unit, &mut xu, &pre, 1e-12, 100);
        let tiny: Vec<f64> = unit.iter().map(|v| v * 1e-162).collect();
        let mut xt = vec![0.0; 8];
        let rt = pcg(&a, &tiny, &mut xt, &pre, 1e-12, 100);
        assert!(rt.converged && rt.relative_residual <= 1e-12, "{rt:?}");
        assert_eq!(rt.iterations, ru.iterations);
        for (t, u) in xt.iter().zip(&xu) {
            assert!((t / 1e-162 - u).abs() <= 1e-9 * u.abs().max(1.0), "{t} {u}");
        }
    }
}
