//! Presets of real yarns for `[material] preset = "..."`: one table, each
//! value with its basis in `source` (the full list with ranges and
//! references is `docs/references.md`, section "Yarn material presets").
//!
//! Checked against a source: the aramid's fibre modulus and density (Kim
//! and Mai 1998, Table 5.10, from Morgan and Allred 1993). Typical values
//! from the ranges of Morton and Hearle (2008) and Bunsell (2018): the other
//! moduli and densities. Derived, not measured: every `EI` (the fibres
//! bending independently, `N E_f A_f^2 / (4 pi)`, or `E pi d^4 / 64` for the
//! monofilament; no measured yarn bending rigidity is used) and every
//! diameter of a multi-fibre yarn (from tex, fibre density and a packing
//! fraction). Estimates: the transverse moduli (no measurement).

use super::material_units::YarnProperties;

/// One preset: a yarn's engineering description.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Preset {
    /// Name as `[material] preset` takes it (kebab case).
    pub name: &'static str,
    /// One line for `yarnsim materials`.
    pub description: &'static str,
    /// Linear density, tex (g/km).
    pub tex: f64,
    /// Diameter, m.
    pub diameter: f64,
    /// Axial stiffness `EA`, N.
    pub ea: f64,
    /// Bending rigidity `EI`, N m^2.
    pub ei: f64,
    /// Yarn-on-yarn friction coefficient.
    pub friction: f64,
    /// Yarn-on-solid (steel, smooth obstacle) friction coefficient.
    pub friction_solid: f64,
    /// Transverse (compression) modulus of the yarn's cross-section, Pa
    /// (an estimate for every preset).
    pub transverse_modulus: f64,
    /// Where each value comes from (keys of `docs/references.md`).
    pub source: &'static str,
}

/// Initial transverse modulus of a multi-fibre yarn's cross-section, Pa:
/// an estimate (a loosely packed fibre bundle compresses by fibre
/// rearrangement first; no measured value is used).
const BUNDLE_TRANSVERSE: f64 = 5e6;

/// Every preset, in the order `yarnsim materials` lists them.
pub const PRESETS: [Preset; 6] = [
    Preset {
        name: "cotton-20tex",
        description: "cotton ring-spun yarn, 20 tex (Ne 30)",
        tex: 20.0,
        // yarn density 850 kg/m^3 (packing 0.56 of the fibre's 1520)
        diameter: 1.73e-4,
        // 2.5 N/tex x 20 tex
        ea: 50.0,
        // 111 fibres of 0.18 tex, E_f = 5 N/tex (7.6 GPa), bending freely
        ei: 9.4e-10,
        friction: 0.3,
        friction_solid: 0.25,
        transverse_modulus: BUNDLE_TRANSVERSE,
        source: "morton-hearle typical (modulus, densities); EI derived; friction gupta typical; E_T estimate",
    },
    Preset {
        name: "polyester-167dtex",
        description: "polyester (PET) continuous filament yarn, 167 dtex f48",
        tex: 16.7,
        // packing 0.6 of the fibre's 1380 kg/m^3
        diameter: 1.6e-4,
        // 10 N/tex x 16.7 tex
        ea: 167.0,
        // 48 filaments of 17.9 um, E_f = 13.8 GPa, bending freely
        ei: 3.35e-9,
        friction: 0.25,
        friction_solid: 0.25,
        transverse_modulus: BUNDLE_TRANSVERSE,
        source: "morton-hearle / bunsell typical (modulus, density); EI derived; friction gupta typical; E_T estimate",
    },
    Preset {
        name: "nylon66-mono-0.30mm",
        description: "nylon 6.6 monofilament, 0.30 mm (80.6 tex)",
        // pi (0.3 mm)^2 / 4 x 1140 kg/m^3
        tex: 80.6,
        diameter: 3.0e-4,
        // E = 2.5 GPa x 7.07e-8 m^2
        ea: 176.7,
        // E pi d^4 / 64
        ei: 9.94e-7,
        friction: 0.2,
        friction_solid: 0.2,
        // estimate: 0.4 of the axial 2.5 GPa (a drawn polymer, weakly anisotropic)
        transverse_modulus: 1.0e9,
        source: "bunsell typical (modulus, density); EI derived (solid rod); friction gupta typical; E_T estimate",
    },
    Preset {
        name: "kevlar29-1670dtex",
        description: "aramid Kevlar 29 filament yarn, 1670 dtex f1000",
        tex: 167.0,
        // packing 0.7 of the fibre's 1440 kg/m^3
        diameter: 4.6e-4,
        // fibre modulus 83 GPa over the fibre area 167e-6 / 1440 m^2 (57.6 N/tex)
        ea: 9626.0,
        // 1000 filaments of 12.2 um, bending freely
        ei: 8.9e-8,
        friction: 0.2,
        friction_solid: 0.2,
        transverse_modulus: BUNDLE_TRANSVERSE,
        source: "kim-mai 1998 table 5.10 (modulus, density: checked); EI derived; friction gupta typical; E_T estimate",
    },
    Preset {
        name: "wool-worsted-40tex",
        description: "wool worsted yarn, 40 tex (Nm 25)",
        tex: 40.0,
        // packing 0.55 of the fibre's 1310 kg/m^3
        diameter: 2.66e-4,
        // 1.2 N/tex x 40 tex
        ea: 48.0,
        // 88 fibres of 21 um, E_f = 2.5 GPa, bending freely
        ei: 2.1e-9,
        // across the scales' directional effect (with 0.1-0.2, against 0.3-0.5)
        friction: 0.3,
        friction_solid: 0.25,
        transverse_modulus: BUNDLE_TRANSVERSE,
        source: "morton-hearle typical (modulus, density); EI derived; friction howell-mieszkis-tabor typical; E_T estimate",
    },
    Preset {
        name: "polyester-spun-thread-27tex",
        description: "spun polyester sewing thread, tex 27 (lubricated finish)",
        tex: 27.0,
        // packing 0.65 of the fibre's 1380 kg/m^3
        diameter: 1.96e-4,
        // 3 N/tex x 27 tex
        ea: 81.0,
        // 208 fibres of 1.3 dtex, E_f = 13.8 GPa, bending freely
        ei: 2.0e-9,
        friction: 0.15,
        friction_solid: 0.12,
        transverse_modulus: BUNDLE_TRANSVERSE,
        source: "morton-hearle typical (modulus, density); EI derived; friction gupta typical (finished thread); E_T estimate",
    },
];

/// The preset named `name`.
pub fn preset(name: &str) -> Option<&'static Preset> {
    PRESETS.iter().find(|p| p.name == name)
}

/// Every preset's name, in table order.
pub fn preset_names() -> Vec<&'static str> {
    PRESETS.iter().map(|p| p.name).collect()
}

impl Preset {
    /// The preset as a yarn in a sheet of touching yarns (spacing = diameter).
    pub fn properties(&self) -> YarnProperties {
        YarnProperties {
            tex: self.tex,
            diameter: self.diameter,
            ea: self.ea,
            ei: self.ei,
            friction: Some(self.friction),
            friction_solid: Some(self.friction_solid),
            spacing: self.diameter,
            transverse_modulus: Some(self.transverse_modulus),
            shear_modulus: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_kebab_case() {
        let names = preset_names();
        for (i, n) in names.iter().enumerate() {
            assert!(
                n.chars()
                    .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-' || c == '.'),
                "{n}"
            );
            assert!(!names[i + 1..].contains(n), "{n} twice");
        }
    }

    #[test]
    fn derived_values_follow_from_the_stated_inputs() {
        // the monofilament: tex = rho A, EA = E A, EI = E pi d^4 / 64 (rho 1140
        // kg/m^3, E 2.5 GPa); 0.2 % for the rounding of the table
        let n = preset("nylon66-mono-0.30mm").unwrap();
        let a = std::f64::consts::PI * n.diameter * n.diameter / 4.0;
        let rel = |x: f64, y: f64| ((x - y) / y).abs();
        assert!(rel(n.tex, 1140.0 * a * 1e6) < 2e-3);
        assert!(rel(n.ea, 2.5e9 * a) < 2e-3);
        assert!(rel(n.ei, 2.5e9 * a * a / (4.0 * std::f64::consts::PI)) < 2e-3);
        // the aramid: EA = 83 GPa over the fibre area tex 1e-6 / 1440
        let k = preset("kevlar29-1670dtex").unwrap();
        assert!(rel(k.ea, 83e9 * k.tex * 1e-6 / 1440.0) < 2e-3);
        // every preset's axial wave speed sqrt(EA / mu) within the sonic
        // speeds of textile fibres, sqrt(E / rho): about 1 km/s (wool,
        // nylon) to 7.6 km/s (aramid)
        for p in PRESETS {
            let c = p.properties().wave_speed();
            assert!((900.0..8000.0).contains(&c), "{}: {c} m/s", p.name);
        }
    }
}
