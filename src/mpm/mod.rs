//! The Material Point Method solver for 2D yarn bundles (after
//! Jiang, Gast, Teran 2017), one file per stage of a substep:
//!
//! * [`constitutive`]: the anisotropic energy, its stress and the return mapping.
//! * [`particles`]: type-2 vertices and type-3 quadrature particles.
//! * [`vertex_forces`]: fiber and bending forces on the vertices (a plain
//!   function of the positions, usable without the grid).
//! * [`grid`]: the background grid, a window of 8x8-node blocks around the
//!   particles, and the chunks' scatter buffers.
//! * [`line_pool`]: the grid's node pools, starting on a cache line.
//! * [`particle_to_grid`]: pass 1, P2G of mass, momentum and force impulses.
//! * [`grid_update`]: pass 2, velocities, gravity, attractor, contact, walls.
//! * [`contact`]: the obstacle (Coulomb), wall and grid-edge laws.
//! * [`fields`]: the held and free velocity fields and their Coulomb contact.
//! * [`grid_to_particle`]: passes 3 and 4, G2P of vertices and quadrature particles.
//! * [`frames`]: the quadrature particles' QR, return mapping and stress,
//!   over a batch (vectorized across particles).
//! * [`transfer`]: the G2P velocity update (APIC or FLIP blend).
//! * [`pins`]: pinned and driven vertices and their reaction forces.
//! * [`spin`]: the per-yarn angular momentum balance of the FLIP transfer.
//! * [`simd`]: AVX2 + FMA / portable kernel dispatch and the fixed chunking.
//! * [`implicit`]: backward Euler on the grid velocities (Newton, PCG).
//! * [`gridless`]: backward Euler and the generalized midpoint rule on a
//!   single yarn's vertices without the grid (banded Newton, contacts).
//! * [`sim`]: [`YarnSim`], which runs the passes a scene needs.
//! * [`state`]: byte serialization of the dynamic state.
//! * [`timestep`]: the stable substep bound (CFL / elastic waves).

pub mod attractor;
pub mod bending;
pub mod constitutive;
pub mod contact;
pub mod error;
pub mod fields;
pub mod frames;
pub mod grid;
pub mod grid_to_particle;
pub mod grid_update;
pub mod gridless;
pub mod implicit;
pub mod line_pool;
pub mod particle_to_grid;
pub mod particles;
pub mod pins;
pub mod sim;
pub mod simd;
pub mod spin;
pub mod state;
pub mod timestep;
pub mod transfer;
pub mod vertex_forces;

pub use pins::{Pin, PinMotion};
pub use sim::{
    Attractor, Diagnostics, DtStats, ImplicitStats, PassTimes, Passes, SimError, Stepping, YarnSim,
};
pub use transfer::Transfer;
