//! Pass 2 of a substep, the grid update: sums the chunk buffers on the
//! active blocks, turns momentum into velocity and applies gravity, the
//! attractor, obstacle contact and walls ([`crate::mpm::laws::contact`]). Each node
//! keeps its new velocity and, for the FLIP transfer, the change over the
//! substep. Work is done per active block; obstacle and wall laws run only
//! on blocks near one. Obstacle friction, pooled over the contact nodes of
//! a cross-section, runs after the parallel pass on the contact nodes it
//! collected, in a fixed order.
//!
//! The implicit step runs the update without the obstacles and walls
//! ([`GridForces::without_boundaries`]) and applies the same laws to its
//! solved velocities ([`boundaries`], with the masses [`record_masses`]
//! kept from the scatter).

use rayon::prelude::*;

use crate::math::Vec2;
use crate::mpm::laws::attractor;
use crate::mpm::laws::contact::{
    obstacle_friction, obstacle_normal, wall_velocity, ContactNode, WedgeTable,
};
use crate::mpm::machinery::grid::{
    Grid, GridGeom, Node, P2gNode, ScatterBuffer, BLOCK, CHUNKS, FX, FY, M, MC, P2G_LANES, PX, PY,
};
use crate::mpm::machinery::simd::multiversion;
use crate::scene::{Obstacle, WallMode};

/// The external-force and boundary settings of the grid update.
#[derive(Clone, Debug)]
pub struct GridForces<'a> {
    pub gravity: Vec2,
    /// `(position, strength)` when the attractor acts.
    pub attractor: Option<(Vec2, f64)>,
    /// The obstacles as contact sees them (grown by `yarn_radius`,
    /// [`crate::mpm::laws::contact::with_yarn_radius`]).
    pub obstacles: &'a [Obstacle],
    /// Half the yarn diameter (`material.diameter`), 0 without one.
    pub yarn_radius: f64,
    pub walls: WallMode,
    pub wall_cells: usize,
}

impl GridForces<'_> {
    /// The same settings without obstacles and walls.
    pub fn without_boundaries(&self) -> Self {
        GridForces {
            obstacles: &[],
            walls: WallMode::None,
            ..self.clone()
        }
    }

    /// Whether an obstacle or a wall acts.
    pub fn has_boundaries(&self) -> bool {
        !self.obstacles.is_empty() || self.walls != WallMode::None
    }
}

/// One band (block row) of a scatter buffer, as the grid update reads and
/// zeroes it: its nodes and the buffer's touched flags.
struct BandSrc<'a> {
    node: &'a mut [P2gNode],
    touched: &'a [bool],
    touched_nodes: &'a [u64],
}

/// What every band of the grid update reads.
struct BandCtx<'a> {
    is_active: &'a [bool],
    geom: &'a GridGeom,
    dt: f64,
    ext: &'a GridForces<'a>,
    wedges: &'a WedgeTable,
}

/// Pass 2 (see the module documentation). `flip`: also store each node's
/// velocity change (the buffers then hold the impulse alone, see
/// [`crate::mpm::explicit::particle_to_grid::scatter`]). The scatter buffers are consumed:
/// each node is zeroed as it is summed, ready for the next scatter (so no
/// separate clearing pass walks them again).
pub fn grid_update(grid: &mut Grid, dt: f64, ext: &GridForces, flip: bool) {
    grid_update_masses(grid, dt, ext, flip, None);
}

/// Where [`grid_update_masses`] writes the node masses it sums: a mass per
/// node of the window, and per window block the mask of its nodes with
/// mass > 0 (bit `8 r + c` for row `r`, column `c` of the block).
pub type MassOut<'a> = (&'a mut [f64], &'a mut [u64]);

/// [`grid_update`] that also writes the node mass it sums (the same sum,
/// in chunk order) on every node of the active blocks, and their masks, to
/// `masses` (for the field contact, [`crate::mpm::laws::fields`]).
pub fn grid_update_masses(
    grid: &mut Grid,
    dt: f64,
    ext: &GridForces,
    flip: bool,
    masses: Option<MassOut>,
) {
    let geom = grid.geom;
    let band_len = geom.stride * BLOCK;
    // per band, the used buffers' parts of it in chunk order (one
    // allocation: many fields run this every substep)
    let mut parts: Vec<_> = grid
        .buffers
        .iter_mut()
        .filter(|b| b.used)
        .map(|b| {
            let ScatterBuffer {
                node,
                touched,
                touched_nodes,
                ..
            } = b;
            (node.chunks_mut(band_len), &*touched, &*touched_nodes)
        })
        .collect();
    let nsrc = parts.len();
    if nsrc == 0 {
        return; // no particle scatters into this grid: nothing is active
    }
    let mut srcs = Vec::with_capacity(nsrc * geom.nbi);
    for _ in 0..geom.nbi {
        for (nodes, touched, touched_nodes) in parts.iter_mut() {
            let node = nodes.next().expect("a used buffer holds the window");
            srcs.push(BandSrc {
                node,
                touched,
                touched_nodes,
            });
        }
    }
    let wedges = WedgeTable::new(ext.obstacles, geom.dx);
    let ctx = BandCtx {
        is_active: &grid.is_active,
        geom: &geom,
        dt,
        ext,
        wedges: &wedges,
    };
    let ctx = &ctx;
    let mut contacts = std::mem::take(&mut grid.contacts);
    contacts.resize_with(geom.nbi, Vec::new);
    let band_masses: Vec<Option<MassOut>> = match masses {
        Some((m, mask)) => m
            .chunks_mut(band_len)
            .zip(mask.chunks_mut(geom.nbj))
            .map(Some)
            .collect(),
        None => (0..geom.nbi).map(|_| None).collect(),
    };
    grid.node
        .par_chunks_mut(band_len)
        .zip(srcs.par_chunks_mut(nsrc))
        .zip(contacts.par_iter_mut())
        .zip(band_masses)
        .enumerate()
        .for_each(|(bi, (((band, srcs), contacts), mut masses))| {
            contacts.clear();
            let out = BandOut {
                node: band,
                masses: masses.as_mut(),
                contacts,
            };
            if flip {
                grid_band::<true>(bi, out, srcs, ctx)
            } else {
                grid_band::<false>(bi, out, srcs, ctx)
            }
        });
    pooled_friction(ext, &wedges, &contacts, &mut grid.node, geom.n, flip);
    grid.contacts = contacts;
}

/// The pooled friction pass ([`obstacle_friction`]) on the contact nodes
/// `contacts`, and the walls again on every node it changed.
fn pooled_friction(
    ext: &GridForces,
    wedges: &WedgeTable,
    contacts: &[Vec<ContactNode>],
    node: &mut [Node],
    n: usize,
    flip: bool,
) {
    if contacts.iter().all(|c| c.is_empty()) {
        return;
    }
    let (walls, cells) = (ext.walls, ext.wall_cells);
    obstacle_friction(
        ext.obstacles,
        wedges,
        contacts,
        node,
        flip,
        &mut |c, out| {
            if walls != WallMode::None {
                let v = Vec2::new(out[0], out[1]);
                let w = wall_velocity(walls, cells, n, c.ij[0] as usize, c.ij[1] as usize, v);
                let d = w - v;
                out[0] = w.x;
                out[1] = w.y;
                if flip {
                    out[2] += d.x;
                    out[3] += d.y;
                }
            }
        },
    );
}

/// Whether an obstacle (within the contact's reach) and the walls reach
/// window block `b`.
#[inline(always)]
pub(crate) fn block_near(geom: &GridGeom, ext: &GridForces, b: usize) -> (bool, bool) {
    let (i0, j0) = geom.block_origin(b);
    let cells = ext.wall_cells;
    let dx = geom.dx;
    // contact reaches nodes up to the particles' stencil (1.5 cells) plus
    // the contact margin outside an obstacle
    let reach = 2.0 * dx;
    let lo = Vec2::new(i0 as f64, j0 as f64) * dx;
    let hi = lo + Vec2::new((BLOCK - 1) as f64, (BLOCK - 1) as f64) * dx;
    let near_obstacle = ext.obstacles.iter().any(|o| {
        let c = Vec2::from(o.center);
        let q = Vec2::new(c.x.clamp(lo.x, hi.x), c.y.clamp(lo.y, hi.y));
        (q - c).norm() < o.radius + reach
    });
    let near_wall = ext.walls != WallMode::None
        && (i0 < cells || j0 < cells || i0 + BLOCK + cells > geom.n || j0 + BLOCK + cells > geom.n);
    (near_obstacle, near_wall)
}

/// The normal part of every obstacle's contact at node `index` (grid
/// coordinates `ij`, position `xi`, mass `m`, touching fraction
/// `touching`) on its velocity `v`, each contact recorded in `contacts`
/// for the friction pass.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn obstacle_contacts(
    ext: &GridForces,
    wedges: &WedgeTable,
    index: usize,
    ij: [usize; 2],
    xi: Vec2,
    v: &mut Vec2,
    m: f64,
    touching: f64,
    contacts: &mut Vec<ContactNode>,
) {
    for (oi, o) in ext.obstacles.iter().enumerate() {
        if let Some((normal, impulse)) =
            obstacle_normal(o, xi, v, m, touching, wedges, ext.yarn_radius)
        {
            contacts.push(ContactNode {
                index,
                ij: [ij[0] as u32, ij[1] as u32],
                wedge: wedges.wedge(oi, normal),
                mass: m,
                impulse,
                normal,
            });
        }
    }
}

/// Node mass and contact mass (lanes [`M`], [`MC`]) of every node of the
/// active blocks, block by block in `grid.active` order, [`BLOCK`]^2 per
/// block, summed over the scatter buffers as [`grid_update`] sums them:
/// call after the scatter and before the grid update consumes the buffers,
/// for [`boundaries`].
pub fn record_masses(grid: &Grid, out: &mut Vec<[f64; 2]>) {
    let geom = grid.geom;
    out.clear();
    for &b in &grid.active {
        let b = b as usize;
        for idx in geom.block_nodes(b) {
            let (mut m, mut mc) = (0.0, 0.0);
            for s in grid.buffers.iter().filter(|s| s.touched[b]) {
                m += s.node[idx][M];
                mc += s.node[idx][MC];
            }
            out.push([m, mc]);
        }
    }
}

/// The obstacle and wall laws of [`grid_update`] (normal law, pooled
/// Coulomb friction, walls, in that order) on the node velocities already
/// in `grid`: the implicit step's, after its solve. `masses` from
/// [`record_masses`] of this substep. With `flip` every change is added to
/// the node's velocity change too. Serial, in block order.
pub fn boundaries(grid: &mut Grid, masses: &[[f64; 2]], ext: &GridForces, flip: bool) {
    if !ext.has_boundaries() {
        return;
    }
    let geom = grid.geom;
    let wedges = WedgeTable::new(ext.obstacles, geom.dx);
    let mut contacts = std::mem::take(&mut grid.contacts);
    contacts.iter_mut().for_each(Vec::clear);
    if contacts.is_empty() {
        contacts.push(Vec::new());
    }
    let list = &mut contacts[0];
    for (k, &b) in grid.active.iter().enumerate() {
        let b = b as usize;
        let (near_obstacle, near_wall) = block_near(&geom, ext, b);
        if !(near_obstacle || near_wall) {
            continue;
        }
        let (i0, j0) = geom.block_origin(b);
        let block = &masses[k * BLOCK * BLOCK..(k + 1) * BLOCK * BLOCK];
        for (n, (idx, &[m, mc])) in geom.block_nodes(b).zip(block).enumerate() {
            if m <= 0.0 {
                continue;
            }
            let (i, j) = (i0 + n / BLOCK, j0 + n % BLOCK);
            let out = &mut grid.node[idx];
            let v0 = Vec2::new(out[0], out[1]);
            let mut v = v0;
            if near_obstacle {
                let xi = Vec2::new(i as f64, j as f64) * geom.dx;
                let touching = mc * (1.0 / m);
                obstacle_contacts(ext, &wedges, idx, [i, j], xi, &mut v, m, touching, list);
            }
            if near_wall {
                v = wall_velocity(ext.walls, ext.wall_cells, geom.n, i, j, v);
            }
            out[0] = v.x;
            out[1] = v.y;
            if flip {
                out[2] += v.x - v0.x;
                out[3] += v.y - v0.y;
            }
        }
    }
    pooled_friction(ext, &wedges, &contacts, &mut grid.node, geom.n, flip);
    grid.contacts = contacts;
}

/// What the grid update of one band (block row) writes: its nodes, their
/// masses and the blocks' masks if asked for ([`MassOut`], the band's
/// part), and its obstacle contact nodes.
struct BandOut<'a, 'm> {
    node: &'a mut [Node],
    masses: Option<&'a mut MassOut<'m>>,
    contacts: &'a mut Vec<ContactNode>,
}

multiversion! {
    /// [`grid_update`] on the active blocks of block row `bi` of the window.
    fn grid_band<const FLIP: bool>(
        bi: usize,
        out: BandOut,
        buffers: &mut [BandSrc],
        ctx: &BandCtx,
    ) {
        let BandCtx { is_active, geom, ext, .. } = *ctx;
        let BandOut { node: band, mut masses, contacts } = out;
        let band_base = bi * geom.stride * BLOCK;
        for bj in 0..geom.nbj {
            let b = bi * geom.nbj + bj;
            if !is_active[b] {
                continue;
            }
            let (i0, j0) = geom.block_origin(b);
            let mut srcs: [usize; CHUNKS] = [0; CHUNKS];
            let (mut nsrc, mut nodes) = (0, 0u64);
            for (k, s) in buffers.iter().enumerate() {
                if s.touched[b] {
                    srcs[nsrc] = k;
                    nsrc += 1;
                    nodes |= s.touched_nodes[b];
                }
            }
            let srcs = &srcs[..nsrc];
            let (near_obstacle, near_wall) = block_near(geom, ext, b);
            let blk = BlockAt { bj, i0, j0, nodes, near_wall };
            let mass = masses.as_mut().map(|m| &mut *m.0);
            let mask = if near_obstacle {
                update_block::<FLIP, true>(&blk, band_base, band, mass, buffers, srcs, ctx, contacts)
            } else {
                update_block::<FLIP, false>(&blk, band_base, band, mass, buffers, srcs, ctx, contacts)
            };
            if let Some(m) = masses.as_mut() {
                m.1[bj] = mask;
            }
        }
    }
}

/// Where a block sits: its column in the band, first node, the nodes the
/// scatter touched (bit `8 r + c`) and whether the walls reach it.
struct BlockAt {
    bj: usize,
    i0: usize,
    j0: usize,
    nodes: u64,
    near_wall: bool,
}

/// The grid update of the touched nodes of one active block (no other
/// node has mass: the others keep what they hold, which no particle's
/// stencil reads), with their masses written to `mass` (the band's) if
/// given; returns the block's mask of nodes with mass ([`MassOut`]). `NEAR`: an obstacle is within reach, so the
/// contact law runs and contact nodes are recorded (a separate instance
/// keeps the common loop free of it).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn update_block<const FLIP: bool, const NEAR: bool>(
    blk: &BlockAt,
    band_base: usize,
    band: &mut [Node],
    mut mass: Option<&mut [f64]>,
    buffers: &mut [BandSrc],
    srcs: &[usize],
    ctx: &BandCtx,
    contacts: &mut Vec<ContactNode>,
) -> u64 {
    let BandCtx {
        geom,
        dt,
        ext,
        wedges,
        ..
    } = *ctx;
    let BlockAt {
        bj,
        i0,
        j0,
        nodes,
        near_wall,
    } = *blk;
    let cells = ext.wall_cells;
    let dx = geom.dx;
    let mut mask = 0u64;
    for r in 0..BLOCK {
        let i = i0 + r;
        let row = r * geom.stride + bj * BLOCK;
        let mut cols = (nodes >> (r * BLOCK)) & 0xff;
        while cols != 0 {
            let c = cols.trailing_zeros() as usize;
            cols &= cols - 1;
            let j = j0 + c;
            let mut acc = [0.0; P2G_LANES];
            for &k in srcs {
                let n = &mut buffers[k].node[row + c];
                for l in 0..P2G_LANES {
                    acc[l] += n[l];
                }
                *n = [0.0; P2G_LANES];
            }
            if let Some(m) = mass.as_deref_mut() {
                m[row + c] = acc[M];
            }
            mask |= ((acc[M] > 0.0) as u64) << (r * BLOCK + c);
            let out = &mut band[row + c];
            if acc[M] <= 0.0 {
                *out = [0.0; 4];
                continue;
            }
            let inv_m = 1.0 / acc[M];
            let mut v = Vec2::new(acc[PX] * inv_m, acc[PY] * inv_m) + ext.gravity * dt;
            if ext.attractor.is_some() || NEAR {
                let xi = Vec2::new(i as f64, j as f64) * dx;
                if let Some((pos, strength)) = ext.attractor {
                    let d = pos - xi;
                    v += attractor::pull(d, dt * strength);
                }
                if NEAR {
                    let touching = acc[MC] * inv_m;
                    let index = band_base + row + c;
                    obstacle_contacts(
                        ext,
                        wedges,
                        index,
                        [i, j],
                        xi,
                        &mut v,
                        acc[M],
                        touching,
                        contacts,
                    );
                }
            }
            if near_wall {
                v = wall_velocity(ext.walls, cells, geom.n, i, j, v);
            }
            *out = if FLIP {
                let v_old = Vec2::new((acc[PX] - acc[FX]) * inv_m, (acc[PY] - acc[FY]) * inv_m);
                [v.x, v.y, v.x - v_old.x, v.y - v_old.y]
            } else {
                [v.x, v.y, 0.0, 0.0]
            };
        }
    }
    mask
}
