//! The explicit integrator (symplectic Euler on the grid, Jiang, Gast,
//! Teran 2017), one pass per file. The implicit grid integrator
//! ([`super::implicit_grid`]) scatters and gathers with the same passes
//! (the driver calls them), with the internal forces left to its solve.
//!
//! * [`particle_to_grid`]: pass 1, P2G of mass, momentum and force impulses.
//! * [`grid_update`]: pass 2, velocities, gravity, attractor, contact, walls.
//! * [`grid_to_particle`]: passes 3 and 4, G2P of vertices and quadrature
//!   particles.

pub mod grid_to_particle;
pub mod grid_update;
pub mod particle_to_grid;
