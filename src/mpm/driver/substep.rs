//! One substep of the yarn bundle: the passes in order (stress, scatter,
//! grid update or implicit solve, boundaries, field contact, gather,
//! pins), their timings, and the checks that turn a bad state into a
//! [`SimError`].

use std::time::Instant;

use super::implicit_grid::{implicit_solve, ImplicitFields};
use super::{SimError, YarnSim};
use crate::math::Vec2;
use crate::mpm::explicit::grid_to_particle::{self, VertexGather};
use crate::mpm::explicit::grid_update::{self, GridForces};
use crate::mpm::explicit::particle_to_grid;
use crate::mpm::laws::pins;
use crate::mpm::machinery::spin;
use crate::scene::Obstacle;

impl YarnSim {
    /// One substep of `dt` (finite, > 0; not failed before): every pass
    /// once. On a `SimError` the state is part-way through the substep
    /// and the error is recorded in `failed`.
    pub(super) fn substep_once(&mut self, dt: f64) -> Result<(), SimError> {
        if self.is_gridless() {
            return self.substep_gridless(dt);
        }
        let passes = self.passes();
        let bending = if passes.bending {
            self.scene.material.bending
        } else {
            0.0
        };
        let empty: [Obstacle; 0] = [];
        let obstacles: &[Obstacle] = if passes.obstacles {
            &self.scene.obstacles
        } else {
            &empty
        };

        let implicit = self.is_implicit();
        let transfer = self.transfer;
        let flip = transfer.needs_delta();
        let t0 = Instant::now();
        if self.frames_stale {
            self.particles.quad.refresh_frames();
            grid_to_particle::quad_stress(&mut self.particles.quad, &self.grid.geom, &self.energy);
            self.frames_stale = false;
        }
        let t1 = Instant::now();
        let held = self
            .fields
            .as_mut()
            .map(|f| (&mut f.grid, &f.vert_held[..], &f.quad_held[..]));
        // implicit: the scatter carries momentum only, the internal forces
        // (and the attractor) enter through the solve
        particle_to_grid::scatter_fields(
            &mut self.particles,
            &mut self.grid,
            held,
            dt,
            bending,
            obstacles,
            !implicit,
        );
        let t2 = Instant::now();
        let attractor = passes
            .attractor
            .then_some((self.attractor.position, self.attractor.strength));
        let ext = GridForces {
            gravity: self.gravity,
            attractor: if implicit { None } else { attractor },
            obstacles,
            walls: self.scene.walls.mode,
            wall_cells: self.scene.walls.cells as usize,
        };
        let pin_entries = if self.pins.is_empty() {
            Vec::new()
        } else {
            let held = self.fields.as_ref().map_or(&self.grid, |f| &f.grid);
            pins::stencil_masses(&self.pins, &self.particles.vert, held, self.time + dt)
        };
        let mut problems = if implicit {
            let model = crate::mpm::implicit_grid::Model {
                energy: self.energy,
                bending,
                attractor,
            };
            self.implicit_problems(&model, dt, &pin_entries)
        } else {
            Vec::new()
        };
        // implicit: v* without obstacles and walls; they act on the solved velocities
        let (interior, mut masses, mut held_masses) =
            (ext.without_boundaries(), Vec::new(), Vec::new());
        let ext_update = if implicit { &interior } else { &ext };
        if implicit && ext.has_boundaries() {
            grid_update::record_masses(&self.grid, &mut masses);
            if let Some(f) = &self.fields {
                grid_update::record_masses(&f.grid, &mut held_masses);
            }
        }
        if let Some(f) = &mut self.fields {
            f.record_masses(&self.grid);
            grid_update::grid_update(&mut f.grid, dt, ext_update, flip);
        }
        grid_update::grid_update(&mut self.grid, dt, ext_update, flip);
        if implicit {
            self.pin_reactions.resize(self.pins.len(), Vec2::zeros());
            let out = ImplicitFields {
                grid: &mut self.grid,
                held: self.fields.as_mut().map(|f| &mut f.grid),
                pin_reactions: &mut self.pin_reactions,
                stats: &mut self.implicit_stats,
            };
            if let Err(what) =
                implicit_solve(&mut problems, out, [&masses, &held_masses], &ext, flip)
            {
                let e = SimError::NonFinite {
                    step: self.steps + 1,
                    time: self.time + dt,
                    what,
                };
                self.failed = Some(e.clone());
                return Err(e);
            }
        } else if !self.pins.is_empty() {
            pins::constrain_grid(
                &pin_entries,
                self.pins.len(),
                self.fields.as_mut().map_or(&mut self.grid, |f| &mut f.grid),
                dt,
                &mut self.pin_reactions,
            );
        }
        if let Some(f) = &mut self.fields {
            let mu = self.scene.material.friction;
            f.contact(
                &mut self.grid,
                &pin_entries,
                mu,
                dt,
                &mut self.pin_reactions,
            );
        }
        let held = self
            .fields
            .as_ref()
            .map(|f| (&f.grid, &f.vert_held[..], &f.quad_held[..]));
        let t3 = Instant::now();
        let gather = VertexGather {
            grid: &self.grid,
            held: held.map(|(g, v, _)| (g, v)),
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
        let t4 = Instant::now();
        let bad_q = grid_to_particle::gather_quads(
            &mut self.particles.quad,
            &self.particles.vert.x,
            &self.grid,
            held.map(|(g, _, q)| (g, q)),
            dt,
            &self.energy,
            passes.plasticity,
            transfer,
        );
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
