//! `[material]` of a yarn scene: the model's parameters per metre of depth
//! (`k`, `gamma`, `youngs_modulus`, `friction`, `bending`, `density`,
//! `plasticity`), given directly or derived from a yarn's engineering
//! description (`preset`, `tex`, `diameter`, `EA` or `specific_modulus`,
//! `EI`, `friction_solid`, `spacing`, `transverse_modulus`,
//! `shear_modulus`) by [`super::material_units`]. A model field given next
//! to the description overrides the value derived from it; a description
//! field overrides the preset's.

use serde::de::Error as _;
use serde::{Deserialize, Deserializer, Serialize};

use super::material_units::{shear_or_default, ModelParameters, Sheet, YarnProperties};
use super::presets::{preset, preset_names};
use crate::scene::readers::{nonnegative, positive};

/// Material of the yarns, per metre of depth: the 2D model is a sheet of
/// parallel yarns one metre deep, so stiffnesses are in N/m (J/m^2, the
/// energy density over the plane), the bending stiffness in N m and the
/// density in kg/m^2. A file may give a yarn's description instead
/// ([`YarnMaterial`]); these fields are then derived from it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "MaterialFile", into = "MaterialFile")]
pub struct Material {
    /// Fiber stretch stiffness `k` (N/m per metre of depth).
    pub k: f64,
    /// Fiber shear stiffness `gamma` (N/m per metre of depth).
    pub gamma: f64,
    /// Young's modulus `E` of the cross-section (N/m per metre of depth);
    /// `mu = 0.4 E`, `lambda = 0.6 E`.
    pub youngs_modulus: f64,
    /// Mohr-Coulomb friction coefficient `c_f` (dimensionless).
    pub friction: f64,
    /// Bending stiffness `B` of the rod in N m^2 per m of depth (N m): the
    /// energy is `int B / 2 kappa^2 ds` (discrete elastic rods, see
    /// `crate::mpm::laws::vertex_forces`). 0 disables bending.
    pub bending: f64,
    /// Density in kg/m^2: mass per metre of yarn per metre of depth.
    pub density: f64,
    /// Mohr-Coulomb return mapping on (default) or off.
    pub plasticity: bool,
    /// The yarn's engineering description as the file gives it, if any.
    pub yarn: Option<YarnMaterial>,
}

impl Material {
    /// Lame `mu = 0.4 E`.
    pub fn mu(&self) -> f64 {
        0.4 * self.youngs_modulus
    }
    /// Lame `lambda = 0.6 E`.
    pub fn lambda(&self) -> f64 {
        0.6 * self.youngs_modulus
    }

    /// The sheet spacing `s` in m where the material is given per yarn.
    pub fn spacing(&self) -> Option<f64> {
        self.per_yarn().map(|p| p.spacing)
    }

    /// The yarn's diameter `d` in m, where the description (or its preset)
    /// gives one: contact keeps a yarn's centre line `d / 2` from an
    /// obstacle's surface and two yarns' centre lines `d` apart
    /// (`crate::mpm::laws::contact`, `crate::mpm::laws::fields`).
    pub fn diameter(&self) -> Option<f64> {
        self.yarn.as_ref()?.partial().ok()?.diameter
    }

    /// The yarn-on-solid friction of the description (or its preset), which
    /// obstacles without their own `friction` take.
    pub fn friction_solid(&self) -> Option<f64> {
        self.yarn.as_ref()?.partial().ok()?.friction_solid
    }

    /// One yarn of this material in engineering units, where the material
    /// is given per yarn: the description's values, and the rest from the
    /// model's (`EA = k s`, `tex = density s / 1e-6`, `EI = bending s`,
    /// `E_T = E s / A`, `G = gamma s / A`). `None` for a material given per
    /// metre of depth only, or a description without a diameter.
    pub fn per_yarn(&self) -> Option<YarnProperties> {
        let p = self.yarn.as_ref()?.partial().ok()?;
        let d = p.diameter?;
        let model = ModelParameters {
            k: self.k,
            density: self.density,
            bending: self.bending,
            youngs_modulus: Some(self.youngs_modulus),
            gamma: Some(self.gamma),
        };
        Some(YarnProperties {
            friction: Some(self.friction),
            friction_solid: p.friction_solid,
            ..YarnProperties::from_model(&model, d, p.spacing.unwrap_or(d))
        })
    }
}

/// A yarn's engineering description in `[material]`, as the file gives it
/// (every field optional; the preset's values fill the fields not given).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct YarnMaterial {
    /// A preset name ([`super::presets::PRESETS`]).
    pub preset: Option<String>,
    /// Linear density, tex (g/km).
    pub tex: Option<f64>,
    /// Diameter, m.
    pub diameter: Option<f64>,
    /// Axial stiffness `EA`, N.
    pub ea: Option<f64>,
    /// Axial stiffness per tex, N/tex (instead of `EA`).
    pub specific_modulus: Option<f64>,
    /// Bending rigidity `EI`, N m^2.
    pub ei: Option<f64>,
    /// Yarn-on-solid friction coefficient.
    pub friction_solid: Option<f64>,
    /// Spacing of the sheet's yarns, m (default: the diameter).
    pub spacing: Option<f64>,
    /// Transverse modulus of the cross-section, Pa.
    pub transverse_modulus: Option<f64>,
    /// Shear modulus of the cross-section, Pa (default 0.4 `transverse_modulus`).
    pub shear_modulus: Option<f64>,
}

/// What a description (with its preset) says, before the model's fields
/// fill the gaps; the values derived from it depend on nothing else, so a
/// scene written back reads to the same parameters.
#[derive(Clone, Debug, Default, PartialEq)]
struct Partial {
    tex: Option<f64>,
    diameter: Option<f64>,
    ea: Option<f64>,
    ei: Option<f64>,
    friction: Option<f64>,
    friction_solid: Option<f64>,
    spacing: Option<f64>,
    transverse_modulus: Option<f64>,
    shear_modulus: Option<f64>,
}

/// The model parameters a description derives, each where it can.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Derived {
    k: Option<f64>,
    gamma: Option<f64>,
    youngs_modulus: Option<f64>,
    friction: Option<f64>,
    bending: Option<f64>,
    density: Option<f64>,
}

impl YarnMaterial {
    fn is_empty(&self) -> bool {
        *self == YarnMaterial::default()
    }

    fn partial(&self) -> Result<Partial, String> {
        let base = match &self.preset {
            Some(name) => Some(preset(name).ok_or_else(|| unknown_preset(name))?),
            None => None,
        };
        let tex = self.tex.or(base.map(|b| b.tex));
        let ea = match (self.ea, self.specific_modulus) {
            (Some(_), Some(_)) => {
                return Err("give one of `EA` (N) and `specific_modulus` (N/tex), not both".into())
            }
            (Some(ea), None) => Some(ea),
            (None, Some(m)) => Some(m * tex.ok_or(
                "missing field `tex`: `specific_modulus` (N/tex) needs the linear density `tex`",
            )?),
            (None, None) => base.map(|b| b.ea),
        };
        let diameter = self.diameter.or(base.map(|b| b.diameter));
        if diameter.is_none() {
            return Err(
                "missing field `diameter`: a yarn given per yarn (tex, EA, ...) needs its \
                        diameter in m (the default sheet spacing and the cross-section area)"
                    .into(),
            );
        }
        Ok(Partial {
            tex,
            diameter,
            ea,
            ei: self.ei.or(base.map(|b| b.ei)),
            friction: base.map(|b| b.friction),
            friction_solid: self.friction_solid.or(base.map(|b| b.friction_solid)),
            spacing: self.spacing.or(diameter),
            transverse_modulus: self
                .transverse_modulus
                .or(base.map(|b| b.transverse_modulus)),
            shear_modulus: self.shear_modulus,
        })
    }
}

impl Partial {
    /// `k = EA / s`, `density = mu / s`, `bending = EI / s`,
    /// `E = E_T A / s`, `gamma = G A / s` ([`super::material_units`]).
    fn derived(&self) -> Derived {
        let (Some(diameter), Some(spacing)) = (self.diameter, self.spacing) else {
            return Derived::default();
        };
        let sheet = Sheet { diameter, spacing };
        let shear = shear_or_default(self.shear_modulus, self.transverse_modulus);
        Derived {
            k: self.ea.map(|ea| sheet.k(ea)),
            gamma: shear.map(|g| sheet.cross_section(g)),
            youngs_modulus: self.transverse_modulus.map(|e| sheet.cross_section(e)),
            friction: self.friction,
            bending: self.ei.map(|ei| sheet.bending(ei)),
            density: self.tex.map(|t| sheet.density(t)),
        }
    }
}

fn unknown_preset(name: &str) -> String {
    format!(
        "unknown yarn preset {name:?}; known presets: {} (yarnsim materials lists them)",
        preset_names().join(", ")
    )
}

/// `[material]` as a file writes it.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialFile {
    #[serde(default, deserialize_with = "opt_preset")]
    preset: Option<String>,
    #[serde(default, deserialize_with = "opt_pos")]
    tex: Option<f64>,
    #[serde(default, deserialize_with = "opt_pos")]
    diameter: Option<f64>,
    #[serde(rename = "EA", default, deserialize_with = "opt_pos")]
    ea: Option<f64>,
    #[serde(default, deserialize_with = "opt_pos")]
    specific_modulus: Option<f64>,
    #[serde(rename = "EI", default, deserialize_with = "opt_nonneg")]
    ei: Option<f64>,
    #[serde(default, deserialize_with = "opt_nonneg")]
    friction_solid: Option<f64>,
    #[serde(default, deserialize_with = "opt_pos")]
    spacing: Option<f64>,
    #[serde(default, deserialize_with = "opt_nonneg")]
    transverse_modulus: Option<f64>,
    #[serde(default, deserialize_with = "opt_nonneg")]
    shear_modulus: Option<f64>,
    #[serde(default, deserialize_with = "opt_nonneg")]
    k: Option<f64>,
    #[serde(default, deserialize_with = "opt_nonneg")]
    gamma: Option<f64>,
    #[serde(default, deserialize_with = "opt_nonneg")]
    youngs_modulus: Option<f64>,
    #[serde(default, deserialize_with = "opt_nonneg")]
    friction: Option<f64>,
    #[serde(default, deserialize_with = "opt_nonneg")]
    bending: Option<f64>,
    #[serde(default, deserialize_with = "opt_pos")]
    density: Option<f64>,
    #[serde(default)]
    plasticity: Option<bool>,
}

impl TryFrom<MaterialFile> for Material {
    type Error = String;

    fn try_from(f: MaterialFile) -> Result<Self, String> {
        let yarn = YarnMaterial {
            preset: f.preset,
            tex: f.tex,
            diameter: f.diameter,
            ea: f.ea,
            specific_modulus: f.specific_modulus,
            ei: f.ei,
            friction_solid: f.friction_solid,
            spacing: f.spacing,
            transverse_modulus: f.transverse_modulus,
            shear_modulus: f.shear_modulus,
        };
        let yarn = (!yarn.is_empty()).then_some(yarn);
        let derived = match &yarn {
            Some(y) => y.partial()?.derived(),
            None => Derived::default(),
        };
        let need = |given: Option<f64>, derived: Option<f64>, name: &str, how: &str| {
            given.or(derived).ok_or_else(|| match &yarn {
                None => format!("missing field `{name}`"),
                Some(_) => format!("missing field `{name}`: give `{name}`{how}"),
            })
        };
        Ok(Material {
            k: need(
                f.k,
                derived.k,
                "k",
                " or the yarn's `EA` or `specific_modulus`",
            )?,
            gamma: need(
                f.gamma,
                derived.gamma,
                "gamma",
                " or `transverse_modulus` (Pa)",
            )?,
            youngs_modulus: need(
                f.youngs_modulus,
                derived.youngs_modulus,
                "youngs_modulus",
                " or `transverse_modulus` (Pa)",
            )?,
            friction: need(f.friction, derived.friction, "friction", " (yarn on yarn)")?,
            bending: f.bending.or(derived.bending).unwrap_or(0.0),
            density: f.density.or(derived.density).unwrap_or(1.0),
            plasticity: f.plasticity.unwrap_or(true),
            yarn,
        })
    }
}

impl From<Material> for MaterialFile {
    /// The description as given, and every model field that it does not
    /// derive to the same bits (all of them without a description).
    fn from(m: Material) -> Self {
        let derived = m
            .yarn
            .as_ref()
            .and_then(|y| y.partial().ok())
            .map(|p| p.derived())
            .unwrap_or_default();
        let own = |v: f64, d: Option<f64>| (d != Some(v)).then_some(v);
        let y = m.yarn.unwrap_or_default();
        MaterialFile {
            preset: y.preset,
            tex: y.tex,
            diameter: y.diameter,
            ea: y.ea,
            specific_modulus: y.specific_modulus,
            ei: y.ei,
            friction_solid: y.friction_solid,
            spacing: y.spacing,
            transverse_modulus: y.transverse_modulus,
            shear_modulus: y.shear_modulus,
            k: own(m.k, derived.k),
            gamma: own(m.gamma, derived.gamma),
            youngs_modulus: own(m.youngs_modulus, derived.youngs_modulus),
            friction: own(m.friction, derived.friction),
            bending: own(m.bending, derived.bending),
            density: own(m.density, derived.density),
            plasticity: Some(m.plasticity),
        }
    }
}

fn opt_pos<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    positive(d).map(Some)
}

fn opt_nonneg<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    nonnegative(d).map(Some)
}

/// A preset name from the table, else an error listing the names.
fn opt_preset<'de, D: Deserializer<'de>>(d: D) -> Result<Option<String>, D::Error> {
    let name = String::deserialize(d)?;
    match preset(&name) {
        Some(_) => Ok(Some(name)),
        None => Err(D::Error::custom(unknown_preset(&name))),
    }
}
