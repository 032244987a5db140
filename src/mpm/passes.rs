//! The passes of one MPM substep, each a free function over the state it
//! needs. [`crate::mpm::YarnSim::step`] runs them in order and skips those a
//! scene does not need.
//!
//! 1. [`scatter`]: APIC particle-to-grid of mass and momentum, with the
//!    internal forces added as `dt f` to the momentum (vertex forces are
//!    assembled here from the quadrature stress and the bending springs).
//! 2. [`grid_update`]: momentum / mass, gravity, attractor, obstacles, walls.
//! 3. [`gather_vertices`]: grid-to-particle and advection of the vertices.
//! 4. [`gather_quads`]: quadrature re-interpolation, `d2` update, return
//!    mapping, and the stress for the next step.
//!
//! [`quad_stress`] computes that stress when the state was set from outside.

use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use super::constitutive::{frame_gradient_qr, YarnEnergy};
use super::grid::{Grid, GridGeom, Node, ScatterBuffer, BLOCK, CHUNKS, M, X, Y};
use super::particles::{Particles, Quads, Vertices, NONE};
use crate::math::bspline::Stencil;
use crate::math::qr::{qr, Qr2};
use crate::math::{Mat2, Vec2};
use crate::scene::{Obstacle, WallMode};

/// Particles per parallel task in the gathers.
const PAR_MIN: usize = 256;

/// Set to run the portable kernels even where AVX2 is available.
static PORTABLE_ONLY: AtomicBool = AtomicBool::new(false);

/// Makes every simulation in the process use the portable kernels (`true`)
/// or the AVX2 + FMA ones where the CPU has them (`false`, the default).
/// Results are bitwise the same; this exists to test exactly that.
pub fn set_portable_kernels(portable: bool) {
    PORTABLE_ONLY.store(portable, Ordering::Relaxed);
}

/// Whether the CPU runs the AVX2 + FMA versions of the kernels (detected
/// once by std, cached).
#[inline(always)]
fn wide_simd() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx2")
            && std::is_x86_feature_detected!("fma")
            && !PORTABLE_ONLY.load(Ordering::Relaxed)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// `multiversion! { fn name(args) -> R { body } }` defines `name`, whose body
/// (an `#[inline(always)]` inner function) is compiled twice: for AVX2 + FMA,
/// run when the CPU has them, and as built otherwise. Both give the same bits: Rust never contracts `a * b + c` into
/// an FMA by itself, so only the register width differs.
macro_rules! multiversion {
    ($(#[$m:meta])* fn $name:ident($($a:ident: $t:ty),* $(,)?) $(-> $r:ty)? $body:block) => {
        $(#[$m])*
        fn $name($($a: $t),*) $(-> $r)? {
            #[inline(always)]
            fn imp($($a: $t),*) $(-> $r)? $body
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx2,fma")]
                unsafe fn wide($($a: $t),*) $(-> $r)? {
                    imp($($a),*)
                }
                if wide_simd() {
                    // SAFETY: the CPU has the features `wide` is compiled for.
                    return unsafe { wide($($a),*) };
                }
            }
            imp($($a),*)
        }
    };
}

/// The external-force and boundary settings used by [`grid_update`].
#[derive(Clone, Debug)]
pub struct GridForces<'a> {
    pub gravity: Vec2,
    /// `(position, strength)` when the attractor acts.
    pub attractor: Option<(Vec2, f64)>,
    pub obstacles: &'a [Obstacle],
    pub walls: WallMode,
    pub wall_cells: usize,
}

/// Stencils and fiber-frame stress of every quadrature particle from its
/// cached frame. [`gather_quads`] does this for each particle as it updates
/// it; this pass is needed only when the state was set from outside the
/// stepper (a new simulation, a restored state, edited particles).
pub fn quad_stress(q: &mut Quads, geom: &GridGeom, energy: &YarnEnergy) {
    let inv_dx = geom.inv_dx;
    (
        &mut q.stencil,
        &mut q.t1,
        &mut q.t2,
        &q.x,
        &q.frame,
        &q.l0,
        &q.vol,
    )
        .into_par_iter()
        .with_min_len(PAR_MIN)
        .for_each(|(st, t1, t2, x, g, l0, vol)| {
            *st = Stencil::new(*x, inv_dx);
            (*t1, *t2) = frame_gradient_qr(energy, g, *l0, *vol);
        });
}

/// Total internal force on vertex `i`: the fiber (tangent) forces of its
/// two segments and its bending springs.
#[inline(always)]
fn vertex_force(v: &Vertices, t1: &[Vec2], i: usize, bending: f64) -> Vec2 {
    // E depends on d1 = x_right - x_left: the left end gets +dE/dd1, the right end -dE/dd1.
    let mut force = Vec2::zeros();
    let (ql, qr_) = (v.q_left[i], v.q_right[i]);
    if qr_ != NONE {
        force += t1[qr_ as usize];
    }
    if ql != NONE {
        force -= t1[ql as usize];
    }
    if bending > 0.0 {
        let x = v.x[i];
        for (j, rest) in [v.bend_prev[i], v.bend_next[i]] {
            if j != NONE {
                force += spring_force(x, v.x[j as usize], bending / rest, rest);
            }
        }
    }
    force
}

/// Force on a particle at `xi` from a spring to `xj` of stiffness `k` and rest length `rest`.
#[inline(always)]
fn spring_force(xi: Vec2, xj: Vec2, k: f64, rest: f64) -> Vec2 {
    let d = xj - xi;
    let len = d.norm();
    if len > 0.0 {
        d * (k * (len - rest) / len)
    } else {
        Vec2::zeros()
    }
}

/// Index ranges of chunk `k` of `n` items.
#[inline]
fn chunk_range(n: usize, k: usize) -> std::ops::Range<usize> {
    (n * k / CHUNKS)..(n * (k + 1) / CHUNKS)
}

/// Adds one particle's mass and momentum to a buffer: node `i` of the
/// stencil gets mass `w_i m` and momentum `w_i (p0 + A (x_i - x_p) / dx)`.
///
/// For APIC, `p0 = m v` (plus the impulse `dt f` of forces acting at the
/// particle) and `A = m C dx`; a force that depends linearly on the node
/// offset (the MLS normal force of a quadrature particle) folds into `A`.
#[inline(always)]
fn splat(buf: &mut ScatterBuffer, geom: &GridGeom, st: &Stencil, m: f64, p0: Vec2, a: &Mat2) {
    buf.touch_stencil(geom, st.base);
    let oy = [-st.fx[1], 1.0 - st.fx[1], 2.0 - st.fx[1]];
    let ay = [a[(0, 1)] * oy[0], a[(0, 1)] * oy[1], a[(0, 1)] * oy[2]];
    let by = [a[(1, 1)] * oy[0], a[(1, 1)] * oy[1], a[(1, 1)] * oy[2]];
    let (bi, bj) = (st.base[0] as usize, st.base[1] as usize);
    for i in 0..3 {
        let ox = i as f64 - st.fx[0];
        let rx = p0.x + a[(0, 0)] * ox;
        let ry = p0.y + a[(1, 0)] * ox;
        let wi = st.w[0][i];
        let start = geom.index(bi + i, bj);
        let row = &mut buf.node[start..start + 3];
        for j in 0..3 {
            let w = wi * st.w[1][j];
            let add: Node = [rx + ay[j], ry + by[j], m, 0.0];
            let n = &mut row[j];
            for l in 0..4 {
                n[l] += w * add[l];
            }
        }
    }
}

/// Pass 1: particle-to-grid of mass, momentum and `dt` times internal
/// force. Vertex stencils and forces (fiber tangent forces from the
/// quadrature stress, bending springs) are computed here as each vertex is
/// splatted; quadrature stencils and stress come from [`gather_quads`] (or
/// [`quad_stress`]).
pub fn scatter(p: &mut Particles, grid: &mut Grid, dt: f64, bending: f64) {
    let geom = grid.geom;
    let (nv, nq) = (p.vert.x.len(), p.quad.x.len());
    // Each chunk writes the stencils of its own vertex range (taken out of
    // `p.vert` meanwhile, so the rest of it can be shared).
    let mut vert_stencils = std::mem::take(&mut p.vert.stencil);
    let mut stencils: Vec<&mut [Stencil]> = Vec::with_capacity(CHUNKS);
    let mut rest = vert_stencils.as_mut_slice();
    for k in 0..CHUNKS {
        let (head, tail) = rest.split_at_mut(chunk_range(nv, k).len());
        stencils.push(head);
        rest = tail;
    }
    let ctx = ScatterCtx {
        vert: &p.vert,
        quad: &p.quad,
        geom,
        dt,
        bending,
    };
    grid.buffers
        .par_iter_mut()
        .zip(stencils)
        .enumerate()
        .for_each(|(k, (buf, sts))| {
            scatter_chunk(buf, sts, chunk_range(nv, k), chunk_range(nq, k), &ctx)
        });
    p.vert.stencil = vert_stencils;
    grid.collect_active();
}

/// What every scatter chunk reads.
struct ScatterCtx<'a> {
    vert: &'a Vertices,
    quad: &'a Quads,
    geom: GridGeom,
    dt: f64,
    bending: f64,
}

multiversion! {
    /// Scatters vertices `vr` (writing their stencils to `sts`) and
    /// quadrature particles `qr` into one chunk's buffer.
    fn scatter_chunk(
        buf: &mut ScatterBuffer,
        sts: &mut [Stencil],
        vr: std::ops::Range<usize>,
        qr: std::ops::Range<usize>,
        ctx: &ScatterCtx,
    ) {
        let (vert, quad, geom, dt) = (ctx.vert, ctx.quad, &ctx.geom, ctx.dt);
        let dx = geom.dx;
        // the normal force per unit of (w_i (x_i - x_p) / dx . d2): -dt dE/dd2 4 / dx
        let normal_scale = -dt * 4.0 * geom.inv_dx;
        buf.clear(geom);
        for (i, st) in vr.zip(sts.iter_mut()) {
            *st = Stencil::new(vert.x[i], geom.inv_dx);
            let m = vert.m[i];
            let p0 = vert.v[i] * m + vertex_force(vert, &quad.t1, i, ctx.bending) * dt;
            splat(buf, geom, st, m, p0, &(vert.c[i] * (m * dx)));
        }
        for q in qr {
            let m = quad.m[q];
            let d2 = quad.d[q].column(1).into_owned();
            let a = quad.c[q] * (m * dx) + quad.t2[q] * normal_scale * d2.transpose();
            splat(buf, geom, &quad.stencil[q], m, quad.v[q] * m, &a);
        }
    }
}

/// Pass 2: sums the chunk buffers on the active blocks, turns momentum into
/// velocity and applies gravity, attractor, obstacles and walls. Work is
/// done per active block; obstacle and wall tests only where a block is near one.
pub fn grid_update(grid: &mut Grid, dt: f64, ext: &GridForces) {
    let geom = grid.geom;
    let buffers = &grid.buffers;
    let is_active = &grid.is_active;
    grid.node
        .par_chunks_mut(geom.stride * BLOCK)
        .enumerate()
        .for_each(|(bi, band)| grid_band(bi, band, buffers, is_active, &geom, dt, ext));
}

multiversion! {
    /// [`grid_update`] on the active blocks of block row `bi`.
    fn grid_band(
        bi: usize,
        band: &mut [Node],
        buffers: &[ScatterBuffer],
        is_active: &[bool],
        geom: &GridGeom,
        dt: f64,
        ext: &GridForces,
    ) {
        let cells = ext.wall_cells;
        let dx = geom.dx;
        for bj in 0..geom.nb {
            let b = bi * geom.nb + bj;
            if !is_active[b] {
                continue;
            }
            let (i0, j0) = (bi * BLOCK, bj * BLOCK);
            let mut srcs: [&ScatterBuffer; CHUNKS] = [&buffers[0]; CHUNKS];
            let mut nsrc = 0;
            for s in buffers.iter().filter(|s| s.touched[b]) {
                srcs[nsrc] = s;
                nsrc += 1;
            }
            let srcs = &srcs[..nsrc];
            let lo = Vec2::new(i0 as f64, j0 as f64) * dx;
            let hi = lo + Vec2::new((BLOCK - 1) as f64, (BLOCK - 1) as f64) * dx;
            let near_obstacle = ext.obstacles.iter().any(|o| {
                let c = Vec2::from(o.center);
                let q = Vec2::new(c.x.clamp(lo.x, hi.x), c.y.clamp(lo.y, hi.y));
                (q - c).norm() < o.radius
            });
            let near_wall = ext.walls != WallMode::None
                && (i0 < cells
                    || j0 < cells
                    || i0 + BLOCK + cells > geom.n
                    || j0 + BLOCK + cells > geom.n);
            for r in 0..BLOCK {
                let i = i0 + r;
                let row = r * geom.stride + j0;
                let gidx = bi * BLOCK * geom.stride + row;
                for c in 0..BLOCK {
                    let j = j0 + c;
                    let mut acc: Node = [0.0; 4];
                    for s in srcs {
                        let n = &s.node[gidx + c];
                        for l in 0..4 {
                            acc[l] += n[l];
                        }
                    }
                    let out = &mut band[row + c];
                    if acc[M] <= 0.0 {
                        *out = [0.0; 4];
                        continue;
                    }
                    let mut v = Vec2::new(acc[X], acc[Y]) / acc[M] + ext.gravity * dt;
                    if ext.attractor.is_some() || near_obstacle {
                        let xi = Vec2::new(i as f64, j as f64) * dx;
                        if let Some((pos, strength)) = ext.attractor {
                            let d = pos - xi;
                            v += d * (dt * strength / (d.norm() + 0.01));
                        }
                        if near_obstacle {
                            for o in ext.obstacles {
                                v = obstacle_velocity(o, xi, v);
                            }
                        }
                    }
                    if near_wall {
                        v = wall_velocity(ext.walls, cells, geom.n, i, j, v);
                    }
                    *out = [v.x, v.y, acc[M], 0.0];
                }
            }
        }
    }
}

/// Velocity of a grid node after contact with a circular obstacle: no
/// inward normal velocity, Coulomb friction on the tangential part.
#[inline]
pub fn obstacle_velocity(o: &Obstacle, xi: Vec2, v: Vec2) -> Vec2 {
    let c = Vec2::from(o.center);
    let r = xi - c;
    let dist = r.norm();
    if dist >= o.radius {
        return v;
    }
    let n = if dist > 0.0 {
        r / dist
    } else {
        Vec2::new(0.0, 1.0)
    };
    let vn = v.dot(&n);
    if vn >= 0.0 {
        return v;
    }
    let vt = v - n * vn;
    let vt_norm = vt.norm();
    if vt_norm <= -o.friction * vn {
        Vec2::zeros()
    } else {
        vt * (1.0 + o.friction * vn / vt_norm)
    }
}

#[inline(always)]
fn wall_velocity(mode: WallMode, cells: usize, n: usize, i: usize, j: usize, mut v: Vec2) -> Vec2 {
    let (lo_x, hi_x) = (i < cells, i + cells >= n);
    let (lo_y, hi_y) = (j < cells, j + cells >= n);
    match mode {
        WallMode::None => v,
        WallMode::Sticky => {
            if lo_x || hi_x || lo_y || hi_y {
                Vec2::zeros()
            } else {
                v
            }
        }
        WallMode::Slip => {
            if lo_x {
                v.x = v.x.max(0.0);
            }
            if hi_x {
                v.x = v.x.min(0.0);
            }
            if lo_y {
                v.y = v.y.max(0.0);
            }
            if hi_y {
                v.y = v.y.min(0.0);
            }
            v
        }
    }
}

/// Grid velocity and APIC matrix at a stencil: `v = sum w v_i`,
/// `C = 4 / dx sum w v_i (i - fx)^T`.
#[inline(always)]
fn interpolate(grid: &Grid, st: &Stencil) -> (Vec2, Mat2) {
    let geom = &grid.geom;
    let (bi, bj) = (st.base[0] as usize, st.base[1] as usize);
    let oy = [-st.fx[1], 1.0 - st.fx[1], 2.0 - st.fx[1]];
    let mut v = Vec2::zeros();
    let (mut c00, mut c01, mut c10, mut c11) = (0.0, 0.0, 0.0, 0.0);
    for i in 0..3 {
        let start = geom.index(bi + i, bj);
        let row = &grid.node[start..start + 3];
        let (mut sx, mut sy, mut sxo, mut syo) = (0.0, 0.0, 0.0, 0.0);
        for j in 0..3 {
            let w = st.w[1][j];
            let (wx, wy) = (w * row[j][X], w * row[j][Y]);
            sx += wx;
            sy += wy;
            sxo += wx * oy[j];
            syo += wy * oy[j];
        }
        let wi = st.w[0][i];
        let ox = i as f64 - st.fx[0];
        v.x += wi * sx;
        v.y += wi * sy;
        c00 += wi * sx * ox;
        c10 += wi * sy * ox;
        c01 += wi * sxo;
        c11 += wi * syo;
    }
    let s = 4.0 * geom.inv_dx;
    (v, Mat2::new(c00 * s, c01 * s, c10 * s, c11 * s))
}

/// Keeps a particle where its stencil stays on the grid; removes outward velocity there.
#[inline(always)]
fn clamp_to_grid(x: &mut Vec2, v: &mut Vec2, lo: f64, hi: f64) {
    for a in 0..2 {
        if x[a] < lo {
            x[a] = lo;
            v[a] = v[a].max(0.0);
        } else if x[a] > hi {
            x[a] = hi;
            v[a] = v[a].min(0.0);
        }
    }
}

/// Pushes a vertex that ended inside an obstacle back to its surface and
/// removes its inward velocity.
#[inline]
fn project_out(o: &Obstacle, x: &mut Vec2, v: &mut Vec2) {
    let c = Vec2::from(o.center);
    let r = *x - c;
    let dist2 = r.norm_squared();
    if dist2 < o.radius * o.radius {
        let dist = dist2.sqrt();
        let n = if dist > 0.0 {
            r / dist
        } else {
            Vec2::new(0.0, 1.0)
        };
        *x = c + n * o.radius;
        let vn = v.dot(&n);
        if vn < 0.0 {
            *v -= n * vn;
        }
    }
}

/// Pass 3: grid-to-particle for vertices and advection `x += dt v`.
/// Returns the index of the first vertex whose state is non-finite or whose
/// speed exceeds one cell per substep (the CFL limit), if any.
pub fn gather_vertices(
    vert: &mut Vertices,
    grid: &Grid,
    dt: f64,
    obstacles: &[Obstacle],
) -> Option<usize> {
    (
        vert.x.par_chunks_mut(PAR_MIN),
        vert.v.par_chunks_mut(PAR_MIN),
        vert.c.par_chunks_mut(PAR_MIN),
        vert.stencil.par_chunks(PAR_MIN),
    )
        .into_par_iter()
        .enumerate()
        .filter_map(|(k, (x, v, c, st))| {
            gather_vertex_chunk(x, v, c, st, grid, dt, obstacles).map(|i| k * PAR_MIN + i)
        })
        .min()
}

multiversion! {
    /// [`gather_vertices`] on one chunk; returns the first bad index in it.
    fn gather_vertex_chunk(
        xs: &mut [Vec2],
        vs: &mut [Vec2],
        cs: &mut [Mat2],
        sts: &[Stencil],
        grid: &Grid,
        dt: f64,
        obstacles: &[Obstacle],
    ) -> Option<usize> {
        let geom = grid.geom;
        let (lo, hi) = (geom.dx, (geom.n as f64 - 2.0) * geom.dx);
        let mut bad = None;
        for (k, (((x, v), c), st)) in xs.iter_mut().zip(vs).zip(cs).zip(sts).enumerate() {
            let (nv, nc) = interpolate(grid, st);
            *v = nv;
            *c = nc;
            *x += nv * dt;
            for o in obstacles {
                project_out(o, x, v);
            }
            clamp_to_grid(x, v, lo, hi);
            // Finite, and no faster than one cell per substep (CFL): beyond
            // that the transfer is meaningless and the run is diverging.
            let ok = x.x.is_finite()
                && x.y.is_finite()
                && c.iter().all(|e| e.is_finite())
                && nv.norm_squared() * (dt * dt) <= geom.dx * geom.dx;
            if !ok && bad.is_none() {
                bad = Some(k);
            }
        }
        bad
    }
}

/// Pass 4: grid-to-particle for quadrature particles: velocity and `C` from
/// the grid, position and `d1` from the (already moved) vertices,
/// `d2 += dt C d2` and the return mapping (when `plastic`);
/// then, for the next step, the particle's stencil and its stress from the
/// new frame. Returns the first quadrature particle with a non-finite
/// frame, if any.
pub fn gather_quads(
    quad: &mut Quads,
    vx: &[Vec2],
    grid: &Grid,
    dt: f64,
    energy: &YarnEnergy,
    plastic: bool,
) -> Option<usize> {
    let rest = QuadRest {
        left: &quad.left,
        l0: &quad.l0,
        vol: &quad.vol,
        vx,
        dt,
        energy,
        plastic,
    };
    (
        quad.x.par_chunks_mut(PAR_MIN),
        quad.v.par_chunks_mut(PAR_MIN),
        quad.c.par_chunks_mut(PAR_MIN),
        quad.d.par_chunks_mut(PAR_MIN),
        quad.frame.par_chunks_mut(PAR_MIN),
        quad.stencil.par_chunks_mut(PAR_MIN),
        quad.t1.par_chunks_mut(PAR_MIN),
        quad.t2.par_chunks_mut(PAR_MIN),
    )
        .into_par_iter()
        .enumerate()
        .filter_map(|(k, (x, v, c, d, frame, st, t1, t2))| {
            let chunk = QuadChunk {
                x,
                v,
                c,
                d,
                frame,
                stencil: st,
                t1,
                t2,
            };
            gather_quad_chunk(k * PAR_MIN, chunk, grid, &rest).map(|i| k * PAR_MIN + i)
        })
        .min()
}

/// The per-particle arrays [`gather_quads`] writes, for one chunk.
struct QuadChunk<'a> {
    x: &'a mut [Vec2],
    v: &'a mut [Vec2],
    c: &'a mut [Mat2],
    d: &'a mut [Mat2],
    frame: &'a mut [Qr2],
    stencil: &'a mut [Stencil],
    t1: &'a mut [Vec2],
    t2: &'a mut [Vec2],
}

/// What [`gather_quads`] only reads (indexed by global particle index).
struct QuadRest<'a> {
    left: &'a [u32],
    l0: &'a [f64],
    vol: &'a [f64],
    vx: &'a [Vec2],
    dt: f64,
    energy: &'a YarnEnergy,
    plastic: bool,
}

multiversion! {
    /// [`gather_quads`] on the chunk starting at particle `base`; returns the
    /// first bad index in it.
    fn gather_quad_chunk(
        base: usize,
        q: QuadChunk,
        grid: &Grid,
        rest: &QuadRest,
    ) -> Option<usize> {
        let (dt, energy) = (rest.dt, rest.energy);
        let inv_dx = grid.geom.inv_dx;
        let mut bad = None;
        for k in 0..q.x.len() {
            let g = base + k;
            let l0 = rest.l0[g];
            let (nv, nc) = interpolate(grid, &q.stencil[k]);
            q.v[k] = nv;
            q.c[k] = nc;
            let left = rest.left[g] as usize;
            let (xl, xr) = (rest.vx[left], rest.vx[left + 1]);
            let x = (xl + xr) * 0.5;
            q.x[k] = x;
            let d1 = xr - xl;
            let d2o = q.d[k].column(1).into_owned();
            let mut d2 = d2o + nc * d2o * dt;
            let inv_l0 = 1.0 / l0;
            let mut r = qr(&(Mat2::from_columns(&[d1, d2]) * inv_l0));
            if rest.plastic {
                let (r12, r22) = energy.return_map(r.r12, r.r22);
                if r12 != r.r12 || r22 != r.r22 {
                    d2 = r.rotate(Vec2::new(r12, r22)) * l0;
                    // refactor (rather than patch r12, r22) so that `frame` is
                    // always bitwise qr(d / l0), as after a state restore
                    r = qr(&(Mat2::from_columns(&[d1, d2]) * inv_l0));
                }
            }
            let d = Mat2::from_columns(&[d1, d2]);
            q.frame[k] = r;
            q.d[k] = d;
            q.stencil[k] = Stencil::new(x, inv_dx);
            (q.t1[k], q.t2[k]) = frame_gradient_qr(energy, &r, l0, rest.vol[g]);
            let ok = d.iter().all(|e| e.is_finite()) && nv.x.is_finite() && nv.y.is_finite();
            if !ok && bad.is_none() {
                bad = Some(k);
            }
        }
        bad
    }
}

/// Whether `n` splits into the same chunks as the scatter uses (for tests).
#[doc(hidden)]
pub fn chunk_bounds(n: usize) -> Vec<std::ops::Range<usize>> {
    (0..CHUNKS).map(|k| chunk_range(n, k)).collect()
}
