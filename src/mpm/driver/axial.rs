//! `[time] axial = "implicit"`: the fibre-stretch term of the explicit
//! substep taken implicitly on the yarn vertices.
//!
//! The `k` term of the yarn energy (Jiang, Gast, Teran 2017) depends only
//! on each segment's edge length ([`crate::mpm::laws::axial`]); its wave,
//! `sqrt(k / rho)`, is 40 to 240 times faster on real yarns than the
//! cross-section's and would set the explicit substep alone. Here it
//! leaves the explicit scatter (the grid pass carries the stress of the
//! energy with `k = 0`, [`YarnSim::grid_energy`]); after the vertices have
//! taken their velocities `v*` from the grid and moved to `x* = x^n + dt
//! v*`, each yarn's axial springs take one backward Euler step on its
//! vertices alone:
//!
//! ```text
//! M dv = dt f_k(x* + dt dv),   v = v* + dv,   x = x* + dt dv
//! ```
//!
//! the minimum of `sum_i m_i |dv_i|^2 / 2 + E_k(x* + dt dv)` (the
//! optimization form of backward Euler, Gast, Schroeder, Stomakhin, Jiang,
//! Teran 2015), found by the projected Newton of the grid-free integrator
//! ([`crate::mpm::implicit_vertex::newton`], a block tridiagonal `LDL^T`
//! solve per iteration without bending,
//! [`crate::mpm::implicit_vertex::block_tridiagonal`]) with no bending, attractor or
//! friction term and the pinned vertices held (`dv = 0`). The solve knows
//! the two boundaries the grid step enforces and it would otherwise undo:
//! a vertex the springs would carry past the grid's bounds (where the
//! gather clamps it, [`crate::mpm::laws::contact::grid_bounds`]) ends on
//! them, held by a normal-velocity constraint
//! ([`crate::mpm::implicit_vertex::contacts`]; a clamp after the solve
//! compressed the segment instead); and a sticky wall, which takes the
//! share `h` of the force on a vertex whose stencil reaches its nodes
//! ([`crate::mpm::laws::contact::sticky_share`]), lets the springs move
//! that vertex as if it weighed `m / (1 - h)` (held where `h = 1`;
//! without it the springs pulled a yarn's end out of the wall, its FLIP
//! velocity growing while the wall held its position). A slip wall gets
//! no such share: the grid removes only the outward velocity at its
//! nodes, and the bounds hold the vertex.
//!
//! The obstacles are not in the solve: the gather leaves the vertices
//! outside them, and a vertex the solve leaves inside one is pushed back
//! with the circle's Coulomb law on its inward velocity, as the gather
//! does. Where that placement would strain one of the vertex's segments
//! by more than [`PLACED_STRAIN`], the vertex is held at the placed
//! position and velocity and the yarn's springs are solved again around
//! it (without it the placement crushed a stiff yarn's end segment, to
//! 0.60 of its length for a yarn thrown end first at a circle at 3 m/s;
//! two neighbours held in one round keep the chord the placement gives
//! their segment).
//!
//! `M` lumps a vertex and half of
//! each adjacent segment's quadrature particle, and each quadrature
//! particle takes the mean `dv` of its two vertices, so
//! away from the walls and the obstacles the step keeps the momentum (the
//! spring forces cancel in pairs; a wall or a circle takes what it holds,
//! and the quadrature particles beside a vertex held on a circle take
//! their share of the Coulomb law's change of its velocity). Under APIC every
//! particle takes the grid's velocity at each transfer, so what the grid
//! cannot hold of `dv` is dropped at the next one. Under FLIP a particle
//! keeps its own velocity but moves with the grid's, so the positions take
//! `dv` and the velocities only what the grid holds of it
//! ([`crate::mpm::machinery::share`]: each vertex's `M dv` with its
//! lumped mass on the nodes, divided by all that mass there, gathered back
//! by every vertex, other yarns' too, and a quadrature particle the mean
//! of its two vertices'; a sticky wall's nodes keep theirs). Given `dv` itself, a vertex kept the
//! part of it that the grid gives other yarns' mass on its nodes and the
//! vertex-scale part: a yarn's end held by other yarns reached FLIP
//! velocities of 13 to 22 m/s while it moved at about 1 m/s, and the
//! stiff bundle's energy rose (0.46 J within 5 ms at `time.safety =
//! 0.15`). FLIP still needs `transfer.flip_time` (checked at load): the
//! particles' own velocity relaxes to the grid's over that time whatever
//! the step ([`crate::mpm::machinery::transfer::Transfer::at_step`]); with
//! `dv` itself, at 2 and 4
//! ms the bundle never gained energy from one frame to the next over its
//! second, at 8 ms it gained 1.0 J in a frame, at 20 ms 2.3 J, and at
//! 100 ms it diverged (measured at dt 4e-5). Shear, the cross-section,
//! bending, gravity and contact stay explicit on the grid; the yarns'
//! solves are independent and run in parallel, each sequentially, so the
//! result has the same bits for any thread count.

use rayon::prelude::*;

use super::{SimError, YarnSim};
use crate::math::Vec2;
use crate::mpm::implicit_vertex::newton;
use crate::mpm::implicit_vertex::{contacts, Rod, Settings};
use crate::mpm::laws::constitutive::YarnEnergy;
use crate::mpm::laws::contact::{
    grid_bounds, keep_in_domain, project_out_of, sticky_holds, sticky_share,
};
use crate::mpm::machinery::particles::{Particles, Vertices};
use crate::mpm::machinery::share::{FieldGrids, Share};
use crate::scene::Obstacle;
use crate::scene::WallMode;

/// The relative round-off of the step's energy at the strains of a stiff
/// fibre (see [`round_off`]): a predicted decrease below this fraction of
/// the energy is not there to find (1e-13 in the grid-free integrator; a
/// yarn thrown into a corner at k = 1e7 stopped its line search with the
/// predicted decrease at 1.2e-13 of the energy and the gradient at half
/// its first value, measured). The energy holds the tension a yarn
/// carries, so this stops Newton at an unbalanced impulse of about 1e-4
/// of that tension's (its strain's error 1e-4 of the strain), where the
/// relative tolerance asks 1e-4 of the step's first gradient.
const DECREASE_TOL: f64 = 1e-8;

/// 100 times the round-off of the step's gradient `|g|_{M^-1}` (the
/// Newton solve's absolute tolerance, beside a relative one of 1e-4 of the
/// first gradient: the impulse left unbalanced is 1e-4 of the one the
/// springs had at `x*`; at 1e-6 half the solves took a second Newton
/// step, for the same energies and stretches on the reference bundle to
/// 6 digits, measured): a position carries an error of
/// `eps |x|`, so a spring's force `a (|e| / l0 - 1) / l0` one of `a / l0^2
/// eps |x|`, the gradient `dt` times that at each vertex, and the norm
/// `sqrt(n / m)` times more. Below it (a yarn whose springs are at rest to
/// round-off, as in free fall) Newton has nothing left to find and its
/// line search, on an energy that cancels to round-off near the rest
/// length, nothing left to measure. The line search may likewise stop once
/// the gradient has fallen by 1e-3 (`floor_tol`, 1e-6 in the grid-free
/// integrator): the spring energy `a / 2 (|e| / l0 - 1)^2` was computed to
/// a relative precision of about `eps |x| / |e| / (|e| / l0 - 1)`, 1e-8 at
/// the strains of a stiff fibre (1e-6 at k = 1e7 on the reference bundle),
/// and for the same reason Newton stops where its step would lower the
/// energy by less than 1e-8 of it ([`DECREASE_TOL`]). Since the step's
/// energy forms its segment vectors from the start's ([`Rod::edges`]),
/// a trial's energy is rounded at `|e|`, not at `|x|`: these floors are
/// now bounds above the round-off, kept as they were measured (the stiff
/// bundle's Newton counts and cost).
fn round_off(rod: &Rod) -> f64 {
    let stiff = rod
        .segments
        .iter()
        .map(|&(a, l0)| a / (l0 * l0))
        .fold(0.0, f64::max);
    let x = rod.x.iter().map(|x| x.amax()).fold(0.0, f64::max);
    let m = rod.m.iter().copied().fold(f64::INFINITY, f64::min);
    100.0 * f64::EPSILON * x * stiff * rod.dt * (rod.len() as f64 / m).sqrt()
}

/// One yarn's axial step: the velocity change of each of its vertices,
/// the impulse each constraint delivered (`dE/dv`: zero to the solve's
/// tolerance but at the held vertices, the pins, the grid's bounds, a
/// sticky wall's whole share and the vertices held on a circle; the
/// caller reads the pins'),
/// the Newton iterations it took, and the vertices it placed on
/// an obstacle (index in the yarn, position), see [`PLACED_STRAIN`].
type YarnStep = Result<(Vec<Vec2>, Vec<Vec2>, usize, Vec<(usize, Vec2)>), String>;

/// The strain, 1e-4 (a tenth of the goal's `[0.999, 1.001]` band for a
/// stiff yarn's stretch), that placing a vertex back on an obstacle's surface
/// may give one of its segments before the springs answer it in the same
/// step. The solve leaves the obstacles to the end-of-step placement
/// ([`keep_in_domain`]: the vertex back on the surface, the circle's
/// Coulomb law on its velocity); at a real `EA` the springs can carry a
/// yarn's end a fraction of a segment into a circle in one step (the stiff
/// reference bundle under `dt = "auto"`, `time.safety = 0.6`: an end
/// pressed into the right circle at 3.5 m/s), and the placement then
/// compressed its end segment to 0.979, 9 J of elastic energy for one
/// substep. Past this strain the vertex is held where the placement puts
/// it, at the velocity the Coulomb law leaves it, and the yarn's springs
/// are solved again around it.
const PLACED_STRAIN: f64 = 1e-4;

/// What bounds the vertices in the axial step: the grid's `bounds`
/// ([`grid_bounds`], on both axes), each vertex's sticky `wall_share`
/// ([`sticky_share`]; empty: none) and the `obstacles` the end-of-step
/// placement keeps them out of.
struct Bounds<'a> {
    bounds: (f64, f64),
    wall_share: &'a [f64],
    obstacles: &'a [Obstacle],
}

/// The backward Euler step of the axial springs of the yarn with vertices
/// `range` (see the module docs), their `lumped` masses
/// ([`Particles::lumped_masses`]), from the positions `x*` the vertices
/// have, held by `within` (the grid's bounds, the sticky walls) and
/// placed out of its obstacles.
fn yarn_step(
    p: &Particles,
    lumped: &[f64],
    pinned: &[bool],
    within: &Bounds,
    k: f64,
    dt: f64,
    range: std::ops::Range<usize>,
) -> YarnStep {
    let (v, q) = (&p.vert, &p.quad);
    let mut m = lumped[range.clone()].to_vec();
    let segments = (range.start..range.end - 1)
        .map(|i| {
            let s = v.q_right[i] as usize;
            (q.vol[s] * k, q.l0[s])
        })
        .collect();
    // a sticky wall absorbs the share `h` of a force on a vertex in its
    // reach: the vertex answers the springs as `m / (1 - h)` would, and
    // not at all where the wall holds its whole stencil
    let mut fixed: Vec<Option<Vec2>> = pinned[range.clone()]
        .iter()
        .map(|&p| p.then(Vec2::zeros))
        .collect();
    let (bounds, wall_share) = (within.bounds, within.wall_share);
    if !wall_share.is_empty() {
        for (i, (m, f)) in m.iter_mut().zip(fixed.iter_mut()).enumerate() {
            let h = wall_share[range.start + i];
            // a stencil held whole sums its nine weights to 1 less round-off
            if h >= 1.0 - 1e-12 {
                *f = Some(Vec2::zeros());
            } else if h > 0.0 {
                *m /= 1.0 - h;
            }
        }
    }
    let n = range.len();
    let rod = Rod {
        x: v.x[range.clone()].to_vec(),
        m,
        vstar: vec![Vec2::zeros(); n],
        dt,
        segments,
        bending: 0.0,
        bend: Vec::new(),
        attractor: None,
    };
    let settings = Settings {
        rel_tol: 1e-4,
        abs_tol: round_off(&rod),
        floor_tol: 1e-3,
        decrease_tol: DECREASE_TOL,
        ..Settings::default()
    };
    // the springs alone, and where that leaves a vertex beyond the grid's
    // bounds, the solve that holds it on them (the same first solve)
    let (mut dv, mut gradient, mut newton) = springs_alone(&rod, &fixed, &settings)?;
    let beyond = |(x, v): (&Vec2, &Vec2)| contacts::inside(&[], Some(bounds), x + v * dt).is_some();
    let near_bounds = rod.x.iter().zip(&dv).any(beyond);
    let solve = |rod: &Rod, fixed: &[Option<Vec2>], settings: &Settings| {
        if near_bounds {
            // (contacts::step repeats the first solve: only near the bounds)
            let o = contacts::step(rod, fixed, &[], Some(bounds), dt, settings)?;
            Ok((o.v, o.gradient, o.newton))
        } else {
            springs_alone(rod, fixed, settings)
        }
    };
    if near_bounds {
        let (d, g, it) = solve(&rod, &fixed, &settings)?;
        (dv, gradient, newton) = (d, g, newton + it);
    }
    // a vertex whose placement on an obstacle would strain a segment past
    // PLACED_STRAIN: held there, the springs solved again (a few rounds;
    // the bounds are held in them where the first solve needed it, and a
    // vertex a later round alone carries past them gets the clamp after
    // the step)
    let mut placed = Vec::new();
    let mut rod = rod;
    for _ in 0..PLACE_ROUNDS {
        let held = place(&rod, &dv, v, range.start, within.obstacles, dt, &fixed);
        if held.is_empty() {
            break;
        }
        let (mut again, mut fix) = (rod.clone(), fixed.clone());
        for &(i, x, d) in &held {
            // the solve fixes dv = d; the position it then gives is x
            again.x[i] = x - d * dt;
            fix[i] = Some(d);
        }
        // against the held vertex Newton may crawl (58 iterations once, a
        // yarn thrown head on at a circle at 3 m/s under APIC): more room
        // than the first solve's 50; past it the round is dropped, and what
        // is left inside gets the end-of-step placement alone
        let Ok((d, g, it)) = solve(
            &again,
            &fix,
            &Settings {
                max_newton: 200,
                ..settings
            },
        ) else {
            break;
        };
        (rod, fixed) = (again, fix);
        placed.extend(held.into_iter().map(|(i, x, _)| (i, x)));
        (dv, gradient, newton) = (d, g, newton + it);
    }
    Ok((dv, gradient, newton, placed))
}

/// The backward Euler step of `rod`'s springs alone, the vertices of
/// `fixed` held: the velocity changes, the impulses (`dE/dv`) and the
/// Newton iterations.
fn springs_alone(
    rod: &Rod,
    fixed: &[Option<Vec2>],
    settings: &Settings,
) -> Result<(Vec<Vec2>, Vec<Vec2>, usize), String> {
    let n = rod.len();
    let (cons, fric) = (contacts::held(fixed), vec![None; n]);
    let o = newton::solve(rod, &cons, &fric, vec![Vec2::zeros(); n], settings)?;
    Ok((o.v, o.gradient, o.newton))
}

/// Rounds of [`place`] and a new solve in one axial step (at most; a
/// vertex left inside after them gets the end-of-step placement alone).
const PLACE_ROUNDS: usize = 3;

/// The free vertices of `rod` whose end-of-step placement on `obstacles`
/// ([`project_out_of`]) would change one of their segments' strain by more
/// than [`PLACED_STRAIN`]: each with the position the placement gives it
/// and its velocity change `d` (the Coulomb law's velocity less the
/// gathered one, `v` from the yarn's first vertex `start` on).
fn place(
    rod: &Rod,
    dv: &[Vec2],
    v: &Vertices,
    start: usize,
    obstacles: &[Obstacle],
    dt: f64,
    fixed: &[Option<Vec2>],
) -> Vec<(usize, Vec2, Vec2)> {
    let y = |i: usize| rod.x[i] + dv[i] * dt;
    let mut held = Vec::new();
    for i in 0..rod.len() {
        if fixed[i].is_some() {
            continue;
        }
        let (mut x, mut w) = (y(i), v.v[start + i] + dv[i]);
        project_out_of(obstacles, &mut x, &mut w);
        if x == y(i) {
            continue;
        }
        let strain = |j: usize, l0: f64| ((x - y(j)).norm() - (y(i) - y(j)).norm()).abs() / l0;
        let left = i > 0 && strain(i - 1, rod.segments[i - 1].1) > PLACED_STRAIN;
        let right = i + 1 < rod.len() && strain(i + 1, rod.segments[i].1) > PLACED_STRAIN;
        if left || right {
            held.push((i, x, w - v.v[start + i]));
        }
    }
    held
}

impl YarnSim {
    /// The energy whose stress the grid pass carries: the material's, less
    /// its `k` term under `axial = "implicit"` (taken by
    /// [`YarnSim::axial_step`] instead).
    pub(super) fn grid_energy(&self) -> YarnEnergy {
        if self.scene.time.axial.is_implicit() {
            YarnEnergy {
                k: 0.0,
                ..self.energy
            }
        } else {
            self.energy
        }
    }

    /// The axial springs' backward Euler step over `dt` of every yarn,
    /// after the vertex gather and the pins (see the module docs): moves
    /// the vertices and keeps each vertex's velocity change for
    /// [`YarnSim::axial_quads`] (`flip`: the substep's transfer is FLIP,
    /// and the particles' velocities take [`Share`] of it). On a failed
    /// solve the error is recorded in `failed`.
    pub(super) fn axial_step(&mut self, dt: f64, flip: bool) -> Result<(), SimError> {
        let k = self.energy.k;
        let yv = &self.particles.yarn_vertices;
        let geom = self.grid.geom;
        let bounds = grid_bounds(geom.dx, geom.n);
        let sticky = self.passes().walls && self.scene.walls.mode == WallMode::Sticky;
        // the step's buffers live from one substep to the next (allocated
        // and freed each substep, they cost the allocator's trimming and
        // page faults: about 2 % of the stiff bundle's wall time, measured)
        let mut scratch = std::mem::take(&mut self.axial_scratch);
        self.particles.lumped_masses(&mut scratch.lumped);
        scratch.wall_share.clear();
        if sticky {
            let cells = self.scene.walls.cells as usize;
            let share = |&x| sticky_share(cells, geom.n, geom.inv_dx, x);
            scratch
                .wall_share
                .extend(self.particles.vert.x.iter().map(share));
        }
        let obstacles = super::substep::active_obstacles(&self.obstacles, self.passes());
        let within = Bounds {
            bounds,
            wall_share: &scratch.wall_share,
            obstacles,
        };
        let step = |y: usize| {
            let range = yv[y]..yv[y + 1];
            let (p, lumped) = (&self.particles, &scratch.lumped[..]);
            yarn_step(p, lumped, &self.pinned, &within, k, dt, range)
        };
        // the yarns in parallel, or in turn on one thread (rayon's split
        // and join took 3 % of the stiff bundle's samples there; the same
        // bits either way, each yarn's solve on its own)
        let yarns = 0..yv.len() - 1;
        let steps: Vec<YarnStep> = if rayon::current_num_threads() > 1 {
            yarns.into_par_iter().map(step).collect()
        } else {
            yarns.map(step).collect()
        };
        let (dv, impulse) = (&mut scratch.dv, &mut scratch.impulse);
        dv.clear();
        impulse.clear();
        let mut placed = Vec::new();
        let (mut newton, mut max_newton) = (0, 0);
        for (y, s) in steps.into_iter().enumerate() {
            match s {
                Ok((d, g, it, at)) => {
                    placed.extend(at.into_iter().map(|(i, x)| (yv[y] + i, x)));
                    dv.extend(d);
                    impulse.extend(g);
                    newton += it as u64;
                    max_newton = max_newton.max(it as u64);
                }
                Err(what) => {
                    let e = SimError::NonFinite {
                        step: self.steps + 1,
                        time: self.time + dt,
                        what: format!("the axial solve of yarn {y} failed: {what}"),
                    };
                    self.failed = Some(e.clone());
                    self.axial_scratch = scratch;
                    return Err(e);
                }
            }
        }
        // the pins hold their vertices against the springs: the impulse
        // of their constraint, per dt, is part of their force on the yarn
        for (pin, r) in self.pins.iter().zip(self.pin_reactions.iter_mut()) {
            *r += pin
                .vertices
                .iter()
                .fold(Vec2::zeros(), |a, &i| a + impulse[i] / dt);
        }
        // under FLIP the particles keep what the grid holds of dv (see
        // the module docs); the positions take dv itself
        if flip {
            let free = &mut scratch.free;
            free.clear();
            free.extend(self.pinned.iter().map(|&p| !p));
            for &(i, _) in &placed {
                free[i] = false;
            }
            let mut grids = vec![&self.grid];
            let mut vert_field = None;
            if let Some(f) = &self.fields {
                grids.extend(&f.grids);
                vert_field = Some(&f.vert_field[..]);
            }
            let fields = FieldGrids { grids, vert_field };
            let (cells, n) = (self.scene.walls.cells as usize, geom.n);
            let held = |i, j| sticky && sticky_holds(cells, n, i, j);
            let s = &mut scratch;
            s.share
                .of(&self.particles, &fields, &s.dv, &s.lumped, &s.free, held);
        } else {
            scratch.share.own(&self.particles, &scratch.dv);
        }
        // the share's momentum that landed on a pinned vertex is the pin's:
        // its force on the yarn takes it away from the others
        for (pin, r) in self.pins.iter().zip(self.pin_reactions.iter_mut()) {
            for &i in &pin.vertices {
                let w = &scratch.share.withheld;
                if let Ok(k) = w.binary_search_by_key(&i, |&(j, _)| j) {
                    *r -= w[k].1 * (scratch.lumped[i] / dt);
                }
            }
        }
        let vert = &mut self.particles.vert;
        let steps = vert.x.iter_mut().zip(&mut vert.v);
        for ((x, v), (d, u)) in steps.zip(scratch.dv.iter().zip(&scratch.share.vert)) {
            *x += d * dt;
            *v += u;
        }
        // the vertices the solve held on an obstacle's surface (their dv is
        // the velocity change the circle's Coulomb law gave them)
        for &(i, x) in &placed {
            vert.x[i] = x;
        }
        for (x, v) in vert.x.iter_mut().zip(vert.v.iter_mut()) {
            // as the gather leaves a vertex: outside the obstacles, inside
            // the grid
            keep_in_domain(obstacles, bounds, x, v);
        }
        let st = &mut self.implicit_stats;
        st.substeps += 1;
        st.newton += newton;
        st.max_newton = st.max_newton.max(max_newton);
        self.axial_scratch = scratch;
        Ok(())
    }

    /// Each quadrature particle's share of the axial step, after its
    /// gather: the mean velocity change `dv` of its two vertices, or under
    /// FLIP what the grid holds of the step ([`Share`]).
    pub(super) fn axial_quads(&mut self) {
        let q = &mut self.particles.quad;
        for (v, u) in q.v.iter_mut().zip(&self.axial_scratch.share.quad) {
            *v += u;
        }
    }
}

impl AxialScratch {
    /// Bytes of the grid-sized buffers: the share's nodes.
    pub(super) fn grid_memory_bytes(&self) -> usize {
        self.share.node_memory_bytes()
    }
}

/// The buffers of [`YarnSim::axial_step`], kept from one substep to the
/// next (not part of the state: each substep overwrites them).
#[derive(Clone, Debug, Default)]
pub(super) struct AxialScratch {
    /// Each vertex's velocity change, for [`YarnSim::axial_quads`].
    dv: Vec<Vec2>,
    /// Each vertex's constraint impulse (`dE/dv`).
    impulse: Vec<Vec2>,
    /// Each vertex's [`sticky_share`] (empty without sticky walls).
    wall_share: Vec<f64>,
    /// Each vertex's lumped mass ([`Particles::lumped_masses`]), for the
    /// yarns' solves and the share.
    lumped: Vec<f64>,
    /// Each particle's share of `dv` (under FLIP what the grid holds of
    /// it, otherwise its own).
    share: Share,
    /// Under FLIP, the vertices the share moves (not pinned, not placed
    /// on an obstacle by the solve).
    free: Vec<bool>,
}
