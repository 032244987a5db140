//! How particles take their velocity and affine matrix back from the grid
//! (the particle side of grid-to-particle).
//!
//! * [`Transfer::Apic`] (Jiang et al. 2015, the reference Taichi implementation's choice): `v` and `C`
//!   are replaced by the grid's interpolation. Whatever part of a particle's
//!   velocity the grid cannot hold (the non-affine part) is dropped at every
//!   transfer, so the dissipation grows with the number of substeps and a
//!   trajectory at a fixed grid does not converge as `dt` shrinks.
//! * [`Transfer::Flip`] with ratio `r`: `v <- r (v + dv) + (1 - r) v_grid`
//!   and `C <- r (C + dC) + (1 - r) C_grid`, where `dv`, `dC` interpolate the
//!   grid's change over the substep. `r = 1` (pure FLIP for `v` and `C`)
//!   keeps each particle's own velocity and adds only what the forces did:
//!   no per-transfer dissipation, first order in `dt`. `r < 1` blends in
//!   APIC's damping at a rate `(1 - r)` per substep. With
//!   `transfer.flip_time = tau` instead, each substep of `dt` takes `r =
//!   exp(-dt / tau)` ([`Transfer::at_step`]): the particles' own velocity
//!   relaxes to the grid's over `tau` seconds whatever the step, where a
//!   fixed `r < 1` damps more the more substeps a second takes.
//!
//! In every scheme positions move with the grid velocity (`x += dt v_grid`)
//! and the material frame with the grid's velocity gradient, so only the
//! momentum carried to the next substep differs.

use crate::math::{Mat2, Vec2};

/// The grid-to-particle velocity update; see the module documentation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Transfer {
    /// APIC: `v`, `C` from the grid.
    Apic,
    /// FLIP / APIC blend with FLIP ratio in `[0, 1]`.
    Flip {
        /// Share of FLIP in the blend, in `[0, 1]`.
        ratio: f64,
    },
}

impl Transfer {
    /// Whether the grid must keep its velocity change (`dv`) for this scheme.
    pub fn needs_delta(&self) -> bool {
        matches!(self, Transfer::Flip { .. })
    }

    /// The transfer of one substep of `dt`: under FLIP with a relaxation
    /// time `flip_time` (s) the ratio `exp(-dt / flip_time)`, so that what
    /// the particles keep of their own velocity decays by `exp(-t /
    /// flip_time)` over a time `t` whatever the step; otherwise `self`.
    pub fn at_step(self, dt: f64, flip_time: Option<f64>) -> Transfer {
        match (self, flip_time) {
            (Transfer::Flip { .. }, Some(tau)) => Transfer::Flip {
                ratio: (-dt / tau).exp(),
            },
            (t, _) => t,
        }
    }

    /// The FLIP ratio (0 for APIC).
    pub fn flip_ratio(&self) -> f64 {
        match *self {
            Transfer::Apic => 0.0,
            Transfer::Flip { ratio } => ratio,
        }
    }
}

/// FLIP / APIC blend of one particle: from its own `(v, c)`, the grid's new
/// `(vn, cn)` and the grid's change `(dv, dc)` at the particle.
#[inline(always)]
pub fn blend(ratio: f64, v: &mut Vec2, c: &mut Mat2, vn: Vec2, cn: Mat2, dv: Vec2, dc: Mat2) {
    if ratio == 1.0 {
        *v += dv;
        *c += dc;
    } else {
        let keep = 1.0 - ratio;
        *v = (*v + dv) * ratio + vn * keep;
        *c = (*c + dc) * ratio + cn * keep;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// With a relaxation time the damping per simulated time is the
    /// step's to round-off: `n` substeps of `dt / n` keep what one of `dt`
    /// keeps; a fixed ratio and APIC are left as they are.
    #[test]
    fn relaxation_time_damps_per_second_not_per_step() {
        let flip = Transfer::Flip { ratio: 1.0 };
        let tau = 4e-3;
        let one = flip.at_step(4e-5, Some(tau)).flip_ratio();
        assert!((one - (-0.01f64).exp()).abs() < 1e-15);
        for n in [2, 4, 8] {
            let r = flip.at_step(4e-5 / n as f64, Some(tau)).flip_ratio();
            assert!(
                (r.powi(n) - one).abs() < 1e-14,
                "{n} substeps: {}",
                r.powi(n)
            );
        }
        assert_eq!(flip.at_step(4e-5, None), flip);
        assert_eq!(Transfer::Apic.at_step(4e-5, Some(tau)), Transfer::Apic);
    }
}
