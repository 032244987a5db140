//! One substep of the yarn bundle: the one choice of integrator
//! ([`YarnSim::substep_once`]), then, for the two grid integrators, the
//! passes in order (stress, scatter, the integrator's grid velocities,
//! field contact, gather, pins, under `axial = "implicit"` the axial
//! springs' vertex step of `axial.rs`), their timings, and the checks that turn a
//! bad state into a [`SimError`]. The explicit grid update is here
//! ([`YarnSim::explicit_grid_velocities`]), the implicit one in
//! `implicit_grid.rs`, the grid-free step in `implicit_vertex.rs`.

use std::time::Instant;

use super::stats::Passes;
use super::{SimError, YarnSim};
use crate::math::Vec2;
use crate::mpm::explicit::grid_to_particle::{self, VertexGather};
use crate::mpm::explicit::grid_update::{self, GridForces};
use crate::mpm::explicit::particle_to_grid;
use crate::mpm::laws::pins::{self, PinEntry};
use crate::mpm::machinery::spin;
use crate::scene::{Integrator, Obstacle, YarnScene};

/// The obstacles contact sees (`YarnSim::obstacles`) when their pass
/// runs, none otherwise.
pub(super) fn active_obstacles(obstacles: &[Obstacle], passes: Passes) -> &[Obstacle] {
    if passes.obstacles {
        obstacles
    } else {
        &[]
    }
}

/// Half the yarn diameter (`material.diameter`), 0 without one.
pub(super) fn yarn_radius(scene: &YarnScene) -> f64 {
    scene.material.diameter().map_or(0.0, |d| 0.5 * d)
}

/// The grid update's external forces: gravity, `attractor`, the active
/// obstacles of `obstacles` and the scene's walls.
pub(super) fn grid_forces<'a>(
    scene: &'a YarnScene,
    obstacles: &'a [Obstacle],
    passes: Passes,
    gravity: Vec2,
    attractor: Option<(Vec2, f64)>,
) -> GridForces<'a> {
    GridForces {
        gravity,
        attractor,
        obstacles: active_obstacles(obstacles, passes),
        yarn_radius: yarn_radius(scene),
        walls: scene.walls.mode,
        wall_cells: scene.walls.cells as usize,
    }
}

impl YarnSim {
    /// The bending stiffness when its pass runs, 0 otherwise.
    pub(super) fn active_bending(&self, passes: Passes) -> f64 {
        if passes.bending {
            self.scene.material.bending
        } else {
            0.0
        }
    }

    /// `(position, strength)` of the attractor when its pass runs.
    pub(super) fn active_attractor(&self, passes: Passes) -> Option<(Vec2, f64)> {
        passes
            .attractor
            .then_some((self.attractor.position, self.attractor.strength))
    }
}

/// The grid velocities of a grid integrator's substep, between the scatter
/// and the field contact: `(sim, dt, flip, pin entries, passes)`.
type GridVelocities = fn(&mut YarnSim, f64, bool, &[PinEntry], Passes) -> Result<(), SimError>;

impl YarnSim {
    /// One substep of `dt` (finite, > 0; not failed before) by the scene's
    /// integrator, chosen here and nowhere else. On a `SimError` the state
    /// is part-way through the substep and the error is recorded in
    /// `failed`.
    pub(super) fn substep_once(&mut self, dt: f64) -> Result<(), SimError> {
        match self.scene.time.integrator {
            // the scatter carries the internal forces; the grid update
            // adds gravity and the attractor and applies the boundaries
            Integrator::Explicit => self.substep_grid(dt, true, Self::explicit_grid_velocities),
            // the scatter carries momentum only: the internal forces (and
            // the attractor) enter through the solve
            Integrator::Implicit => self.substep_grid(dt, false, Self::implicit_grid_velocities),
            Integrator::ImplicitVertices | Integrator::MidpointVertices => {
                self.substep_gridless(dt)
            }
        }
    }

    /// The explicit grid update of every field: velocities, gravity, the
    /// attractor, obstacles and walls, then the pins' constraint.
    fn explicit_grid_velocities(
        &mut self,
        dt: f64,
        flip: bool,
        pin_entries: &[PinEntry],
        passes: Passes,
    ) -> Result<(), SimError> {
        let attractor = self.active_attractor(passes);
        let ext = grid_forces(
            &self.scene,
            &self.obstacles,
            passes,
            self.gravity,
            attractor,
        );
        match &mut self.fields {
            Some(f) => {
                for (g, m, mask) in f.grids_with_masses(&mut self.grid) {
                    grid_update::grid_update_masses(g, dt, &ext, flip, Some((m, mask)));
                }
            }
            None => grid_update::grid_update(&mut self.grid, dt, &ext, flip),
        }
        if !self.pins.is_empty() {
            let held = match &mut self.fields {
                Some(f) => f.held_grid_mut(&mut self.grid),
                None => &mut self.grid,
            };
            pins::constrain_grid(
                pin_entries,
                self.pins.len(),
                held,
                dt,
                &mut self.pin_reactions,
            );
        }
        Ok(())
    }

    /// A substep of a grid integrator: `scatter_forces` whether the
    /// scatter carries the internal forces, `grid_velocities` the
    /// integrator's update of the grid velocities.
    fn substep_grid(
        &mut self,
        dt: f64,
        scatter_forces: bool,
        grid_velocities: GridVelocities,
    ) -> Result<(), SimError> {
        let passes = self.passes();
        let bending = self.active_bending(passes);
        let transfer = self.transfer.at_step(dt, self.scene.transfer.flip_time);
        let flip = transfer.needs_delta();
        let energy = self.grid_energy();
        let t0 = Instant::now();
        if self.frames_stale {
            self.particles.quad.refresh_frames();
            grid_to_particle::quad_stress(&mut self.particles.quad, &self.grid.geom, &energy);
            self.frames_stale = false;
        }
        let t1 = Instant::now();
        let others = self
            .fields
            .as_mut()
            .map(|f| (&mut f.grids[..], &f.vert_field[..], &f.quad_field[..]));
        particle_to_grid::scatter_fields(
            &mut self.particles,
            &mut self.grid,
            others,
            dt,
            bending,
            active_obstacles(&self.obstacles, passes),
            yarn_radius(&self.scene),
            scatter_forces,
        );
        let t2 = Instant::now();
        let pin_entries = if self.pins.is_empty() {
            Vec::new()
        } else {
            let held = match &self.fields {
                Some(f) => f.held_grid(&self.grid),
                None => &self.grid,
            };
            pins::stencil_masses(&self.pins, &self.particles.vert, held, self.time + dt)
        };
        grid_velocities(self, dt, flip, &pin_entries, passes)?;
        if let Some(f) = &mut self.fields {
            let mu = self.scene.material.friction;
            f.locate(&self.particles);
            f.contact(
                &mut self.grid,
                &pin_entries,
                mu,
                dt,
                &mut self.pin_reactions,
            );
        }
        let obstacles = active_obstacles(&self.obstacles, passes);
        let others = self
            .fields
            .as_ref()
            .map(|f| (&f.grids[..], &f.vert_field[..], &f.quad_field[..]));
        let t3 = Instant::now();
        let gather = VertexGather {
            grid: &self.grid,
            fields: others.map(|(g, v, _)| (g, v)),
            dt,
            obstacles,
            transfer,
        };
        let bad_v = grid_to_particle::gather_vertices(&mut self.particles.vert, &gather);
        if !self.pins.is_empty() {
            pins::apply(
                &self.pins,
                &mut self.particles.vert,
                self.time + dt,
                dt,
                &mut self.pin_reactions,
            );
        }
        // `axial = "implicit"`: the fibre springs' step on the vertices
        // (`axial.rs`), before the quadrature particles read their edges
        let axial = self.scene.time.axial.is_implicit() && bad_v.is_none();
        if axial {
            self.axial_step(dt, flip)?;
        }
        let t4 = Instant::now();
        let bad_q = grid_to_particle::gather_quads(
            &mut self.particles.quad,
            &self.particles.vert.x,
            &self.grid,
            self.fields
                .as_ref()
                .map(|f| (&f.grids[..], &f.quad_field[..])),
            dt,
            &energy,
            passes.plasticity,
            transfer,
        );
        if axial {
            self.axial_quads();
        }
        if flip {
            spin::balance(&mut self.particles, &self.pinned);
        }
        let t5 = Instant::now();

        let tm = &mut self.timings;
        tm.forces += (t1 - t0).as_secs_f64();
        tm.scatter += (t2 - t1).as_secs_f64();
        tm.grid += (t3 - t2).as_secs_f64();
        tm.gather_vertices += (t4 - t3).as_secs_f64();
        tm.gather_quads += (t5 - t4).as_secs_f64();
        tm.substeps += 1;
        self.dt_stats.record(dt);

        self.steps += 1;
        self.time += dt;
        let what = match (bad_v, bad_q) {
            (Some(b), _) => {
                let (i, v) = (b.index, b.grid_velocity);
                Some(
                    if v.x.is_finite() && v.y.is_finite() && v.norm() * dt > self.grid.geom.dx {
                        format!(
                        "vertex {i} moves {:.3} m/s, more than one cell per substep (CFL limit {:.3} m/s)",
                        v.norm(),
                        self.grid.geom.dx / dt
                    )
                    } else {
                        format!("the state of vertex {i} is not finite")
                    },
                )
            }
            (None, Some(q)) => Some(format!(
                "the frame of quadrature particle {q} is not finite"
            )),
            _ => None,
        };
        if let Some(what) = what {
            let e = SimError::NonFinite {
                step: self.steps,
                time: self.time,
                what,
            };
            self.failed = Some(e.clone());
            return Err(e);
        }
        Ok(())
    }
}
