//! The one conversion between a yarn's engineering description (per yarn:
//! tex, diameter, EA, EI, ...) and the 2D model's material (per metre of
//! depth: `k`, `density`, `bending`, `youngs_modulus`, `gamma`).
//!
//! The 2D model is a sheet of parallel yarns one metre deep, `1 / s` yarns
//! per metre at the spacing `s`. A quadrature particle's volume is its
//! segment's rest length `l0` (`crate::mpm::machinery::particles`), its
//! mass `density l0`, its energy `l0 psi` with
//! `psi = 1/2 k (r11 - 1)^2 + 1/2 gamma r12^2 + 1/2 (2 mu + lambda) (log r22)^2`
//! (`crate::mpm::laws::constitutive`); the bending energy is
//! `int bending / 2 kappa^2 ds` (`crate::mpm::laws::vertex_forces`). A
//! metre of depth holds `1 / s` yarns, each of axial stiffness `EA`, line
//! density `mu = tex 1e-6` kg/m and bending rigidity `EI`, so
//!
//! ```text
//! k = EA / s            (N/m per m of depth)
//! density = mu / s      (kg/m^2)
//! bending = EI / s      (N m)
//! ```
//!
//! and the axial wave speed `sqrt(k / density) = sqrt(EA / mu)` does not
//! depend on `s`. The cross-section (the model's `youngs_modulus` `E`,
//! with `mu = 0.4 E`, `lambda = 0.6 E`, and `gamma`) is the yarn's
//! transverse modulus `E_T` over its area `A = pi d^2 / 4`, and the shear
//! modulus `G` (default `0.4 E_T`, the model's own `mu / E`) over the same
//! area: `E = E_T A / s`, `gamma = G A / s`. No measured transverse
//! modulus of a yarn backs this: it is an estimate (see
//! `docs/yarn-materials.md`).
//!
//! A force the model reports per metre of depth (a pin's reaction) is
//! `1 / s` yarns' worth: one yarn carries `F s`.

use std::f64::consts::PI;

/// Kilograms per metre in one tex (1 g per km).
pub const KG_PER_M_PER_TEX: f64 = 1e-6;

/// The default shear modulus of the cross-section as a fraction of its
/// transverse modulus: the model's own `mu = 0.4 E`.
pub const SHEAR_OF_TRANSVERSE: f64 = 0.4;

/// One yarn in engineering units, every value resolved.
#[derive(Clone, Debug, PartialEq)]
pub struct YarnProperties {
    /// Linear density in tex (g/km).
    pub tex: f64,
    /// Diameter in m.
    pub diameter: f64,
    /// Axial stiffness `EA` in N.
    pub ea: f64,
    /// Bending rigidity `EI` in N m^2 (0: no bending).
    pub ei: f64,
    /// Yarn-on-yarn friction coefficient, if known.
    pub friction: Option<f64>,
    /// Yarn-on-solid friction coefficient (obstacles), if known.
    pub friction_solid: Option<f64>,
    /// Spacing of the sheet's yarns in the depth direction, m.
    pub spacing: f64,
    /// Transverse (compression) modulus `E_T` in Pa, if known.
    pub transverse_modulus: Option<f64>,
    /// Shear modulus `G` of the cross-section in Pa, if known (default
    /// [`SHEAR_OF_TRANSVERSE`] `E_T`).
    pub shear_modulus: Option<f64>,
}

/// The sheet of yarns of diameter `d` at spacing `s`: each conversion of a
/// per-yarn value to its value per metre of depth, written once (the whole
/// description's [`YarnProperties::model`] and a partial one's, which
/// converts the values it has).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sheet {
    /// Yarn diameter `d`, m.
    pub diameter: f64,
    /// Spacing `s` of the sheet's yarns, m.
    pub spacing: f64,
}

impl Sheet {
    /// `k = EA / s`, N/m.
    pub fn k(&self, ea: f64) -> f64 {
        ea / self.spacing
    }
    /// `density = tex 1e-6 / s`, kg/m^2.
    pub fn density(&self, tex: f64) -> f64 {
        tex * KG_PER_M_PER_TEX / self.spacing
    }
    /// `bending = EI / s`, N m.
    pub fn bending(&self, ei: f64) -> f64 {
        ei / self.spacing
    }
    /// A cross-section modulus (Pa) over the yarn's area per metre of
    /// depth, `M A / s` (N/m): the model's `youngs_modulus` from `E_T`,
    /// its `gamma` from `G`.
    pub fn cross_section(&self, modulus: f64) -> f64 {
        let d = self.diameter;
        modulus * (PI * d * d / 4.0 / self.spacing)
    }
}

/// The cross-section's shear modulus: the given one, else
/// [`SHEAR_OF_TRANSVERSE`] times the transverse modulus.
pub fn shear_or_default(shear: Option<f64>, transverse: Option<f64>) -> Option<f64> {
    shear.or(transverse.map(|e| SHEAR_OF_TRANSVERSE * e))
}

/// The model parameters (per metre of depth) one engineering description
/// gives; `None` where the description has nothing to say.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelParameters {
    /// Fiber stretch stiffness `k`, N/m.
    pub k: f64,
    /// Density, kg/m^2.
    pub density: f64,
    /// Bending stiffness, N m.
    pub bending: f64,
    /// Young's modulus of the cross-section, N/m.
    pub youngs_modulus: Option<f64>,
    /// Shear stiffness `gamma`, N/m.
    pub gamma: Option<f64>,
}

impl YarnProperties {
    /// Line density `mu` in kg/m.
    pub fn line_density(&self) -> f64 {
        self.tex * KG_PER_M_PER_TEX
    }

    /// Cross-section area `pi d^2 / 4` in m^2.
    pub fn area(&self) -> f64 {
        PI * self.diameter * self.diameter / 4.0
    }

    /// Yarns per metre of depth, `1 / s`.
    pub fn yarns_per_metre(&self) -> f64 {
        1.0 / self.spacing
    }

    /// Specific modulus in N/tex, `EA / tex`.
    pub fn specific_modulus(&self) -> f64 {
        self.ea / self.tex
    }

    /// Axial wave speed `sqrt(EA / mu)` in m/s (independent of the spacing).
    pub fn wave_speed(&self) -> f64 {
        (self.ea / self.line_density()).sqrt()
    }

    /// The shear modulus in Pa: the given one, else [`SHEAR_OF_TRANSVERSE`]
    /// times the transverse modulus.
    pub fn shear(&self) -> Option<f64> {
        shear_or_default(self.shear_modulus, self.transverse_modulus)
    }

    /// The sheet these yarns form.
    pub fn sheet(&self) -> Sheet {
        Sheet {
            diameter: self.diameter,
            spacing: self.spacing,
        }
    }

    /// The model's parameters per metre of depth (module documentation).
    pub fn model(&self) -> ModelParameters {
        let sheet = self.sheet();
        ModelParameters {
            k: sheet.k(self.ea),
            density: sheet.density(self.tex),
            bending: sheet.bending(self.ei),
            youngs_modulus: self.transverse_modulus.map(|e| sheet.cross_section(e)),
            gamma: self.shear().map(|g| sheet.cross_section(g)),
        }
    }

    /// The engineering description of model parameters at spacing `s` with
    /// diameter `d`: the inverse of [`YarnProperties::model`].
    pub fn from_model(m: &ModelParameters, diameter: f64, spacing: f64) -> YarnProperties {
        let area = PI * diameter * diameter / 4.0;
        YarnProperties {
            tex: m.density * spacing / KG_PER_M_PER_TEX,
            diameter,
            ea: m.k * spacing,
            ei: m.bending * spacing,
            friction: None,
            friction_solid: None,
            spacing,
            transverse_modulus: m.youngs_modulus.map(|e| e * spacing / area),
            shear_modulus: m.gamma.map(|g| g * spacing / area),
        }
    }
}

/// The force one yarn carries, N, of a force per metre of depth at the
/// sheet spacing `spacing` (m): `F s`.
pub fn per_yarn(force_per_depth: f64, spacing: f64) -> f64 {
    force_per_depth * spacing
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The polyester filament preset's numbers, written out.
    fn yarn(spacing: f64) -> YarnProperties {
        YarnProperties {
            tex: 16.7,
            diameter: 1.6e-4,
            ea: 167.0,
            ei: 3.4e-9,
            friction: Some(0.25),
            friction_solid: Some(0.25),
            spacing,
            transverse_modulus: Some(5e7),
            shear_modulus: None,
        }
    }

    fn close(a: f64, b: f64) -> bool {
        // round-off of a product and a quotient: 1e-14 relative
        (a - b).abs() <= 1e-14 * a.abs().max(b.abs())
    }

    #[test]
    fn engineering_to_model_and_back_round_trips() {
        for s in [1.6e-4, 3.2e-4, 1e-3] {
            let y = yarn(s);
            let m = y.model();
            let back = YarnProperties::from_model(&m, y.diameter, s);
            assert!(close(back.tex, y.tex), "{} {}", back.tex, y.tex);
            assert!(close(back.ea, y.ea));
            assert!(close(back.ei, y.ei));
            assert!(close(back.transverse_modulus.unwrap(), 5e7));
            assert!(close(back.shear_modulus.unwrap(), 0.4 * 5e7));
        }
    }

    #[test]
    fn model_to_engineering_and_back_round_trips() {
        // the reference material of Jiang et al. 2017 (k 1000, gamma 500,
        // E 1000, bending 1e-3, density 1) at a spacing of 2 mm, d 1 mm
        let m = ModelParameters {
            k: 1000.0,
            density: 1.0,
            bending: 1e-3,
            youngs_modulus: Some(1000.0),
            gamma: Some(500.0),
        };
        let y = YarnProperties::from_model(&m, 1e-3, 2e-3);
        let back = y.model();
        assert!(close(back.k, m.k));
        assert!(close(back.density, m.density));
        assert!(close(back.bending, m.bending));
        assert!(close(back.youngs_modulus.unwrap(), 1000.0));
        assert!(close(back.gamma.unwrap(), 500.0));
        // the converted yarn: EA = k s = 2 N, mu = density s = 2 g/m
        assert!(close(y.ea, 2.0) && close(y.tex, 2000.0));
    }

    #[test]
    fn the_wave_speed_does_not_depend_on_the_spacing() {
        let c = yarn(1.0).wave_speed();
        // sqrt(EA / mu) = sqrt(167 / 16.7e-6) = sqrt(1e7) m/s
        assert!(close(c, 1e7f64.sqrt()));
        for s in [1e-4, 1.6e-4, 7e-4, 0.01, 1.0] {
            let m = yarn(s).model();
            let model_c = (m.k / m.density).sqrt();
            // 1e-14 relative: the quotient k / density cancels s exactly
            // up to round-off
            assert!(close(model_c, c), "s {s}: {model_c} against {c}");
        }
    }

    #[test]
    fn more_yarns_per_metre_scale_the_model_and_not_the_yarn() {
        // halving the spacing doubles every per-depth stiffness and mass
        let (a, b) = (yarn(2e-4).model(), yarn(4e-4).model());
        assert!(close(a.k, 2.0 * b.k));
        assert!(close(a.density, 2.0 * b.density));
        assert!(close(a.bending, 2.0 * b.bending));
        assert!(close(
            a.youngs_modulus.unwrap(),
            2.0 * b.youngs_modulus.unwrap()
        ));
        // a force per metre of depth is 1 / s yarns' worth
        assert!(close(per_yarn(10.0, 2e-4), 2e-3));
    }
}
