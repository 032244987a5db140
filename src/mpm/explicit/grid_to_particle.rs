//! Passes 3 and 4 of a substep, grid-to-particle: the vertices take their
//! velocity from the grid by the scene's [`Transfer`] scheme and move with
//! the grid velocity; then the quadrature particles follow their vertices,
//! update their cross-section direction with the grid's velocity gradient,
//! return-map, and compute the stress for the next substep.
//! [`quad_stress`] computes that stress when the state was set from outside.

use rayon::prelude::*;

use crate::math::bspline::Stencil;
use crate::math::qr::Qr2;
use crate::math::{cross, Mat2, Vec2};
use crate::mpm::laws::constitutive::frames::{update_frames, Frames};
use crate::mpm::laws::constitutive::{frame_gradient_qr, YarnEnergy};
use crate::mpm::laws::contact::{grid_bounds, keep_in_domain};
use crate::mpm::machinery::grid::GridGeom;
use crate::mpm::machinery::grid::{Grid, DVX, DVY, VX, VY};
use crate::mpm::machinery::particles::Quads;
use crate::mpm::machinery::simd::{kernels, multiversion, Kernels, PAR_MIN};
use crate::mpm::machinery::transfer::{blend, Transfer};
use crate::scene::Obstacle;

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

/// Grid velocity and affine matrix at a stencil, `v = sum w v_i`,
/// `C = 4 / dx sum w v_i (i - fx)^T`, and with `DELTA` the same of the
/// grid's velocity change (zero otherwise).
#[inline(always)]
fn interpolate<const DELTA: bool>(
    grid: &Grid,
    st: &Stencil,
    avx: bool,
) -> (Vec2, Mat2, Vec2, Mat2) {
    let s = 4.0 * grid.geom.inv_dx;
    if DELTA {
        // lanes: v.x, v.y, dv.x, dv.y
        let [s0, sx, sy] = weighted_sums4(grid, st, avx);
        let v = Vec2::new(s0[VX], s0[VY]);
        let c = Mat2::new(sx[VX] * s, sy[VX] * s, sx[VY] * s, sy[VY] * s);
        let dv = Vec2::new(s0[DVX], s0[DVY]);
        let dc = Mat2::new(sx[DVX] * s, sy[DVX] * s, sx[DVY] * s, sy[DVY] * s);
        (v, c, dv, dc)
    } else {
        let [s0, sx, sy] = weighted_sums::<2>(grid, st);
        let v = Vec2::new(s0[VX], s0[VY]);
        let c = Mat2::new(sx[VX] * s, sy[VX] * s, sx[VY] * s, sy[VY] * s);
        (v, c, Vec2::zeros(), Mat2::zeros())
    }
}

/// The first `N` lanes of the grid nodes at a stencil, summed with the
/// weights `w` (`s0`), with `w` times the x offset (`sx`) and with `w`
/// times the y offset (`sy`), in node units. Written lane-wise over whole
/// `[f64; N]` rows so that each node is one vector load and a few vector
/// operations; the per-lane arithmetic (and so every bit) is that of one
/// lane at a time.
#[inline(always)]
fn weighted_sums<const N: usize>(grid: &Grid, st: &Stencil) -> [[f64; N]; 3] {
    let geom = &grid.geom;
    let (bi, bj) = (st.base[0] as usize, st.base[1] as usize);
    let oy = [-st.fx[1], 1.0 - st.fx[1], 2.0 - st.fx[1]];
    let mut s0 = [0.0; N];
    let mut sx = [0.0; N];
    let mut sy = [0.0; N];
    let rows = geom.stencil_rows(&grid.node, bi, bj);
    for (i, row) in rows.iter().enumerate() {
        let mut r0 = [0.0; N];
        let mut ry = [0.0; N];
        for j in 0..3 {
            let (w, oyj) = (st.w[1][j], oy[j]);
            for l in 0..N {
                let wl = w * row[j][l];
                r0[l] += wl;
                ry[l] += wl * oyj;
            }
        }
        let wi = st.w[0][i];
        let ox = i as f64 - st.fx[0];
        for l in 0..N {
            let a = wi * r0[l];
            s0[l] += a;
            sx[l] += a * ox;
            sy[l] += wi * ry[l];
        }
    }
    [s0, sx, sy]
}

/// [`weighted_sums`] of all four lanes; with `avx` (the CPU has AVX2, see
/// [`crate::mpm::machinery::simd::kernels`]) in 256-bit registers, one node per load.
#[inline(always)]
fn weighted_sums4(grid: &Grid, st: &Stencil, avx: bool) -> [[f64; 4]; 3] {
    #[cfg(target_arch = "x86_64")]
    if avx {
        // SAFETY: `avx` is set only when the CPU has AVX2.
        return unsafe { weighted_sums4_avx(grid, st) };
    }
    let _ = avx;
    weighted_sums::<4>(grid, st)
}

/// [`weighted_sums`]`::<4>` in AVX registers: the same multiplications and
/// additions in the same order (no FMA), so the same bits.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
#[inline]
unsafe fn weighted_sums4_avx(grid: &Grid, st: &Stencil) -> [[f64; 4]; 3] {
    use std::arch::x86_64::*;
    let geom = &grid.geom;
    let (bi, bj) = (st.base[0] as usize, st.base[1] as usize);
    let oy = [-st.fx[1], 1.0 - st.fx[1], 2.0 - st.fx[1]];
    let mut s0 = _mm256_setzero_pd();
    let mut sx = _mm256_setzero_pd();
    let mut sy = _mm256_setzero_pd();
    let rows = geom.stencil_rows(&grid.node, bi, bj);
    for (i, row) in rows.iter().enumerate() {
        let mut r0 = _mm256_setzero_pd();
        let mut ry = _mm256_setzero_pd();
        for j in 0..3 {
            // SAFETY: `row[j]` is four f64 in bounds
            let n = unsafe { _mm256_loadu_pd(row[j].as_ptr()) };
            let wl = _mm256_mul_pd(_mm256_set1_pd(st.w[1][j]), n);
            r0 = _mm256_add_pd(r0, wl);
            ry = _mm256_add_pd(ry, _mm256_mul_pd(wl, _mm256_set1_pd(oy[j])));
        }
        let wi = _mm256_set1_pd(st.w[0][i]);
        let a = _mm256_mul_pd(wi, r0);
        s0 = _mm256_add_pd(s0, a);
        sx = _mm256_add_pd(sx, _mm256_mul_pd(a, _mm256_set1_pd(i as f64 - st.fx[0])));
        sy = _mm256_add_pd(sy, _mm256_mul_pd(wi, ry));
    }
    let mut out = [[0.0; 4]; 3];
    // SAFETY: each row of `out` is four f64
    unsafe {
        _mm256_storeu_pd(out[0].as_mut_ptr(), s0);
        _mm256_storeu_pd(out[1].as_mut_ptr(), sx);
        _mm256_storeu_pd(out[2].as_mut_ptr(), sy);
    }
    out
}

/// New `(v, C)` of a particle by the transfer scheme, and the grid velocity
/// at it (which moves it).
#[inline(always)]
fn transfer<const FLIP: bool>(
    grid: &Grid,
    st: &Stencil,
    ratio: f64,
    avx: bool,
    v: &mut Vec2,
    c: &mut Mat2,
) -> (Vec2, Mat2) {
    let (vn, cn, dv, dc) = interpolate::<FLIP>(grid, st, avx);
    if FLIP {
        blend(ratio, v, c, vn, cn, dv, dc);
    } else {
        *v = vn;
        *c = cn;
    }
    (vn, cn)
}

/// The other fields of a scene with several: the grids of fields 1, 2,
/// ... and the field of each particle (0: the gather's own grid;
/// [`crate::mpm::laws::fields`]).
pub type FieldSources<'a> = (&'a [Grid], &'a [u16]);

/// The grid particle `i` gathers from: its field's.
#[inline(always)]
fn field_of<'a>(grid: &'a Grid, fields: Option<FieldSources<'a>>, i: usize) -> &'a Grid {
    match fields {
        Some((gs, f)) if f[i] > 0 => &gs[f[i] as usize - 1],
        _ => grid,
    }
}

/// What the vertex gather reads.
pub struct VertexGather<'a> {
    pub grid: &'a Grid,
    /// With several fields: the other fields' grids and each vertex's
    /// field (field 0's vertices gather from `grid`).
    pub fields: Option<FieldSources<'a>>,
    pub dt: f64,
    pub obstacles: &'a [Obstacle],
    pub transfer: Transfer,
}

/// A vertex that failed the gather's checks, with the velocity that failed them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BadVertex {
    pub index: usize,
    /// Grid velocity at the vertex (what moved it).
    pub grid_velocity: Vec2,
}

/// Pass 3: grid-to-particle for vertices and advection `x += dt v_grid`.
/// Returns the first vertex whose state is non-finite or whose grid
/// velocity exceeds one cell per substep (the CFL limit), if any.
pub fn gather_vertices(
    vert: &mut crate::mpm::machinery::particles::Vertices,
    g: &VertexGather,
) -> Option<BadVertex> {
    (
        vert.x.par_chunks_mut(PAR_MIN),
        vert.v.par_chunks_mut(PAR_MIN),
        vert.c.par_chunks_mut(PAR_MIN),
        vert.stencil.par_chunks(PAR_MIN),
        vert.spin.par_chunks_mut(PAR_MIN),
    )
        .into_par_iter()
        .enumerate()
        .filter_map(|(k, (x, v, c, st, sp))| {
            let base = k * PAR_MIN;
            let bad = if g.transfer.needs_delta() {
                gather_vertex_chunk::<true>(base, x, v, c, st, sp, g)
            } else {
                gather_vertex_chunk::<false>(base, x, v, c, st, sp, g)
            };
            bad.map(|b| BadVertex {
                index: k * PAR_MIN + b.index,
                ..b
            })
        })
        .min_by_key(|b| b.index)
}

multiversion! {
    /// [`gather_vertices`] on one chunk; returns the first bad vertex in it
    /// (index within the chunk); `base` is the chunk's first vertex.
    fn gather_vertex_chunk<const FLIP: bool>(
        base: usize,
        xs: &mut [Vec2],
        vs: &mut [Vec2],
        cs: &mut [Mat2],
        sts: &[Stencil],
        spins: &mut [f64],
        g: &VertexGather,
    ) -> Option<BadVertex> {
        let geom = g.grid.geom;
        let (dt, ratio) = (g.dt, g.transfer.flip_ratio());
        let avx = kernels() >= Kernels::Avx2;
        let bounds = grid_bounds(geom.dx, geom.n);
        let mut bad = None;
        let it = xs.iter_mut().zip(vs).zip(cs).zip(sts).zip(spins);
        for (k, ((((x, v), c), st), spin)) in it.enumerate() {
            let grid = field_of(g.grid, g.fields, base + k);
            let (nv, _) = transfer::<FLIP>(grid, st, ratio, avx, v, c);
            *x += nv * dt;
            if FLIP {
                // the moment this move gives the particle's momentum (zero
                // for APIC, which moves with its own velocity)
                *spin = dt * cross(nv, *v);
            }
            keep_in_domain(g.obstacles, bounds, x, v);
            // Finite, and no faster than one cell per substep (CFL): beyond
            // that the transfer is meaningless and the run is diverging.
            let ok = x.x.is_finite()
                && x.y.is_finite()
                && v.x.is_finite()
                && v.y.is_finite()
                && c.iter().all(|e| e.is_finite())
                && nv.norm_squared() * (dt * dt) <= geom.dx * geom.dx;
            if !ok && bad.is_none() {
                bad = Some(BadVertex {
                    index: k,
                    grid_velocity: nv,
                });
            }
        }
        bad
    }
}

/// Pass 4: grid-to-particle for quadrature particles: velocity and `C` by
/// the transfer scheme, position and `d1` from the (already moved)
/// vertices, `d2 += dt grad(v_grid) d2` and the return mapping (when
/// `plastic`); then, for the next step, the particle's stencil and its
/// stress from the new frame. Returns the first quadrature particle with a
/// non-finite frame or velocity, if any. With `fields`, each particle
/// gathers from its field's grid.
#[allow(clippy::too_many_arguments)]
pub fn gather_quads(
    quad: &mut Quads,
    vx: &[Vec2],
    grid: &Grid,
    fields: Option<FieldSources>,
    dt: f64,
    energy: &YarnEnergy,
    plastic: bool,
    transfer: Transfer,
) -> Option<usize> {
    let rest = QuadRest {
        left: &quad.left,
        l0: &quad.l0,
        vol: &quad.vol,
        vx,
        dt,
        energy,
        plastic,
        ratio: transfer.flip_ratio(),
        fields,
    };
    let flip = transfer.needs_delta();
    (
        quad.x.par_chunks_mut(PAR_MIN),
        quad.v.par_chunks_mut(PAR_MIN),
        quad.c.par_chunks_mut(PAR_MIN),
        quad.d.par_chunks_mut(PAR_MIN),
        quad.frame.par_chunks_mut(PAR_MIN),
        quad.stencil.par_chunks_mut(PAR_MIN),
        quad.t1.par_chunks_mut(PAR_MIN),
        quad.t2.par_chunks_mut(PAR_MIN),
        quad.spin.par_chunks_mut(PAR_MIN),
    )
        .into_par_iter()
        .enumerate()
        .filter_map(|(k, (x, v, c, d, frame, st, t1, t2, spin))| {
            let chunk = QuadChunk {
                x,
                v,
                c,
                d,
                frame,
                stencil: st,
                t1,
                t2,
                spin,
            };
            let bad = if flip {
                gather_quad_chunk::<true>(k * PAR_MIN, chunk, grid, &rest)
            } else {
                gather_quad_chunk::<false>(k * PAR_MIN, chunk, grid, &rest)
            };
            bad.map(|i| k * PAR_MIN + i)
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
    spin: &'a mut [f64],
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
    ratio: f64,
    fields: Option<FieldSources<'a>>,
}

multiversion! {
    /// [`gather_quads`] on the chunk starting at particle `base`; returns the
    /// first bad index in it.
    fn gather_quad_chunk<const FLIP: bool>(
        base: usize,
        q: QuadChunk,
        grid: &Grid,
        rest: &QuadRest,
    ) -> Option<usize> {
        let (dt, energy) = (rest.dt, rest.energy);
        let inv_dx = grid.geom.inv_dx;
        let avx = kernels() >= Kernels::Avx2;
        let n = q.x.len();
        // the grid's part, one particle at a time: velocity and C by the
        // transfer, position and d1 from the vertices, d2 advected
        for k in 0..n {
            let g = base + k;
            let field = field_of(grid, rest.fields, g);
            let (_, nc) = transfer::<FLIP>(field, &q.stencil[k], rest.ratio, avx, &mut q.v[k], &mut q.c[k]);
            let left = rest.left[g] as usize;
            let (xl, xr) = (rest.vx[left], rest.vx[left + 1]);
            let x = (xl + xr) * 0.5;
            if FLIP {
                q.spin[k] = cross(x - q.x[k], q.v[k]);
            }
            q.x[k] = x;
            let d2o = q.d[k].column(1).into_owned();
            q.d[k] = Mat2::from_columns(&[xr - xl, d2o + nc * d2o * dt]);
        }
        // the particle's own part over the chunk: QR, return mapping and
        // stress (`frame` stays bitwise qr(d / l0), as after a state restore)
        let frames = Frames {
            l0: &rest.l0[base..base + n],
            vol: &rest.vol[base..base + n],
            d: q.d,
            frame: q.frame,
            t1: q.t1,
            t2: q.t2,
        };
        update_frames(energy, rest.plastic, frames);
        let mut bad = None;
        for k in 0..n {
            q.stencil[k] = Stencil::new(q.x[k], inv_dx);
            let (d, v) = (q.d[k], q.v[k]);
            let ok = d.iter().all(|e| e.is_finite()) && v.x.is_finite() && v.y.is_finite();
            if !ok && bad.is_none() {
                bad = Some(k);
            }
        }
        bad
    }
}
