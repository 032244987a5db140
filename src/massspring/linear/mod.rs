//! Linear algebra for the implicit integrators: a symmetric sparse matrix in
//! CSR form assembled from 3x3 spring blocks, preconditioned conjugate
//! gradients with Jacobi or incomplete-Cholesky IC(0) preconditioning, and a
//! dense direct solve (tests only) used to check CG on small systems (the three-particle system).

pub mod cg;
#[cfg(test)]
pub mod dense;
pub mod sparse;

pub use cg::{pcg, Preconditioner, PreconditionerKind};
#[cfg(test)]
pub use dense::dense_solve;
pub use sparse::{assemble_block_system, CsrMatrix, DofMap};
