//! The implicit substep's grid update ([`crate::mpm::implicit`]) as the
//! substep calls it.

use super::super::grid::Grid;
use super::super::grid_update::{self, GridForces};
use super::super::implicit::{self, Model, Problem};
use super::super::pins::PinEntry;
use super::YarnSim;
use crate::math::Vec2;

/// Cost of the implicit substeps (`[time] integrator = "implicit"`) since
/// the start, the attempts that a cutback undid included
/// ([`super::cutback`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ImplicitStats {
    /// Solves that converged.
    pub substeps: u64,
    pub newton: u64,
    pub cg: u64,
    /// Most Newton iterations of one substep.
    pub max_newton: u64,
    /// Substeps run as two halves ([`super::cutback`]).
    pub cutbacks: u64,
    /// Of those, the ones tried first and undone (a failed solve or a
    /// vertex past a cell); the others were past the advection limit of
    /// their starting state.
    pub undone: u64,
    /// Most halvings of one substep (at most [`super::MAX_CUTBACKS`]).
    pub deepest_cut: u32,
}

/// What [`implicit_grid`] writes.
pub(super) struct ImplicitOut<'a> {
    pub grid: &'a mut Grid,
    pub pin_reactions: &'a mut Vec<Vec2>,
    pub stats: &'a mut ImplicitStats,
}

/// The implicit grid update of one velocity field: solves for the grid
/// velocities ([`implicit::solve`]) from `v*` and writes them (and, for
/// FLIP, the change they add) to the grid; adds the pins' forces from the
/// solve's multipliers to `pin_reactions` (which the caller clears and
/// sizes) and the iterations to `stats` (the caller counts the substep).
/// `Err`: why the solve failed.
pub(super) fn implicit_grid(
    problem: &mut implicit::Problem,
    out: ImplicitOut,
    n_pins: usize,
    flip: bool,
) -> Result<(), String> {
    problem.read_vstar(out.grid);
    let dt = problem.dt();
    let sol = implicit::solve(problem, &implicit::Settings::default())?;
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
    /// wholly in one, so the energy has no element across them): the only
    /// field's, or the free field's then the held field's (with the pins).
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
            Some(f) => {
                let (v, q) = (&f.vert_held[..], &f.quad_held[..]);
                let free = Some((v, q, false));
                let held = Some((v, q, true));
                vec![
                    Problem::collect_field(p, &self.grid, model, dt, &[], free),
                    Problem::collect_field(p, &f.grid, model, dt, pin_entries, held),
                ]
            }
        }
    }
}

/// What [`implicit_solve`] writes: the (free) field's grid, the held
/// field's with two fields, the pins' forces and the cost.
pub(super) struct ImplicitFields<'a> {
    pub grid: &'a mut Grid,
    pub held: Option<&'a mut Grid>,
    pub pin_reactions: &'a mut Vec<Vec2>,
    pub stats: &'a mut ImplicitStats,
}

/// Solves each field's problem ([`implicit_grid`]; `problems` as
/// [`YarnSim::implicit_problems`] made them), then the obstacle and wall
/// laws act on its solved velocities (`masses`: each field's `(M, MC)`
/// from before the grid update); the pins' forces from the multipliers.
/// `Err`: why a solve failed.
pub(super) fn implicit_solve(
    problems: &mut [Problem],
    out: ImplicitFields,
    masses: [&[[f64; 2]]; 2],
    ext: &GridForces,
    flip: bool,
) -> Result<(), String> {
    let n_pins = out.pin_reactions.len();
    out.pin_reactions
        .iter_mut()
        .for_each(|r| *r = Vec2::zeros());
    let mut grids = [Some(out.grid), out.held];
    for ((problem, grid), m) in problems.iter_mut().zip(&mut grids).zip(masses) {
        let grid = grid.as_deref_mut().expect("one grid per problem");
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
