//! Compressed sparse row matrix (both triangles stored) and the assembly of
//! `A = diag(m_i I) + sum_s C_s` over the free particles, where spring `s`
//! between `a` and `b` adds `C_s` to blocks `(a,a)`, `(b,b)` and `-C_s` to
//! `(a,b)`, `(b,a)`. Rows are ordered particle by particle, `x, y, z` within
//! a particle, so a chain gives a block-tridiagonal matrix.

use nalgebra::Matrix3;

use crate::scene::massspring::Spring;

/// A square sparse matrix in CSR form with sorted column indices.
#[derive(Clone, Debug, PartialEq)]
pub struct CsrMatrix {
    /// Number of rows and columns.
    pub n: usize,
    /// Start of each row in `col` and `val` (`n + 1` entries).
    pub row_ptr: Vec<usize>,
    /// Column index of each stored entry.
    pub col: Vec<usize>,
    /// Value of each stored entry.
    pub val: Vec<f64>,
}

impl CsrMatrix {
    /// `y = A x`.
    pub fn matvec(&self, x: &[f64], y: &mut [f64]) {
        for (i, yi) in y.iter_mut().enumerate().take(self.n) {
            let mut s = 0.0;
            for k in self.row_ptr[i]..self.row_ptr[i + 1] {
                s += self.val[k] * x[self.col[k]];
            }
            *yi = s;
        }
    }

    /// Entry `(i, j)`, 0 when outside the pattern.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let cols = &self.col[self.row_ptr[i]..self.row_ptr[i + 1]];
        match cols.binary_search(&j) {
            Ok(k) => self.val[self.row_ptr[i] + k],
            Err(_) => 0.0,
        }
    }

    /// The diagonal.
    pub fn diagonal(&self) -> Vec<f64> {
        (0..self.n).map(|i| self.get(i, i)).collect()
    }

    /// The matrix as a dense nalgebra matrix.
    #[cfg(test)]
    pub fn to_dense(&self) -> nalgebra::DMatrix<f64> {
        let mut d = nalgebra::DMatrix::zeros(self.n, self.n);
        for i in 0..self.n {
            for k in self.row_ptr[i]..self.row_ptr[i + 1] {
                d[(i, self.col[k])] = self.val[k];
            }
        }
        d
    }

    /// Largest `|A_ij - A_ji|`.
    #[cfg(test)]
    pub fn asymmetry(&self) -> f64 {
        let mut worst: f64 = 0.0;
        for i in 0..self.n {
            for k in self.row_ptr[i]..self.row_ptr[i + 1] {
                worst = worst.max((self.val[k] - self.get(self.col[k], i)).abs());
            }
        }
        worst
    }
}

/// Numbering of the free particles' degrees of freedom.
#[derive(Clone, Debug, PartialEq)]
pub struct DofMap {
    /// Free index of each particle, `None` for kinematic ones.
    pub index: Vec<Option<usize>>,
    /// Particle of each free index.
    pub particle: Vec<usize>,
}

impl DofMap {
    /// Numbers the particles for which `free(i)` holds, in order.
    pub fn new(n: usize, free: impl Fn(usize) -> bool) -> DofMap {
        let mut index = vec![None; n];
        let mut particle = Vec::new();
        for (i, slot) in index.iter_mut().enumerate() {
            if free(i) {
                *slot = Some(particle.len());
                particle.push(i);
            }
        }
        DofMap { index, particle }
    }

    /// Number of scalar unknowns (3 per free particle).
    pub fn dofs(&self) -> usize {
        3 * self.particle.len()
    }
}

/// Assembles `diag(mass_i I) + sum_s C_s` over the free particles. Every
/// spring between two free particles puts full 3x3 blocks into the pattern,
/// whatever their values, so the pattern depends on the topology only.
pub fn assemble_block_system(
    map: &DofMap,
    masses: &[f64],
    springs: &[Spring],
    blocks: &[Matrix3<f64>],
) -> CsrMatrix {
    let nf = map.particle.len();
    // Neighbour lists (free indices), including self.
    let mut nbrs: Vec<Vec<usize>> = (0..nf).map(|i| vec![i]).collect();
    for s in springs {
        if let (Some(a), Some(b)) = (map.index[s.a], map.index[s.b]) {
            nbrs[a].push(b);
            nbrs[b].push(a);
        }
    }
    for l in &mut nbrs {
        l.sort_unstable();
        l.dedup();
    }
    let n = 3 * nf;
    let mut row_ptr = Vec::with_capacity(n + 1);
    let mut col = Vec::new();
    row_ptr.push(0);
    for l in &nbrs {
        for _ in 0..3 {
            for &j in l {
                col.extend_from_slice(&[3 * j, 3 * j + 1, 3 * j + 2]);
            }
            row_ptr.push(col.len());
        }
    }
    let mut m = CsrMatrix {
        n,
        row_ptr,
        col,
        val: Vec::new(),
    };
    m.val = vec![0.0; m.col.len()];
    let add_block = |m: &mut CsrMatrix, bi: usize, bj: usize, c: &Matrix3<f64>, sign: f64| {
        for r in 0..3 {
            let row = 3 * bi + r;
            let (lo, hi) = (m.row_ptr[row], m.row_ptr[row + 1]);
            let k = lo
                + m.col[lo..hi]
                    .binary_search(&(3 * bj))
                    .expect("block in pattern");
            for cc in 0..3 {
                m.val[k + cc] += sign * c[(r, cc)];
            }
        }
    };
    for (fi, &p) in map.particle.iter().enumerate() {
        add_block(&mut m, fi, fi, &(Matrix3::identity() * masses[p]), 1.0);
    }
    for (s, c) in springs.iter().zip(blocks) {
        let (a, b) = (map.index[s.a], map.index[s.b]);
        if let Some(a) = a {
            add_block(&mut m, a, a, c, 1.0);
        }
        if let Some(b) = b {
            add_block(&mut m, b, b, c, 1.0);
        }
        if let (Some(a), Some(b)) = (a, b) {
            add_block(&mut m, a, b, c, -1.0);
            add_block(&mut m, b, a, c, -1.0);
        }
    }
    m
}
