//! The yarn MPM's stable substep: the CFL / elastic-wave bound that the
//! library, the CLI, the FMU and the stability evidence share.
//!
//! The substep is explicit: grid velocities are updated from the elastic
//! forces and then carried back to the particles. Two limits apply.
//!
//! * **Elastic waves.** The energy density `psi` (Pa, per unit area of the
//!   2D cross-section, unit thickness) has the stiffnesses `k` (fiber
//!   stretch), `gamma` (fiber shear) and `2 mu + lambda = 1.4 E` (normal
//!   compression, [`YarnEnergy::normal`]); the mass per unit area is the line
//!   density `rho` (kg/m per unit thickness, see [`crate::mpm::machinery::particles`]: a
//!   segment of rest length `l0` has mass `rho l0` and volume `l0`). The
//!   fastest wave runs at `c = sqrt(max(k, gamma, 2 mu + lambda) / rho)`.
//!   A wave must not cross more than one grid cell `dx` per substep (the
//!   grid couples only neighbouring nodes), which gives `dt <= dx / c`.
//!   A cross-section compressed to `r22 < 1` is stiffer than at rest: the
//!   energy `1/2 (2 mu + lambda) (log r22)^2` has the tangent
//!   `(2 mu + lambda) (1 - log r22) / r22^2` (6.8x the rest value at
//!   `r22 = 0.5`, 65x at 0.2), so [`YarnSim::stable_dt`] takes the normal
//!   stiffness at the most compressed quadrature particle
//!   ([`YarnSim::min_r22`], [`explicit_wave_speed`]). Without it, `dt = "auto"`
//!   stepped a bundle whose yarns were crushed against each other under
//!   the rest bound, above the crushed one, and it diverged.
//! * **Advection.** A particle must not move more than one cell per substep
//!   (the check in the vertex gather that reports divergence):
//!   `dt <= dx / |v|`.
//!
//! Together (Courant number 1): `dt <= dx / (c + |v|max)`. The bound is
//! conservative where it was measured (`yarnsim bench stress`, README
//! "Stability stress"): on yarn-small the largest stable substep is 1.5 to
//! 1.8 times the bound when `k` or `E` change by 100x, and it scales as
//! `1/sqrt(k)` and `1/sqrt(E)` as the bound does; a stiffer `gamma` hardly
//! lowers the real limit (the return mapping caps the shear stress), so
//! there the bound is pessimistic (up to 10x).
//! * **Bending.** The bending energy `B/2 kappa^2` (discrete elastic rods,
//!   `crate::mpm::laws::vertex_forces`) gives flexural waves with `omega = sqrt(B / rho) q^2`;
//!   at the grid's shortest wavelength (`q = 2 / dx`) an explicit step needs
//!   `dt <= 2 / omega = dx^2 sqrt(rho / B) / 2`. It is far above the
//!   elastic bound at the built-in values (B = 1e-3 N m on 256^2: 7.6e-3 s
//!   against 1.6e-4 s) but decides for stiff rods on fine grids.
//!
//! Velocities the run will reach later (gravity, attractor,
//! impacts) are not known in advance: [`YarnSim::stable_dt`] uses the
//! current largest particle speed, so at initialization it is the elastic
//! bound of a scene at rest, a necessary condition, not a guarantee.
//!
//! **Implicit integrator** (`[time] integrator = "implicit"`, backward
//! Euler on the grid velocities, `crate::mpm::implicit_grid`): the elastic
//! forces enter the solve, so neither the elastic-wave nor the bending
//! bound applies. What remains is advection: a particle must not cross
//! more than one cell per substep (the gather's check), so
//! [`YarnSim::stable_dt`] is `COURANT dx / |v|max` ([`implicit_stable_dt`];
//! infinite at rest) and `dt = "auto"` takes the substep over which the
//! fastest particle, gaining `|g| dt` from gravity, moves `safety dx`
//! ([`implicit_auto_dt`]; `safety * dx / |v|max` without gravity), capped
//! by `dt_max`, `dt_max` defaulting to the scene's `frame_dt` under the
//! implicit integrator (no default cap under the explicit one). Accuracy,
//! not stability, decides a good cap: backward Euler damps and slows a
//! mode of angular frequency `omega` by terms in `(omega dt)^2` (measured on
//! the hanging chain in `tests/implicit.rs`).
//!
//! **Axial springs implicit** (`[time] axial = "implicit"` under the
//! explicit integrator, `crate::mpm::driver::axial`): the fibre-stretch
//! term `k` takes a backward Euler step on the vertices, so its wave leaves
//! the elastic bound: `c = sqrt(max(gamma, 2 mu + lambda) / rho)`
//! ([`explicit_wave_speed`]); the bending and advection bounds stay.
//!
//! `[time] dt = "auto"` applies the bound in every substep instead:
//! [`YarnSim::auto_dt`] is `min(safety * stable_dt, dt_max)` of the state
//! the substep starts from (default safety
//! [`crate::scene::DEFAULT_SAFETY`], measured on the reference scene), and
//! [`YarnSim::advance_to`] lands on frame and communication times exactly.

use crate::mpm::laws::constitutive::YarnEnergy;
use crate::mpm::YarnSim;
use crate::scene::{Axial, Material};

/// Courant number of [`stable_dt`]: 1, the cell-crossing limit itself (the
/// measured limits lie above it, see the module docs).
pub const COURANT: f64 = 1.0;

/// The fastest elastic wave speed `c = sqrt(max(k, gamma, 2 mu + lambda) / rho)`
/// of a material, in m/s.
pub fn wave_speed(m: &Material) -> f64 {
    explicit_wave_speed(m, Axial::Explicit, 1.0)
}

/// The fastest elastic wave the explicit step carries, in m/s, with the
/// cross-section compressed to `r22` (its smallest value over the
/// quadrature particles; `r22 >= 1` is the cross-section at rest): the
/// normal stiffness is the tangent [`YarnEnergy::normal_tangent`], up to
/// 65x the rest value at `r22 = 0.2`; under `axial = "implicit"` without
/// the fibre wave `sqrt(k / rho)` (`crate::mpm::driver::axial` steps the
/// `k` term implicitly): `sqrt(max(gamma, n(r22)) / rho)`.
pub fn explicit_wave_speed(m: &Material, axial: Axial, r22: f64) -> f64 {
    let e = YarnEnergy::from_material(m);
    let k = if axial.is_implicit() { 0.0 } else { e.k };
    (k.max(e.gamma).max(e.normal_tangent(r22)) / m.density).sqrt()
}

/// The largest stable substep in s for a grid spacing `dx` (m) and a largest
/// particle speed `v_max` (m/s): `COURANT dx / (c + v_max)`, and with
/// bending also `dx^2 sqrt(rho / B) / 2`.
pub fn stable_dt(m: &Material, dx: f64, v_max: f64) -> f64 {
    explicit_stable_dt(m, Axial::Explicit, dx, v_max, 1.0)
}

/// [`stable_dt`] with the wave speed of [`explicit_wave_speed`]: under
/// `axial = "implicit"` the fibre wave does not bound the substep, and a
/// cross-section crushed to `r22 < 1` lowers the bound.
pub fn explicit_stable_dt(m: &Material, axial: Axial, dx: f64, v_max: f64, r22: f64) -> f64 {
    let elastic = COURANT * dx / (explicit_wave_speed(m, axial, r22) + v_max.abs());
    if m.bending > 0.0 {
        elastic.min(0.5 * dx * dx * (m.density / m.bending).sqrt())
    } else {
        elastic
    }
}

/// The implicit integrator's substep bound in s: the advection limit
/// `COURANT dx / |v|max` alone (infinite for `v_max = 0`); the elastic and
/// bending bounds of [`stable_dt`] are for the explicit step only.
pub fn implicit_stable_dt(dx: f64, v_max: f64) -> f64 {
    COURANT * dx / v_max.abs()
}

/// The implicit integrator's adaptive substep in s (`dt = "auto"`, before
/// the cap): the largest `dt` over which a particle that starts at
/// `v_max` and gains `accel dt` (m/s^2: gravity) crosses at most
/// `safety COURANT dx`, `(v_max + accel dt) dt = safety COURANT dx`, i.e.
/// `dt = 2 h / (v_max + sqrt(v_max^2 + 4 accel h))`, `h = safety COURANT
/// dx`. The gather checks the speed at the end of the substep: from rest
/// under gravity `safety * implicit_stable_dt` would take the cap, and a
/// falling yarn would pass one cell within it. With `accel = 0` it is
/// `safety * implicit_stable_dt`.
pub fn implicit_auto_dt(dx: f64, v_max: f64, accel: f64, safety: f64) -> f64 {
    let v = v_max.abs();
    if accel == 0.0 {
        return safety * implicit_stable_dt(dx, v);
    }
    let h = safety * COURANT * dx;
    2.0 * h / (v + (v * v + 4.0 * accel.abs() * h).sqrt())
}

/// Why an explicit run without the return mapping diverged within its
/// step's bound, as the CLI and the FMU report it ([`YarnSim::diverges_without_plasticity`]).
/// Measured: the built-in bundle with `material.plasticity = false`
/// diverges at its landing (t = 0.126 to 0.147 s) at dt 4e-5 and 1e-5 and
/// under `"auto"` at safety 0.8, 0.4 and 0.1
/// (`docs/performance/bundle-convergence.md`).
pub const WITHOUT_PLASTICITY: &str = "material.plasticity = false keeps every cross-section \
     that has opened (no return mapping of Jiang et al. 2017: r22 > 1 is kept), and yarns that \
     land on each other or on an obstacle may then diverge whatever the step (the built-in \
     bundle does at dt 4e-5 and 1e-5 and under dt = \"auto\" at time.safety 0.8, 0.4 and 0.1); \
     set material.plasticity = true";

impl YarnSim {
    /// Whether a divergence of this run is the missing return mapping's
    /// rather than its step's ([`WITHOUT_PLASTICITY`]): the explicit
    /// integrator on a material with a cross-section or shear stiffness
    /// and `plasticity = false`, stepping under `dt = "auto"` or at a
    /// fixed `dt` within the bound of the scene at rest (above it the
    /// step is the first suspect).
    pub fn diverges_without_plasticity(&self) -> bool {
        let scene = self.scene();
        let m = &scene.material;
        if self.is_implicit() || m.plasticity || (m.youngs_modulus <= 0.0 && m.gamma <= 0.0) {
            return false;
        }
        match scene.time.dt.fixed() {
            None => true,
            Some(dt) => {
                let bound = explicit_stable_dt(m, scene.time.axial, scene.dx(), 0.0, 1.0);
                dt <= bound * (1.0 + 1e-9)
            }
        }
    }

    /// The largest particle speed now, in m/s (vertices and quadrature
    /// particles). A parallel maximum: the same value for any thread count
    /// (the maximum does not depend on the order of the reduction).
    pub fn max_speed(&self) -> f64 {
        use rayon::prelude::*;
        let p = self.particles();
        let max = |v: &[crate::math::Vec2]| {
            v.par_iter()
                .with_min_len(4096)
                .map(|v| v.norm_squared())
                .reduce(|| 0.0, f64::max)
        };
        max(&p.vert.v).max(max(&p.quad.v)).sqrt()
    }

    /// The stable substep bound of the current state
    /// ([`stable_dt`] with this scene's material, grid and the current
    /// largest particle speed; under the implicit integrator
    /// [`implicit_stable_dt`], the advection limit alone). The
    /// simulation's own `dt()` should not exceed it.
    pub fn stable_dt(&self) -> f64 {
        if self.is_implicit() {
            return implicit_stable_dt(self.advection_length(), self.max_speed());
        }
        let scene = self.scene();
        explicit_stable_dt(
            &scene.material,
            scene.time.axial,
            self.grid_geom().dx,
            self.max_speed(),
            self.min_r22(),
        )
    }

    /// The most compressed cross-section now: the smallest `r22` of the
    /// quadrature particles' `qr(d / l0)`, `r22 = det(d) / (l0 |d1|)`
    /// (1 without quadrature particles). A parallel minimum: the same
    /// value for any thread count.
    pub fn min_r22(&self) -> f64 {
        use rayon::prelude::*;
        let q = &self.particles().quad;
        q.d.par_iter()
            .zip(q.l0.par_iter())
            .with_min_len(4096)
            .map(|(d, &l0)| {
                let d1 = (d[(0, 0)] * d[(0, 0)] + d[(1, 0)] * d[(1, 0)]).sqrt();
                let det = d[(0, 0)] * d[(1, 1)] - d[(0, 1)] * d[(1, 0)];
                if d1 > 0.0 {
                    det / (l0 * d1)
                } else {
                    1.0
                }
            })
            .reduce(|| 1.0, f64::min)
    }
}
