//! The implicit substep's grid update ([`crate::mpm::implicit`]) as the
//! substep calls it.

use super::super::grid::Grid;
use super::super::implicit;
use crate::math::Vec2;

/// Cost of the implicit substeps (`[time] integrator = "implicit"`) since
/// the start.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ImplicitStats {
    pub substeps: u64,
    pub newton: u64,
    pub cg: u64,
    /// Most Newton iterations of one substep.
    pub max_newton: u64,
}

/// What [`implicit_grid`] writes.
pub(super) struct ImplicitOut<'a> {
    pub grid: &'a mut Grid,
    pub pin_reactions: &'a mut Vec<Vec2>,
    pub stats: &'a mut ImplicitStats,
}

/// The implicit grid update: solves for the grid velocities
/// ([`implicit::solve`]) from `v*` and writes them (and, for FLIP, the
/// change they add) to the grid; the pins' forces from the solve's
/// multipliers. `Err`: why the solve failed.
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
    out.pin_reactions.clear();
    out.pin_reactions.resize(n_pins, Vec2::zeros());
    for (pin, j) in problem.row_pins().zip(&sol.impulses) {
        out.pin_reactions[pin] += j / dt;
    }
    let st = out.stats;
    st.substeps += 1;
    st.newton += sol.stats.newton as u64;
    st.cg += sol.stats.cg as u64;
    st.max_newton = st.max_newton.max(sol.stats.newton as u64);
    Ok(())
}
