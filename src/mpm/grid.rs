//! The background grid, stored block by block (8 x 8 nodes) so that work and
//! clearing touch only the blocks that particles reach.
//!
//! Scattering runs over a fixed number of particle chunks, each into its own
//! buffer; the buffers are summed in chunk order. Results therefore do not
//! depend on the number of threads.

/// Side of a block in nodes.
pub const BLOCK: usize = 8;
const BLOCK_SHIFT: usize = 3;
const BLOCK_NODES: usize = BLOCK * BLOCK;

/// Number of scatter chunks (fixed for determinism).
pub const CHUNKS: usize = 4;

/// Grid geometry: `n x n` nodes at `(i dx, j dx)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridGeom {
    pub n: usize,
    pub dx: f64,
    pub inv_dx: f64,
    /// Blocks per side.
    pub nb: usize,
}

impl GridGeom {
    pub fn new(n: usize, size: f64) -> Self {
        let dx = size / n as f64;
        GridGeom {
            n,
            dx,
            inv_dx: 1.0 / dx,
            nb: n.div_ceil(BLOCK),
        }
    }

    /// Storage index of node `(i, j)`.
    #[inline(always)]
    pub fn index(&self, i: usize, j: usize) -> usize {
        (((i >> BLOCK_SHIFT) * self.nb + (j >> BLOCK_SHIFT)) << (2 * BLOCK_SHIFT))
            + ((i & (BLOCK - 1)) << BLOCK_SHIFT)
            + (j & (BLOCK - 1))
    }

    /// Node `(i, j)` of storage index `idx`.
    #[inline(always)]
    pub fn node(&self, idx: usize) -> (usize, usize) {
        let b = idx >> (2 * BLOCK_SHIFT);
        let (bi, bj) = (b / self.nb, b % self.nb);
        let r = idx & (BLOCK_NODES - 1);
        (
            (bi << BLOCK_SHIFT) + (r >> BLOCK_SHIFT),
            (bj << BLOCK_SHIFT) + (r & (BLOCK - 1)),
        )
    }

    /// Total stored nodes (whole blocks).
    pub fn storage(&self) -> usize {
        self.nb * self.nb * BLOCK_NODES
    }

    pub fn blocks(&self) -> usize {
        self.nb * self.nb
    }

    /// Range of storage indices of block `b`.
    #[inline(always)]
    pub fn block_range(&self, b: usize) -> std::ops::Range<usize> {
        b * BLOCK_NODES..(b + 1) * BLOCK_NODES
    }
}

/// One chunk's scatter target: mass and momentum (`[m, px, py]`) per node,
/// plus the blocks it touched.
#[derive(Clone, Debug)]
pub struct ScatterBuffer {
    pub node: Vec<[f64; 3]>,
    pub touched: Vec<bool>,
    pub touched_list: Vec<u32>,
}

impl ScatterBuffer {
    pub fn new(geom: &GridGeom) -> Self {
        ScatterBuffer {
            node: vec![[0.0; 3]; geom.storage()],
            touched: vec![false; geom.blocks()],
            touched_list: Vec::new(),
        }
    }

    /// Zeroes the blocks touched last time and forgets them.
    pub fn clear(&mut self, geom: &GridGeom) {
        for &b in &self.touched_list {
            let r = geom.block_range(b as usize);
            self.node[r].fill([0.0; 3]);
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
        for bi in [i0, i1] {
            for bj in [j0, j1] {
                let b = bi * geom.nb + bj;
                if !self.touched[b] {
                    self.touched[b] = true;
                    self.touched_list.push(b as u32);
                }
            }
        }
    }
}

/// The summed grid: velocity `[m, vx, vy]` per node on the active blocks.
#[derive(Clone, Debug)]
pub struct Grid {
    pub geom: GridGeom,
    pub node: Vec<[f64; 3]>,
    /// Blocks touched this substep, sorted.
    pub active: Vec<u32>,
    pub buffers: Vec<ScatterBuffer>,
}

impl Grid {
    pub fn new(geom: GridGeom) -> Self {
        Grid {
            geom,
            node: vec![[0.0; 3]; geom.storage()],
            active: Vec::new(),
            buffers: (0..CHUNKS).map(|_| ScatterBuffer::new(&geom)).collect(),
        }
    }

    /// Collects the union of the chunks' touched blocks into `active`, sorted.
    pub fn collect_active(&mut self) {
        let mut mark = vec![false; self.geom.blocks()];
        self.active.clear();
        for b in &self.buffers {
            for &k in &b.touched_list {
                if !mark[k as usize] {
                    mark[k as usize] = true;
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
    fn index_roundtrip() {
        let g = GridGeom::new(37, 1.0);
        let mut seen = vec![false; g.storage()];
        for i in 0..37 {
            for j in 0..37 {
                let k = g.index(i, j);
                assert!(!seen[k]);
                seen[k] = true;
                assert_eq!(g.node(k), (i, j));
            }
        }
    }
}
