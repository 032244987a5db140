//! Dense direct solve (Cholesky, falling back to LU) for small systems such
//! as Baraff and Witkin 1998's 9x9 three-particle system.

use nalgebra::{DMatrix, DVector};

/// Solves `A x = b` directly; `None` when `A` is singular.
pub fn dense_solve(a: &DMatrix<f64>, b: &DVector<f64>) -> Option<DVector<f64>> {
    if let Some(ch) = a.clone().cholesky() {
        return Some(ch.solve(b));
    }
    a.clone().lu().solve(b)
}
