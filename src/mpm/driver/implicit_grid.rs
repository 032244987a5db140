//! The implicit substep's grid update ([`crate::mpm::implicit_grid`]) as the
//! substep calls it.
//!
//! The obstacles' normal law is part of the solve: each node the explicit
//! law would act on (`contact::normal_share`, on the blocks
//! `grid_update::block_near` finds) adds `w / 2 min(v . n, 0)^2` to the
//! energy ([`ContactTerm`]), whose minimiser alone with the node's
//! kinetic term is that law. Applied after the solve instead (Stomakhin
//! et al. 2013's projection), the law stops the contact nodes while their
//! neighbours keep the solved velocity: the vertices it moves stretch the
//! segments and the velocity jump it leaves compresses the cross-sections
//! (`d2 += dt C d2`), a deformation the solve never saw, of order
//! `|v| dt / dx` per substep (measured on a bundle landing at 1.1 m/s,
//! dt 2.85e-3: 5.5 J of elastic energy from 0.54 J of kinetic energy in
//! one substep). The solved velocities are then mapped back through the
//! law's inverse ([`unapply_contacts`]), so that `grid_update::boundaries`
//! (unchanged: normal law, pooled Coulomb friction, walls) returns them
//! and pools its friction over the normal impulse the solve delivered.

use super::stats::Passes;
use super::substep::grid_forces;
use super::{SimError, YarnSim};
use crate::math::Vec2;
use crate::mpm::explicit::grid_update::{self, GridForces};
use crate::mpm::implicit_grid::{self, ContactTerm, Model, Problem};
use crate::mpm::laws::contact::{normal_share, touch_reach};
use crate::mpm::laws::pins::PinEntry;
use crate::mpm::machinery::grid::{Grid, BLOCK};

/// Cost of the implicit substeps (`[time] integrator = "implicit"`) since
/// the start, the attempts that a cutback undid included
/// (`super::cutback`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ImplicitStats {
    /// Solves that converged.
    pub substeps: u64,
    /// Newton iterations, summed.
    pub newton: u64,
    /// CG iterations, summed.
    pub cg: u64,
    /// Most Newton iterations of one substep.
    pub max_newton: u64,
    /// Substeps run as two halves (`super::cutback`).
    pub cutbacks: u64,
    /// Of those, the ones tried first and undone (a failed solve or a
    /// vertex past a cell); the others were past the advection limit of
    /// their starting state.
    pub undone: u64,
    /// Most halvings of one substep (at most [`super::MAX_CUTBACKS`]).
    pub deepest_cut: u32,
    /// Of the undone ones, those refused for raising the total energy
    /// ([`super::ENERGY_TOL`]).
    pub energy_cuts: u64,
    /// Substeps at the deepest cutback kept although they raised the total
    /// energy by more than [`super::ENERGY_TOL`], and the largest such
    /// rise, J.
    pub energy_kept: u64,
    /// The largest energy rise so kept, J.
    pub max_energy_kept: f64,
    /// Of the undone ones, those refused for taking a segment's stretch
    /// out of its band (`super::cutback::stretch_band`, `dt = "auto"`).
    pub stretch_cuts: u64,
}

/// What [`implicit_grid`] writes.
pub(super) struct ImplicitOut<'a> {
    pub grid: &'a mut Grid,
    pub pin_reactions: &'a mut Vec<Vec2>,
    pub stats: &'a mut ImplicitStats,
}

/// The implicit grid update of one velocity field: solves for the grid
/// velocities ([`implicit_grid::solve`]) from `v*` and writes them (and, for
/// FLIP, the change they add) to the grid; adds the pins' forces from the
/// solve's multipliers to `pin_reactions` (which the caller clears and
/// sizes) and the iterations to `stats` (the caller counts the substep).
/// `Err`: why the solve failed.
pub(super) fn implicit_grid(
    problem: &mut implicit_grid::Problem,
    out: ImplicitOut,
    n_pins: usize,
    flip: bool,
) -> Result<(), String> {
    problem.read_vstar(out.grid);
    let dt = problem.dt();
    let mut sol = implicit_grid::solve(problem, &implicit_grid::Settings::default())?;
    unapply_contacts(problem, &mut sol.v);
    for ((&idx, v), vs) in problem.nodes.iter().zip(&sol.v).zip(&problem.vstar) {
        let n = &mut out.grid.node[idx];
        let d = v - vs;
        *n = if flip {
            [v.x, v.y, n[2] + d.x, n[3] + d.y]
        } else {
            [v.x, v.y, 0.0, 0.0]
        };
    }
    debug_assert_eq!(out.pin_reactions.len(), n_pins);
    for (pin, j) in problem.row_pins().zip(&sol.impulses) {
        out.pin_reactions[pin] += j / dt;
    }
    let st = out.stats;
    st.newton += sol.stats.newton as u64;
    st.cg += sol.stats.cg as u64;
    st.max_newton = st.max_newton.max(sol.stats.newton as u64);
    Ok(())
}

impl YarnSim {
    /// The implicit substep's problems, one per velocity field (a yarn is
    /// wholly in one, so the energy has no element across them), in field
    /// order (the held field's with the pins).
    /// Call after the scatter, before the grid update.
    pub(super) fn implicit_problems(
        &self,
        model: &Model,
        dt: f64,
        pin_entries: &[PinEntry],
    ) -> Vec<Problem> {
        let p = &self.particles;
        match &self.fields {
            None => vec![Problem::collect(p, &self.grid, model, dt, pin_entries)],
            Some(f) => (0..f.count() as u16)
                .map(|k| {
                    let only = Some((&f.vert_field[..], &f.quad_field[..], k));
                    let pins = if f.held == Some(k) { pin_entries } else { &[] };
                    Problem::collect_field(p, f.grid(&self.grid, k), model, dt, pins, only)
                })
                .collect(),
        }
    }
}

impl YarnSim {
    /// The implicit grid update: `v*` without obstacles and walls (gravity
    /// only), the fields' problems solved, then the obstacles and walls on
    /// the solved velocities ([`implicit_solve`]); the pins are
    /// constraints of the solve. `Err` (recorded in `failed`): a solve
    /// failed.
    pub(super) fn implicit_grid_velocities(
        &mut self,
        dt: f64,
        flip: bool,
        pin_entries: &[PinEntry],
        passes: Passes,
    ) -> Result<(), SimError> {
        // the attractor is a term of the solve, not a force of the update
        let ext = grid_forces(&self.scene, &self.obstacles, passes, self.gravity, None);
        let model = Model {
            energy: self.energy,
            bending: self.active_bending(passes),
            attractor: self.active_attractor(passes),
        };
        let mut problems = self.implicit_problems(&model, dt, pin_entries);
        // v* without obstacles and walls; they act on the solved velocities
        let interior = ext.without_boundaries();
        let mut masses = vec![Vec::new(); problems.len()];
        if ext.has_boundaries() {
            grid_update::record_masses(&self.grid, &mut masses[0]);
            if let Some(f) = &self.fields {
                for (g, m) in f.grids.iter().zip(&mut masses[1..]) {
                    grid_update::record_masses(g, m);
                }
            }
        }
        match &mut self.fields {
            Some(f) => {
                for (g, m, mask) in f.grids_with_masses(&mut self.grid) {
                    grid_update::grid_update_masses(g, dt, &interior, flip, Some((m, mask)));
                }
            }
            None => grid_update::grid_update(&mut self.grid, dt, &interior, flip),
        }
        self.pin_reactions.resize(self.pins.len(), Vec2::zeros());
        let out = ImplicitFields {
            grid: &mut self.grid,
            others: self
                .fields
                .as_mut()
                .map_or(&mut [][..], |f| &mut f.grids[..]),
            pin_reactions: &mut self.pin_reactions,
            stats: &mut self.implicit_stats,
        };
        if let Err(what) = implicit_solve(&mut problems, out, &masses, &ext, flip) {
            let e = SimError::NonFinite {
                step: self.steps + 1,
                time: self.time + dt,
                what,
            };
            self.failed = Some(e.clone());
            return Err(e);
        }
        Ok(())
    }
}

/// What [`implicit_solve`] writes: field 0's grid, the other fields'
/// grids, the pins' forces and the cost.
struct ImplicitFields<'a> {
    pub grid: &'a mut Grid,
    pub others: &'a mut [Grid],
    pub pin_reactions: &'a mut Vec<Vec2>,
    pub stats: &'a mut ImplicitStats,
}

/// Solves each field's problem ([`implicit_grid`]; `problems` as
/// [`YarnSim::implicit_problems`] made them), then the obstacle and wall
/// laws act on its solved velocities (`masses`: each field's `(M, MC)`
/// from before the grid update); the pins' forces from the multipliers.
/// `Err`: why a solve failed.
fn implicit_solve(
    problems: &mut [Problem],
    out: ImplicitFields,
    masses: &[Vec<[f64; 2]>],
    ext: &GridForces,
    flip: bool,
) -> Result<(), String> {
    let n_pins = out.pin_reactions.len();
    out.pin_reactions
        .iter_mut()
        .for_each(|r| *r = Vec2::zeros());
    let grids = std::iter::once(out.grid).chain(out.others.iter_mut());
    for ((problem, grid), m) in problems.iter_mut().zip(grids).zip(masses) {
        problem.set_contacts(contact_terms(problem, grid, m, ext));
        let o = ImplicitOut {
            grid: &mut *grid,
            pin_reactions: &mut *out.pin_reactions,
            stats: &mut *out.stats,
        };
        implicit_grid(problem, o, n_pins, flip)?;
        grid_update::boundaries(grid, m, ext, flip);
    }
    out.stats.substeps += 1;
    Ok(())
}

/// Largest contact coefficient `c` of a [`ContactTerm`] (`w = c m`): a
/// node inside the circle (touching share 1, where the law stops the
/// inward velocity wholly) or nearly wholly touching. The solve then
/// leaves at most `1 / (1 + c)` of the inward velocity that the law,
/// after the solve, removes.
pub const CONTACT_MAX: f64 = 1e2;

/// The contact terms of `problem`'s nodes: on the blocks near an obstacle,
/// every node with mass that the obstacle's normal law acts on (`masses`:
/// `(M, MC)` of `grid`'s active blocks, [`grid_update::record_masses`]),
/// with the law's share `s` as `c = s / (1 - s)`, at most [`CONTACT_MAX`].
fn contact_terms(
    problem: &Problem,
    grid: &Grid,
    masses: &[[f64; 2]],
    ext: &GridForces,
) -> Vec<ContactTerm> {
    if ext.obstacles.is_empty() || masses.is_empty() {
        return Vec::new();
    }
    let geom = grid.geom;
    let mut unknown = vec![u32::MAX; geom.storage()];
    for (u, &idx) in problem.nodes.iter().enumerate() {
        unknown[idx] = u as u32;
    }
    let mut out = Vec::new();
    let reach = touch_reach(geom.dx);
    for (k, &b) in grid.active.iter().enumerate() {
        let b = b as usize;
        if !grid_update::block_near(&geom, ext, b).0 {
            continue;
        }
        let (i0, j0) = geom.block_origin(b);
        let block = &masses[k * BLOCK * BLOCK..(k + 1) * BLOCK * BLOCK];
        for (n, (idx, &[m, mc])) in geom.block_nodes(b).zip(block).enumerate() {
            let u = unknown[idx];
            if m <= 0.0 || u == u32::MAX {
                continue;
            }
            let xi = Vec2::new((i0 + n / BLOCK) as f64, (j0 + n % BLOCK) as f64) * geom.dx;
            let touching = mc * (1.0 / m);
            for o in ext.obstacles {
                let (share, normal, _) = normal_share(o, xi, touching, ext.yarn_radius, reach);
                if share > 0.0 {
                    let c = if share < 1.0 {
                        (share / (1.0 - share)).min(CONTACT_MAX)
                    } else {
                        CONTACT_MAX
                    };
                    out.push(ContactTerm {
                        node: u,
                        n: normal,
                        w: c * problem.mass[u as usize],
                    });
                }
            }
        }
    }
    out
}

/// Maps the solved velocities `v` back through the normal law's inverse
/// (last contact first): an inward normal velocity `a` becomes `(1 + c)
/// a`, which the law (`(1 - s)` of it kept) returns to `a` for `c = s /
/// (1 - s)`, with the normal impulse `s m (1 + c) |a| = w |a|`, the one the
/// contact term delivered in the solve. Capped terms (`c` =
/// [`CONTACT_MAX`]) are returned to `(1 - s)(1 + c) a`, within `1 / c` of
/// the law's full stop.
fn unapply_contacts(problem: &Problem, v: &mut [Vec2]) {
    for t in problem.contacts().iter().rev() {
        let i = t.node as usize;
        let a = v[i].dot(&t.n);
        if a < 0.0 {
            v[i] += t.n * (a * t.w / problem.mass[i]);
        }
    }
}
