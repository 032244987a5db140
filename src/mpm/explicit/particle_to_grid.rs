//! Pass 1 of a substep, particle-to-grid: mass and momentum of every particle
//! (APIC affine transfer with quadratic B-splines), with the internal forces
//! added as `dt f` to the momentum: the vertex forces of
//! [`crate::mpm::laws::vertex_forces`] at the vertices, and each quadrature particle's
//! normal force through its affine term (MLS). For the FLIP transfer the
//! impulse is also kept alone, so the grid knows its velocity before the
//! forces; near obstacles, the mass of particles touching one is marked.

use rayon::prelude::*;

use crate::math::bspline::Stencil;
use crate::math::{Mat2, Vec2};
use crate::mpm::laws::contact::CONTACT_CELLS;
use crate::mpm::laws::vertex_forces::vertex_forces;
use crate::mpm::machinery::grid::{
    Grid, GridGeom, P2gNode, ScatterBuffer, StencilBounds, CHUNKS, FX, FY, M, MC, P2G_LANES, PX, PY,
};
use crate::mpm::machinery::particles::{Particles, Quads, Vertices};
use crate::mpm::machinery::simd::{chunk_range, multiversion};
use crate::scene::Obstacle;

/// What one particle adds to the grid, as an affine function of the node
/// offset `o = (x_i - x_p) / dx`: node `i` of the stencil gets
/// `w_i (base + o.x cx + o.y cy)` in every lane of its [`P2gNode`]: mass
/// `m`, contact mass `mc`, momentum `p0 + A o` (including the impulse) and
/// the impulse `f0 + Af o` alone.
struct Splat {
    base: P2gNode,
    cx: P2gNode,
    cy: P2gNode,
}

impl Splat {
    /// From mass `m`, contact mass `mc`, momentum `p0` and affine momentum
    /// `a` (impulse included), impulse `f0` and affine impulse `af`.
    #[inline(always)]
    fn new(m: f64, mc: f64, p0: Vec2, a: Mat2, f0: Vec2, af: Mat2) -> Self {
        let mut s = Splat {
            base: [0.0; P2G_LANES],
            cx: [0.0; P2G_LANES],
            cy: [0.0; P2G_LANES],
        };
        s.base[PX] = p0.x;
        s.base[PY] = p0.y;
        s.base[M] = m;
        s.base[MC] = mc;
        s.base[FX] = f0.x;
        s.base[FY] = f0.y;
        s.cx[PX] = a[(0, 0)];
        s.cx[PY] = a[(1, 0)];
        s.cx[FX] = af[(0, 0)];
        s.cx[FY] = af[(1, 0)];
        s.cy[PX] = a[(0, 1)];
        s.cy[PY] = a[(1, 1)];
        s.cy[FX] = af[(0, 1)];
        s.cy[FY] = af[(1, 1)];
        s
    }
}

#[inline(always)]
fn splat(buf: &mut ScatterBuffer, geom: &GridGeom, st: &Stencil, s: &Splat) {
    buf.touch_stencil(geom, st.base);
    let oy = [-st.fx[1], 1.0 - st.fx[1], 2.0 - st.fx[1]];
    let (bi, bj) = (st.base[0] as usize, st.base[1] as usize);
    let rows = geom.stencil_rows_mut(&mut buf.node, bi, bj);
    for (i, row) in rows.into_iter().enumerate() {
        let ox = i as f64 - st.fx[0];
        let rb: P2gNode = std::array::from_fn(|l| s.base[l] + s.cx[l] * ox);
        let wi = st.w[0][i];
        for j in 0..3 {
            let w = wi * st.w[1][j];
            let n = &mut row[j];
            for l in 0..P2G_LANES {
                n[l] += w * (rb[l] + s.cy[l] * oy[j]);
            }
        }
    }
}

/// Mass of a particle at `x` that touches an obstacle (`m` or 0).
#[inline(always)]
fn contact_mass(obstacles: &[Obstacle], margin: f64, x: Vec2, m: f64) -> f64 {
    for o in obstacles {
        let r = o.radius + margin;
        if (x - Vec2::from(o.center)).norm_squared() <= r * r {
            return m;
        }
    }
    0.0
}

/// What every scatter chunk reads.
struct ScatterCtx<'a> {
    vert: &'a Vertices,
    quad: &'a Quads,
    geom: GridGeom,
    dt: f64,
    bending: f64,
    obstacles: &'a [Obstacle],
    /// How far outside an obstacle a particle touches it, m.
    margin: f64,
    /// Whether the internal forces are scattered.
    forces: bool,
    /// The field each vertex and quadrature particle scatters into (empty
    /// with one field).
    vert_field: &'a [u16],
    quad_field: &'a [u16],
}

/// The other fields of a scene with several as the scatter fills them:
/// the grids of fields 1, 2, ... and the field of each vertex and
/// quadrature particle (0: the scatter's own grid;
/// [`crate::mpm::laws::fields`]).
pub type FieldTargets<'a> = (&'a mut [Grid], &'a [u16], &'a [u16]);

/// Splits `v` into the scatter's chunks of `n` items.
fn split_chunks<T>(v: &mut [T], n: usize) -> Vec<&mut [T]> {
    let mut out = Vec::with_capacity(CHUNKS);
    let mut rest = v;
    for k in 0..CHUNKS {
        let (head, tail) = rest.split_at_mut(chunk_range(n, k).len());
        out.push(head);
        rest = tail;
    }
    out
}

/// Pass 1: particle-to-grid of mass, momentum and `dt` times the internal
/// force. Vertex stencils and forces are computed here, chunk by chunk;
/// quadrature stencils and stress come from the previous gather (or
/// [`crate::mpm::explicit::grid_to_particle::quad_stress`]). `flip` keeps the impulse
/// alone too (in lanes that only FLIP reads); `obstacles` are the ones
/// whose contact mass is marked.
#[cfg(feature = "testing")]
pub fn scatter(p: &mut Particles, grid: &mut Grid, dt: f64, bending: f64, obstacles: &[Obstacle]) {
    scatter_fields(p, grid, None, dt, bending, obstacles, 0.0, true)
}

/// [`scatter`] with several fields: the particles `fields` puts in field
/// `k > 0` go into its grid `k - 1` instead (same window, same chunks). `with_forces = false`: mass and
/// momentum only (no vertex, bending or normal force; the vertex forces
/// `p.vert.f` are left zero), for the implicit step, whose solve adds them.
/// `yarn_radius` (half `material.diameter`, 0 without one): a particle
/// touches an obstacle (grown by it) within [`CONTACT_CELLS`] of its
/// surface without one, only on or inside it with one.
#[allow(clippy::too_many_arguments)]
pub fn scatter_fields(
    p: &mut Particles,
    grid: &mut Grid,
    fields: Option<FieldTargets>,
    dt: f64,
    bending: f64,
    obstacles: &[Obstacle],
    yarn_radius: f64,
    with_forces: bool,
) {
    // a window that holds every stencil
    let inv_dx = grid.geom.inv_dx;
    let mut bounds = StencilBounds::default();
    bounds.add_positions(&p.vert.x, inv_dx);
    for st in &p.quad.stencil {
        bounds.add(st.base);
    }
    grid.fit_window(&bounds);
    let geom = grid.geom;
    let (others, vert_field, quad_field) = match fields {
        Some((gs, v, q)) => {
            for g in gs.iter_mut() {
                g.fit_window(&bounds);
            }
            (gs, v, q)
        }
        None => (&mut [][..], &[][..], &[][..]),
    };
    let (nv, nq) = (p.vert.x.len(), p.quad.x.len());
    // Each chunk writes the stencils and forces of its own vertex range
    // (taken out of `p.vert` meanwhile, so the rest of it can be shared).
    let mut vert_stencils = std::mem::take(&mut p.vert.stencil);
    let mut vert_forces = std::mem::take(&mut p.vert.f);
    let stencils = split_chunks(&mut vert_stencils, nv);
    let forces = split_chunks(&mut vert_forces, nv);
    let ctx = ScatterCtx {
        vert: &p.vert,
        quad: &p.quad,
        geom,
        dt,
        bending,
        obstacles,
        margin: if yarn_radius > 0.0 {
            0.0
        } else {
            CONTACT_CELLS * geom.dx
        },
        forces: with_forces,
        vert_field,
        quad_field,
    };
    // per chunk, its buffer of every field
    let mut chunk_bufs: Vec<ChunkBuffers> = (0..CHUNKS)
        .map(|_| ChunkBuffers(Vec::with_capacity(1 + others.len())))
        .collect();
    for g in std::iter::once(&mut *grid).chain(others.iter_mut()) {
        for (c, buf) in chunk_bufs.iter_mut().zip(g.buffers.iter_mut()) {
            c.0.push(buf);
        }
    }
    chunk_bufs
        .into_par_iter()
        .zip(stencils)
        .zip(forces)
        .enumerate()
        .for_each(|(k, ((bufs, sts), fs))| {
            let (vr, qr) = (chunk_range(nv, k), chunk_range(nq, k));
            scatter_chunk(bufs, sts, fs, vr, qr, &ctx)
        });
    p.vert.stencil = vert_stencils;
    p.vert.f = vert_forces;
    grid.collect_active();
    for g in others.iter_mut() {
        g.collect_active();
    }
}

/// One chunk's scatter buffers, one per field (field 0: the scatter's own
/// grid's).
struct ChunkBuffers<'a>(Vec<&'a mut ScatterBuffer>);

impl ChunkBuffers<'_> {
    /// The buffer of field `k`.
    #[inline(always)]
    fn of(&mut self, k: u16) -> &mut ScatterBuffer {
        &mut *self.0[k as usize]
    }
}

multiversion! {
    /// Scatters vertices `vr` (writing their stencils to `sts` and forces to
    /// `fs`) and quadrature particles `qr` into one chunk's buffer.
    fn scatter_chunk(
        bufs: ChunkBuffers,
        sts: &mut [Stencil],
        fs: &mut [Vec2],
        vr: std::ops::Range<usize>,
        qr: std::ops::Range<usize>,
        ctx: &ScatterCtx,
    ) {
        let (vert, quad, geom, dt) = (ctx.vert, ctx.quad, &ctx.geom, ctx.dt);
        let dx = geom.dx;
        let margin = ctx.margin;
        // the normal force per unit of (w_i (x_i - x_p) / dx . d2): -dt dE/dd2 4 / dx
        let normal_scale = -dt * 4.0 * geom.inv_dx;
        let mut bufs = bufs;
        for b in bufs.0.iter_mut() {
            b.clear();
        }
        let many = bufs.0.len() > 1;
        let (v0, q0) = (vr.start, qr.start);
        if ctx.forces {
            vertex_forces(vert, &quad.t1, ctx.bending, vr.clone(), fs);
        } else {
            fs.fill(Vec2::zeros());
        }
        let normal_scale = if ctx.forces { normal_scale } else { 0.0 };
        let (vx, vm) = (&vert.x[vr.clone()], &vert.m[vr.clone()]);
        let (vv, vc) = (&vert.v[vr.clone()], &vert.c[vr]);
        let it = sts.iter_mut().zip(fs.iter()).zip(vx).zip(vm).zip(vv).zip(vc);
        for (k, (((((st, f), &x), &m), &v), &c)) in it.enumerate() {
            *st = Stencil::new(x, geom.inv_dx);
            let f0 = f * dt;
            let mc = contact_mass(ctx.obstacles, margin, x, m);
            let a = c * (m * dx);
            let s = Splat::new(m, mc, v * m + f0, a, f0, Mat2::zeros());
            let field = if many { ctx.vert_field[v0 + k] } else { 0 };
            splat(bufs.of(field), geom, st, &s);
        }
        let (qm, qd, qt2) = (&quad.m[qr.clone()], &quad.d[qr.clone()], &quad.t2[qr.clone()]);
        let (qx, qc, qv) = (&quad.x[qr.clone()], &quad.c[qr.clone()], &quad.v[qr.clone()]);
        let it = qm.iter().zip(qd).zip(qt2).zip(qx).zip(qc).zip(qv).zip(&quad.stencil[qr]);
        for (k, ((((((&m, d), &t2), &x), &c), &v), st)) in it.enumerate() {
            let d2 = d.column(1).into_owned();
            let af = t2 * normal_scale * d2.transpose();
            let mc = contact_mass(ctx.obstacles, margin, x, m);
            let a = c * (m * dx) + af;
            let s = Splat::new(m, mc, v * m, a, Vec2::zeros(), af);
            let field = if many { ctx.quad_field[q0 + k] } else { 0 };
            splat(bufs.of(field), geom, st, &s);
        }
    }
}
