//! What the grid holds of a velocity change given to the yarn vertices
//! after the gather: the change's momentum `M dv` of each vertex, with its
//! lumped mass `M` (its own and half of each adjacent quadrature
//! particle's, the mass the axial step moves with it), scattered with the
//! substep's stencils onto the nodes of its field, divided by the mass
//! all the vertices of the field put on those nodes, and gathered back by
//! every vertex; a quadrature particle takes the mean of its two
//! vertices' shares, as it takes the mean of their changes in the step.
//! This is the PIC transfer of the change alone on the lumped yarns,
//! `u_i = sum_n w_in (sum_j w_jn M_j dv_j) / (sum_j w_jn M_j)`: among
//! vertices that all take their share it keeps the momentum exactly
//! (`sum_i M_i u_i = sum_i M_i dv_i`, so with the quadrature particles'
//! means the momentum of every particle), spreads it over every vertex
//! that shares the nodes (the other yarns' too), and drops most of the
//! part the grid cannot represent (the change from one vertex to the
//! next: a third of it is left at the one vertex per cell of the
//! reference bundle, the unit test below). A vertex that keeps its own
//! change instead (a pinned vertex, one held on an obstacle) still lends
//! its mass to the nodes: the part of the momentum that lands on it is
//! the pin's or the obstacle's, as the grid update's constraints take
//! what reaches the nodes they hold ([`Share::withheld`]; a pin's reported
//! force includes it, so that the pin's impulse balances the yarn's
//! momentum, `tests/axial_momentum.rs`). With no affine part, like PIC, it
//! does not keep the angular momentum of what it drops (four crossed
//! yarns thrown at random velocities lose 3.7e-4 of `sum m r v` over 12
//! ms, `tests/axial_momentum.rs`). The axial step of
//! `axial = "implicit"` gives its velocity change through it under FLIP,
//! where a particle keeps its own velocity from one substep to the next
//! (`crate::mpm::driver`'s `axial.rs`).
//!
//! The quadrature particles are lumped into the vertices rather than
//! scattered at their own stencils: that halves the share's splat and
//! gather (from 14 % to 6 % of the stiff bundle's samples, `perf`), and
//! the stiff reference bundle came closer to its explicit runs with it
//! (`docs/performance/cost.md`, "The axial solve by blocks and the share
//! on the vertices").

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
    /// Each vertex that kept its own change (not `free`, in vertex order)
    /// with the share it would have gathered: the momentum `M u` that
    /// landed on it is what its constraint (a pin, an obstacle) took from
    /// the others.
    pub withheld: Vec<(usize, Vec2)>,
}

/// The vertices' fields: the grid of each field (field 0 the
/// simulation's own grid; its window and the blocks its scatter touched,
/// which hold every node of the substep's stencils) and, with more than
/// one, each vertex's field.
pub struct FieldGrids<'a> {
    pub grids: Vec<&'a Grid>,
    pub vert_field: Option<&'a [u16]>,
}

impl Share {
    /// Bytes of the node buffers (one per field, the size of its grid's
    /// window; empty until the first call).
    pub fn node_memory_bytes(&self) -> usize {
        self.nodes
            .iter()
            .map(|n| n.capacity() * std::mem::size_of::<[f64; 3]>())
            .sum()
    }

    /// The grid's share of the velocity change `dv` of the vertices whose
    /// `free` is set, into [`Share::vert`]; the others keep their own
    /// change and still lend their lumped mass (`lumped`,
    /// [`Particles::lumped_masses`]) to the nodes. Each
    /// quadrature particle takes the mean of its two vertices' results,
    /// into [`Share::quad`]. One sequential pass in vertex order, so the bits do not
    /// depend on the thread count. A node where `held(i, j)` (a sticky wall's: bands
    /// at the grid's edges) gives its particles nothing: what reached it is
    /// the wall's, as the grid update holds that node.
    pub fn of(
        &mut self,
        p: &Particles,
        fields: &FieldGrids,
        dv: &[Vec2],
        lumped: &[f64],
        free: &[bool],
        held: impl Fn(usize, usize) -> bool,
    ) {
        of(p, fields, dv, lumped, free, held, self);
    }

    /// Each particle keeps its own change: a vertex its `dv`, a
    /// quadrature particle the mean of its two vertices' (a substep whose
    /// transfer drops what the grid cannot hold at the next one, APIC).
    pub fn own(&mut self, p: &Particles, dv: &[Vec2]) {
        self.withheld.clear();
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
    lumped: &[f64],
    free: &[bool],
    held: impl Fn(usize, usize) -> bool,
    out: &mut Share,
) {
    let (v, q) = (&p.vert, &p.quad);
    let (nodes, vert_u, quad_u) = (&mut out.nodes, &mut out.vert, &mut out.quad);
    let withheld = &mut out.withheld;
    nodes.resize(fields.grids.len(), Nodes::new());
    for (buf, g) in nodes.iter_mut().zip(&fields.grids) {
        if buf.len() != g.geom.storage() {
            // every node is zero between calls: only the size changes
            buf.clear();
            buf.resize(g.geom.storage(), [0.0; 3]);
        }
    }
    let field = |i: usize| fields.vert_field.map_or(0, |f| f[i] as usize);
    for i in 0..v.x.len() {
        let (f, d) = (field(i), if free[i] { dv[i] } else { Vec2::zeros() });
        splat(
            &mut nodes[f],
            &fields.grids[f].geom,
            &v.stencil[i],
            lumped[i],
            d,
        );
    }
    // each node's velocity change: its momentum over its mass, once per
    // node of the blocks the substep's scatter touched with the same
    // stencils (a division per node and not per particle and node: the
    // gather's nine divisions took a fifth of the share's time, measured)
    for (buf, g) in nodes.iter_mut().zip(&fields.grids) {
        for row in g.active_rows() {
            for n in &mut buf[row] {
                if n[2] > 0.0 {
                    n[0] /= n[2];
                    n[1] /= n[2];
                }
            }
        }
    }
    let nodes = &*nodes;
    let share = |i: usize| {
        let f = field(i);
        gather(&nodes[f], &fields.grids[f].geom, &v.stencil[i], &held)
    };
    vert_u.clear();
    vert_u.extend((0..v.x.len()).map(|i| if free[i] { share(i) } else { dv[i] }));
    withheld.clear();
    withheld.extend((0..v.x.len()).filter(|&i| !free[i]).map(|i| (i, share(i))));
    // a quadrature particle takes the mean of its two vertices' shares, as
    // it takes the mean of their changes in the step (a vertex that keeps
    // its own change gives it: half the particle's mass is in each
    // vertex's lumped mass, so the momentum is kept)
    quad_u.clear();
    quad_u.extend(q.left.iter().map(|&l| mean(vert_u, l)));
    // zero what the splats wrote, for the next call: the blocks the
    // substep's scatter touched with the same stencils
    for (buf, g) in out.nodes.iter_mut().zip(&fields.grids) {
        for row in g.active_rows() {
            buf[row].fill([0.0; 3]);
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
            // (a node with no mass holds no momentum: zero)
            if !(edge && held(bi + a, bj + b)) {
                u += Vec2::new(n[0], n[1]) * st.weight(a, b);
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
        let s = run_share(p, g, dv, free);
        (s.vert, s.quad)
    }

    fn run_share(p: &Particles, g: GridGeom, dv: &[Vec2], free: &[bool]) -> Share {
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
        };
        let mut s = Share::default();
        let mut lumped = Vec::new();
        p.lumped_masses(&mut lumped);
        s.of(p, &fields, dv, &lumped, free, |_, _| false);
        // the buffers are left zero for the next call
        assert!(s.nodes[0].iter().all(|n| *n == [0.0; 3]));
        s
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
        // the alternating x component is vertex-scale: the grid holds its
        // mean, 0.25, and at most a third of the +-0.75 about it (0.2475
        // measured, at about one vertex per cell along the yarns)
        let spread = vu.iter().map(|u| (u.x - 0.25).abs()).fold(0.0, f64::max);
        assert!(spread < 0.3, "{spread}");
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
        // (which carries half of its two quadrature particles' mass, 4 and
        // 5, and gives no change), within three cells of one of them, on
        // its yarn or the next, get less of `d`, never more; every other
        // one gets `d`
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
        // every quadrature particle takes the mean of its vertices' shares
        // (the held vertex's: its own change)
        for (k, u) in qu.iter().enumerate() {
            let l = p.quad.left[k] as usize;
            assert_eq!(*u, (vu[l] + vu[l + 1]) * 0.5, "quad {k}");
            let far_q = far(&p.quad.x[k]) && !matches!(p.quad.left[k], 4 | 5);
            assert!(!far_q || (u - d).norm() < 1e-12, "quad {k}: {u:?}");
        }
        // the momentum the free vertices lose is what lands on the held
        // vertex's lumped mass (the pin's or the obstacle's), to
        // round-off: its mass times what the grid would give it, read from
        // a run where every vertex is free and vertex 5's change is zero
        // (the same node momenta and masses)
        let mut dv0 = dv.clone();
        dv0[5] = Vec2::zeros();
        let (v0, _) = run(&p, g, &dv0, &vec![true; n]);
        let lumped5 = p.vert.m[5] + 0.5 * (p.quad.m[4] + p.quad.m[5]);
        let momentum = |vu: &[Vec2], qu: &[Vec2]| {
            let v = vu.iter().zip(&p.vert.m).map(|(u, m)| u * *m);
            let q = qu.iter().zip(&p.quad.m).map(|(u, m)| u * *m);
            v.chain(q).fold(Vec2::zeros(), |a, b| a + b)
        };
        let given: Vec<Vec2> = p.quad.left.iter().map(|&l| mean(&dv, l)).collect();
        let lost = momentum(&dv, &given) - momentum(&vu, &qu);
        let scale = momentum(&dv, &given).norm();
        assert!(
            (lost - v0[5] * lumped5).norm() <= 1e-12 * scale,
            "{lost:?} against {:?}",
            v0[5] * lumped5
        );
        // and `withheld` gives it: the held vertex with what the grid
        // would give it (the pin's force adds its momentum)
        let w = run_share(&p, g, &dv, &free).withheld;
        assert_eq!(w.len(), 1);
        assert_eq!(w[0].0, 5);
        assert!(
            (w[0].1 - v0[5]).norm() <= 1e-12 * v0[5].norm(),
            "{w:?} against {:?}",
            v0[5]
        );
        assert!(run_share(&p, g, &dv0, &vec![true; n]).withheld.is_empty());
        assert!(lost.norm() > 1e-3 * (d * lumped5).norm(), "{lost:?}");
    }
}
