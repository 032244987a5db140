//! Node storage that starts on a cache line: the grid's and the scatter
//! buffers' pools ([`crate::mpm::machinery::grid`]).
//!
//! A `Vec` of 48- or 32-byte nodes starts wherever the allocator puts it
//! (16 bytes into a line for a large block from glibc), so every other
//! 32-byte grid node straddled two lines, and the rows of neighbouring 8x8
//! blocks shared a line at their seam. In a [`LinePool`] node 0 starts a
//! 64-byte line: a [`crate::mpm::machinery::grid::Node`] never straddles one, and a block
//! row (8 nodes of 48 or 32 bytes, 384 or 256 bytes) is whole lines, so two
//! threads working on different blocks never write the same line.

use std::marker::PhantomData;
use std::ops::{Deref, DerefMut};

/// Resizes a pool to `len` entries (new ones `zero`), giving memory back
/// when the window has shrunk to under a quarter of the capacity: the rule
/// for every pool of the grid, the [`LinePool`]s' lines included.
pub(super) fn fit<T: Clone>(pool: &mut Vec<T>, len: usize, zero: T) {
    pool.resize(len, zero);
    if pool.capacity() > 4 * len {
        pool.shrink_to(2 * len);
    }
}

/// One cache line.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Line([f64; 8]);

/// Node types a [`LinePool`] can hold: `f64` lanes, for which every bit
/// pattern is a value and zero bits are zero.
pub trait Lanes: Copy {}
impl<const N: usize> Lanes for [f64; N] {}

/// A pool of `len` nodes `T` stored in whole cache lines, node 0 at the
/// start of a line; new nodes are zero.
#[derive(Clone, Debug)]
pub struct LinePool<T: Lanes> {
    lines: Vec<Line>,
    len: usize,
    _node: PhantomData<T>,
}

impl<T: Lanes> Default for LinePool<T> {
    fn default() -> Self {
        LinePool {
            lines: Vec::new(),
            len: 0,
            _node: PhantomData,
        }
    }
}

impl<T: Lanes> LinePool<T> {
    /// `len` zero nodes.
    pub fn zeroed(len: usize) -> Self {
        let mut pool = Self::default();
        pool.fit(len);
        pool
    }

    /// Resizes to `len` nodes, keeping the first ones and zeroing new ones,
    /// by [`fit`] on its lines.
    pub fn fit(&mut self, len: usize) {
        let lines = (len * std::mem::size_of::<T>()).div_ceil(64);
        fit(&mut self.lines, lines, Line([0.0; 8]));
        self.len = len;
    }

    /// Bytes held (by capacity).
    pub fn capacity_bytes(&self) -> usize {
        self.lines.capacity() * std::mem::size_of::<Line>()
    }
}

impl<T: Lanes> Deref for LinePool<T> {
    type Target = [T];
    #[inline(always)]
    fn deref(&self) -> &[T] {
        // SAFETY: `lines` holds at least `len * size_of::<T>()` initialized
        // bytes (`fit`), aligned to 64 >= align_of::<T>() (8); `T` is an
        // array of f64, valid for any bits.
        unsafe { std::slice::from_raw_parts(self.lines.as_ptr().cast::<T>(), self.len) }
    }
}

impl<T: Lanes> DerefMut for LinePool<T> {
    #[inline(always)]
    fn deref_mut(&mut self) -> &mut [T] {
        // SAFETY: as in `deref`, borrowed uniquely through `&mut self`.
        unsafe { std::slice::from_raw_parts_mut(self.lines.as_mut_ptr().cast::<T>(), self.len) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_zero_starts_a_line_and_new_nodes_are_zero() {
        // a plain Vec would start on a line now and then by chance (one
        // time in four from glibc); thirty pools of other sizes do not
        let pools: Vec<LinePool<[f64; 6]>> = (1..=30).map(|k| LinePool::zeroed(37 * k)).collect();
        assert!(pools
            .iter()
            .all(|p| (p.as_ptr() as usize).is_multiple_of(64)));
        let mut p: LinePool<[f64; 6]> = LinePool::zeroed(100);
        assert_eq!(p.len(), 100);
        assert_eq!(p.as_ptr() as usize % 64, 0);
        assert!(p.iter().all(|n| *n == [0.0; 6]));
        p[99] = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        p.fit(1000);
        assert_eq!(p.as_ptr() as usize % 64, 0);
        assert_eq!(p[99], [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        assert!(p[100..].iter().all(|n| *n == [0.0; 6]));
        assert!(p.capacity_bytes() >= 1000 * 48);
    }

    #[test]
    fn shrinking_gives_memory_back() {
        let mut p: LinePool<[f64; 4]> = LinePool::zeroed(1 << 16);
        let big = p.capacity_bytes();
        p.fit(100);
        assert_eq!(p.len(), 100);
        assert!(
            p.capacity_bytes() <= 2 * 100 * 32 + 64,
            "{}",
            p.capacity_bytes()
        );
        assert!(p.capacity_bytes() < big);
        let empty: LinePool<[f64; 4]> = LinePool::default();
        assert!(empty.is_empty());
    }
}
