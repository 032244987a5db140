//! The background grid: dense row-major storage, worked on block by block
//! (8 x 8 nodes) so that clearing, summing and the grid update touch only the
//! blocks that particles reach.
//!
//! Scattering runs over a fixed number of particle chunks, each into its own
//! buffer; the buffers are summed in chunk order, so results do not depend on
//! the number of threads.

/// Side of a block in nodes.
pub const BLOCK: usize = 8;
const BLOCK_SHIFT: usize = 3;

/// Number of scatter chunks (fixed for determinism).
pub const CHUNKS: usize = 4;

/// One node of a scatter buffer, one cache line (one AVX-512 register, two
/// AVX2 ones): momentum including the impulse of the internal forces
/// `[PX, PY]`, mass `M`, the mass of particles touching an obstacle `MC`,
/// and the impulse `dt f` alone `[FX, FY]` (read only by the FLIP transfer,
/// for the grid velocity before the forces; APIC leaves it zero). Two lanes
/// pad the node to 64 bytes.
pub type P2gNode = [f64; P2G_LANES];
/// Lanes of a [`P2gNode`].
pub const P2G_LANES: usize = 8;
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

/// Grid geometry: `n x n` nodes at `(i dx, j dx)`, stored with row stride
/// `stride` (`n` rounded up to whole blocks): node `(i, j)` is at `i * stride + j`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridGeom {
    pub n: usize,
    pub dx: f64,
    pub inv_dx: f64,
    /// Blocks per side.
    pub nb: usize,
    /// Row stride, `nb * BLOCK`.
    pub stride: usize,
}

impl GridGeom {
    pub fn new(n: usize, size: f64) -> Self {
        let dx = size / n as f64;
        let nb = n.div_ceil(BLOCK);
        GridGeom {
            n,
            dx,
            inv_dx: 1.0 / dx,
            nb,
            stride: nb * BLOCK,
        }
    }

    /// Storage index of node `(i, j)`.
    #[inline(always)]
    pub fn index(&self, i: usize, j: usize) -> usize {
        i * self.stride + j
    }

    /// Node `(i, j)` of storage index `idx`.
    #[inline(always)]
    pub fn node(&self, idx: usize) -> (usize, usize) {
        (idx / self.stride, idx % self.stride)
    }

    /// Total stored nodes.
    pub fn storage(&self) -> usize {
        self.stride * self.stride
    }

    pub fn blocks(&self) -> usize {
        self.nb * self.nb
    }

    /// Block of node `(i, j)`.
    #[inline(always)]
    pub fn block_of(&self, i: usize, j: usize) -> usize {
        (i >> BLOCK_SHIFT) * self.nb + (j >> BLOCK_SHIFT)
    }

    /// Storage indices of block `b`, row by row (eight runs of eight).
    pub fn block_nodes(&self, b: usize) -> impl Iterator<Item = usize> + '_ {
        let (bi, bj) = (b / self.nb, b % self.nb);
        (0..BLOCK).flat_map(move |r| {
            let start = ((bi << BLOCK_SHIFT) + r) * self.stride + (bj << BLOCK_SHIFT);
            start..start + BLOCK
        })
    }
}

/// One chunk's scatter target: a [`P2gNode`] per node, plus the blocks it
/// touched.
#[derive(Clone, Debug)]
pub struct ScatterBuffer {
    pub node: Vec<P2gNode>,
    pub touched: Vec<bool>,
    pub touched_list: Vec<u32>,
}

impl ScatterBuffer {
    pub fn new(geom: &GridGeom) -> Self {
        ScatterBuffer {
            node: vec![[0.0; P2G_LANES]; geom.storage()],
            touched: vec![false; geom.blocks()],
            touched_list: Vec::new(),
        }
    }

    /// Forgets the blocks touched last time (the grid update zeroed their
    /// nodes as it summed them).
    pub fn clear(&mut self) {
        for &b in &self.touched_list {
            self.touched[b as usize] = false;
        }
        self.touched_list.clear();
    }

    /// Marks the blocks covered by the 3x3 stencil at `base`.
    #[inline(always)]
    pub fn touch_stencil(&mut self, geom: &GridGeom, base: [i32; 2]) {
        let (i0, j0) = (
            base[0] as usize >> BLOCK_SHIFT,
            base[1] as usize >> BLOCK_SHIFT,
        );
        let (i1, j1) = (
            (base[0] as usize + 2) >> BLOCK_SHIFT,
            (base[1] as usize + 2) >> BLOCK_SHIFT,
        );
        self.touch(i0 * geom.nb + j0);
        if j1 != j0 {
            self.touch(i0 * geom.nb + j1);
        }
        if i1 != i0 {
            self.touch(i1 * geom.nb + j0);
            if j1 != j0 {
                self.touch(i1 * geom.nb + j1);
            }
        }
    }

    #[inline(always)]
    fn touch(&mut self, b: usize) {
        if !self.touched[b] {
            self.touched[b] = true;
            self.touched_list.push(b as u32);
        }
    }
}

/// The summed grid: a [`Node`] per node on the active blocks.
#[derive(Clone, Debug)]
pub struct Grid {
    pub geom: GridGeom,
    pub node: Vec<Node>,
    /// Blocks touched this substep, sorted.
    pub active: Vec<u32>,
    /// `is_active[b]` for every block.
    pub is_active: Vec<bool>,
    pub buffers: Vec<ScatterBuffer>,
}

impl Grid {
    pub fn new(geom: GridGeom) -> Self {
        Grid {
            geom,
            node: vec![[0.0; 4]; geom.storage()],
            active: Vec::new(),
            is_active: vec![false; geom.blocks()],
            buffers: (0..CHUNKS).map(|_| ScatterBuffer::new(&geom)).collect(),
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn index_roundtrip_and_blocks_partition_the_nodes() {
        let g = GridGeom::new(37, 1.0);
        for i in 0..37 {
            for j in 0..37 {
                assert_eq!(g.node(g.index(i, j)), (i, j));
            }
        }
        let mut seen = vec![0u8; g.storage()];
        for b in 0..g.blocks() {
            for k in g.block_nodes(b) {
                seen[k] += 1;
                let (i, j) = g.node(k);
                assert_eq!(g.block_of(i, j), b);
            }
        }
        assert!(seen.iter().all(|&c| c == 1));
    }
}
