//! The limit: a roofline of the yarn substep on this machine (issue 16).
//!
//! * Peaks, measured with simple kernels on one core: `f64` multiply-adds
//!   over 12 independent vector registers (intrinsics: SSE2 multiply and
//!   add, AVX2 FMA and AVX-512 FMA when the CPU has them), and a STREAM-like triad `a = b + s c` over
//!   arrays resident in L2, in L3 and larger than the last-level cache
//!   (DRAM). Median of the repeats.
//! * Counts per particle of each pass, from the kernels' source: the
//!   [`Term`] tables below (one term per line of work, with the file it is
//!   counted from). Adds, subtractions, multiplications, divisions, `sqrt`
//!   and `ln` count 1 flop each; comparisons, `abs`, `max`/`min`, sign
//!   flips of `perp` and integer index arithmetic count 0. Bytes are what
//!   the kernel loads and stores as written (each particle-array element or
//!   grid node accessed, once per access in the source), not the DRAM
//!   traffic: the working set of the reference scene (about 2 MB of
//!   particles, 5 MB of grid window) stays in the caches.
//! * The roofline: per pass, the measured time per substep of the
//!   `yarn-reference` scene on 1 thread ([`YarnSim::timings`]) against
//!   `min(peak flop/s, flop/byte x bandwidth)`, for the DRAM, L3 and L2
//!   bandwidth; and the 20x-Taichi goal against the same bound.
//!
//! When a kernel changes, update its [`Term`] table; `term_totals` (a unit
//! test) checks the totals quoted in the documentation of the tables.

use std::collections::{HashMap, HashSet};
use std::hint::black_box;
use std::time::Instant;

use crate::Table;
use yarnsim::math::bspline::Stencil;
use yarnsim::mpm::grid::BLOCK;
use yarnsim::mpm::simd::chunk_bounds;
use yarnsim::mpm::{PassTimes, YarnSim};
use yarnsim::scene::{builtin::yarn_reference, YarnScene};

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
pub const P2G_LANES: u64 = yarnsim::mpm::grid::P2G_LANES as u64;
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

/// Pass "P2G scatter + vertex forces", per vertex: 394 flops, 1192 bytes.
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

/// Pass "P2G scatter + vertex forces", per quadrature particle: 305 flops, 1048 bytes.
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
/// (of the 4 chunk buffers): 6 flops, 96 bytes.
pub const GRID_PER_SOURCE: &[Term] = &[t(
    "sum one buffer's node (6 lanes) and zero it (node read and written)",
    "grid_update.rs grid_band",
    P2G_LANES,
    2 * P2G_NODE_BYTES,
)];

/// Pass "grid update", per node of an active block: 0 flops, 32 bytes
/// (a node without mass is written as zero and skipped).
pub const GRID_NODE: &[Term] = &[t(
    "grid node written",
    "grid_update.rs grid_band",
    0,
    GRID_NODE_BYTES,
)];

/// Pass "grid update", per node with mass: 13 flops.
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

/// Pass "G2P vertices + advection + obstacle projection", per vertex:
/// 281 flops, 496 bytes.
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
/// particle: 355 flops, 804 bytes. The frame update (`frames.rs`) works on
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
/// particle (vertices and quadrature particles): 20 flops, 104 bytes.
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

// ---------------------------------------------------------------- peaks

/// Independent accumulator registers of the multiply-add kernels: 12,
/// enough chains to cover the latency (4 cycles) of 2 pipes, and few
/// enough to stay in registers.
const CHAINS: usize = 12;

/// `acc = acc m + a` on `CHAINS` scalar accumulators, `iters` times
/// (fallback off x86-64).
#[allow(dead_code)]
fn madd_generic(iters: u64, m: f64, a: f64) -> f64 {
    let mut acc = [0.0f64; CHAINS];
    for (i, x) in acc.iter_mut().enumerate() {
        *x = i as f64 * 1e-3;
    }
    for _ in 0..iters {
        for x in acc.iter_mut() {
            *x = *x * m + a;
        }
    }
    acc.iter().sum()
}

/// SSE2 (x86-64 baseline, what the portable kernels are built for):
/// `CHAINS` registers of 2 lanes, separate multiply and add.
#[cfg(target_arch = "x86_64")]
fn madd_sse2(iters: u64, m: f64, a: f64) -> f64 {
    use std::arch::x86_64::*;
    // SAFETY: SSE2 is part of the x86-64 baseline.
    unsafe {
        let (vm, va) = (_mm_set1_pd(m), _mm_set1_pd(a));
        let mut acc: [__m128d; CHAINS] = std::array::from_fn(|i| _mm_set1_pd(i as f64 * 1e-3));
        for _ in 0..iters {
            for x in acc.iter_mut() {
                *x = _mm_add_pd(_mm_mul_pd(*x, vm), va);
            }
        }
        let mut out = [0.0f64; 2];
        let s = acc.iter().fold(_mm_setzero_pd(), |s, &x| _mm_add_pd(s, x));
        _mm_storeu_pd(out.as_mut_ptr(), s);
        out.iter().sum()
    }
}

/// AVX2 + FMA: `CHAINS` registers of 4 lanes, one FMA each.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn madd_avx2(iters: u64, m: f64, a: f64) -> f64 {
    use std::arch::x86_64::*;
    let (vm, va) = (_mm256_set1_pd(m), _mm256_set1_pd(a));
    let mut acc: [__m256d; CHAINS] = std::array::from_fn(|i| _mm256_set1_pd(i as f64 * 1e-3));
    for _ in 0..iters {
        for x in acc.iter_mut() {
            *x = _mm256_fmadd_pd(*x, vm, va);
        }
    }
    let mut out = [0.0f64; 4];
    let s = acc
        .iter()
        .fold(_mm256_setzero_pd(), |s, &x| _mm256_add_pd(s, x));
    // SAFETY: `out` holds 4 f64.
    unsafe { _mm256_storeu_pd(out.as_mut_ptr(), s) };
    out.iter().sum()
}

/// AVX-512 F: `CHAINS` registers of 8 lanes, one FMA each.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
fn madd_avx512(iters: u64, m: f64, a: f64) -> f64 {
    use std::arch::x86_64::*;
    let (vm, va) = (_mm512_set1_pd(m), _mm512_set1_pd(a));
    let mut acc: [__m512d; CHAINS] = std::array::from_fn(|i| _mm512_set1_pd(i as f64 * 1e-3));
    for _ in 0..iters {
        for x in acc.iter_mut() {
            *x = _mm512_fmadd_pd(*x, vm, va);
        }
    }
    let s = acc
        .iter()
        .fold(_mm512_setzero_pd(), |s, &x| _mm512_add_pd(s, x));
    _mm512_reduce_add_pd(s)
}

#[inline(always)]
fn triad_body(a: &mut [f64], b: &[f64], c: &[f64], s: f64) {
    for ((x, y), z) in a.iter_mut().zip(b).zip(c) {
        *x = y + s * z;
    }
}

fn triad_portable(a: &mut [f64], b: &[f64], c: &[f64], s: f64) {
    triad_body(a, b, c, s)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn triad_avx2(a: &mut [f64], b: &[f64], c: &[f64], s: f64) {
    triad_body(a, b, c, s)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
fn triad_avx512(a: &mut [f64], b: &[f64], c: &[f64], s: f64) {
    triad_body(a, b, c, s)
}

/// Instruction sets of the peak kernels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    /// The x86-64 baseline the portable kernels are built for: SSE2, 2
    /// lanes, separate multiply and add.
    Portable,
    Avx2Fma,
    Avx512,
}

impl Isa {
    pub fn name(self) -> &'static str {
        match self {
            Isa::Portable => "SSE2 (x86-64 baseline)",
            Isa::Avx2Fma => "AVX2 + FMA",
            Isa::Avx512 => "AVX-512 F + FMA",
        }
    }
    /// The instruction sets this CPU runs, narrowest first.
    pub fn available() -> Vec<Isa> {
        let mut v = vec![Isa::Portable];
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
                v.push(Isa::Avx2Fma);
                if std::is_x86_feature_detected!("avx512f")
                    && std::is_x86_feature_detected!("avx512vl")
                {
                    v.push(Isa::Avx512);
                }
            }
        }
        v
    }
    /// Runs the multiply-add kernel; returns its result and the number of
    /// accumulators (f64 lanes).
    fn madd(self, iters: u64, m: f64, a: f64) -> (f64, usize) {
        match self {
            #[cfg(target_arch = "x86_64")]
            Isa::Portable => (madd_sse2(iters, m, a), 2 * CHAINS),
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2Fma => {
                // SAFETY: `available` listed this instruction set only where the CPU has it.
                (unsafe { madd_avx2(iters, m, a) }, 4 * CHAINS)
            }
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => {
                // SAFETY: as for AVX2 above.
                (unsafe { madd_avx512(iters, m, a) }, 8 * CHAINS)
            }
            #[cfg(not(target_arch = "x86_64"))]
            _ => (madd_generic(iters, m, a), CHAINS),
        }
    }
    fn triad(self, a: &mut [f64], b: &[f64], c: &[f64], s: f64) {
        match self {
            Isa::Portable => triad_portable(a, b, c, s),
            #[cfg(target_arch = "x86_64")]
            // SAFETY: as in `madd`.
            Isa::Avx2Fma => unsafe { triad_avx2(a, b, c, s) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: as in `madd`.
            Isa::Avx512 => unsafe { triad_avx512(a, b, c, s) },
            #[cfg(not(target_arch = "x86_64"))]
            _ => triad_portable(a, b, c, s),
        }
    }
}

/// One measured peak.
#[derive(Clone, Debug, PartialEq)]
pub struct Peak {
    pub kernel: String,
    pub detail: String,
    /// flop/s or byte/s.
    pub value: f64,
    pub unit: &'static str,
    pub repeats: usize,
}

/// The peaks of one core.
#[derive(Clone, Debug, PartialEq)]
pub struct Peaks {
    pub flops: Vec<Peak>,
    /// Triad bandwidth: L2, L3, DRAM.
    pub bandwidth: Vec<Peak>,
}

impl Peaks {
    /// The compute roof: the fastest multiply-add kernel.
    pub fn peak_flops(&self) -> f64 {
        self.flops.iter().map(|p| p.value).fold(0.0, f64::max)
    }
    fn bw(&self, level: &str) -> f64 {
        self.bandwidth
            .iter()
            .find(|p| p.kernel.contains(level))
            .map_or(f64::NAN, |p| p.value)
    }
    pub fn dram(&self) -> f64 {
        self.bw("DRAM")
    }
    pub fn l3(&self) -> f64 {
        self.bw("L3")
    }
    pub fn l2(&self) -> f64 {
        self.bw("L2")
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Measures the peaks on the calling thread, median of `repeats`.
pub fn measure_peaks(repeats: usize) -> Peaks {
    let repeats = repeats.max(1);
    let mut flops = Vec::new();
    // about 2e8 flops per timing
    let work = 200_000_000u64;
    let isas = Isa::available();
    for &isa in &isas {
        let (_, n) = isa.madd(1, 1.0, 0.0);
        let iters = work / (2 * n as u64);
        let _ = isa.madd(iters / 10, black_box(0.999_999), black_box(1e-6)); // warm up clocks
        let rates: Vec<f64> = (0..repeats)
            .map(|_| {
                let t0 = Instant::now();
                let r = isa.madd(iters, black_box(0.999_999), black_box(1e-6));
                let s = t0.elapsed().as_secs_f64();
                black_box(r);
                (2 * n as u64 * iters) as f64 / s
            })
            .collect();
        flops.push(Peak {
            kernel: format!("f64 multiply-add, {}", isa.name()),
            detail: format!(
                "{CHAINS} registers, {n} f64 accumulators, {} (2 flop each)",
                if isa == Isa::Portable {
                    "mul + add"
                } else {
                    "fma"
                }
            ),
            value: median(rates),
            unit: "flop/s",
            repeats,
        });
    }
    let widest = *isas.last().unwrap_or(&Isa::Portable);
    let mut bandwidth = Vec::new();
    // (level, elements per array, passes per timing)
    for (level, n, passes) in [
        ("L2", 32 * 1024, 2000usize),
        ("L3", 256 * 1024, 200),
        ("DRAM", 8 * 1024 * 1024, 4),
    ] {
        let mut a = vec![0.0f64; n];
        let b = vec![1.0f64; n];
        let c = vec![2.0f64; n];
        isa_triad_passes(widest, &mut a, &b, &c, passes.div_ceil(4));
        let rates: Vec<f64> = (0..repeats)
            .map(|_| {
                let t0 = Instant::now();
                isa_triad_passes(widest, &mut a, &b, &c, passes);
                let s = t0.elapsed().as_secs_f64();
                (24 * n * passes) as f64 / s
            })
            .collect();
        bandwidth.push(Peak {
            kernel: format!("triad a = b + s c, {level}"),
            detail: format!(
                "3 arrays of {} KiB ({}), 24 byte per element (no write-allocate)",
                8 * n / 1024,
                widest.name()
            ),
            value: median(rates),
            unit: "byte/s",
            repeats,
        });
    }
    Peaks { flops, bandwidth }
}

fn isa_triad_passes(isa: Isa, a: &mut [f64], b: &[f64], c: &[f64], passes: usize) {
    for _ in 0..passes {
        isa.triad(a, b, c, black_box(3.0));
        black_box(&mut *a);
    }
}

// ---------------------------------------------------------------- study

/// What to run.
#[derive(Clone, Debug)]
pub struct RooflineOptions {
    /// Timed substeps per repeat.
    pub steps: u64,
    pub warmup: u64,
    /// Repeats of the substep timing (the fastest is kept) and of each peak
    /// kernel (the median is kept).
    pub repeats: usize,
    /// Particle-substeps/s of the Taichi seed on this host (low, high), for
    /// the 20x goal.
    pub seed_rate: (f64, f64),
    /// The goal as a multiple of the seed.
    pub goal_factor: f64,
}

impl Default for RooflineOptions {
    fn default() -> Self {
        RooflineOptions {
            steps: 200,
            warmup: 100,
            repeats: 7,
            // tools/taichi_bench.sh on this host (README, "Against the Taichi seed")
            seed_rate: (1.9e6, 2.7e6),
            goal_factor: 20.0,
        }
    }
}

/// One pass on the roofline.
#[derive(Clone, Debug, PartialEq)]
pub struct PassPoint {
    pub work: PassWork,
    /// Measured seconds per substep.
    pub seconds: f64,
}

impl PassPoint {
    pub fn flop_rate(&self) -> f64 {
        self.work.flops as f64 / self.seconds
    }
    pub fn byte_rate(&self) -> f64 {
        self.work.bytes as f64 / self.seconds
    }
    pub fn intensity(&self) -> f64 {
        self.work.flops as f64 / self.work.bytes as f64
    }
}

/// `min(peak, intensity x bandwidth)`.
pub fn bound(peak_flops: f64, intensity: f64, bandwidth: f64) -> f64 {
    peak_flops.min(intensity * bandwidth)
}

/// The whole report.
#[derive(Clone, Debug)]
pub struct RooflineReport {
    pub peaks: Peaks,
    pub passes: Vec<PassPoint>,
    pub particles: u64,
    pub vertices: u64,
    pub quads: u64,
    pub grid: GridWork,
    pub sim_active_blocks: usize,
    pub steps: u64,
    pub opts: RooflineOptions,
}

/// Runs the study: the peaks, then the reference scene on 1 thread.
pub fn run(opts: &RooflineOptions) -> Result<RooflineReport, String> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| e.to_string())?;
    pool.install(|| run_on_this_thread(opts))
}

fn run_on_this_thread(opts: &RooflineOptions) -> Result<RooflineReport, String> {
    let peaks = measure_peaks(opts.repeats);
    let scene: YarnScene = yarn_reference();
    let mut start = YarnSim::new(&scene).map_err(|e| e.to_string())?;
    start.steps_n(opts.warmup).map_err(|e| e.to_string())?;
    let mut best: Option<(f64, PassTimes, GridWork, usize)> = None;
    for _ in 0..opts.repeats.max(1) {
        let mut s = start.clone();
        s.reset_timings();
        s.steps_n(opts.steps.max(1)).map_err(|e| e.to_string())?;
        let tm = s.timings();
        if best.as_ref().is_none_or(|b| tm.total() < b.0) {
            best = Some((tm.total(), tm, GridWork::of(&s), s.active_blocks()));
        }
    }
    let (_, tm, grid, sim_active_blocks) = best.expect("at least one repeat");
    let p = start.particles();
    let (nv, nq) = (p.vert.x.len() as u64, p.quad.x.len() as u64);
    let work = pass_work(nv, nq, scene.obstacles.len() as u64, &grid);
    let per = |s: f64| s / tm.substeps.max(1) as f64;
    let secs = [
        per(tm.scatter + tm.forces),
        per(tm.grid),
        per(tm.gather_vertices),
        per(tm.gather_quads),
    ];
    Ok(RooflineReport {
        peaks,
        passes: work
            .into_iter()
            .zip(secs)
            .map(|(work, seconds)| PassPoint { work, seconds })
            .collect(),
        particles: nv + nq,
        vertices: nv,
        quads: nq,
        grid,
        sim_active_blocks,
        steps: opts.steps,
        opts: opts.clone(),
    })
}

impl RooflineReport {
    pub fn peaks_table(&self) -> Table {
        let mut t = Table::new(&["kernel", "detail", "median", "unit"]);
        for p in self.peaks.flops.iter().chain(&self.peaks.bandwidth) {
            let (v, unit) = if p.unit == "flop/s" {
                (p.value / 1e9, "GFLOP/s")
            } else {
                (p.value / 1e9, "GB/s")
            };
            t.push(vec![
                p.kernel.clone(),
                p.detail.clone(),
                format!("{v:.2}"),
                unit.into(),
            ]);
        }
        t
    }

    /// Everything of one pass or the total, for the pass table.
    fn row(&self, name: &str, flops: u64, bytes: u64, seconds: f64) -> Vec<String> {
        let pk = self.peaks.peak_flops();
        let ai = flops as f64 / bytes as f64;
        let rate = flops as f64 / seconds;
        let b_dram = bound(pk, ai, self.peaks.dram());
        let b_l3 = bound(pk, ai, self.peaks.l3());
        let b_l2 = bound(pk, ai, self.peaks.l2());
        let n = self.particles as f64;
        vec![
            name.to_string(),
            format!("{:.1}", seconds * 1e6),
            format!("{:.0}", flops as f64 / n),
            format!("{:.0}", bytes as f64 / n),
            format!("{ai:.3}"),
            format!("{:.2}", rate / 1e9),
            format!("{:.2}", bytes as f64 / seconds / 1e9),
            format!("{:.1}", b_dram / 1e9),
            format!("{:.1}%", 100.0 * rate / b_dram),
            format!("{:.1}", b_l3 / 1e9),
            format!("{:.1}%", 100.0 * rate / b_l3),
            format!("{:.1}", b_l2 / 1e9),
            format!("{:.1}%", 100.0 * rate / b_l2),
        ]
    }

    fn total(&self) -> (u64, u64, f64) {
        self.passes.iter().fold((0, 0, 0.0), |(f, b, s), p| {
            (f + p.work.flops, b + p.work.bytes, s + p.seconds)
        })
    }

    pub fn passes_table(&self) -> Table {
        let mut t = Table::new(&[
            "pass",
            "us_per_substep",
            "flop_per_particle",
            "byte_per_particle",
            "flop_per_byte",
            "GFLOP_per_s",
            "GB_per_s",
            "bound_DRAM_GFLOP_per_s",
            "of_DRAM_bound",
            "bound_L3_GFLOP_per_s",
            "of_L3_bound",
            "bound_L2_GFLOP_per_s",
            "of_L2_bound",
        ]);
        for p in &self.passes {
            t.push(self.row(p.work.name, p.work.flops, p.work.bytes, p.seconds));
        }
        let (f, b, s) = self.total();
        t.push(self.row("total", f, b, s));
        t
    }

    /// The goal: `goal_factor` x the seed's rate, as time per substep and
    /// as a fraction of the roofline bound of the whole substep.
    pub fn goal_table(&self) -> Table {
        let (f, b, s) = self.total();
        let n = self.particles as f64;
        let pk = self.peaks.peak_flops();
        let ai = f as f64 / b as f64;
        let mut t = Table::new(&[
            "rate",
            "particle_substeps_per_s",
            "us_per_substep",
            "GFLOP_per_s",
            "GB_per_s",
            "of_DRAM_bound",
            "of_L3_bound",
            "of_L2_bound",
        ]);
        let mut push = |name: String, rate: f64| {
            let secs = n / rate;
            let fr = f as f64 / secs;
            t.push(vec![
                name,
                format!("{:.2} M", rate / 1e6),
                format!("{:.1}", secs * 1e6),
                format!("{:.2}", fr / 1e9),
                format!("{:.2}", b as f64 / secs / 1e9),
                format!("{:.1}%", 100.0 * fr / bound(pk, ai, self.peaks.dram())),
                format!("{:.1}%", 100.0 * fr / bound(pk, ai, self.peaks.l3())),
                format!("{:.1}%", 100.0 * fr / bound(pk, ai, self.peaks.l2())),
            ]);
        };
        push("measured (1 thread)".into(), n / s);
        let (lo, hi) = self.opts.seed_rate;
        let g = self.opts.goal_factor;
        push(format!("goal {g}x seed (seed {:.1} M)", lo / 1e6), g * lo);
        push(format!("goal {g}x seed (seed {:.1} M)", hi / 1e6), g * hi);
        push(
            "roofline bound (L3)".into(),
            n * bound(pk, ai, self.peaks.l3()) / f as f64,
        );
        t
    }

    /// The count tables, term by term.
    pub fn counts_table(&self) -> Table {
        let obstacles = 3u64;
        let mut t = Table::new(&["pass", "per", "term", "source", "flops", "bytes"]);
        let groups: [(&str, &str, &[Term]); 8] = [
            ("P2G", "vertex", P2G_VERTEX),
            ("P2G", "quadrature particle", P2G_QUAD),
            (
                "grid",
                "buffer touching the block, per node",
                GRID_PER_SOURCE,
            ),
            ("grid", "node of an active block", GRID_NODE),
            ("grid", "node with mass", GRID_MASS_NODE),
            (
                "grid",
                "node with mass near an obstacle",
                GRID_NEAR_OBSTACLE,
            ),
            ("G2P vertices", "vertex", G2P_VERTEX),
            ("G2P quadrature", "quadrature particle", G2P_QUAD),
        ];
        for (pass, per, terms) in
            groups
                .into_iter()
                .chain([("G2P quadrature (spin balance)", "particle", SPIN_BALANCE)])
        {
            for term in terms {
                let k = if term.per_obstacle { obstacles } else { 1 };
                t.push(vec![
                    pass.into(),
                    per.into(),
                    if term.per_obstacle {
                        format!("{} (x{obstacles})", term.what)
                    } else {
                        term.what.into()
                    },
                    term.source.into(),
                    (k * term.flops).to_string(),
                    (k * term.bytes).to_string(),
                ]);
            }
            let (f, b) = totals(terms, obstacles);
            t.push(vec![
                pass.into(),
                per.into(),
                "total".into(),
                String::new(),
                f.to_string(),
                b.to_string(),
            ]);
        }
        t
    }

    pub fn to_text(&self) -> String {
        let g = &self.grid;
        format!(
            "Roofline of the yarn substep on one core\n\nPeaks (median of {} repeats)\n\n{}\nCounts per particle-substep (1 flop per add, mul, div, sqrt, ln; bytes loaded and stored by the kernel as written), measured time of the fastest of {} repeats of {} substeps (yarn-reference, 1 thread, {} particles: {} vertices, {} quadrature particles; grid: {} active blocks ({} by the simulator), {:.2} scatter buffers per block, {} nodes with mass, {} near an obstacle). Bounds: min(peak {:.2} GFLOP/s, flop/byte x triad bandwidth (DRAM {:.1} GB/s, L3 {:.1} GB/s, L2 {:.1} GB/s))\n\n{}\nThe goal against the bound of the whole substep\n\n{}",
            self.peaks.flops.first().map_or(0, |p| p.repeats),
            self.peaks_table().to_text(),
            self.opts.repeats,
            self.steps,
            self.particles,
            self.vertices,
            self.quads,
            g.active_blocks,
            self.sim_active_blocks,
            g.block_sources as f64 / g.active_blocks.max(1) as f64,
            g.mass_nodes,
            g.mass_nodes_near_obstacle,
            self.peaks.peak_flops() / 1e9,
            self.peaks.dram() / 1e9,
            self.peaks.l3() / 1e9,
            self.peaks.l2() / 1e9,
            self.passes_table().to_text(),
            self.goal_table().to_text(),
        )
    }

    /// Files: `roofline_peaks.csv`, `roofline_passes.csv`,
    /// `roofline_goal.csv`, `roofline_counts.csv`, `roofline.txt`.
    pub fn files(&self) -> Vec<(String, String)> {
        vec![
            ("roofline_peaks.csv".into(), self.peaks_table().to_csv()),
            ("roofline_passes.csv".into(), self.passes_table().to_csv()),
            ("roofline_goal.csv".into(), self.goal_table().to_csv()),
            ("roofline_counts.csv".into(), self.counts_table().to_csv()),
            ("roofline.txt".into(), self.to_text()),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn term_totals() {
        // the totals quoted in the tables' documentation (3 obstacles)
        assert_eq!(SPLAT_FLOPS, 267);
        assert_eq!(INTERPOLATE_FLIP_FLOPS, 243);
        assert_eq!(STENCIL_FLOPS, 24);
        assert_eq!(totals(P2G_VERTEX, 3), (394, 1192));
        assert_eq!(totals(P2G_QUAD, 3), (305, 1048));
        assert_eq!(totals(GRID_PER_SOURCE, 3), (6, 96));
        assert_eq!(totals(GRID_MASS_NODE, 3), (13, 0));
        assert_eq!(totals(GRID_NEAR_OBSTACLE, 3), (21, 0));
        assert_eq!(totals(G2P_VERTEX, 3), (281, 496));
        assert_eq!(totals(G2P_QUAD, 3), (355, 804));
        assert_eq!(totals(SPIN_BALANCE, 3), (20, 104));
        // per-obstacle terms scale, the others do not
        let (f0, _) = totals(P2G_VERTEX, 0);
        assert_eq!(f0, 394 - 21);
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
        assert_eq!(w[0].flops, 10 * 394 + 9 * 305);
        assert_eq!(w[0].bytes, 10 * 1192 + 9 * 1048);
        assert_eq!(w[1].flops, 3 * 64 * 6 + 50 * 13 + 10 * 21);
        assert_eq!(w[1].bytes, 3 * 64 * 96 + 2 * 64 * 32);
        assert_eq!(w[2].flops, 10 * 281);
        assert_eq!(w[3].flops, 9 * 355 + 19 * 20);
        assert_eq!(w[3].bytes, 9 * 804 + 19 * 104);
    }

    #[test]
    fn bound_is_the_lower_roof() {
        assert_eq!(bound(100.0, 0.1, 50.0), 5.0);
        assert_eq!(bound(100.0, 10.0, 50.0), 100.0);
    }

    #[test]
    fn median_of_odd_and_even() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(vec![4.0, 1.0, 2.0, 3.0]), 2.5);
    }
}
