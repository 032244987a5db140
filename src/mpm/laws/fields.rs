//! Velocity fields for yarn-on-yarn contact: the yarns held by a pin
//! scatter into one field (the *held* field) and the others (the *free*
//! yarns) into fields of their own, each gets the grid update, the pin
//! constraint acts on the held field only, and where two or more fields
//! have mass a Coulomb contact lets them slide past each other
//! (multi-velocity-field MPM contact: Bardenhagen, Brackbill, Sulsky 2000,
//! "The material-point method for granular materials", CMAME 187;
//! Bardenhagen et al. 2001, "An improved contact algorithm for the
//! material point method"; Nairn 2013; Homel and Herbold 2017 for many
//! bodies).
//!
//! The partition ([`Partition`], the scene's `[contact] fields`):
//! `PerYarn` gives every free yarn a field of its own (free yarns beyond
//! [`FREE_FIELDS_MAX`] share them, yarn `k` in field `k mod`
//! [`FREE_FIELDS_MAX`], so that neighbouring yarns of a bundle still differ);
//! `HeldFree` puts all free yarns in one field, where they interact only
//! through the shared grid velocity and the return mapping, which is not
//! Coulomb's law between yarns. Held yarns always share one field: the pin
//! constraint ([`crate::mpm::laws::pins::constrain_grid`]) sets grid node
//! velocities, so in a field shared with free yarns it would hold them
//! too. Field 0 is the simulation's own grid; the free yarns' fields come
//! first (in yarn order), the held field last, so a scene with one free
//! and one held yarn has the same two fields under both partitions.
//!
//! The contact of two fields `f`, `h` at a node with masses `m_f`, `m_h`
//! and velocities `v_f`, `v_h` after the grid update and the pin
//! constraint (central differences of the node masses for the gradients):
//! with the held field `h`, the normal `n` from `h` to `f` is along `h`'s
//! mass gradient, oriented by the difference of the two fields' gradients
//! ([`contact_normal`]); between two free fields (`h` the lower index) it
//! is the difference of the gradients itself ([`symmetric_normal`]; along
//! either yarn's own gradient, a free yarn resting on another at 1.9 cells
//! stuck there and slid at a third of the Coulomb rate, measured with
//! `tests/yarn_on_yarn.rs`). If the fields approach, `u = v_f -
//! v_h` with `u . n < 0`, the relative velocity becomes `u' = coulomb(u, n,
//! mu)` ([`crate::mpm::laws::contact::coulomb`]: no approach, tangential
//! part reduced by `mu` times the normal change, or stopped), shared about
//! the pair's centre of mass: `v_f' = v_cm + m_h / (m_f + m_h) u'`, `v_h' =
//! v_cm - m_f / (m_f + m_h) u'` (momentum conserved, the same Coulomb form
//! in impulse terms as the obstacle law). Where three or more fields meet,
//! the pairs are taken in order of field index, each from the velocities
//! the pairs before it left (a Gauss-Seidel sweep over the pairs: each
//! pair conserves momentum exactly, so the sweep does; the velocities it
//! leaves do not approach pairwise along the normals of the pairs taken
//! last). At nodes of a pinned vertex's stencil the held field is
//! kinematic (`v_h' = v_h`, as for infinite mass), so the contact leaves
//! the pin constraint satisfied; the impulse it delivers there is added to
//! that pin's reaction. `mu` is `material.friction` (the derivation in
//! `docs/obstacle-contact.md`).
//!
//! With a yarn diameter `d` (`material.diameter`) a pair is in contact at
//! a node only where the two yarns' centre lines there are less than `d`
//! apart: each field's position at the node is the mass-weighted mean of
//! its particles' positions over the node's kernel (`sum_p w_ip m_p x_p /
//! sum_p w_ip m_p`, [`Fields::locate`]) and the separation is the
//! difference of the two along the contact normal (the position-based
//! contact detection of Lemiale et al. 2010 and Nairn 2013, "Modeling
//! imperfect interfaces in the material point method using multimaterial
//! methods", CMES 92, with the yarns' centre lines for the particles and
//! `d` for the sum of their half-widths). For straight parallel yarns the
//! estimate is their centre lines' distance exactly. Two fields share a
//! node only within the kernel support (3 cells), and a yarn pressed onto
//! another is held only where enough of its stencil shares nodes with the
//! other's: the scene refuses `d` above
//! [`crate::scene::MAX_DIAMETER_CELLS`] cells. Without a diameter, contact
//! acts wherever both fields have mass (a yarn dropped on another rests
//! about two cells above it, whatever the grid). Nodes are visited in the order of the
//! window's blocks, one at a time: the same bits for any thread count.

use crate::math::Vec2;
use crate::mpm::laws::contact::coulomb;
use crate::mpm::laws::pins::{self, PinEntry};
use crate::mpm::machinery::grid::{Grid, GridGeom, BLOCK, CHUNKS, DVX, DVY, VX, VY};
use crate::mpm::machinery::particles::Particles;
use crate::mpm::machinery::simd::chunk_range;

/// How yarns are partitioned into velocity fields (the scene's `[contact]
/// fields`, see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Partition {
    /// Held yarns in one field, all free yarns in another.
    HeldFree,
    /// Held yarns in one field, each free yarn in one of its own.
    PerYarn,
}

/// Most fields the free yarns get under [`Partition::PerYarn`]: each
/// field stores the grid window (a node, 32 bytes, and a scatter buffer of
/// 48 bytes for each scatter chunk that holds some of its particles, per
/// node), so a bundle of many yarns shares them.
pub const FREE_FIELDS_MAX: usize = 32;

/// One field's node masses on the window `geom` (zero off the blocks
/// `written`), and per window block the nodes where it has mass (bit
/// `8 r + c` for the node of row `r`, column `c` of the block).
#[derive(Clone, Debug, Default)]
struct NodeMasses {
    m: Vec<f64>,
    mask: Vec<u64>,
    /// With a diameter, per node `[sum w m, sum w m x, sum w m y]` of the
    /// field's particles ([`Fields::locate`]); empty otherwise.
    centre: Vec<[f64; 3]>,
    geom: Option<GridGeom>,
    written: Vec<u32>,
}

/// The velocity fields of a scene with more than one, and the scratch of
/// their contact.
#[derive(Clone, Debug)]
pub struct Fields {
    /// The grids of fields 1, 2, ... (field 0 is the simulation's own grid).
    pub grids: Vec<Grid>,
    /// The field of each vertex.
    pub vert_field: Vec<u16>,
    /// The field of each quadrature particle.
    pub quad_field: Vec<u16>,
    /// The held yarns' field, if any yarn is held.
    pub held: Option<u16>,
    /// Node masses of each field this substep (window storage), written by
    /// the grid update ([`Fields::grids_with_masses`]).
    masses: Vec<NodeMasses>,
    /// The yarn diameter (`material.diameter`), if given: contact only
    /// where the centre lines are closer than it.
    diameter: Option<f64>,
    /// Per node, 1 + the pin whose vertex's stencil holds it, or 0 (zero
    /// between contacts, on the window `pinned_geom`).
    pinned_node: Vec<u32>,
    pinned_geom: Option<GridGeom>,
    /// Per window block, how many fields touched it.
    block_fields: Vec<u16>,
}

impl Fields {
    /// The fields of `partition` (`held_yarn[y]`: yarn `y` has a pinned
    /// vertex); `None` where that is one field (the single-grid code
    /// path). `yarn_vertices` and `quad_left` are the particles' yarn
    /// ranges and quadrature particles' left vertices.
    pub fn of_yarns(
        partition: Partition,
        held_yarn: &[bool],
        yarn_vertices: &[usize],
        quad_left: &[u32],
        grid: &mut Grid,
        diameter: Option<f64>,
    ) -> Option<Self> {
        let n_free = held_yarn.iter().filter(|&&h| !h).count();
        let free_fields = match partition {
            Partition::HeldFree => n_free.min(1),
            Partition::PerYarn => n_free.min(FREE_FIELDS_MAX),
        };
        let held = held_yarn.iter().any(|&h| h).then_some(free_fields as u16);
        let n = free_fields + held.is_some() as usize;
        if n < 2 {
            return None;
        }
        let mut vert_field = vec![0u16; *yarn_vertices.last().unwrap_or(&0)];
        let mut free = 0;
        for (y, &h) in held_yarn.iter().enumerate() {
            let f = if h {
                free_fields
            } else {
                free += 1;
                (free - 1) % free_fields
            };
            vert_field[yarn_vertices[y]..yarn_vertices[y + 1]].fill(f as u16);
        }
        let quad_field: Vec<u16> = quad_left.iter().map(|&l| vert_field[l as usize]).collect();
        // the scatter chunks each field's particles fall in
        let mut used = vec![[false; CHUNKS]; n];
        for (of, len) in [
            (&vert_field, vert_field.len()),
            (&quad_field, quad_field.len()),
        ] {
            for k in 0..CHUNKS {
                for &f in &of[chunk_range(len, k)] {
                    used[f as usize][k] = true;
                }
            }
        }
        grid.use_chunks(used[0]);
        let grids = (1..n)
            .map(|f| {
                let mut g = grid.clone();
                g.use_chunks(used[f]);
                g
            })
            .collect();
        Some(Fields {
            grids,
            vert_field,
            quad_field,
            held,
            masses: vec![NodeMasses::default(); n],
            diameter,
            pinned_node: Vec::new(),
            pinned_geom: None,
            block_fields: Vec::new(),
        })
    }

    /// Number of fields.
    pub fn count(&self) -> usize {
        self.grids.len() + 1
    }

    /// Field `k`'s grid (`main`: field 0's, the simulation's own).
    pub fn grid<'a>(&'a self, main: &'a Grid, k: u16) -> &'a Grid {
        match k {
            0 => main,
            k => &self.grids[k as usize - 1],
        }
    }

    /// [`Fields::grid`] for writing.
    pub fn grid_mut<'a>(&'a mut self, main: &'a mut Grid, k: u16) -> &'a mut Grid {
        match k {
            0 => main,
            k => &mut self.grids[k as usize - 1],
        }
    }

    /// The grid the pins act on: the held field's, or `main` without one.
    pub fn held_grid<'a>(&'a self, main: &'a Grid) -> &'a Grid {
        self.grid(main, self.held.unwrap_or(0))
    }

    /// [`Fields::held_grid`] for writing.
    pub fn held_grid_mut<'a>(&'a mut self, main: &'a mut Grid) -> &'a mut Grid {
        let k = self.held.unwrap_or(0);
        self.grid_mut(main, k)
    }

    /// Bytes the fields' grids hold (field 0's not counted).
    pub fn memory_bytes(&self) -> usize {
        self.grids.iter().map(Grid::memory_bytes).sum()
    }

    /// Every field's grid (field 0: `main`) with its node-mass storage
    /// ready for the grid update to fill: a mass per node of the window,
    /// written on the grid's active blocks (zero elsewhere), and per window
    /// block the mask of nodes with mass > 0 (bit `8 r + c` for row `r`,
    /// column `c`). Call after the scatter; the grid update sums the masses
    /// in chunk order, as it sums them for the velocities.
    pub fn grids_with_masses<'a>(
        &'a mut self,
        main: &'a mut Grid,
    ) -> Vec<(&'a mut Grid, &'a mut [f64], &'a mut [u64])> {
        let centres = self.diameter.is_some();
        std::iter::once(main)
            .chain(self.grids.iter_mut())
            .zip(self.masses.iter_mut())
            .map(|(g, m)| {
                m.prepare(g, centres);
                (g, &mut m.m[..], &mut m.mask[..])
            })
            .collect()
    }

    /// With a diameter, each field's mass-weighted particle position at its
    /// nodes (see the module documentation) from the particles `p` as the
    /// scatter placed them, over the stencils it stored (call after
    /// [`Fields::grids_with_masses`]'s grid update and before
    /// [`Fields::contact`]); nothing without one. Serial, in particle
    /// order: the same bits for any thread count.
    pub fn locate(&mut self, p: &Particles) {
        if self.diameter.is_none() {
            return;
        }
        let items = (p.vert.x.iter().zip(&p.vert.stencil))
            .zip(&p.vert.m)
            .zip(&self.vert_field);
        let quads = (p.quad.x.iter().zip(&p.quad.stencil))
            .zip(&p.quad.m)
            .zip(&self.quad_field);
        for (((x, st), &m), &k) in items.chain(quads) {
            let node = &mut self.masses[k as usize];
            let geom = node.geom.expect("located after the grid update");
            let (bi, bj) = (st.base[0] as usize, st.base[1] as usize);
            let rows = geom.stencil_rows_mut(&mut node.centre, bi, bj);
            for (i, row) in rows.into_iter().enumerate() {
                for (j, c) in row.iter_mut().enumerate() {
                    let w = st.weight(i, j) * m;
                    c[0] += w;
                    c[1] += w * x.x;
                    c[2] += w * x.y;
                }
            }
        }
    }

    /// The contact of the fields (see the module documentation), after
    /// the grid update of every field and the pin constraint on the held
    /// field (`entries`, [`pins::stencil_masses`]). Adds to `reactions[k]`
    /// the force pin `k` exerts through its kinematic nodes over `dt`.
    pub fn contact(
        &mut self,
        main: &mut Grid,
        entries: &[PinEntry],
        mu: f64,
        dt: f64,
        reactions: &mut [Vec2],
    ) {
        let geom = main.geom;
        debug_assert!(self.grids.iter().all(|g| g.geom == geom), "one window");
        if self.held.is_some() {
            if self.pinned_geom != Some(geom) {
                self.pinned_node.clear();
                self.pinned_node.resize(geom.storage(), 0);
                self.pinned_geom = Some(geom);
            }
            pins::mark_stencil_nodes(entries, &mut self.pinned_node);
        }
        self.block_fields.clear();
        self.block_fields.resize(geom.blocks(), 0);
        for g in std::iter::once(&*main).chain(&self.grids) {
            for &b in &g.active {
                self.block_fields[b as usize] += 1;
            }
        }
        let rows = geom.nbi * BLOCK;
        let s = geom.stride;
        // the central difference at node `idx`, row `i`, column `j` of the window
        let grad = |m: &[f64], idx: usize, i: usize, j: usize| {
            let at = |ok: bool, k: usize| if ok { m[k] } else { 0.0 };
            Vec2::new(
                at(i + 1 < rows, idx + s) - at(i > 0, idx.wrapping_sub(s)),
                at(j + 1 < s, idx + 1) - at(j > 0, idx.wrapping_sub(1)),
            )
        };
        let n = self.count();
        let (mut in_block, mut here) = (Vec::with_capacity(n), Vec::with_capacity(n));
        let mut grads: Vec<Vec2> = Vec::with_capacity(n);
        for b in 0..geom.blocks() {
            if self.block_fields[b] < 2 {
                continue;
            }
            // the fields with mass in the block, and its nodes where two
            // or more have (in node order: bit 8 r + c)
            in_block.clear();
            let (mut one, mut two) = (0u64, 0u64);
            for k in 0..n {
                let mk = self.masses[k].mask[b];
                if mk != 0 {
                    in_block.push(k as u16);
                    two |= one & mk;
                    one |= mk;
                }
            }
            let (bi, bj) = (b / geom.nbj * BLOCK, b % geom.nbj * BLOCK);
            let mut nodes = two;
            while nodes != 0 {
                let bit = nodes.trailing_zeros() as usize;
                nodes &= nodes - 1;
                let (ni, nj) = (bi + bit / BLOCK, bj + bit % BLOCK);
                let idx = ni * s + nj;
                here.clear();
                here.extend(
                    in_block
                        .iter()
                        .filter(|&&k| self.masses[k as usize].mask[b] >> bit & 1 != 0),
                );
                // each field's mass gradient, once for all its pairs
                grads.clear();
                grads.extend(
                    here.iter()
                        .map(|&k| grad(&self.masses[k as usize].m, idx, ni, nj)),
                );
                for a in 0..here.len() {
                    for c in a + 1..here.len() {
                        let (i, j) = (here[a], here[c]);
                        // h: the held field in a pair with it, else the lower index
                        let ((f, gf), (h, gh)) = if self.held == Some(j) {
                            ((i, grads[a]), (j, grads[c]))
                        } else {
                            ((j, grads[c]), (i, grads[a]))
                        };
                        let (m_f, m_h) = (
                            self.masses[f as usize].m[idx],
                            self.masses[h as usize].m[idx],
                        );
                        let normal = if self.held == Some(h) {
                            contact_normal(gf, gh)
                        } else {
                            symmetric_normal(gf, gh)
                        };
                        let Some(nrm) = normal else {
                            continue;
                        };
                        if let Some(d) = self.diameter {
                            let at = |k: u16| centre(&self.masses[k as usize].centre[idx]);
                            if (at(f) - at(h)).dot(&nrm) >= d {
                                continue;
                            }
                        }
                        let pin = if self.held == Some(h) {
                            self.pinned_node[idx]
                        } else {
                            0
                        };
                        let nf = self.grid(main, f).node[idx];
                        let nh = self.grid(main, h).node[idx];
                        let (vf, vh) = (Vec2::new(nf[VX], nf[VY]), Vec2::new(nh[VX], nh[VY]));
                        let u = vf - vh;
                        if u.dot(&nrm) >= 0.0 {
                            continue;
                        }
                        let u2 = coulomb(u, nrm, mu);
                        let (dvf, dvh) = if pin > 0 {
                            (vh + u2 - vf, Vec2::zeros())
                        } else {
                            let inv = 1.0 / (m_f + m_h);
                            let vcm = (vf * m_f + vh * m_h) * inv;
                            (vcm + u2 * (m_h * inv) - vf, vcm - u2 * (m_f * inv) - vh)
                        };
                        add_velocity(&mut self.grid_mut(main, f).node[idx], dvf);
                        add_velocity(&mut self.grid_mut(main, h).node[idx], dvh);
                        if pin > 0 {
                            reactions[pin as usize - 1] += dvf * (m_f / dt);
                        }
                    }
                }
            }
        }
        if self.held.is_some() {
            pins::unmark_stencil_nodes(entries, &mut self.pinned_node);
        }
    }
}

/// The mass-weighted particle position `[sum w m, sum w m x, sum w m y]`
/// of a field at a node (0 where it has none).
#[inline]
fn centre(c: &[f64; 3]) -> Vec2 {
    if c[0] > 0.0 {
        Vec2::new(c[1], c[2]) / c[0]
    } else {
        Vec2::zeros()
    }
}

/// The contact normal from the held to the free field at a node, from the
/// two fields' mass gradients `gf`, `gh`: along the held field's gradient
/// (perpendicular to the held yarn's surface, so that the free yarn's own
/// ends do not plough into it), oriented toward the free field by the
/// difference `gf - gh`; the difference itself where the held gradient is
/// perpendicular to it (a node on the held yarn's centre line). `None`
/// where both vanish.
#[inline]
pub fn contact_normal(gf: Vec2, gh: Vec2) -> Option<Vec2> {
    let d = gf - gh;
    let s = gh.dot(&d);
    let n = if s != 0.0 { gh * s.signum() } else { d };
    let norm = n.norm();
    (norm > 0.0).then(|| n / norm)
}

/// The contact normal between two free fields, from `h` to `f`: the
/// difference of their mass gradients `gf - gh`, normalised (each
/// gradient points into its own yarn, so the difference points from `h`
/// into `f`; the symmetric choice of Nairn 2013, neither yarn's surface
/// preferred); `None` where it vanishes.
#[inline]
pub fn symmetric_normal(gf: Vec2, gh: Vec2) -> Option<Vec2> {
    let d = gf - gh;
    let norm = d.norm();
    (norm > 0.0).then(|| d / norm)
}

/// Adds `dv` to a node's velocity and to its change over the substep (read
/// by the FLIP transfer only).
#[inline]
fn add_velocity(node: &mut [f64; 4], dv: Vec2) {
    node[VX] += dv.x;
    node[VY] += dv.y;
    node[DVX] += dv.x;
    node[DVY] += dv.y;
}

impl NodeMasses {
    /// Ready for `grid`'s active blocks to be written: sized to its window
    /// and zeroed there when the window has moved, otherwise zeroed on the
    /// nodes with mass last time only (the grid update writes the nodes
    /// the scatter touched, and those without mass it writes 0; with many
    /// fields the window is mostly other fields' blocks).
    /// With `centres`, the same for the mass-weighted positions.
    fn prepare(&mut self, grid: &Grid, centres: bool) {
        let geom = grid.geom;
        if self.geom != Some(geom) {
            self.m.clear();
            self.m.resize(geom.storage(), 0.0);
            self.mask.clear();
            self.mask.resize(geom.blocks(), 0);
            if centres {
                self.centre.clear();
                self.centre.resize(geom.storage(), [0.0; 3]);
            }
            self.geom = Some(geom);
        } else {
            for &b in &self.written {
                let (i, j) = geom.block_origin(b as usize);
                let first = geom.index(i, j);
                let bits = std::mem::take(&mut self.mask[b as usize]);
                // whole rows of the block (one line each): the other nodes
                // of a row hold 0 already
                for r in (0..BLOCK).filter(|r| (bits >> (r * BLOCK)) & 0xff != 0) {
                    self.m[first + r * geom.stride..][..BLOCK].fill(0.0);
                    if centres {
                        self.centre[first + r * geom.stride..][..BLOCK].fill([0.0; 3]);
                    }
                }
            }
        }
        self.written.clear();
        self.written.extend_from_slice(&grid.active);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A free yarn one cell above a held one (centres at 1.2 and 2.2 cells,
    /// quadratic B-spline masses): at both shared nodes, and at the free
    /// yarn's end (its gradient along the yarn), the normal points up, from
    /// the held yarn to the free one.
    #[test]
    fn the_normal_points_from_the_held_yarn_to_the_free_one() {
        let w = |d: f64| {
            let d = d.abs();
            if d < 0.5 {
                0.75 - d * d
            } else if d < 1.5 {
                0.5 * (1.5 - d) * (1.5 - d)
            } else {
                0.0
            }
        };
        let grad_y = |centre: f64, j: f64| w(j + 1.0 - centre) - w(j - 1.0 - centre);
        for j in [1.0, 2.0] {
            let gh = Vec2::new(0.0, grad_y(1.2, j));
            let gf = Vec2::new(0.0, grad_y(2.2, j));
            assert_eq!(
                contact_normal(gf, gh),
                Some(Vec2::new(0.0, 1.0)),
                "node {j}"
            );
            let end = Vec2::new(-0.5, gf.y);
            assert_eq!(
                contact_normal(end, gh),
                Some(Vec2::new(0.0, 1.0)),
                "end, node {j}"
            );
        }
        // a held yarn without gradient there: the difference
        let n = contact_normal(Vec2::new(0.0, 2.0), Vec2::zeros()).unwrap();
        assert_eq!(n, Vec2::new(0.0, 1.0));
        assert_eq!(contact_normal(Vec2::zeros(), Vec2::zeros()), None);
    }

    /// The partitions: free yarns first in yarn order, the held yarns in
    /// the last field; free yarns beyond [`FREE_FIELDS_MAX`] wrap around;
    /// one field is `None`; a quadrature particle is in its left vertex's
    /// field.
    #[test]
    fn partitions_number_free_yarns_first_and_the_held_field_last() {
        use crate::mpm::machinery::grid::GridGeom;
        let grid = Grid::new(GridGeom::new(16, 1.0));
        // yarns of two vertices, one quadrature particle each
        let fields = |p: Partition, held: &[bool]| {
            let verts: Vec<usize> = (0..=held.len()).map(|y| 2 * y).collect();
            let quads: Vec<u32> = (0..held.len() as u32).map(|y| 2 * y).collect();
            Fields::of_yarns(p, held, &verts, &quads, &mut grid.clone(), None)
        };
        let f = fields(Partition::PerYarn, &[false, true, false, true]).unwrap();
        assert_eq!(f.count(), 3);
        assert_eq!(f.held, Some(2));
        assert_eq!(f.vert_field, [0, 0, 2, 2, 1, 1, 2, 2]);
        assert_eq!(f.quad_field, [0, 2, 1, 2]);
        let f = fields(Partition::HeldFree, &[false, true, false, true]).unwrap();
        assert_eq!((f.count(), f.held), (2, Some(1)));
        assert_eq!(f.quad_field, [0, 1, 0, 1]);
        assert!(fields(Partition::HeldFree, &[false, false, false]).is_none());
        assert!(fields(Partition::PerYarn, &[true, true]).is_none());
        assert!(fields(Partition::PerYarn, &[false]).is_none());
        let many = vec![false; FREE_FIELDS_MAX + 2];
        let f = fields(Partition::PerYarn, &many).unwrap();
        assert_eq!((f.count(), f.held), (FREE_FIELDS_MAX, None));
        assert_eq!(f.quad_field[FREE_FIELDS_MAX..], [0, 1]);
    }
}
