//! The implicit (backward Euler) grid update of a yarn scene: the
//! optimization form of Gast, Schroeder, Stomakhin, Jiang, Teran 2015,
//! "Optimization integrator for large time steps" (IEEE TVCG 21(10)). The
//! new grid velocities `v` minimise
//!
//! ```text
//! E(v) = sum_i m_i |v_i - v*_i|^2 / 2 + Psi(v)
//! Psi  = sum_q vol_q psi(G_q(v)) + sum_j B/2 (kappa_j - kappa0_j)^2 inv_len_j
//!        + sum_i m_i phi(|x_i + dt v_i - p|)
//! ```
//!
//! with `v*` the scattered momentum over mass plus `dt g`. The terms are
//! the explicit model's own energies, so both integrators model the same
//! material: `psi` the anisotropic yarn energy of Jiang, Gast, Teran 2017
//! ([`crate::mpm::laws::constitutive`], on `G = [d1 | d2] / l0`, clamps included),
//! the discrete-elastic-rod bending of [`crate::mpm::laws::bending`], and the
//! attractor's potential `phi(r) = s (r - 0.01 ln(r + 0.01))`
//! (`-grad phi` is the explicit attractor acceleration). Each frame is
//! affine in `v` as the gather computes it: `d1 = x_r - x_l` with the
//! vertices at `x + dt sum_i w_i v_i`, `d2 = d2_old + dt C d2_old` with
//! `C` the APIC velocity gradient at the start-of-step stencil
//! ([`problem`] keeps the merged sparse lists); after the solve, the
//! ordinary gather recomputes the frames from the grid and applies the
//! plastic return mapping.
//!
//! The gradient is the explicit force law (written over
//! [`crate::math::dual`] in the laws); the Hessian is
//! assembled once per Newton iteration as small element blocks (4x4 per
//! quadrature particle in `(d1, d2)`, 4x4 per bending vertex in its edges
//! `(e1, e2)`, 2x2 per node for the attractor), exact by forward-mode dual
//! numbers (a pure fibre stretch in closed form), and each block projected
//! onto the PSD cone ([`crate::math::psd`]: projected Newton, Teran, Sifakis, Irving,
//! Fedkiw 2005; the bending blocks in closed form) so the CG systems are
//! positive definite.
//! Fixed pins are linear constraints held by the mass-weighted projection
//! ([`pins`]). The solver is in [`newton`].

mod energy;
pub mod newton;
mod pins;
pub mod precond;
mod problem;
#[cfg(test)]
mod tests;

pub use problem::ContactTerm;
use problem::{AttractorTerm, BendElem, BendTerm, QuadElem, QuadTerm, Weights};

use crate::math::Vec2;
use crate::mpm::laws::constitutive::YarnEnergy;

pub use energy::Blocks;
#[cfg(test)]
use newton::Precond;
pub use newton::{solve, Settings};
pub use problem::Model;

/// The minimisation of one implicit substep on the active grid nodes.
#[derive(Clone, Debug)]
pub struct Problem {
    /// Window index of each unknown node.
    pub nodes: Vec<usize>,
    /// Node masses.
    pub mass: Vec<f64>,
    /// `v*`: momentum over mass plus `dt g`.
    pub vstar: Vec<Vec2>,
    dt: f64,
    energy: YarnEnergy,
    bending: f64,
    quads: Vec<QuadElem>,
    quad_terms: Vec<QuadTerm>,
    bends: Vec<BendElem>,
    bend_terms: Vec<BendTerm>,
    attractor: Option<AttractorTerm>,
    /// The obstacles' normal law on the nodes in contact
    /// ([`Problem::set_contacts`]).
    contacts: Vec<ContactTerm>,
    /// Pin constraint rows (weights in unknown indices) and targets.
    rows: Vec<(Weights, Vec2, usize)>,
    /// Pivoted Cholesky factor of `S = A M^-1 A^T` ([`pins::PinFactor`]).
    chol: pins::PinFactor,
}

/// `sum a_i . b_i`.
pub fn dot(a: &[Vec2], b: &[Vec2]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a.dot(b)).sum()
}
