//! The Material Point Method solver for 2D yarn bundles (seed 000, after
//! Jiang, Gast, Teran 2017).
//!
//! * [`constitutive`]: the anisotropic energy, its stress and the return mapping.
//! * [`particles`]: type-2 vertices and type-3 quadrature particles.
//! * [`grid`]: the block-sparse background grid.
//! * [`passes`]: the passes of one substep.
//! * [`sim`]: [`YarnSim`], which runs the passes a scene needs.
//! * [`state`]: byte serialization of the dynamic state.
//! * [`timestep`]: the stable substep bound (CFL / elastic waves).

pub mod constitutive;
pub mod grid;
pub mod particles;
pub mod passes;
pub mod sim;
pub mod state;
pub mod timestep;

pub use sim::{Attractor, Diagnostics, PassTimes, Passes, SimError, YarnSim};
