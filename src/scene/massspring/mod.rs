//! The mass-spring scene (the course notes' `SIMULATION_LAYOUT`): what exists in a
//! wire or cloth scene, as plain data read from TOML. Particles and springs are
//! given one by one (`[[particles]]`, `[[springs]]`) or generated
//! (`[[chains]]`, `[[sheets]]`); kinematic constraints (`pinned`,
//! `[[driven]]`), colliders (`[[spheres]]`), gravity and time parameters
//! complete it. [`MassSpringScene::build`] expands it into a [`System`] that
//! the integrators in [`crate::massspring`] advance; they never look at the
//! file form. See the README, "Mass-spring scene files", for every field with
//! its unit and default.
//!
//! * `system`: the expanded scene, flat arrays.
//! * `build`: the expansion, one function per scene element.

mod build;
mod overlap;
pub(crate) mod system;

use serde::{Deserialize, Deserializer, Serialize};

use super::error::{from_toml_error, SceneError};
use super::readers::{
    bounded_u32, finite, finite3, half, nonnegative, one, opt_positive, positive,
    unit_interval_open_low, yes,
};
use serde::de::Error as _;

pub use system::{Kinematic, Sphere, Spring, System, V3};

/// The scene kinds a mass-spring scene answers to (the top-level `kind`).
pub const KINDS: [&str; 4] = ["mass-spring", "wire", "cloth", "three-particle"];

/// A complete mass-spring scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MassSpringScene {
    /// One of [`KINDS`] (default `"mass-spring"`); all mean the same model.
    #[serde(default = "kind_default", deserialize_with = "kind_ok")]
    pub kind: String,
    /// Short name shown by the CLI.
    #[serde(default)]
    pub name: String,
    /// One line of description.
    #[serde(default)]
    pub description: String,
    /// Gravity acceleration `[gx, gy, gz]` in m/s^2 (default `[0, -9.81, 0]`).
    #[serde(default = "default_gravity", deserialize_with = "finite3")]
    pub gravity: [f64; 3],
    /// Indices of particles held fixed at their initial position.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub pinned: Vec<usize>,
    /// Time and integration parameters.
    pub time: TimeParams,
    /// Individually given particles (global indices 0, 1, ... in file order).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub particles: Vec<ParticleSpec>,
    /// Generated straight chains (their particles follow the explicit ones).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub chains: Vec<ChainSpec>,
    /// Generated rectangular sheets (their particles follow the chains').
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub sheets: Vec<SheetSpec>,
    /// Individually given springs between global particle indices.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub springs: Vec<SpringSpec>,
    /// Particles driven on a prescribed circle.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub driven: Vec<DrivenSpec>,
    /// Fixed spheres the particles collide with (projection + velocity fix-up).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub spheres: Vec<SphereSpec>,
}

/// Frame loop and step parameters (the course notes' "user-specified parameters").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeParams {
    /// Frame (snapshot) interval in s.
    #[serde(deserialize_with = "positive")]
    pub frame_time: f64,
    /// Number of frames of a full run (1 or more).
    #[serde(deserialize_with = "frame_count")]
    pub frames: u32,
    /// Step size in s of the implicit and position-based integrators
    /// (default: `frame_time`). Explicit integrators use the CFL bound.
    #[serde(default, deserialize_with = "opt_positive")]
    pub time_step: Option<f64>,
    /// Fraction of the stability bound the explicit integrators step at
    /// (0 < c <= 1, default 0.5 as in the course notes).
    #[serde(default = "half", deserialize_with = "unit_interval_open_low")]
    pub cfl_number: f64,
    /// Fraction of the free particles' velocity kept per `frame_time`
    /// (0 < d <= 1, default 1 = none); a step of size `h` multiplies the
    /// velocity by `d^(h / frame_time)` before it starts (the Unity cloth scripts: 0.99).
    #[serde(default = "one", deserialize_with = "unit_interval_open_low")]
    pub velocity_damping: f64,
    /// Strain limit `s` of the position-based pass: after each step every
    /// spring length is pulled into `[(1-s) l0, (1+s) l0]`. Absent: no pass
    /// (the `pbd` integrator then uses `s = 0`).
    #[serde(default, deserialize_with = "opt_strain")]
    pub strain_limit: Option<f64>,
}

/// One particle.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParticleSpec {
    /// Initial position in m.
    #[serde(deserialize_with = "finite3")]
    pub position: [f64; 3],
    /// Initial velocity in m/s (default 0).
    #[serde(default, deserialize_with = "finite3")]
    pub velocity: [f64; 3],
    /// Mass in kg.
    #[serde(deserialize_with = "positive")]
    pub mass: f64,
}

/// One spring between two particles.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpringSpec {
    /// Global indices of the two particles.
    #[serde(deserialize_with = "particle_pair")]
    pub particles: [usize; 2],
    /// Stiffness `k` in N/m: force `k (l - l0)` along the spring.
    #[serde(deserialize_with = "nonnegative")]
    pub stiffness: f64,
    /// Damping `b` in N s/m: force `b (d . (v_b - v_a))` along the spring (default 0).
    #[serde(default, deserialize_with = "nonnegative")]
    pub damping: f64,
    /// Rest length in m (default: the initial distance).
    #[serde(default, deserialize_with = "opt_positive")]
    pub rest_length: Option<f64>,
}

/// A straight chain of `particles` equal masses joined by springs (the course notes' wire).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChainSpec {
    /// First particle's position in m.
    #[serde(deserialize_with = "finite3")]
    pub start: [f64; 3],
    /// Last particle's position in m; springs rest at the initial spacing.
    #[serde(deserialize_with = "finite3")]
    pub end: [f64; 3],
    /// Number of particles (2 or more).
    #[serde(deserialize_with = "chain_count")]
    pub particles: u32,
    /// Total mass in kg, shared equally.
    #[serde(deserialize_with = "positive")]
    pub mass: f64,
    /// The course notes' `youngs_modulus` E in N: a spring of rest length `l0` has
    /// stiffness `k = E / l0` (force `E (l / l0 - 1)`).
    #[serde(deserialize_with = "nonnegative")]
    pub youngs_modulus: f64,
    /// The course notes' `damping_coefficient` b in N s/m, per spring (default 0).
    #[serde(default, deserialize_with = "nonnegative")]
    pub damping: f64,
}

/// A rectangular sheet of `nu x nv` vertices, triangulated as in the Unity cloth scripts
/// (structural edges plus the diagonal `(i, j)-(i+1, j+1)` of every quad).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SheetSpec {
    /// Position of vertex `(0, 0)` in m.
    #[serde(deserialize_with = "finite3")]
    pub origin: [f64; 3],
    /// Vector from vertex `(0, j)` to `(nu-1, j)` in m.
    #[serde(deserialize_with = "finite3")]
    pub edge_u: [f64; 3],
    /// Vector from vertex `(i, 0)` to `(i, nv-1)` in m.
    #[serde(deserialize_with = "finite3")]
    pub edge_v: [f64; 3],
    /// Vertices along `edge_u` (2 or more); vertex `(i, j)` has local index `j nu + i`.
    #[serde(deserialize_with = "chain_count")]
    pub nu: u32,
    /// Vertices along `edge_v` (2 or more).
    #[serde(deserialize_with = "chain_count")]
    pub nv: u32,
    /// Mass of each vertex in kg.
    #[serde(deserialize_with = "positive")]
    pub mass: f64,
    /// Stiffness of every edge spring in N/m.
    #[serde(deserialize_with = "nonnegative")]
    pub stiffness: f64,
    /// Damping of every edge spring in N s/m (default 0).
    #[serde(default, deserialize_with = "nonnegative")]
    pub damping: f64,
    /// Whether the quad diagonals are springs too (default true).
    #[serde(default = "yes")]
    pub diagonals: bool,
}

/// A particle moved on the circle `center + u sin(w t + phase) + v cos(w t + phase)`,
/// `w = 2 pi / period` (the course notes' upper endpoint).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DrivenSpec {
    /// Global index of the driven particle.
    pub particle: usize,
    /// Circle centre in m.
    #[serde(deserialize_with = "finite3")]
    pub center: [f64; 3],
    /// Radius vector multiplying `sin` in m.
    #[serde(deserialize_with = "finite3")]
    pub u: [f64; 3],
    /// Radius vector multiplying `cos` in m.
    #[serde(deserialize_with = "finite3")]
    pub v: [f64; 3],
    /// Period in s.
    #[serde(deserialize_with = "positive")]
    pub period: f64,
    /// Phase in rad (default 0).
    #[serde(default, deserialize_with = "finite")]
    pub phase: f64,
}

/// A fixed sphere collider.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SphereSpec {
    /// Centre in m.
    #[serde(deserialize_with = "finite3")]
    pub center: [f64; 3],
    /// Radius in m.
    #[serde(deserialize_with = "positive")]
    pub radius: f64,
}

impl MassSpringScene {
    /// Parses and validates a scene from TOML text; errors name the field and line.
    pub fn from_toml_str(text: &str) -> Result<MassSpringScene, SceneError> {
        let scene: MassSpringScene = toml::from_str(text).map_err(|e| from_toml_error(text, e))?;
        scene.build_with_source(Some(text))?;
        Ok(scene)
    }

    /// The scene as TOML text that [`MassSpringScene::from_toml_str`] reads back.
    pub fn to_toml_string(&self) -> String {
        toml::to_string_pretty(self).expect("a mass-spring scene always serializes")
    }

    /// Checks cross-field constraints (indices, degenerate springs).
    pub fn validate(&self) -> Result<(), SceneError> {
        self.build().map(|_| ())
    }

    /// Number of particles after expansion of chains and sheets.
    pub fn particle_count(&self) -> usize {
        self.particles.len()
            + self
                .chains
                .iter()
                .map(|c| c.particles as usize)
                .sum::<usize>()
            + self
                .sheets
                .iter()
                .map(|s| s.nu as usize * s.nv as usize)
                .sum::<usize>()
    }

    /// Expands the scene into the flat [`System`].
    pub fn build(&self) -> Result<System, SceneError> {
        self.build_with_source(None)
    }
}

// ---- defaults -------------------------------------------------------------

fn kind_default() -> String {
    "mass-spring".into()
}
fn default_gravity() -> [f64; 3] {
    [0.0, -9.81, 0.0]
}

// ---- validating field readers (the error carries the value's span) --------
// The common ones live in `scene::readers`; these are this model's own.

fn kind_ok<'de, D: Deserializer<'de>>(d: D) -> Result<String, D::Error> {
    let s = String::deserialize(d)?;
    if KINDS.contains(&s.as_str()) {
        Ok(s)
    } else {
        Err(D::Error::custom(format!(
            "kind must be one of {KINDS:?} for a mass-spring scene, got {s:?}"
        )))
    }
}

fn opt_strain<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    let v = finite(d)?;
    if (0.0..1.0).contains(&v) {
        Ok(Some(v))
    } else {
        Err(D::Error::custom(format!("must be in [0, 1), got {v}")))
    }
}

/// Two particle indices (serde's `[usize; 2]` would drop a third).
fn particle_pair<'de, D: Deserializer<'de>>(d: D) -> Result<[usize; 2], D::Error> {
    let v = Vec::<usize>::deserialize(d)?;
    <[usize; 2]>::try_from(v.as_slice()).map_err(|_| {
        D::Error::custom(format!(
            "must be 2 particle indices, got {} ({v:?})",
            v.len()
        ))
    })
}

fn frame_count<'de, D: Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    bounded_u32(d, 1, 100_000_000)
}

fn chain_count<'de, D: Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    bounded_u32(d, 2, 1_000_000)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::assert_mentions;

    const WIRE: &str = r#"
kind = "wire"
[time]
frame_time = 0.05
frames = 100
[[chains]]
start = [0.0, 0.0, 0.5]
end = [0.0, -1.0, 0.5]
particles = 11
mass = 1.0
youngs_modulus = 100.0
damping = 100.0
"#;

    #[test]
    fn chain_expands_to_the_course_wire() {
        let s = MassSpringScene::from_toml_str(WIRE)
            .unwrap()
            .build()
            .unwrap();
        assert_eq!(s.len(), 11);
        assert_eq!(s.springs.len(), 10);
        assert!((s.masses[3] - 1.0 / 11.0).abs() < 1e-15);
        assert!((s.springs[0].rest_length - 0.1).abs() < 1e-12);
        assert!((s.springs[0].k - 1000.0).abs() < 1e-9);
        assert_eq!(s.gravity, V3::new(0.0, -9.81, 0.0));
        assert_eq!(s.time_step, 0.05);
    }

    #[test]
    fn bad_value_names_field_and_line() {
        let e =
            MassSpringScene::from_toml_str(&WIRE.replace("mass = 1.0", "mass = -1.0")).unwrap_err();
        let m = e.to_string();
        assert_mentions(&m, &["line 10", "`chains[0].mass`", "> 0"]);
    }

    #[test]
    fn out_of_range_pin_names_field_and_line() {
        let text = WIRE.replace("kind = \"wire\"", "kind = \"wire\"\npinned = [11]");
        let m = MassSpringScene::from_toml_str(&text)
            .unwrap_err()
            .to_string();
        assert_mentions(&m, &["line 3", "`pinned[0]`"]);
    }

    #[test]
    fn sheet_has_the_cloth_scripts_edge_count() {
        // the built-in cloth: the cloth scripts' 21 x 21 sheet over 10 m
        let s = crate::scene::builtin::cloth().build().unwrap();
        assert_eq!(s.len(), 441);
        // 20*21 horizontal + 20*21 vertical + 20*20 diagonals.
        assert_eq!(s.springs.len(), 1240);
        assert_eq!(s.positions[20], V3::new(-5.0, 0.0, 5.0));
    }
}
