//! The grid-free implicit step of a single yarn (`[time] integrator =
//! "implicit-vertices"`): backward Euler on the yarn's vertex velocities,
//! the same energies as the grid solver ([`super::implicit_grid`]) where a
//! single yarn without a cross-section energy needs no grid.
//!
//! In the model of Jiang, Gast, Teran 2017 the grid carries what couples a
//! yarn to its neighbours (the cross-section energy of the quadrature
//! particles, yarn-yarn contact); a yarn alone whose material has neither a
//! shear nor a normal stiffness (`gamma = youngs_modulus = 0`: a string, or
//! a rod with bending) moves by its vertex energies alone: fibre stretch
//! `vol k / 2 (|d1| / l0 - 1)^2` per segment, discrete-elastic-rod bending
//! (Bergou et al. 2008) per interior vertex, gravity, the attractor. On the
//! grid those energies are sampled through the B-spline transfers (the
//! hanging chain's period then carries the grid's error, +0.04 % at 64^2,
//! `docs/yarn-integrators.md`); here they act on the vertices exactly. The step
//! minimises ([`energy`])
//!
//! ```text
//! E(v) = sum_i m_i |v_i - v_i^n - dt g|^2 / 2 + Psi(x + dt v)
//! ```
//!
//! (Gast, Schroeder, Stomakhin, Jiang, Teran 2015, the optimization form of
//! backward Euler; Baraff and Witkin 1998 for a mass-spring yarn) by
//! projected Newton with a banded Cholesky solve per iteration
//! ([`newton`], [`banded`]; block tridiagonal without bending,
//! [`block_tridiagonal`]): the Hessian of a yarn is block pentadiagonal,
//! so an iteration costs `O(n)` and the solve is exact. Pins prescribe their
//! vertices' velocities; obstacles are normal-velocity constraints with
//! Coulomb friction in the minimisation ([`contacts`]). Masses are lumped:
//! a vertex and half of each adjacent segment (the quadrature particle's
//! mass split between its two vertices). The quadrature particles follow
//! their vertices (midpoint, mean velocity, `d1` the edge, `d2` turned
//! with it) for the outputs.

pub mod banded;
pub mod block_tridiagonal;
pub mod contacts;
pub mod energy;
pub mod newton;

pub use contacts::step;
pub use energy::Rod;
pub use newton::Settings;
