//! The physical laws of the yarn model, one file each: its parameters, its
//! energy and force, and the Hessian or dual-number form an implicit
//! integrator needs, written once and used by every integrator.
//!
//! * [`constitutive`]: the anisotropic yarn energy of Jiang, Gast, Teran
//!   2017, its stress and Mohr-Coulomb return mapping (with its dual-number
//!   form), and `constitutive::frames`, the same over batches of frames.
//! * [`axial`]: the fibre-stretch (`k`) term on one segment as a spring
//!   between its vertices: energy, gradient, PSD Hessian block.
//! * [`bending`]: discrete-elastic-rod bending (Bergou et al. 2008): rest
//!   state, energy, gradient, dual-number form and the PSD projection of
//!   its Hessian blocks.
//! * `vertex_forces`: fibre and bending forces on the yarn vertices.
//! * [`attractor`]: the attractor's potential, pull and Hessian, and its
//!   input check.
//! * `contact`: obstacles with Coulomb friction, walls, the grid's edge.
//! * `fields`: the held and free velocity fields and their Coulomb contact.
//! * [`pins`]: pinned and driven vertices and their reaction forces.

pub mod attractor;
pub mod axial;
pub mod bending;
pub mod constitutive;
pub(crate) mod contact;
pub(crate) mod fields;
pub mod pins;
pub(crate) mod vertex_forces;
