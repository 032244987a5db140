//! The Material Point Method solver for 2D yarn bundles (after
//! Jiang, Gast, Teran 2017), by role, from the bottom layer up:
//!
//! * [`machinery`]: the grid and the particles and what moves data between
//!   them: the block grid and its node pools, the particle store, the
//!   transfer schemes (APIC / FLIP), the FLIP spin balance, the SIMD
//!   kernel dispatch and the fixed chunking.
//! * [`laws`]: the physical laws, one file each, with their energy, force
//!   and (where an implicit integrator needs it) Hessian or dual-number
//!   form written once: the constitutive model and its return mapping,
//!   bending, the vertex forces, the attractor, obstacle and wall contact,
//!   the two velocity fields' contact, pins.
//! * the integrators, one folder each: `explicit` (the explicit passes:
//!   P2G, grid update, G2P; the implicit grid integrator scatters and
//!   gathers with the same passes), `implicit_grid` (backward Euler on
//!   the grid velocities: Newton, PCG) and `implicit_vertex` (backward
//!   Euler and the generalized midpoint rule on a single yarn's vertices,
//!   without the grid).
//! * [`driver`]: [`YarnSim`], which runs the integrator a scene names
//!   (one `match` per substep), cutback, the stable time step, the
//!   dynamic state, diagnostics and statistics.
//! * [`error`]: the error of a failed step or input, [`SimError`].
//!
//! A layer uses only the layers below it (`tools/checks/check_modules.py` checks
//! it): laws use the machinery, integrators the laws and the machinery,
//! the driver everything; no integrator uses another.

pub mod driver;
pub mod error;
pub(crate) mod explicit;
pub(crate) mod implicit_grid;
pub(crate) mod implicit_vertex;
pub mod laws;
pub mod machinery;

pub use driver::{
    Attractor, Diagnostics, DtStats, ImplicitStats, PassTimes, Passes, SimError, Stepping, YarnSim,
};
pub use laws::pins::{Pin, PinMotion};
pub use machinery::grid::GridGeom;
pub use machinery::transfer::Transfer;

/// The scatter's layout, which the roofline counts of `yarnsim-evidence`
/// (`yarnsim bench roofline`) read: the grid's block size, the scatter's
/// lanes per node and its fixed chunks.
pub mod scatter_layout {
    pub use super::machinery::grid::{BLOCK, P2G_LANES};
    pub use super::machinery::simd::chunk_bounds;
}
