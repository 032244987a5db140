//! The internal forces on the yarn vertices: the fiber (tangent) force of
//! the two adjacent segments, from the quadrature particles' stress, and the
//! discrete bending force of the turning angles.
//!
//! Bending follows discrete elastic rods (Bergou et al. 2008) in 2D: at each
//! interior vertex `j` with edges `e1 = x_j - x_{j-1}`, `e2 = x_{j+1} - x_j`
//! the curvature is `kappa_j = 2 tan(theta_j / 2) = 2 (e1 x e2) / (|e1| |e2| + e1 . e2)`
//! (`theta_j` the turning angle) and the energy is
//!
//! ```text
//! E = sum_j B / 2 (kappa_j - kappa0_j)^2 / l_j
//! ```
//!
//! with `kappa0_j` the rest curvature and `l_j = (|E1| + |E2|) / 2` the rest
//! Voronoi length: the discrete form of `int B / 2 kappa^2 ds`, so the same
//! yarn bends alike at any number of vertices. `B` (`material.bending`) is
//! the bending stiffness of the rod in N m^2 per m of depth (N m).
//!
//! The bending gradient is the bending law's ([`super::bending`]).
//! [`vertex_forces`] is a plain function of the positions (and the quadrature
//! stress), callable without a grid: the scatter calls it per chunk, and an
//! implicit solver or a test can call it directly.

use crate::math::Vec2;
use crate::mpm::laws::bending::bend_gradients;
use crate::mpm::machinery::particles::{Vertices, NONE};

/// Internal force on every vertex of `range`, written to `out` (same length):
/// fiber forces from the quadrature particles' `t1 = dE/dd1` plus, when
/// `bending > 0`, the bending force `-dE/dx`.
#[inline(always)]
pub fn vertex_forces(
    v: &Vertices,
    t1: &[Vec2],
    bending: f64,
    range: std::ops::Range<usize>,
    out: &mut [Vec2],
) {
    debug_assert_eq!(range.len(), out.len());
    // E depends on d1 = x_right - x_left: the left end gets +dE/dd1, the right end -dE/dd1.
    for (i, f) in range.clone().zip(out.iter_mut()) {
        let mut force = Vec2::zeros();
        let (ql, qr) = (v.q_left[i], v.q_right[i]);
        if qr != NONE {
            force += t1[qr as usize];
        }
        if ql != NONE {
            force -= t1[ql as usize];
        }
        *f = force;
    }
    if bending > 0.0 {
        // the gradients at range.start - 1 ..= range.end: one curvature
        // evaluation per vertex
        let (lo, hi) = (range.start as isize - 1, range.end as isize + 1);
        let g = bend_gradients(&v.x, &v.bend, bending, lo, hi);
        for (k, f) in out.iter_mut().enumerate() {
            let (prev, cur, next) = (g[k], g[k + 1], g[k + 2]);
            // dkappa_{i-1}/dx_i = de2 of i-1; dkappa_i/dx_i = de1 - de2; dkappa_{i+1}/dx_i = -de1
            *f -= Vec2::new(
                prev[2] + cur[0] - cur[2] - next[0],
                prev[3] + cur[1] - cur[3] - next[1],
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mpm::laws::bending::{bending_energy, rest_of_curve};
    use crate::mpm::machinery::particles::Particles;
    use crate::scene::{builtin::yarn_reference, Material, YarnScene, YarnSpec};

    /// The reference scene's settings on a 64^2 grid at dt 1e-4, without
    /// obstacles, holding `yarns` of a fibre with `[k, gamma, E] = fibre`, no
    /// friction, and `bending`.
    fn scene(fibre: [f64; 3], bending: f64, yarns: Vec<YarnSpec>) -> YarnScene {
        let mut s = yarn_reference();
        s.name.clear();
        s.description.clear();
        s.grid.resolution = 64;
        s.time.dt = 1e-4.into();
        s.material = Material {
            k: fibre[0],
            gamma: fibre[1],
            youngs_modulus: fibre[2],
            friction: 0.0,
            bending,
            ..s.material
        };
        s.obstacles.clear();
        s.yarns = yarns;
        s.validate().unwrap();
        s
    }

    /// A yarn along the polyline `points` with `vertices` vertices.
    fn polyline(points: &[[f64; 2]], vertices: u32) -> YarnSpec {
        YarnSpec {
            points: Some(points.to_vec()),
            vertices,
            count: 1,
            ..Default::default()
        }
    }

    /// A curved yarn (rest curvature) bent further, with random offsets.
    fn bent_vertices() -> crate::mpm::machinery::particles::Vertices {
        let scene = scene(
            [1000.0, 500.0, 1000.0],
            0.01,
            vec![
                polyline(&[[0.2, 0.3], [0.4, 0.45], [0.6, 0.4], [0.7, 0.6]], 30),
                YarnSpec::straight([0.2, 0.8], [0.8, 0.8], 12),
            ],
        );
        let mut p = Particles::from_scene(&scene, rest_of_curve);
        let l = p.quad.l0[0];
        for (i, x) in p.vert.x.iter_mut().enumerate() {
            let a = i as f64 * 1.7;
            *x += Vec2::new(a.sin(), (2.3 * a).cos()) * (0.2 * l);
        }
        p.vert
    }

    #[test]
    fn bending_force_is_minus_the_energy_gradient() {
        let v = bent_vertices();
        let b = 0.01;
        let n = v.x.len();
        let t1 = vec![Vec2::zeros(); 64];
        let mut f = vec![Vec2::zeros(); n];
        // split in uneven chunks: the rolling window must not depend on them
        vertex_forces(&v, &t1, b, 0..7, &mut f[0..7]);
        vertex_forces(&v, &t1, b, 7..n, &mut f[7..n]);
        let mut whole = vec![Vec2::zeros(); n];
        vertex_forces(&v, &t1, b, 0..n, &mut whole);
        assert_eq!(f, whole);
        let eps = 1e-7;
        let mut worst: f64 = 0.0;
        let mut max_f: f64 = 0.0;
        for (i, fi) in f.iter().enumerate() {
            for axis in 0..2 {
                let mut w = v.clone();
                w.x[i][axis] += eps;
                let ep = bending_energy(&w, b);
                w.x[i][axis] -= 2.0 * eps;
                let em = bending_energy(&w, b);
                let fd = -(ep - em) / (2.0 * eps);
                worst = worst.max((fd - fi[axis]).abs());
                max_f = max_f.max(fi[axis].abs());
            }
        }
        // central differences at eps 1e-7: truncation ~eps^2, round-off ~1e-16 E / eps
        assert!(max_f > 0.1, "{max_f}");
        assert!(worst < 1e-6 * max_f, "worst {worst} of {max_f}");
    }

    #[test]
    fn straight_rest_yarn_has_no_bending_energy_or_force() {
        let scene = scene(
            [1.0; 3],
            1.0,
            vec![polyline(&[[0.2, 0.3], [0.5, 0.5], [0.7, 0.4]], 20)],
        );
        let p = Particles::from_scene(&scene, rest_of_curve);
        // curved at rest: zero energy and force at rest, whatever the shape
        assert_eq!(bending_energy(&p.vert, 1.0), 0.0);
        let mut f = vec![Vec2::zeros(); 20];
        vertex_forces(&p.vert, &[Vec2::zeros(); 19], 1.0, 0..20, &mut f);
        assert!(f.iter().all(|f| f.norm() < 1e-12), "{f:?}");
    }

    #[test]
    fn discrete_energy_of_a_circular_arc_matches_the_continuum() {
        // an arc of radius R and length L: int B/2 kappa^2 ds = B L / (2 R^2),
        // the same at every resolution (to O(h^2) from 2 tan(theta/2) ~ theta)
        let (r, len, b) = (0.5, 0.6, 2.0);
        for n in [20usize, 80, 320] {
            let straight: Vec<Vec2> = (0..n)
                .map(|i| Vec2::new(len * i as f64 / (n - 1) as f64, 0.0))
                .collect();
            let mut vert = crate::mpm::machinery::particles::Vertices {
                bend: rest_of_curve(&straight),
                ..Default::default()
            };
            vert.x = (0..n)
                .map(|i| {
                    let phi = len / r * i as f64 / (n - 1) as f64;
                    Vec2::new(r * phi.sin(), r * (1.0 - phi.cos()))
                })
                .collect();
            let e = bending_energy(&vert, b);
            let exact = b * len / (2.0 * r * r);
            // the discrete sum spans L - h (half cells at the ends are not
            // counted), so the relative error is about 1/n
            let rel = (e - exact).abs() / exact;
            assert!(rel < 1.5 / n as f64, "n {n}: {e} vs {exact} ({rel})");
        }
    }
}
