//! The background grid: dense row-major storage of a *window* of whole
//! blocks (8 x 8 nodes) around the particles, worked on block by block so
//! that summing and the grid update touch only the blocks that particles
//! reach. The window follows the particles' bounding box (with a margin of
//! two blocks, refitted when a particle leaves it or it is four times larger
//! than needed), so memory follows the yarns, not the domain: a bundle on
//! an 8192^2 grid stores what it stores on 256^2. Where the window sits
//! changes no result (only where nodes are kept, not how they are summed).
//!
//! Scattering runs over a fixed number of particle chunks, each into its own
//! buffer; the buffers are summed in chunk order, so results do not depend on
//! the number of threads.

use crate::math::bspline::base_of;
use crate::math::Vec2;
use crate::mpm::machinery::line_pool::{fit, LinePool};

/// Side of a block in nodes.
pub const BLOCK: usize = 8;
const BLOCK_SHIFT: usize = 3;

/// Number of scatter chunks (fixed for determinism).
pub const CHUNKS: usize = 4;

/// One node of a scatter buffer, 48 bytes: momentum including the impulse
/// of the internal forces `[PX, PY]`, mass `M`, the mass of particles
/// touching an obstacle `MC`, and the impulse `dt f` alone `[FX, FY]` (read
/// only by the FLIP transfer, for the grid velocity before the forces; APIC
/// leaves it zero). No padding: the scatter and the grid update are bound
/// by the bytes they stream, and six lanes ran 1.2x faster in the scatter
/// than eight padded to a 64-byte line (same bits).
pub type P2gNode = [f64; P2G_LANES];
/// Lanes of a `P2gNode`.
pub const P2G_LANES: usize = 6;
/// Lane of the x momentum in a [`P2gNode`].
pub const PX: usize = 0;
/// Lane of the y momentum.
pub const PY: usize = 1;
/// Lane of the mass.
pub const M: usize = 2;
/// Lane of the mass of particles in contact with an obstacle.
pub const MC: usize = 3;
/// Lane of the x impulse `dt f`.
pub const FX: usize = 4;
/// Lane of the y impulse.
pub const FY: usize = 5;

/// One node of the summed grid after the grid update: the new velocity
/// `[VX, VY]` and its change over the substep `[DVX, DVY]` (forces, gravity,
/// attractor, contact; read by the FLIP transfer). Four lanes, one SIMD
/// register (or two).
pub type Node = [f64; 4];
/// Lane of the new x velocity in a [`Node`].
pub const VX: usize = 0;
/// Lane of the new y velocity.
pub const VY: usize = 1;
/// Lane of the x velocity change.
pub const DVX: usize = 2;
/// Lane of the y velocity change.
pub const DVY: usize = 3;

/// Grid geometry, `n x n` nodes at `(i dx, j dx)`, and the stored window:
/// blocks `nbi x nbj` from node `(i0, j0)`, row-major with row stride
/// `stride = nbj * BLOCK`: node `(i, j)` is at `(i - i0) * stride + j - j0`.
/// Blocks are numbered inside the window.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridGeom {
    /// Nodes per side.
    pub n: usize,
    /// Node spacing, m.
    pub dx: f64,
    /// `1 / dx`.
    pub inv_dx: f64,
    /// Blocks per side of the whole grid.
    pub nb: usize,
    /// First node of the window (multiples of `BLOCK`).
    pub i0: usize,
    /// (`i0`: first row, `j0`: first column.)
    pub j0: usize,
    /// Window size in blocks.
    pub nbi: usize,
    /// (`nbi` rows, `nbj` columns.)
    pub nbj: usize,
    /// Row stride of the window, `nbj * BLOCK`.
    pub stride: usize,
}

impl GridGeom {
    /// The geometry with a window over the whole grid.
    pub fn new(n: usize, size: f64) -> Self {
        let dx = size / n as f64;
        let nb = n.div_ceil(BLOCK);
        GridGeom {
            n,
            dx,
            inv_dx: 1.0 / dx,
            nb,
            i0: 0,
            j0: 0,
            nbi: nb,
            nbj: nb,
            stride: nb * BLOCK,
        }
    }

    /// The same grid with the window of blocks `bi0..bi0 + nbi`,
    /// `bj0..bj0 + nbj`.
    pub fn with_window(&self, bi0: usize, bj0: usize, nbi: usize, nbj: usize) -> Self {
        GridGeom {
            i0: bi0 * BLOCK,
            j0: bj0 * BLOCK,
            nbi,
            nbj,
            stride: nbj * BLOCK,
            ..*self
        }
    }

    /// Storage index of node `(i, j)` (inside the window).
    #[inline(always)]
    pub fn index(&self, i: usize, j: usize) -> usize {
        (i - self.i0) * self.stride + (j - self.j0)
    }

    /// The three rows of three nodes of the 3x3 stencil whose lower-left
    /// node is `(bi, bj)`, in `nodes` (a pool of this window), with one
    /// bounds check for all nine.
    #[inline(always)]
    pub fn stencil_rows<'a, T>(&self, nodes: &'a [T], bi: usize, bj: usize) -> [&'a [T; 3]; 3] {
        let first = self.index(bi, bj);
        let s = self.stride;
        let span = &nodes[first..first + 2 * s + 3];
        // SAFETY: row `i` is `span[i * s..i * s + 3]`, inside `span` for
        // i <= 2; shared references may overlap.
        std::array::from_fn(|i| unsafe { &*(span.as_ptr().add(i * s) as *const [T; 3]) })
    }

    /// [`GridGeom::stencil_rows`] for writing (the scatter's splat). The
    /// rows are disjoint: the stride is whole blocks, at least 8 nodes.
    #[inline(always)]
    pub fn stencil_rows_mut<'a, T>(
        &self,
        nodes: &'a mut [T],
        bi: usize,
        bj: usize,
    ) -> [&'a mut [T; 3]; 3] {
        let first = self.index(bi, bj);
        let s = self.stride;
        assert!(s >= 3, "a window row holds a stencil row");
        let span = &mut nodes[first..first + 2 * s + 3];
        let p = span.as_mut_ptr();
        // SAFETY: row `i` is `span[i * s..i * s + 3]`, inside `span` for
        // i <= 2, and the three rows do not overlap (s >= 3).
        std::array::from_fn(|i| unsafe { &mut *(p.add(i * s) as *mut [T; 3]) })
    }

    /// Node `(i, j)` of storage index `idx`.
    #[inline(always)]
    pub fn node(&self, idx: usize) -> (usize, usize) {
        (idx / self.stride + self.i0, idx % self.stride + self.j0)
    }

    /// Stored nodes (the window's).
    pub fn storage(&self) -> usize {
        self.nbi * BLOCK * self.stride
    }

    /// Blocks of the window.
    pub fn blocks(&self) -> usize {
        self.nbi * self.nbj
    }

    /// Window block of node `(i, j)`.
    #[inline(always)]
    pub fn block_of(&self, i: usize, j: usize) -> usize {
        ((i - self.i0) >> BLOCK_SHIFT) * self.nbj + ((j - self.j0) >> BLOCK_SHIFT)
    }

    /// First node `(i, j)` of window block `b`.
    #[inline(always)]
    pub fn block_origin(&self, b: usize) -> (usize, usize) {
        (
            self.i0 + ((b / self.nbj) << BLOCK_SHIFT),
            self.j0 + ((b % self.nbj) << BLOCK_SHIFT),
        )
    }

    /// Storage indices of window block `b`, row by row (eight runs of eight).
    pub fn block_nodes(&self, b: usize) -> impl Iterator<Item = usize> + '_ {
        self.block_rows(b).flatten()
    }

    /// The rows of window block `b`: eight runs of eight storage indices.
    #[inline(always)]
    pub fn block_rows(&self, b: usize) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
        let (bi, bj) = (b / self.nbj, b % self.nbj);
        (0..BLOCK).map(move |r| {
            let start = ((bi << BLOCK_SHIFT) + r) * self.stride + (bj << BLOCK_SHIFT);
            start..start + BLOCK
        })
    }

    /// Whether the 3x3 stencils with lower-left nodes in `lo..=hi` (per
    /// axis) lie inside the window.
    fn window_holds(&self, lo: [usize; 2], hi: [usize; 2]) -> bool {
        lo[0] >= self.i0
            && lo[1] >= self.j0
            && hi[0] + 2 < self.i0 + self.nbi * BLOCK
            && hi[1] + 2 < self.j0 + self.nbj * BLOCK
    }
}

/// One chunk's scatter target: a [`P2gNode`] per node, plus the blocks it
/// touched and, per window block, the nodes it touched (bit `8 r + c` for
/// row `r`, column `c` of the block, as the field contact's masks): a yarn
/// a few cells wide fills a fraction of each of its blocks, and the grid
/// update works on the touched nodes only. Nodes outside the masks are
/// zero. A buffer that no particle of its grid's field scatters into
/// (`used` false: its chunk holds none of them) stores no nodes. Without
/// `track_nodes` (the single grid: its blocks are mostly full) a touched
/// block is marked whole.
#[derive(Clone, Debug)]
pub struct ScatterBuffer {
    pub node: LinePool<P2gNode>,
    pub touched: Vec<bool>,
    pub touched_list: Vec<u32>,
    pub touched_nodes: Vec<u64>,
    pub used: bool,
    pub track_nodes: bool,
}

impl ScatterBuffer {
    pub fn new(geom: &GridGeom) -> Self {
        ScatterBuffer {
            node: LinePool::zeroed(geom.storage()),
            touched: vec![false; geom.blocks()],
            touched_list: Vec::new(),
            touched_nodes: vec![0; geom.blocks()],
            used: true,
            track_nodes: false,
        }
    }

    /// Forgets the blocks touched last time (the grid update zeroed their
    /// nodes as it summed them).
    pub fn clear(&mut self) {
        for &b in &self.touched_list {
            self.touched[b as usize] = false;
            self.touched_nodes[b as usize] = 0;
        }
        self.touched_list.clear();
    }

    /// Marks the blocks and nodes covered by the 3x3 stencil at `base`.
    #[inline(always)]
    pub fn touch_stencil(&mut self, geom: &GridGeom, base: [i32; 2]) {
        let (ri, rj) = (base[0] as usize - geom.i0, base[1] as usize - geom.j0);
        let (i0, j0) = (ri >> BLOCK_SHIFT, rj >> BLOCK_SHIFT);
        if !self.track_nodes {
            let (i1, j1) = ((ri + 2) >> BLOCK_SHIFT, (rj + 2) >> BLOCK_SHIFT);
            self.touch(i0 * geom.nbj + j0, !0);
            if j1 != j0 {
                self.touch(i0 * geom.nbj + j1, !0);
            }
            if i1 != i0 {
                self.touch(i1 * geom.nbj + j0, !0);
                if j1 != j0 {
                    self.touch(i1 * geom.nbj + j1, !0);
                }
            }
            return;
        }
        // the stencil's rows and columns from the block's first, over this
        // block and the next (bits 8 and up)
        let rows = 0b111u32 << (ri & (BLOCK - 1));
        let cols = 0b111u64 << (rj & (BLOCK - 1));
        let b = i0 * geom.nbj + j0;
        let (left, right) = (cols & 0xff, cols >> BLOCK);
        self.touch(b, stencil_mask(rows & 0xff, left));
        if right != 0 {
            self.touch(b + 1, stencil_mask(rows & 0xff, right));
        }
        if rows >> BLOCK != 0 {
            self.touch(b + geom.nbj, stencil_mask(rows >> BLOCK, left));
            if right != 0 {
                self.touch(b + geom.nbj + 1, stencil_mask(rows >> BLOCK, right));
            }
        }
    }

    #[inline(always)]
    fn touch(&mut self, b: usize, nodes: u64) {
        if !self.touched[b] {
            self.touched[b] = true;
            self.touched_list.push(b as u32);
        }
        self.touched_nodes[b] |= nodes;
    }
}

/// The node mask (bit `8 r + c`) of the block's rows `rows` (bit `r`) and
/// columns `cols` (bit `c`).
#[inline(always)]
fn stencil_mask(rows: u32, cols: u64) -> u64 {
    let mut m = 0;
    let mut rs = rows;
    while rs != 0 {
        m |= cols << (BLOCK as u32 * rs.trailing_zeros());
        rs &= rs - 1;
    }
    m
}

/// The summed grid: a [`Node`] per node of the window (meaningful on the
/// active blocks), and the chunks' scatter buffers.
#[derive(Clone, Debug)]
pub struct Grid {
    /// Geometry and window.
    pub geom: GridGeom,
    /// The summed nodes of the window.
    pub node: LinePool<Node>,
    /// Blocks touched this substep, sorted.
    pub active: Vec<u32>,
    /// `is_active[b]` for every block.
    pub is_active: Vec<bool>,
    /// The chunks' scatter buffers.
    pub buffers: Vec<ScatterBuffer>,
    /// The grid update's obstacle contact nodes, one list per block row
    /// (kept between substeps so their storage is reused).
    pub contacts: Vec<Vec<ContactNode>>,
}

/// The bounding box of stencil bases (lower-left nodes, clamped at 0) that
/// a window must hold; empty (`lo > hi`) until a base is added.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StencilBounds {
    pub lo: [usize; 2],
    pub hi: [usize; 2],
}

impl Default for StencilBounds {
    fn default() -> Self {
        StencilBounds {
            lo: [usize::MAX; 2],
            hi: [0; 2],
        }
    }
}

impl StencilBounds {
    /// Adds the stencil with lower-left node `b`.
    #[inline(always)]
    pub fn add(&mut self, b: [i32; 2]) {
        let (i, j) = (b[0].max(0) as usize, b[1].max(0) as usize);
        self.lo = [self.lo[0].min(i), self.lo[1].min(j)];
        self.hi = [self.hi[0].max(i), self.hi[1].max(j)];
    }

    /// Adds the stencils of particles at `xs` ([`base_of`] each): from the
    /// coordinates' extremes, since `base_of` does not decrease with `x`
    /// while `x / dx` is finite and well inside `i32`; one particle at a time
    /// otherwise (a NaN or runaway position), to the same result.
    pub fn add_positions(&mut self, xs: &[Vec2], inv_dx: f64) {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        let mut nan = false;
        for x in xs {
            for a in 0..2 {
                lo[a] = if x[a] < lo[a] { x[a] } else { lo[a] };
                hi[a] = if x[a] > hi[a] { x[a] } else { hi[a] };
            }
            nan |= x.x.is_nan() | x.y.is_nan();
        }
        if xs.is_empty() {
            return;
        }
        const SAFE: f64 = 1e9;
        let tame = (0..2).all(|a| lo[a] * inv_dx > -SAFE && hi[a] * inv_dx < SAFE);
        if nan || !tame {
            for &x in xs {
                self.add(base_of(x, inv_dx));
            }
            return;
        }
        let (l, h) = (Vec2::new(lo[0], lo[1]), Vec2::new(hi[0], hi[1]));
        self.add(base_of(l, inv_dx));
        self.add(base_of(h, inv_dx));
    }
}

impl Grid {
    /// A grid of geometry `geom` with an empty window (nothing stored until
    /// the first [`Grid::fit_window`]).
    pub fn new(geom: GridGeom) -> Self {
        let geom = geom.with_window(0, 0, 0, 0);
        Grid {
            geom,
            node: LinePool::default(),
            active: Vec::new(),
            is_active: Vec::new(),
            buffers: (0..CHUNKS).map(|_| ScatterBuffer::new(&geom)).collect(),
            contacts: Vec::new(),
        }
    }

    /// Moves the window so that it holds the 3x3 stencils with lower-left
    /// nodes from `lo` to `hi` (per axis, as [`StencilBounds`] collects
    /// them): kept while it holds them and is at most four times the blocks
    /// they need (and 16), otherwise refitted with a margin of two blocks per
    /// side. Call before a scatter (it forgets the last scatter's touched
    /// blocks).
    pub fn fit_window(&mut self, bounds: &StencilBounds) {
        let (lo, hi) = (bounds.lo, bounds.hi);
        if lo[0] > hi[0] {
            return; // no particles
        }
        let g = self.geom;
        let (k_lo, k_hi) = (
            [lo[0] >> BLOCK_SHIFT, lo[1] >> BLOCK_SHIFT],
            [(hi[0] + 2) >> BLOCK_SHIFT, (hi[1] + 2) >> BLOCK_SHIFT],
        );
        let need = (k_hi[0] - k_lo[0] + 1) * (k_hi[1] - k_lo[1] + 1);
        if g.window_holds(lo, hi) && g.blocks() <= 4 * need.max(16) {
            return;
        }
        const MARGIN: usize = 2;
        let last = g.nb - 1;
        let (bi0, bj0) = (
            k_lo[0].saturating_sub(MARGIN),
            k_lo[1].saturating_sub(MARGIN),
        );
        let (bi1, bj1) = ((k_hi[0] + MARGIN).min(last), (k_hi[1] + MARGIN).min(last));
        // forget the touched and active blocks while their numbers still
        // mean the old window
        for buf in &mut self.buffers {
            buf.clear();
        }
        for &b in &self.active {
            self.is_active[b as usize] = false;
        }
        self.active.clear();
        let geom = g.with_window(bi0, bj0, bi1 - bi0 + 1, bj1 - bj0 + 1);
        self.geom = geom;
        // every scatter node is zero here (the grid update zeroed what it
        // summed), so the pools need no clearing wherever the window moved
        self.node.fit(geom.storage());
        fit(&mut self.is_active, geom.blocks(), false);
        for buf in self.buffers.iter_mut() {
            buf.node.fit(if buf.used { geom.storage() } else { 0 });
            fit(&mut buf.touched, geom.blocks(), false);
            fit(&mut buf.touched_nodes, geom.blocks(), 0);
        }
    }

    /// Marks the chunks whose particles scatter into this grid
    /// (`used[k]`: chunk `k` has some) and gives back the node storage of
    /// the others' buffers, which the scatter never writes; the buffers
    /// mark the nodes they touch (a field's grid: one yarn's blocks are
    /// mostly empty).
    pub fn use_chunks(&mut self, used: [bool; CHUNKS]) {
        for (buf, &u) in self.buffers.iter_mut().zip(&used) {
            buf.used = u;
            buf.track_nodes = true;
            if !u {
                buf.node = LinePool::default();
            }
        }
    }

    /// Bytes the grid holds now (its pools by capacity).
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of;
        let mut b = self.node.capacity_bytes()
            + self.active.capacity() * size_of::<u32>()
            + self.is_active.capacity();
        for buf in &self.buffers {
            b += buf.node.capacity_bytes()
                + buf.touched.capacity()
                + buf.touched_list.capacity() * size_of::<u32>()
                + buf.touched_nodes.capacity() * size_of::<u64>();
        }
        b
    }

    /// Mass the scatter put on node `(i, j)` (window index `idx`), summed
    /// over the chunk buffers: read before the grid update consumes them.
    pub fn scattered_mass(&self, idx: usize, i: usize, j: usize) -> f64 {
        let blk = self.geom.block_of(i, j);
        self.buffers
            .iter()
            .filter(|s| s.touched[blk])
            .map(|s| s.node[idx][M])
            .sum()
    }

    /// The rows (runs of eight storage indices) of the active blocks.
    pub fn active_rows(&self) -> impl Iterator<Item = std::ops::Range<usize>> + '_ {
        self.active
            .iter()
            .flat_map(|&b| self.geom.block_rows(b as usize))
    }

    /// Collects the union of the chunks' touched blocks into `active`, sorted.
    pub fn collect_active(&mut self) {
        for &b in &self.active {
            self.is_active[b as usize] = false;
        }
        self.active.clear();
        for buf in &self.buffers {
            for &k in &buf.touched_list {
                if !self.is_active[k as usize] {
                    self.is_active[k as usize] = true;
                    self.active.push(k);
                }
            }
        }
        self.active.sort_unstable();
    }
}

/// A grid node in contact with an obstacle, as the normal part of the law
/// (`crate::mpm::laws::contact`) left it, for the friction part.
#[derive(Clone, Copy, Debug)]
pub struct ContactNode {
    /// Index of the node in the grid's node pool.
    pub index: usize,
    /// Grid coordinates (for the walls).
    pub ij: [u32; 2],
    /// Friction wedge, numbered over all obstacles
    /// (`crate::mpm::laws::contact::WedgeTable`).
    pub wedge: u32,
    /// The node's mass: all of it joins the wedge's friction pool (the
    /// normal part acts on the touching share only).
    pub mass: f64,
    /// Normal impulse the obstacle delivered to it (`>= 0`).
    pub impulse: f64,
    /// Outward unit normal at the node.
    pub normal: Vec2,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn position_bounds_match_the_bases_one_by_one() {
        let inv_dx = 256.0;
        let one_by_one = |xs: &[Vec2]| {
            let mut b = StencilBounds::default();
            for &x in xs {
                b.add(base_of(x, inv_dx));
            }
            b
        };
        let mut xs: Vec<Vec2> = (0..97)
            .map(|k| {
                let t = k as f64 * 0.731;
                Vec2::new(0.5 + 0.4 * t.sin(), 0.5 + 0.3 * (1.3 * t).cos())
            })
            .collect();
        let mut cases = vec![xs.clone(), Vec::new(), xs[..1].to_vec()];
        // cell edges exactly, a NaN, a runaway and a negative coordinate
        xs.push(Vec2::new(10.5 / inv_dx, 3.5 / inv_dx));
        cases.push(xs.clone());
        for bad in [
            Vec2::new(f64::NAN, 0.3),
            Vec2::new(0.4, f64::INFINITY),
            Vec2::new(1e12, 0.2),
            Vec2::new(-0.7, 0.2),
        ] {
            let mut c = xs.clone();
            c.insert(40, bad);
            cases.push(c);
        }
        for c in &cases {
            let mut fast = StencilBounds::default();
            fast.add_positions(c, inv_dx);
            assert_eq!(fast, one_by_one(c), "{} positions", c.len());
        }
    }

    #[test]
    fn stencil_rows_are_the_nodes_of_the_stencil() {
        let g = GridGeom::new(37, 1.0).with_window(1, 2, 3, 2);
        let nodes: Vec<usize> = (0..g.storage()).collect();
        // every stencil inside the window, including its last row and column
        for bi in 8..30 {
            for bj in 16..30 {
                let rows = g.stencil_rows(&nodes, bi, bj);
                for (i, row) in rows.iter().enumerate() {
                    for (j, &k) in row.iter().enumerate() {
                        assert_eq!(k, g.index(bi + i, bj + j));
                    }
                }
                // the writable rows are the same nodes
                let mut marks = vec![0usize; g.storage()];
                for (i, row) in g
                    .stencil_rows_mut(&mut marks, bi, bj)
                    .into_iter()
                    .enumerate()
                {
                    for (j, m) in row.iter_mut().enumerate() {
                        *m = g.index(bi + i, bj + j) + 1;
                    }
                }
                let written: Vec<usize> = (0..marks.len()).filter(|&k| marks[k] != 0).collect();
                assert_eq!(written.len(), 9);
                assert!(written.iter().all(|&k| marks[k] == k + 1));
            }
        }
    }

    /// The node masks a stencil touches are its nine nodes, over the one,
    /// two or four blocks it covers, for every base in a window.
    #[test]
    fn touched_nodes_are_the_stencils_nodes() {
        let g = GridGeom::new(37, 1.0).with_window(1, 2, 3, 2);
        let mut buf = ScatterBuffer::new(&g);
        buf.track_nodes = true;
        for bi in 8..30 {
            for bj in 16..30 {
                buf.clear();
                buf.touch_stencil(&g, [bi as i32, bj as i32]);
                let mut marked = Vec::new();
                for &b in &buf.touched_list {
                    let (i0, j0) = g.block_origin(b as usize);
                    let m = buf.touched_nodes[b as usize];
                    assert_ne!(m, 0, "block {b} touched without nodes");
                    for bit in (0..64).filter(|k| m >> k & 1 != 0) {
                        marked.push((i0 + bit / BLOCK, j0 + bit % BLOCK));
                    }
                }
                marked.sort_unstable();
                let want: Vec<_> = (0..3)
                    .flat_map(|i| (0..3).map(move |j| (bi + i, bj + j)))
                    .collect();
                assert_eq!(marked, want, "base ({bi}, {bj})");
            }
        }
        buf.clear();
        assert!(buf.touched_nodes.iter().all(|&m| m == 0));
        // untracked (the single grid): the same blocks, each whole
        let mut whole = ScatterBuffer::new(&g);
        for base in [[8, 16], [13, 21], [14, 22], [15, 23], [29, 29]] {
            buf.clear();
            whole.clear();
            buf.touch_stencil(&g, base);
            whole.touch_stencil(&g, base);
            assert_eq!(buf.touched_list, whole.touched_list, "base {base:?}");
            assert!(whole
                .touched_list
                .iter()
                .all(|&b| whole.touched_nodes[b as usize] == !0));
        }
    }

    #[test]
    #[should_panic]
    fn stencil_rows_past_the_window_panic() {
        let g = GridGeom::new(37, 1.0).with_window(1, 2, 3, 2);
        let nodes = vec![0u8; g.storage()];
        // lower-left node on the window's last row but one: its third row
        // would be outside
        let _ = g.stencil_rows(&nodes, 30, 16);
    }

    #[test]
    #[should_panic]
    fn writable_stencil_rows_past_the_window_panic() {
        let g = GridGeom::new(37, 1.0).with_window(1, 2, 3, 2);
        let mut nodes = vec![0u8; g.storage()];
        let _ = g.stencil_rows_mut(&mut nodes, 30, 16);
    }

    #[test]
    fn index_roundtrip_and_blocks_partition_the_nodes() {
        let full = GridGeom::new(37, 1.0);
        let g = full.with_window(1, 2, 3, 2);
        for i in 8..32 {
            for j in 16..32 {
                assert_eq!(g.node(g.index(i, j)), (i, j));
            }
        }
        let mut seen = vec![0u8; g.storage()];
        for b in 0..g.blocks() {
            for k in g.block_nodes(b) {
                seen[k] += 1;
                let (i, j) = g.node(k);
                assert_eq!(g.block_of(i, j), b);
                let (i0, j0) = g.block_origin(b);
                assert!((i0..i0 + BLOCK).contains(&i) && (j0..j0 + BLOCK).contains(&j));
            }
        }
        assert!(seen.iter().all(|&c| c == 1));
    }
}
