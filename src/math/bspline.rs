//! Quadratic B-spline weights for MPM transfers on a uniform grid.
//!
//! A particle at `x` touches the 3x3 nodes `base + (i, j)` with
//! `base = floor(x / dx - 0.5)`; node `base + i` sits at `(base + i) dx`.

use super::Vec2;

/// Weights of one particle on its 3x3 stencil.
#[derive(Clone, Copy, Debug, Default)]
pub struct Stencil {
    /// Lower-left node of the stencil.
    pub base: [i32; 2],
    /// `w[axis][i]`: the 1D weight of node `base[axis] + i`.
    pub w: [[f64; 3]; 2],
    /// `x / dx - base` per axis, in `[0.5, 1.5)`; node offset `(x_i - x_p) / dx = i - fx`.
    pub fx: [f64; 2],
}

/// 1D quadratic B-spline weights for a fractional coordinate `fx` in `[0.5, 1.5)`.
#[inline(always)]
pub fn weights_1d(fx: f64) -> [f64; 3] {
    let a = 1.5 - fx;
    let b = fx - 1.0;
    let c = fx - 0.5;
    [0.5 * a * a, 0.75 - b * b, 0.5 * c * c]
}

/// Lower-left node of the stencil of a particle at `x` (what
/// [`Stencil::new`] puts in `base`).
#[inline(always)]
pub fn base_of(x: Vec2, inv_dx: f64) -> [i32; 2] {
    // Truncation is floor here: particles are kept at x >= dx, so
    // x / dx - 0.5 > 0 (and it avoids a libm call on baseline x86-64).
    [
        ((x.x * inv_dx - 0.5) as i64) as i32,
        ((x.y * inv_dx - 0.5) as i64) as i32,
    ]
}

impl Stencil {
    /// Stencil of a particle at `x >= 0.5 dx` (per axis) on a grid of spacing `1 / inv_dx`.
    #[inline(always)]
    pub fn new(x: Vec2, inv_dx: f64) -> Self {
        let base = base_of(x, inv_dx);
        let fx = x.x * inv_dx - base[0] as f64;
        let fy = x.y * inv_dx - base[1] as f64;
        Stencil {
            base,
            w: [weights_1d(fx), weights_1d(fy)],
            fx: [fx, fy],
        }
    }

    /// Weight of stencil node `(i, j)`.
    #[inline(always)]
    pub fn weight(&self, i: usize, j: usize) -> f64 {
        self.w[0][i] * self.w[1][j]
    }

    /// `(x_i - x_p) / dx` for stencil node `(i, j)`.
    #[inline(always)]
    pub fn offset(&self, i: usize, j: usize) -> Vec2 {
        Vec2::new(i as f64 - self.fx[0], j as f64 - self.fx[1])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn partition_of_unity_and_linear_reproduction() {
        for k in 0..1000 {
            let x = Vec2::new(0.1 + 0.000731 * k as f64, 0.37 + 0.000419 * k as f64);
            let s = Stencil::new(x, 64.0);
            let mut sum = 0.0;
            let mut first = Vec2::zeros();
            for i in 0..3 {
                for j in 0..3 {
                    sum += s.weight(i, j);
                    first += s.weight(i, j) * s.offset(i, j);
                }
            }
            assert!((sum - 1.0).abs() < 1e-14);
            assert!(first.norm() < 1e-14);
            assert!((0.5..1.5).contains(&s.fx[0]));
        }
    }

    #[test]
    fn second_moment_is_quarter_cell() {
        // sum_i w_i (x_i - x_p)(x_i - x_p)^T = dx^2 / 4 I: the APIC inertia tensor.
        let s = Stencil::new(Vec2::new(0.4321, 0.6789), 32.0);
        let mut m = nalgebra::Matrix2::<f64>::zeros();
        for i in 0..3 {
            for j in 0..3 {
                let o = s.offset(i, j);
                m += s.weight(i, j) * o * o.transpose();
            }
        }
        assert!((m - nalgebra::Matrix2::identity() * 0.25).norm() < 1e-14);
    }
}
