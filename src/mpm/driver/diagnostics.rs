//! Measurements of the current state: yarn ends, segment stretch, elastic
//! energy, and the summary of energies and momenta.

use super::YarnSim;
use crate::math::Vec2;
use crate::mpm::laws::bending;

/// Summary quantities of the current state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Diagnostics {
    /// Simulated time, s.
    pub time: f64,
    /// Substeps taken.
    pub steps: u64,
    /// Kinetic energy `sum m v^2 / 2` of the particles, J (per m of depth).
    pub kinetic_energy: f64,
    /// Elastic energy of the yarn material and of bending, J (per m of depth).
    pub elastic_energy: f64,
    /// Gravitational potential energy `-sum m g.x`.
    pub potential_energy: f64,
    /// Linear momentum.
    pub momentum: Vec2,
    /// Angular momentum about the origin, including the APIC affine part.
    pub angular_momentum: f64,
    /// Smallest segment stretch `|x_r - x_l| / l0`.
    pub min_stretch: f64,
    /// Largest segment stretch `|x_r - x_l| / l0`.
    pub max_stretch: f64,
    /// Mean segment stretch `|x_r - x_l| / l0`.
    pub mean_stretch: f64,
    /// Centre of mass, m.
    pub center_of_mass: Vec2,
    /// Total mass (per m of depth).
    pub total_mass: f64,
}

impl YarnSim {
    /// Grid node `(i, j)` after the last grid update, `[vx, vy, dvx, dvy]`
    /// (its velocity and the velocity's change over the substep: forces,
    /// gravity, contact), or `None` outside the stored window. For
    /// measurement programs (`evidence/examples/crush_probe.rs`).
    #[cfg(feature = "testing")]
    pub fn grid_node(&self, i: usize, j: usize) -> Option<[f64; 4]> {
        let g = &self.grid.geom;
        if i < g.i0 || j < g.j0 || j - g.j0 >= g.stride {
            return None;
        }
        self.grid.node.get(g.index(i, j)).copied()
    }

    /// Left and right end of yarn `y`.
    pub fn yarn_endpoints(&self, y: usize) -> (Vec2, Vec2) {
        let r = &self.particles.yarn_vertices;
        (
            self.particles.vert.x[r[y]],
            self.particles.vert.x[r[y + 1] - 1],
        )
    }

    /// Stretch `|x_r - x_l| / l0` of every segment.
    pub fn stretches(&self) -> Vec<f64> {
        let p = &self.particles;
        p.quad
            .left
            .iter()
            .zip(&p.quad.l0)
            .map(|(&l, &l0)| (p.vert.x[l as usize + 1] - p.vert.x[l as usize]).norm() / l0)
            .collect()
    }

    /// Total elastic energy: the yarn energy of every quadrature particle
    /// plus the bending energy.
    pub fn elastic_energy(&self) -> f64 {
        let p = &self.particles;
        let mut e = 0.0;
        for q in 0..p.quad.x.len() {
            e += p.quad.vol[q] * self.energy.psi(&(p.quad.d[q] / p.quad.l0[q]));
        }
        e + bending::bending_energy(&p.vert, self.scene.material.bending)
    }

    /// Energies, momenta, stretch and centre of mass.
    pub fn diagnostics(&self) -> Diagnostics {
        let p = &self.particles;
        let dx = self.grid.geom.dx;
        let mut ke = 0.0;
        let mut pe = 0.0;
        let mut mom = Vec2::zeros();
        let mut ang = 0.0;
        let mut mass = 0.0;
        let mut com = Vec2::zeros();
        let mut add = |x: &[Vec2], v: &[Vec2], c: &[nalgebra::Matrix2<f64>], m: &[f64]| {
            for k in 0..x.len() {
                ke += 0.5 * m[k] * v[k].norm_squared();
                pe -= m[k] * self.gravity.dot(&x[k]);
                mom += v[k] * m[k];
                ang += m[k] * crate::math::cross(x[k], v[k])
                    + m[k] * dx * dx * 0.25 * (c[k][(1, 0)] - c[k][(0, 1)]);
                mass += m[k];
                com += x[k] * m[k];
            }
        };
        add(&p.vert.x, &p.vert.v, &p.vert.c, &p.vert.m);
        add(&p.quad.x, &p.quad.v, &p.quad.c, &p.quad.m);
        let s = self.stretches();
        let (mut lo, mut hi, mut sum) = (f64::INFINITY, f64::NEG_INFINITY, 0.0);
        for &x in &s {
            lo = lo.min(x);
            hi = hi.max(x);
            sum += x;
        }
        Diagnostics {
            time: self.time,
            steps: self.steps,
            kinetic_energy: ke,
            elastic_energy: self.elastic_energy(),
            potential_energy: pe,
            momentum: mom,
            angular_momentum: ang,
            min_stretch: lo,
            max_stretch: hi,
            mean_stretch: sum / s.len().max(1) as f64,
            center_of_mass: com / mass,
            total_mass: mass,
        }
    }
}
