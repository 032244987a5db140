//! Counts per particle of each pass, from the kernels' source (the [`Term`]
//! tables), and the work of one substep of a scene.

use std::collections::{HashMap, HashSet};

use yarnsim::math::bspline::Stencil;
use yarnsim::mpm::scatter_layout::{chunk_bounds, BLOCK};
use yarnsim::mpm::YarnSim;

/// One term of a kernel's count, per particle (or per grid node).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Term {
    /// What is computed.
    pub what: &'static str,
    /// Where it is counted from (file, function).
    pub source: &'static str,
    /// Floating-point operations (see the module documentation).
    pub flops: u64,
    /// Bytes loaded and stored.
    pub bytes: u64,
    /// Counted once per obstacle of the scene (the contact tests).
    pub per_obstacle: bool,
}

const fn t(what: &'static str, source: &'static str, flops: u64, bytes: u64) -> Term {
    Term {
        what,
        source,
        flops,
        bytes,
        per_obstacle: false,
    }
}

const fn per_obstacle(what: &'static str, source: &'static str, flops: u64) -> Term {
    Term {
        what,
        source,
        flops,
        bytes: 0,
        per_obstacle: true,
    }
}

/// Lanes of a scatter node `[px, py, m, mc, fx, fy]`.
pub const P2G_LANES: u64 = yarnsim::mpm::scatter_layout::P2G_LANES as u64;
/// Bytes of a scatter node.
pub const P2G_NODE_BYTES: u64 = 8 * P2G_LANES;
/// Bytes of a grid node `[vx, vy, dvx, dvy]`.
pub const GRID_NODE_BYTES: u64 = 32;
/// Bytes of a `Stencil` (`base: [i32; 2]`, `w: [[f64; 3]; 2]`, `fx: [f64; 2]`).
pub const STENCIL_BYTES: u64 = 8 + 48 + 16;
/// Nodes of a quadratic B-spline stencil.
pub const STENCIL_NODES: u64 = 9;

/// `splat` (particle_to_grid.rs): 3 offsets `oy`; per stencil row `i`:
/// 1 offset `ox`, `rb = base + cx ox` (2 per lane); per node: 1 weight
/// product, `n += w (rb + cy oy)` (4 per lane).
pub const SPLAT_FLOPS: u64 = 3 + 3 * (1 + 2 * P2G_LANES + 3 * (1 + 4 * P2G_LANES));
/// `interpolate::<true>` (grid_to_particle.rs, FLIP: 4 lanes v, dv):
/// 3 offsets; per node 4 per lane (`wl`, `r0 +=`, `ry += wl oy`); per row
/// 1 offset and 7 per lane (`s0`, `sx`, `sy`); then `s = 4 / dx` and 8
/// products for `C` and `dC`.
pub const INTERPOLATE_FLIP_FLOPS: u64 = 3 + 3 * (3 * 4 * 4 + 1 + 7 * 4) + 1 + 8;
/// `Stencil::new` (math/bspline.rs): 2 scalings, 2 `- 0.5`, 2 fractions,
/// 2 x `weights_1d` (3 differences, 6 products and sums).
pub const STENCIL_FLOPS: u64 = 2 + 2 + 2 + 2 * 9;

/// Pass "P2G scatter + vertex forces", per vertex.
pub const P2G_VERTEX: &[Term] = &[
    t("window fit: base_of(x)", "particle_to_grid.rs scatter, bspline.rs base_of", 4, 16),
    t("fiber force f = t1[q_right] - t1[q_left] (q_left, q_right, 2 t1 read, f written)", "vertex_forces.rs vertex_forces", 4, 8 + 32 + 16),
    t("bending gradient at one vertex (rolling window): e1, e2, |e1|, |e2| (2 sqrt), cross, d, kappa, tau, s, g1, g2 (3 div); x[j-1..=j+1], bend rest", "vertex_forces.rs bend_gradient", 55, 48 + 16),
    t("bending force f -= prev.1 + cur.0 - cur.1 - next.0 (f read and written)", "vertex_forces.rs vertex_forces", 8, 32),
    t("stencil: Stencil::new(x) (x read, stencil written)", "particle_to_grid.rs scatter_chunk, bspline.rs Stencil::new", STENCIL_FLOPS, 16 + STENCIL_BYTES),
    t("impulse f0 = dt f (f read)", "particle_to_grid.rs scatter_chunk", 2, 16),
    per_obstacle("contact mass: |x - centre|^2 <= (r + margin)^2, per obstacle (none touched)", "particle_to_grid.rs contact_mass", 7),
    t("affine A = C (m dx), momentum v m + f0 (m, v, C read)", "particle_to_grid.rs scatter_chunk", 9, 8 + 16 + 32),
    t("splat into 9 scatter nodes of 6 lanes (each node read and written)", "particle_to_grid.rs splat", SPLAT_FLOPS, STENCIL_NODES * 2 * P2G_NODE_BYTES),
];

/// Pass "P2G scatter + vertex forces", per quadrature particle.
pub const P2G_QUAD: &[Term] = &[
    t(
        "window fit: stencil base read",
        "particle_to_grid.rs scatter",
        0,
        8,
    ),
    t(
        "normal force af = t2 (-4 dt / dx) d2^T (t2, d2 read)",
        "particle_to_grid.rs scatter_chunk",
        6,
        16 + 16,
    ),
    t(
        "x read for the contact test",
        "particle_to_grid.rs scatter_chunk",
        0,
        16,
    ),
    per_obstacle(
        "contact mass: |x - centre|^2 <= (r + margin)^2, per obstacle (none touched)",
        "particle_to_grid.rs contact_mass",
        7,
    ),
    t(
        "affine A = C (m dx) + af, momentum v m (m, v, C read)",
        "particle_to_grid.rs scatter_chunk",
        11,
        8 + 16 + 32,
    ),
    t(
        "stencil read (computed by the previous quadrature gather)",
        "particle_to_grid.rs scatter_chunk",
        0,
        STENCIL_BYTES,
    ),
    t(
        "splat into 9 scatter nodes of 6 lanes (each node read and written)",
        "particle_to_grid.rs splat",
        SPLAT_FLOPS,
        STENCIL_NODES * 2 * P2G_NODE_BYTES,
    ),
];

/// Pass "grid update", per scatter buffer that touched the node's block
/// (of the 4 chunk buffers).
pub const GRID_PER_SOURCE: &[Term] = &[t(
    "sum one buffer's node (6 lanes) and zero it (node read and written)",
    "grid_update.rs grid_band",
    P2G_LANES,
    2 * P2G_NODE_BYTES,
)];

/// Pass "grid update", per node of an active block
/// (a node without mass is written as zero and skipped).
pub const GRID_NODE: &[Term] = &[t(
    "grid node written",
    "grid_update.rs grid_band",
    0,
    GRID_NODE_BYTES,
)];

/// Pass "grid update", per node with mass.
pub const GRID_MASS_NODE: &[Term] = &[
    t("1 / m", "grid_update.rs grid_band", 1, 0),
    t("v = p / m + g dt", "grid_update.rs grid_band", 6, 0),
    t(
        "FLIP: v_old = (p - f) / m, dv = v - v_old",
        "grid_update.rs grid_band",
        6,
        0,
    ),
];

/// Pass "grid update", per node with mass in a block near an obstacle:
/// 3 flops and 6 per obstacle (the common case: outside the circle, not
/// touching; the friction law of touching nodes is not counted).
pub const GRID_NEAR_OBSTACLE: &[Term] = &[
    t(
        "node position xi, touching share mc / m",
        "grid_update.rs grid_band",
        3,
        0,
    ),
    per_obstacle(
        "r = xi - c, |r| (1 sqrt), per obstacle",
        "contact.rs obstacle_velocity",
        6,
    ),
];

/// Pass "G2P vertices + advection + obstacle projection", per vertex.
pub const G2P_VERTEX: &[Term] = &[
    t(
        "interpolate v, C, dv, dC from 9 grid nodes (stencil, nodes read)",
        "grid_to_particle.rs interpolate::<true>",
        INTERPOLATE_FLIP_FLOPS,
        STENCIL_BYTES + STENCIL_NODES * GRID_NODE_BYTES,
    ),
    t(
        "FLIP (ratio 1): v += dv, C += dC (v, C read and written)",
        "transfer.rs blend",
        6,
        2 * (16 + 32),
    ),
    t(
        "advection x += dt v_grid (x read and written)",
        "grid_to_particle.rs gather_vertex_chunk",
        4,
        2 * 16,
    ),
    t(
        "moment leak spin = dt v_grid x v (spin written)",
        "grid_to_particle.rs gather_vertex_chunk",
        4,
        8,
    ),
    per_obstacle(
        "projection test |x - c|^2 < r^2, per obstacle (outside)",
        "contact.rs project_out",
        6,
    ),
    t(
        "CFL check |v_grid|^2 dt^2 <= dx^2",
        "grid_to_particle.rs gather_vertex_chunk",
        6,
        0,
    ),
];

/// Pass "G2P quadrature + return mapping + stress", per quadrature
/// particle. The frame update (`frames.rs`) works on
/// structure-of-arrays scratch on the stack (about 350 bytes stored and
/// 270 loaded per particle, all in L1): not counted, as it is no traffic to
/// the caches the roofs measure.
pub const G2P_QUAD: &[Term] = &[
    t("interpolate v, C, dv, dC from 9 grid nodes (stencil, nodes read)", "grid_to_particle.rs interpolate::<true>", INTERPOLATE_FLIP_FLOPS, STENCIL_BYTES + STENCIL_NODES * GRID_NODE_BYTES),
    t("FLIP (ratio 1): v += dv, C += dC (v, C read and written)", "transfer.rs blend", 6, 2 * (16 + 32)),
    t("x = (xl + xr) / 2, d1 = xr - xl (left, 2 vertex x, l0 read)", "grid_to_particle.rs gather_quad_chunk", 6, 4 + 32 + 8),
    t("moment leak spin = (x - x_old) x v (x read and written, spin written)", "grid_to_particle.rs gather_quad_chunk", 5, 32 + 8),
    t("d2 += dt C d2 (d2 read)", "grid_to_particle.rs gather_quad_chunk", 10, 16),
    t("d = [d1, d2] written for the frame update, read back by it", "grid_to_particle.rs gather_quad_chunk, frames.rs update_frames", 0, 32 + 32),
    t("G = d / l0 (1 div)", "frames.rs update_frames", 5, 0),
    t("Givens QR of G (1 sqrt, 2 div)", "frames.rs update_frames (as math/qr.rs qr)", 12, 0),
    t("return mapping, common case inside the cone (no ln)", "frames.rs update_frames (as constitutive.rs return_map)", 5, 0),
    t("frame and d written", "frames.rs update_frames", 0, 40 + 32),
    t("stencil for the next scatter: Stencil::new(x) (written)", "grid_to_particle.rs gather_quad_chunk, bspline.rs", STENCIL_FLOPS, STENCIL_BYTES),
    t("stress P = Q A R^-T (1 ln, 2 div) and t1, t2 = P columns vol / l0 (vol read, t1, t2 written)", "frames.rs update_frames (as constitutive.rs stress_qr, frame_gradient_qr)", 39, 8 + 32),
];

/// FLIP angular-momentum balance, timed with the quadrature pass, per
/// particle (vertices and quadrature particles).
pub const SPIN_BALANCE: &[Term] = &[
    t(
        "leak, mass and centre sums (m, spin, x read)",
        "spin.rs balance",
        7,
        8 + 8 + 16,
    ),
    t(
        "inertia about the centre (m, x read)",
        "spin.rs balance",
        7,
        8 + 16,
    ),
    t(
        "rigid rotation v += omega perp(x - c) (x read, v read and written)",
        "spin.rs balance",
        6,
        16 + 32,
    ),
];

/// `(flops, bytes)` of a term table for a scene with `obstacles` obstacles.
pub fn totals(terms: &[Term], obstacles: u64) -> (u64, u64) {
    terms.iter().fold((0, 0), |(f, b), t| {
        let k = if t.per_obstacle { obstacles } else { 1 };
        (f + k * t.flops, b + k * t.bytes)
    })
}

/// What the grid update works on in one substep, from the particles'
/// stencils (as the scatter touches the blocks).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GridWork {
    pub active_blocks: u64,
    /// Sum over active blocks of the chunk buffers that touched them.
    pub block_sources: u64,
    /// Nodes with mass (inside some particle's stencil).
    pub mass_nodes: u64,
    /// Of those, nodes in blocks near an obstacle.
    pub mass_nodes_near_obstacle: u64,
}

impl GridWork {
    /// From the stencils the last scatter used (vertex and quadrature
    /// particles, chunked as the scatter chunks them).
    pub fn of(sim: &YarnSim) -> GridWork {
        let p = sim.particles();
        let scene = sim.scene();
        let dx = scene.grid.size / scene.grid.resolution as f64;
        let b = BLOCK as i32;
        let mut per_block: HashMap<(i32, i32), u64> = HashMap::new();
        let mut nodes: HashSet<(i32, i32)> = HashSet::new();
        let vb = chunk_bounds(p.vert.stencil.len());
        let qb = chunk_bounds(p.quad.stencil.len());
        for (vr, qr) in vb.into_iter().zip(qb) {
            let mut blocks = HashSet::new();
            let sts: Vec<&Stencil> = p.vert.stencil[vr]
                .iter()
                .chain(&p.quad.stencil[qr])
                .collect();
            for st in sts {
                let [i, j] = st.base;
                for di in 0..3 {
                    for dj in 0..3 {
                        nodes.insert((i + di, j + dj));
                        blocks.insert(((i + di).div_euclid(b), (j + dj).div_euclid(b)));
                    }
                }
            }
            for k in blocks {
                *per_block.entry(k).or_default() += 1;
            }
        }
        let reach = 2.0 * dx;
        let near = |(bi, bj): (i32, i32)| {
            let lo = (bi as f64 * dx * BLOCK as f64, bj as f64 * dx * BLOCK as f64);
            let hi = (
                lo.0 + (BLOCK - 1) as f64 * dx,
                lo.1 + (BLOCK - 1) as f64 * dx,
            );
            scene.obstacles.iter().any(|o| {
                let q = (o.center[0].clamp(lo.0, hi.0), o.center[1].clamp(lo.1, hi.1));
                ((q.0 - o.center[0]).powi(2) + (q.1 - o.center[1]).powi(2)).sqrt()
                    < o.radius + reach
            })
        };
        let near_nodes = nodes
            .iter()
            .filter(|&&(i, j)| near((i.div_euclid(b), j.div_euclid(b))))
            .count();
        GridWork {
            active_blocks: per_block.len() as u64,
            block_sources: per_block.values().sum(),
            mass_nodes: nodes.len() as u64,
            mass_nodes_near_obstacle: near_nodes as u64,
        }
    }

    /// `(flops, bytes)` of the grid update.
    pub fn totals(&self, obstacles: u64) -> (u64, u64) {
        let nodes = self.active_blocks * (BLOCK * BLOCK) as u64;
        let (sf, sb) = totals(GRID_PER_SOURCE, obstacles);
        let (nf, nb) = totals(GRID_NODE, obstacles);
        let (mf, mb) = totals(GRID_MASS_NODE, obstacles);
        let (of, ob) = totals(GRID_NEAR_OBSTACLE, obstacles);
        let per_block_sources = self.block_sources * (BLOCK * BLOCK) as u64;
        (
            per_block_sources * sf
                + nodes * nf
                + self.mass_nodes * mf
                + self.mass_nodes_near_obstacle * of,
            per_block_sources * sb
                + nodes * nb
                + self.mass_nodes * mb
                + self.mass_nodes_near_obstacle * ob,
        )
    }
}

/// Work of one pass in one substep.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PassWork {
    pub name: &'static str,
    pub flops: u64,
    pub bytes: u64,
}

/// The four passes' work in one substep of a scene with `nv` vertices,
/// `nq` quadrature particles, `obstacles` obstacles and the grid work `g`.
pub fn pass_work(nv: u64, nq: u64, obstacles: u64, g: &GridWork) -> [PassWork; 4] {
    let (pvf, pvb) = totals(P2G_VERTEX, obstacles);
    let (pqf, pqb) = totals(P2G_QUAD, obstacles);
    let (gf, gb) = g.totals(obstacles);
    let (vf, vb) = totals(G2P_VERTEX, obstacles);
    let (qf, qb) = totals(G2P_QUAD, obstacles);
    let (sf, sb) = totals(SPIN_BALANCE, obstacles);
    [
        PassWork {
            name: "P2G scatter + vertex forces",
            flops: nv * pvf + nq * pqf,
            bytes: nv * pvb + nq * pqb,
        },
        PassWork {
            name: "grid update",
            flops: gf,
            bytes: gb,
        },
        PassWork {
            name: "G2P vertices",
            flops: nv * vf,
            bytes: nv * vb,
        },
        PassWork {
            name: "G2P quadrature + return map + stress + spin balance",
            flops: nq * qf + (nv + nq) * sf,
            bytes: nq * qb + (nv + nq) * sb,
        },
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use yarnsim::scene::builtin::yarn_reference;

    #[test]
    fn byte_sizes_are_the_kernels_types() {
        // The sizes the byte counts use, against the types the kernels read
        // and write: a new lane or field in them changes these.
        assert_eq!(STENCIL_BYTES as usize, std::mem::size_of::<Stencil>());
        assert_eq!(
            P2G_NODE_BYTES as usize,
            std::mem::size_of::<yarnsim::testing::internals::P2gNode>()
        );
        assert_eq!(
            GRID_NODE_BYTES as usize,
            std::mem::size_of::<yarnsim::testing::internals::Node>()
        );
        let st = Stencil::new(yarnsim::math::Vec2::new(0.3, 0.4), 32.0);
        assert_eq!(STENCIL_NODES as usize, st.w[0].len() * st.w[1].len());
    }

    #[test]
    #[cfg_attr(
        debug_assertions,
        ignore = "60 substeps of the reference scene: release only"
    )]
    fn grid_work_is_the_blocks_the_simulator_touched() {
        // The grid work is derived from the particles' stencils as the
        // scatter chunks them; the simulator's own active-block list of the
        // same substep is the measured check.
        let mut sim = YarnSim::new(&yarn_reference()).unwrap();
        for _ in 0..3 {
            sim.steps_n(20).unwrap();
            let g = GridWork::of(&sim);
            assert_eq!(g.active_blocks, sim.active_blocks() as u64);
            // Every active block has 1 to 4 (chunk) buffers and at most
            // BLOCK^2 nodes with mass; the reference bundle (2400 vertices
            // on a 256^2 grid) puts mass on far fewer nodes than it has
            // particles times a 9-node stencil.
            let chunks = chunk_bounds(sim.particles().vert.stencil.len()).len() as u64;
            assert!(g.block_sources >= g.active_blocks);
            assert!(g.block_sources <= chunks * g.active_blocks);
            assert!(g.mass_nodes <= g.active_blocks * (BLOCK * BLOCK) as u64);
            assert!(g.mass_nodes_near_obstacle <= g.mass_nodes);
        }
    }

    #[test]
    fn pass_work_sums_the_terms() {
        let g = GridWork {
            active_blocks: 2,
            block_sources: 3,
            mass_nodes: 50,
            mass_nodes_near_obstacle: 10,
        };
        let w = pass_work(10, 9, 3, &g);
        let (pv, pq) = (totals(P2G_VERTEX, 3), totals(P2G_QUAD, 3));
        assert_eq!(w[0].flops, 10 * pv.0 + 9 * pq.0);
        assert_eq!(w[0].bytes, 10 * pv.1 + 9 * pq.1);
        let node = (BLOCK * BLOCK) as u64;
        let (s, n, m, o) = (
            totals(GRID_PER_SOURCE, 3),
            totals(GRID_NODE, 3),
            totals(GRID_MASS_NODE, 3),
            totals(GRID_NEAR_OBSTACLE, 3),
        );
        assert_eq!(
            w[1].flops,
            3 * node * s.0 + 2 * node * n.0 + 50 * m.0 + 10 * o.0
        );
        assert_eq!(
            w[1].bytes,
            3 * node * s.1 + 2 * node * n.1 + 50 * m.1 + 10 * o.1
        );
        let (v, q, b) = (
            totals(G2P_VERTEX, 3),
            totals(G2P_QUAD, 3),
            totals(SPIN_BALANCE, 3),
        );
        assert_eq!((w[2].flops, w[2].bytes), (10 * v.0, 10 * v.1));
        assert_eq!(w[3].flops, 9 * q.0 + 19 * b.0);
        assert_eq!(w[3].bytes, 9 * q.1 + 19 * b.1);
    }

    #[test]
    fn per_obstacle_terms_scale_with_the_obstacles() {
        for table in [P2G_VERTEX, P2G_QUAD, GRID_NEAR_OBSTACLE, G2P_VERTEX] {
            let per: u64 = table
                .iter()
                .filter(|t| t.per_obstacle)
                .map(|t| t.flops)
                .sum();
            assert!(per > 0);
            assert_eq!(totals(table, 3).0 - totals(table, 0).0, 3 * per);
            assert_eq!(totals(table, 3).1, totals(table, 0).1);
        }
    }
}
