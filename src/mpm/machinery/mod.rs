//! The grid and particle machinery the integrators share: storage and
//! data movement, no physical law.
//!
//! * `grid`: the background grid, a window of 8x8-node blocks around the
//!   particles, and the chunks' scatter buffers.
//! * `line_pool`: the grid's node pools, starting on a cache line.
//! * [`particles`]: type-2 vertices and type-3 quadrature particles.
//! * `transfer`: the G2P velocity update (APIC or FLIP blend).
//! * `share`: what the grid holds of a velocity change given to the
//!   particles after the gather (the axial step's, under FLIP).
//! * `spin`: the per-yarn angular momentum balance of the FLIP transfer.
//! * `simd`: AVX2 + FMA / portable kernel dispatch and the fixed chunking.

pub(crate) mod grid;
pub(crate) mod line_pool;
pub mod particles;
pub(crate) mod share;
pub(crate) mod simd;
pub(crate) mod spin;
pub(crate) mod transfer;
