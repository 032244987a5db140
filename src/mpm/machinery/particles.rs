//! Particle storage of the yarn bundle: type-2 vertices (the yarns' mesh
//! vertices) and type-3 quadrature particles (one per segment, carrying the
//! material frame), as structures of arrays.
//!
//! Mass lives on both kinds: a segment of rest length `l0` and line density
//! `rho` has mass `rho l0`; half of it sits on its quadrature particle and a
//! quarter on each end vertex. Every particle takes its velocity from the grid
//! (APIC), so linear momentum is conserved exactly; quadrature particle
//! positions are re-interpolated from the vertices each step.

use crate::math::bspline::Stencil;
use crate::math::qr::{qr, Qr2};
use crate::math::{perp, Mat2, Vec2};
use crate::scene::YarnScene;

/// Marks "no neighbour" in the index arrays.
pub const NONE: u32 = u32::MAX;

/// Rest data of the bending energy at one vertex (the law and the rest
/// state of a curve: `crate::mpm::laws::bending`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BendRest {
    /// Rest curvature `kappa0 = 2 tan(theta0 / 2)`.
    pub kappa0: f64,
    /// `1 / l` with `l` the rest Voronoi length; 0 at yarn ends (no bending).
    pub inv_len: f64,
}

/// Type-2 particles: the yarn vertices.
#[derive(Clone, Debug, Default)]
pub struct Vertices {
    /// Positions, m.
    pub x: Vec<Vec2>,
    /// Velocities, m/s.
    pub v: Vec<Vec2>,
    /// Affine velocity matrix (APIC `C`).
    pub c: Vec<Mat2>,
    /// Masses (per m of depth).
    pub m: Vec<f64>,
    /// Quadrature particle of the segment to the left (this vertex is its right end), or [`NONE`].
    pub q_left: Vec<u32>,
    /// Quadrature particle of the segment to the right, or [`NONE`].
    pub q_right: Vec<u32>,
    /// Rest curvature and Voronoi length of the bending energy (see
    /// `crate::mpm::laws::vertex_forces`); none at yarn ends.
    pub bend: Vec<BendRest>,
    /// Stencils at the start-of-step positions (scratch).
    pub stencil: Vec<Stencil>,
    /// Internal force of the current substep (scratch).
    pub f: Vec<Vec2>,
    /// `(x_new - x_old) x v_new` of the current substep without the mass
    /// (scratch of the FLIP angular momentum balance, `crate::mpm::machinery::spin`).
    pub spin: Vec<f64>,
}

/// Type-3 particles: one quadrature point per segment.
#[derive(Clone, Debug, Default)]
pub struct Quads {
    /// Positions, m.
    pub x: Vec<Vec2>,
    /// Velocities, m/s.
    pub v: Vec<Vec2>,
    /// Affine velocity matrix (APIC `C`).
    pub c: Vec<Mat2>,
    /// Masses (per m of depth).
    pub m: Vec<f64>,
    /// Current material frame `d = [d1 | d2]`.
    pub d: Vec<Mat2>,
    /// Rest frame `D = [D1 | R90 D1]`.
    pub d_rest: Vec<Mat2>,
    /// `D^-1`.
    pub d_rest_inv: Vec<Mat2>,
    /// Rest length `|D1|`.
    pub l0: Vec<f64>,
    /// Volume (per unit depth): `l0` times unit thickness.
    pub vol: Vec<f64>,
    /// Index of the left vertex; the right one is `left + 1`.
    pub left: Vec<u32>,
    /// Stencils at the start-of-step positions (scratch).
    pub stencil: Vec<Stencil>,
    /// QR factorisation of `G = d / l0` for the current `d` (kept by the
    /// quadrature gather for the next step's stress; see [`Quads::refresh_frames`]).
    pub frame: Vec<Qr2>,
    /// `dE/dd1` (scratch).
    pub t1: Vec<Vec2>,
    /// `dE/dd2` (scratch).
    pub t2: Vec<Vec2>,
    /// See [`Vertices::spin`] (scratch).
    pub spin: Vec<f64>,
}

impl Quads {
    /// Deformation gradient `F = d D^-1` (world frame) of particle `q`.
    pub fn deformation_gradient(&self, q: usize) -> Mat2 {
        self.d[q] * self.d_rest_inv[q]
    }

    /// Recomputes [`Quads::frame`] from `d` (after `d` was set from outside the stepper).
    pub fn refresh_frames(&mut self) {
        self.frame = self
            .d
            .iter()
            .zip(&self.l0)
            .map(|(d, l0)| qr(&(d * (1.0 / l0))))
            .collect();
    }
}

/// All particles and the yarn topology.
#[derive(Clone, Debug, Default)]
pub struct Particles {
    /// The vertices.
    pub vert: Vertices,
    /// The quadrature particles.
    pub quad: Quads,
    /// `yarn_vertices[y]..yarn_vertices[y + 1]` are yarn `y`'s vertices.
    pub yarn_vertices: Vec<usize>,
}

impl Particles {
    /// Builds the particles of a validated scene at rest, the bending rest
    /// state of each yarn's vertices from `bend_rest` (the bending law's
    /// `rest_of_curve`).
    pub fn from_scene(scene: &YarnScene, bend_rest: fn(&[Vec2]) -> Vec<BendRest>) -> Self {
        let curves = scene.curves();
        let vels = scene.curve_velocities();
        let rho = scene.material.density;
        let mut p = Particles::default();
        p.yarn_vertices.push(0);
        for (curve, vel) in curves.iter().zip(vels) {
            let base = p.vert.x.len();
            let n = curve.len();
            for &x in curve.iter() {
                p.vert.x.push(x);
                p.vert.v.push(vel);
                p.vert.c.push(Mat2::zeros());
                p.vert.m.push(0.0);
                p.vert.q_left.push(NONE);
                p.vert.q_right.push(NONE);
            }
            p.vert.bend.extend(bend_rest(curve));
            for i in 0..n - 1 {
                let (l, r) = (base + i, base + i + 1);
                let d1 = curve[i + 1] - curve[i];
                let l0 = d1.norm();
                let dm = Mat2::from_columns(&[d1, perp(d1)]);
                let q = p.quad.x.len() as u32;
                let seg_mass = rho * l0;
                p.vert.m[l] += 0.25 * seg_mass;
                p.vert.m[r] += 0.25 * seg_mass;
                p.vert.q_right[l] = q;
                p.vert.q_left[r] = q;
                p.quad.x.push((curve[i] + curve[i + 1]) * 0.5);
                p.quad.v.push(vel);
                p.quad.c.push(Mat2::zeros());
                p.quad.m.push(0.5 * seg_mass);
                p.quad.d.push(dm);
                p.quad.d_rest.push(dm);
                p.quad
                    .d_rest_inv
                    .push(dm.try_inverse().expect("segments have positive length"));
                p.quad.l0.push(l0);
                p.quad.vol.push(l0);
                p.quad.left.push(l as u32);
            }
            p.yarn_vertices.push(p.vert.x.len());
        }
        let (nv, nq) = (p.vert.x.len(), p.quad.x.len());
        p.vert.stencil = vec![Stencil::default(); nv];
        p.vert.f = vec![Vec2::zeros(); nv];
        p.vert.spin = vec![0.0; nv];
        p.quad.spin = vec![0.0; nq];
        p.quad.stencil = vec![Stencil::default(); nq];
        p.quad.t1 = vec![Vec2::zeros(); nq];
        p.quad.t2 = vec![Vec2::zeros(); nq];
        p.quad.refresh_frames();
        p
    }

    /// Number of yarns.
    pub fn num_yarns(&self) -> usize {
        self.yarn_vertices.len() - 1
    }

    /// Total number of particles (vertices plus quadrature points).
    pub fn len(&self) -> usize {
        self.vert.x.len() + self.quad.x.len()
    }

    /// Whether there are no particles.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Each vertex's lumped mass into `out`: its own and half of each
    /// adjacent quadrature particle's (the mass a vertex solve moves with
    /// it; the quadrature particle's mass split between its two vertices).
    pub fn lumped_masses(&self, out: &mut Vec<f64>) {
        out.clear();
        out.extend_from_slice(&self.vert.m);
        for (&l, &m) in self.quad.left.iter().zip(&self.quad.m) {
            out[l as usize] += 0.5 * m;
            out[l as usize + 1] += 0.5 * m;
        }
    }
}
