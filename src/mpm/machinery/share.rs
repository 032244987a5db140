//! What the grid holds of a velocity change given to the particles
//! after the gather: the change's momentum `m dv` scattered with the
//! substep's stencils onto the nodes of each particle's field, divided by
//! the mass that every particle of the field puts on those nodes, and
//! gathered back by every particle. This is the PIC transfer of the
//! change alone, `u_p = sum_n w_pn (sum_q w_qn m_q dv_q) / (sum_q w_qn
//! m_q)`: among particles that all take their share it keeps the momentum
//! exactly (`sum_p m_p u_p = sum_p m_p dv_p`), spreads it over every
//! particle that shares the nodes (the other yarns' too), and drops the
//! part the grid cannot represent (the change from one vertex to the
//! next). A particle that keeps its own change instead (a pinned vertex,
//! one held on an obstacle) still lends its mass to the nodes: the part
//! of the momentum that lands on it is the pin's or the obstacle's, as
//! the grid update's constraints take what reaches the nodes they hold.
//! With no affine part, like PIC, it does not keep the angular momentum
//! of what it drops. The axial step of `axial =
//! "implicit"` gives its velocity change through it under FLIP, where a
//! particle keeps its own velocity from one substep to the next
//! (`crate::mpm::driver`'s `axial.rs`).

use crate::math::bspline::Stencil;
use crate::math::Vec2;
use crate::mpm::machinery::grid::{Grid, GridGeom};
use crate::mpm::machinery::particles::Particles;

/// Momentum `[x, y]` and mass per node of a field's window.
type Nodes = Vec<[f64; 3]>;

/// What the grid holds of a velocity change ([`Share::of`]): each
/// vertex's and each quadrature particle's share, and the node buffers,
/// kept between substeps (all zero between calls).
#[derive(Clone, Debug, Default)]
pub struct Share {
    nodes: Vec<Nodes>,
    /// Each vertex's share of the change.
    pub vert: Vec<Vec2>,
    /// Each quadrature particle's share of the change.
    pub quad: Vec<Vec2>,
}

/// The particles' fields: the grid of each field (field 0 the
/// simulation's own grid; its window and the blocks its scatter touched,
/// which hold every node of the substep's stencils) and, with more than
/// one, each vertex's and each quadrature particle's field.
pub struct FieldGrids<'a> {
    pub grids: Vec<&'a Grid>,
    pub vert_field: Option<&'a [u16]>,
    pub quad_field: Option<&'a [u16]>,
}

impl Share {
    /// The grid's share of the velocity change `dv` of the vertices whose
    /// `free` is set and of the quadrature particles between two of them
    /// (the mean of their two), into [`Share::vert`] and [`Share::quad`];
    /// the others keep their own change (`dv`, or the mean of the
    /// quadrature particle's two) and still lend their mass to the nodes.
    /// One sequential pass in particle order, so the bits do not depend on
    /// the thread count. A node where `held(i, j)` (a sticky wall's: bands
    /// at the grid's edges) gives its particles nothing: what reached it is
    /// the wall's, as the grid update holds that node.
    pub fn of(
        &mut self,
        p: &Particles,
        fields: &FieldGrids,
        dv: &[Vec2],
        free: &[bool],
        held: impl Fn(usize, usize) -> bool,
    ) {
        of(p, fields, dv, free, held, self);
    }

    /// Each particle keeps its own change: a vertex its `dv`, a
    /// quadrature particle the mean of its two vertices' (a substep whose
    /// transfer drops what the grid cannot hold at the next one, APIC).
    pub fn own(&mut self, p: &Particles, dv: &[Vec2]) {
        self.vert.clear();
        self.vert.extend_from_slice(dv);
        self.quad.clear();
        self.quad.extend(p.quad.left.iter().map(|&l| mean(dv, l)));
    }
}

/// The mean change of the two vertices of the quadrature particle whose
/// left vertex is `l`.
#[inline(always)]
fn mean(dv: &[Vec2], l: u32) -> Vec2 {
    let l = l as usize;
    (dv[l] + dv[l + 1]) * 0.5
}

/// [`Share::of`] (a free function: the node buffers and the outputs are
/// borrowed apart).
fn of(
    p: &Particles,
    fields: &FieldGrids,
    dv: &[Vec2],
    free: &[bool],
    held: impl Fn(usize, usize) -> bool,
    out: &mut Share,
) {
    let (v, q) = (&p.vert, &p.quad);
    let (nodes, vert_u, quad_u) = (&mut out.nodes, &mut out.vert, &mut out.quad);
    nodes.resize(fields.grids.len(), Nodes::new());
    for (buf, g) in nodes.iter_mut().zip(&fields.grids) {
        if buf.len() != g.geom.storage() {
            // every node is zero between calls: only the size changes
            buf.clear();
            buf.resize(g.geom.storage(), [0.0; 3]);
        }
    }
    let field = |f: Option<&[u16]>, i: usize| f.map_or(0, |f| f[i] as usize);
    // every particle, vertices first: its field, stencil and mass, whether
    // it takes a share, and its own change
    let verts = (0..v.x.len()).map(|i| {
        let f = field(fields.vert_field, i);
        (f, &v.stencil[i], v.m[i], free[i], dv[i])
    });
    let quads = (0..q.x.len()).map(|k| {
        let (f, l) = (field(fields.quad_field, k), q.left[k] as usize);
        let shared = free[l] && free[l + 1];
        (f, &q.stencil[k], q.m[k], shared, mean(dv, q.left[k]))
    });
    for (f, st, m, shared, d) in verts.clone().chain(quads.clone()) {
        let d = if shared { d } else { Vec2::zeros() };
        splat(&mut nodes[f], &fields.grids[f].geom, st, m, d);
    }
    let nodes = &*nodes;
    let share_of = |(f, st, _, shared, d): (usize, &Stencil, f64, bool, Vec2)| {
        if shared {
            gather(&nodes[f], &fields.grids[f].geom, st, &held)
        } else {
            d
        }
    };
    vert_u.clear();
    vert_u.extend(verts.map(share_of));
    quad_u.clear();
    quad_u.extend(quads.map(share_of));
    // zero what the splats wrote, for the next call: the blocks the
    // substep's scatter touched with the same stencils
    for (buf, g) in out.nodes.iter_mut().zip(&fields.grids) {
        for &b in &g.active {
            for k in g.geom.block_nodes(b as usize) {
                buf[k] = [0.0; 3];
            }
        }
    }
}

/// Adds a particle of mass `m` and velocity change `d` to the nodes.
#[inline(always)]
fn splat(nodes: &mut [[f64; 3]], g: &GridGeom, st: &Stencil, m: f64, d: Vec2) {
    // a particle's stencil lies inside the window its scatter fitted, at
    // nodes >= 0
    let (bi, bj) = (st.base[0] as usize, st.base[1] as usize);
    for (a, row) in g.stencil_rows_mut(nodes, bi, bj).into_iter().enumerate() {
        for (b, n) in row.iter_mut().enumerate() {
            let w = st.weight(a, b) * m;
            n[0] += w * d.x;
            n[1] += w * d.y;
            n[2] += w;
        }
    }
}

/// The velocity change the nodes hold, interpolated at the particle
/// (none from a node `held`; `held` marks bands at the grid's edges, so a
/// stencil reaches a held node exactly when one of its corners `(bi, bj)`,
/// `(bi + 2, bj + 2)` is held, and a stencil away from them skips the
/// node by node test, which took about 2 % of the stiff bundle's samples,
/// `perf`; same bits).
#[inline(always)]
fn gather(
    nodes: &[[f64; 3]],
    g: &GridGeom,
    st: &Stencil,
    held: &impl Fn(usize, usize) -> bool,
) -> Vec2 {
    let (bi, bj) = (st.base[0] as usize, st.base[1] as usize);
    let edge = held(bi, bj) || held(bi + 2, bj + 2);
    let mut u = Vec2::zeros();
    for (a, row) in g.stencil_rows(nodes, bi, bj).into_iter().enumerate() {
        for (b, n) in row.iter().enumerate() {
            let w = st.weight(a, b);
            // (the particle's own mass is on a node of weight w > 0)
            if w > 0.0 && n[2] > 0.0 && !(edge && held(bi + a, bj + b)) {
                u += Vec2::new(n[0], n[1]) * (w / n[2]);
            }
        }
    }
    u
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mpm::laws::bending::rest_of_curve;
    use crate::scene::builtin::yarn_reference;

    /// The reference bundle's particles (12 yarns side by side, sharing
    /// nodes), their stencils set, on its 256^2 grid.
    fn bundle() -> (Particles, GridGeom) {
        let scene = yarn_reference();
        let mut p = Particles::from_scene(&scene, rest_of_curve);
        let g = GridGeom::new(scene.grid.resolution as usize, scene.grid.size);
        for (s, x) in p.vert.stencil.iter_mut().zip(&p.vert.x) {
            *s = Stencil::new(*x, g.inv_dx);
        }
        for (s, x) in p.quad.stencil.iter_mut().zip(&p.quad.x) {
            *s = Stencil::new(*x, g.inv_dx);
        }
        (p, g)
    }

    fn run(p: &Particles, g: GridGeom, dv: &[Vec2], free: &[bool]) -> (Vec<Vec2>, Vec<Vec2>) {
        // a window over the whole domain, with the blocks the particles'
        // stencils touch marked active, as the scatter marks them
        let mut grid = Grid::new(g);
        grid.geom = g;
        let stencils = p.vert.stencil.iter().chain(&p.quad.stencil);
        let mut touched = vec![false; g.blocks()];
        for st in stencils {
            for (a, b) in [(0, 0), (0, 2), (2, 0), (2, 2)] {
                let (i, j) = (st.base[0] as usize + a, st.base[1] as usize + b);
                touched[g.block_of(i, j)] = true;
            }
        }
        grid.active = (0..g.blocks() as u32)
            .filter(|&b| touched[b as usize])
            .collect();
        assert!(grid.active.len() < g.blocks() / 4);
        let fields = FieldGrids {
            grids: vec![&grid],
            vert_field: None,
            quad_field: None,
        };
        let mut s = Share::default();
        s.of(p, &fields, dv, free, |_, _| false);
        // the buffers are left zero for the next call
        assert!(s.nodes[0].iter().all(|n| *n == [0.0; 3]));
        (s.vert, s.quad)
    }

    /// Momentum kept (to round-off, 1e-12 of `sum m |dv|`) for a change
    /// that varies from vertex to vertex; the vertex-scale part is what
    /// the grid drops, so the shared change is smoother than `dv`.
    #[test]
    fn keeps_the_momentum_and_drops_the_vertex_scale() {
        let (p, g) = bundle();
        let n = p.vert.x.len();
        let dv: Vec<Vec2> = (0..n)
            .map(|i| Vec2::new(if i % 2 == 0 { 1.0 } else { -0.5 }, 0.3 * (i as f64).sin()))
            .collect();
        let (vu, qu) = run(&p, g, &dv, &vec![true; n]);
        let mean = |i: usize| (dv[i] + dv[i + 1]) * 0.5;
        let (mut given, mut kept, mut scale) = (Vec2::zeros(), Vec2::zeros(), 0.0);
        for i in 0..n {
            given += dv[i] * p.vert.m[i];
            kept += vu[i] * p.vert.m[i];
            scale += dv[i].norm() * p.vert.m[i];
        }
        for ((&l, &m), u) in p.quad.left.iter().zip(&p.quad.m).zip(&qu) {
            given += mean(l as usize) * m;
            kept += u * m;
        }
        assert!((given - kept).norm() <= 1e-12 * scale, "{given:?} {kept:?}");
        // the alternating x component is mostly vertex-scale: the grid
        // holds its mean, 0.25, and little of the +-0.75 about it
        let spread = vu.iter().map(|u| (u.x - 0.25).abs()).fold(0.0, f64::max);
        assert!(spread < 0.2, "{spread}");
    }

    /// A change the same for every particle is held whole (the weights
    /// sum to one), and a vertex that is not free keeps its own.
    #[test]
    fn a_uniform_change_is_held_whole() {
        let (p, g) = bundle();
        let n = p.vert.x.len();
        let d = Vec2::new(0.7, -1.3);
        let mut free = vec![true; n];
        free[5] = false;
        let mut dv = vec![d; n];
        dv[5] = Vec2::new(9.0, 9.0);
        let (vu, qu) = run(&p, g, &dv, &free);
        assert_eq!(vu[5], dv[5]);
        // the particles whose stencils share nodes with those of vertex 5
        // and of its two quadrature particles (4 and 5, which give no
        // change either), within three cells of one of them, on its yarn
        // or the next, get less of `d`, never more; every other one gets `d`
        let zero = [p.vert.x[5], p.quad.x[4], p.quad.x[5]];
        let far = |x: &Vec2| zero.iter().all(|z| (x - z).amax() >= 3.0 * g.dx);
        let mut less = 0;
        for (i, u) in vu.iter().enumerate().filter(|&(i, _)| i != 5) {
            assert!(!far(&p.vert.x[i]) || (u - d).norm() < 1e-12, "{i}: {u:?}");
            assert!(u.norm() <= d.norm() * (1.0 + 1e-12), "{i}: {u:?}");
            less += usize::from(u.norm() < d.norm() * (1.0 - 1e-3));
        }
        // the held vertex's mass takes its part: its neighbours get less
        assert!(less >= 4, "{less}");
        // its quadrature particles keep the mean of their vertices' changes
        for k in [4, 5] {
            assert_eq!(qu[k], (dv[k] + dv[k + 1]) * 0.5, "quad {k}");
        }
        for (k, u) in qu.iter().enumerate() {
            let far_q = far(&p.quad.x[k]) && !matches!(p.quad.left[k], 4 | 5);
            assert!(!far_q || (u - d).norm() < 1e-12, "quad {k}: {u:?}");
        }
    }
}
