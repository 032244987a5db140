//! The yarn-bundle scene: what exists (grid, material, yarns, obstacles,
//! walls, attractor, gravity), as plain data read from TOML. How it moves is
//! the business of [`crate::mpm`].

use serde::{Deserialize, Deserializer, Serialize};

use super::error::{from_toml_error, line_of, table_line, SceneError};
use crate::math::Vec2;

mod axial;
mod geometry;
mod material;
pub mod material_units;
mod overlap;
pub mod presets;
mod transfer;
mod validate;

pub use axial::Axial;
pub use material::{Material, YarnMaterial};
pub use transfer::{TransferScheme, TransferSpec};
pub use validate::MAX_DIAMETER_CELLS;

/// A complete yarn-bundle scene. See the README section "Scene files" for
/// every field with its unit and default.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct YarnScene {
    /// Scene kind tag, always `"yarn"` for this type.
    #[serde(default = "kind_yarn", deserialize_with = "kind_is_yarn")]
    pub kind: String,
    /// Short name shown by the CLI.
    #[serde(default)]
    pub name: String,
    /// One line of description.
    #[serde(default)]
    pub description: String,
    /// The background grid (`[grid]`).
    pub grid: GridSpec,
    /// Substep, output frames and integrator (`[time]`).
    pub time: TimeSpec,
    /// The yarns' material (`[material]`).
    pub material: Material,
    /// Gravity acceleration `[gx, gy]` in m/s^2 (default `[0, -9.8]`).
    #[serde(default = "default_gravity", deserialize_with = "finite2")]
    pub gravity: [f64; 2],
    #[serde(default)]
    /// The point attractor (`[attractor]`, off by default).
    pub attractor: AttractorSpec,
    #[serde(default)]
    /// The domain's walls (`[walls]`).
    pub walls: Walls,
    #[serde(default)]
    /// Circular obstacles (`[[obstacles]]`).
    pub obstacles: Vec<Obstacle>,
    /// How particles take their velocity back from the grid.
    #[serde(default)]
    pub transfer: TransferSpec,
    /// Yarn-on-yarn contact (`[contact]`): how yarns are split into
    /// velocity fields.
    #[serde(default, skip_serializing_if = "ContactSpec::is_default")]
    pub contact: ContactSpec,
    /// The yarns (`[[yarns]]`), each entry with its copies.
    pub yarns: Vec<YarnSpec>,
    /// Pinned or driven yarn vertices.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub pins: Vec<PinSpec>,
}

/// Yarn-on-yarn contact (`[contact]`); see `crate::mpm::laws::fields`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// `"held-free"` (default) or `"per-yarn"`.
    #[serde(default)]
    pub fields: FieldPartition,
}

impl ContactSpec {
    /// Whether every setting is the default (then not written out).
    pub fn is_default(&self) -> bool {
        *self == ContactSpec::default()
    }
}

/// How yarns are split into velocity fields (`[contact] fields`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum FieldPartition {
    /// Held yarns in one field, all free yarns in another: free yarns
    /// interact through the shared grid velocity and the return mapping.
    #[default]
    HeldFree,
    /// Held yarns in one field, each free yarn in one of its own: Coulomb
    /// friction with `material.friction` between any two yarns (its cost:
    /// `docs/performance/contact.md`).
    PerYarn,
}

/// Which end of a yarn a pin starts from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum YarnEnd {
    /// The first vertex (index 0).
    Start,
    /// The last vertex.
    End,
}

/// How pinned vertices move.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum PinMotionKind {
    /// Held at the start position.
    #[default]
    Fixed,
    /// Moved at constant `velocity`.
    Line,
    /// Turned rigidly about `center` at `angular_velocity`.
    Circle,
    /// Driven at run time (`YarnSim::set_pin_target`, the FMU's
    /// `pin[i].*` inputs): held at the start position until a target is set.
    Input,
}

/// Pinned or driven vertices of one yarn (`[[pins]]`): `count` consecutive
/// vertices from `end` inward, or from index `vertex` onward.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PinSpec {
    /// Yarn index, counting every copy (`count`) of every `[[yarns]]` entry in order.
    pub yarn: u32,
    /// `"start"` or `"end"` of the yarn.
    #[serde(default)]
    pub end: Option<YarnEnd>,
    /// First vertex index within the yarn (instead of `end`).
    #[serde(default)]
    pub vertex: Option<u32>,
    /// How many consecutive vertices (default 1).
    #[serde(default = "one_u32", deserialize_with = "copy_count")]
    pub count: u32,
    /// `"fixed"` (default), `"line"`, `"circle"` or `"input"`.
    #[serde(default)]
    pub motion: PinMotionKind,
    /// Velocity `[vx, vy]` in m/s of a `"line"` motion.
    #[serde(default, deserialize_with = "opt_finite2")]
    pub velocity: Option<[f64; 2]>,
    /// Centre `[x, y]` in m of a `"circle"` motion.
    #[serde(default, deserialize_with = "opt_finite2")]
    pub center: Option<[f64; 2]>,
    /// Angular velocity in rad/s of a `"circle"` motion (counter-clockwise positive).
    #[serde(default, deserialize_with = "opt_finite")]
    pub angular_velocity: Option<f64>,
}

/// The background grid: a square domain `[0, size]^2` of `resolution^2` cells.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridSpec {
    /// Cells per side (8 to 8192).
    #[serde(deserialize_with = "resolution")]
    pub resolution: u32,
    /// Side length of the domain in m (default 1).
    #[serde(default = "one", deserialize_with = "positive")]
    pub size: f64,
}

/// Time stepping.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeSpec {
    /// Substep size: a number in s, or `"auto"` (each substep from the
    /// stability bound of the current state, see [`crate::mpm::driver::timestep`]).
    pub dt: StepSize,
    /// Safety factor of `dt = "auto"`: the substep is `safety` times the
    /// stability bound (default [`DEFAULT_SAFETY`]; 0 < safety <= 2). Only
    /// with `dt = "auto"`.
    #[serde(default, deserialize_with = "opt_safety")]
    pub safety: Option<f64>,
    /// Largest substep of `dt = "auto"` in s (default: no cap). Only with
    /// `dt = "auto"`.
    #[serde(default, deserialize_with = "opt_positive")]
    pub dt_max: Option<f64>,
    /// Output frame interval in s (CLI frames and recordings; default 1/60).
    #[serde(default = "default_frame_dt", deserialize_with = "positive")]
    pub frame_dt: f64,
    /// How a substep advances the velocities: `"explicit"` (default),
    /// `"implicit"` (backward Euler on the grid), `"implicit-vertices"`
    /// (backward Euler on a single yarn's vertices, without the grid) or
    /// `"midpoint-vertices"` (the generalized midpoint rule there), each in
    /// its scope only, see [`Integrator`].
    #[serde(default, skip_serializing_if = "Integrator::is_explicit")]
    pub integrator: Integrator,
    /// The fibre-stretch term under the explicit integrator: `"explicit"`
    /// (default) or `"implicit"` (a backward Euler step of each yarn's
    /// axial springs on its vertices, see [`Axial`]).
    #[serde(default, skip_serializing_if = "Axial::is_explicit")]
    pub axial: Axial,
}

/// The time integrator of the grid velocities (`[time] integrator`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Integrator {
    /// Symplectic Euler: grid forces from the state at the start of the
    /// substep (the model's only step so far; `dt` is bound by stability).
    #[default]
    Explicit,
    /// Backward Euler on the grid velocities as a minimisation (Gast,
    /// Schroeder, Stomakhin, Jiang, Teran 2015, "Optimization integrator for
    /// large time steps", IEEE TVCG 21(10)), `crate::mpm::implicit_grid`: the
    /// whole yarn energy in one velocity field (pins, obstacles and walls
    /// act as in the explicit step, after the solve); a
    /// scene outside that scope is refused at load naming the field, never
    /// run with the explicit step instead.
    Implicit,
    /// Backward Euler on the vertex velocities of a single yarn without the
    /// grid (`crate::mpm::implicit_vertex`): for one yarn whose material has no
    /// cross-section energy (`gamma = youngs_modulus = 0`), no walls; a
    /// scene outside that scope is refused at load naming the field.
    #[serde(rename = "implicit-vertices")]
    ImplicitVertices,
    /// The generalized midpoint rule (theta 0.55) on the same vertices, in
    /// the same scope (`crate::mpm::implicit_vertex`): the implicit midpoint
    /// rule's period error on slow modes with light damping (1.3 % per
    /// period at `omega dt = 0.042`) and strong damping of modes far above
    /// `1 / dt`; a contact's normal velocity stays inelastic.
    #[serde(rename = "midpoint-vertices")]
    MidpointVertices,
}

impl Integrator {
    /// Every value of `[time] integrator`, as a scene file writes it.
    pub const NAMES: [&'static str; 4] = [
        "explicit",
        "implicit",
        "implicit-vertices",
        "midpoint-vertices",
    ];

    /// The value as a scene file writes it (one of [`Integrator::NAMES`]).
    pub fn name(&self) -> &'static str {
        match self {
            Integrator::Explicit => Self::NAMES[0],
            Integrator::Implicit => Self::NAMES[1],
            Integrator::ImplicitVertices => Self::NAMES[2],
            Integrator::MidpointVertices => Self::NAMES[3],
        }
    }

    /// Whether this is the default explicit step.
    pub fn is_explicit(&self) -> bool {
        *self == Integrator::Explicit
    }
    /// Whether this is an implicit step (on the grid or the vertices).
    pub fn is_implicit(&self) -> bool {
        !self.is_explicit()
    }
    /// Whether this steps a single yarn's vertices without the grid.
    pub fn is_gridless(&self) -> bool {
        matches!(
            self,
            Integrator::ImplicitVertices | Integrator::MidpointVertices
        )
    }
}

/// Default safety factor of `dt = "auto"`: the substep is this fraction of
/// the stability bound `dx / (c + |v|max)` (and of the bending bound).
/// Measured on the reference scene (README "Adaptive substeps"): it runs
/// to 0.5 s at a factor of 1.1 and diverges at 1.2 (t = 0.13 s), so 0.8
/// leaves a margin of about 1.4x below the largest stable factor.
pub const DEFAULT_SAFETY: f64 = 0.8;

/// The substep setting `[time] dt`: a fixed size or `"auto"`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StepSize {
    /// Every substep is this long (s, finite, > 0).
    Fixed(f64),
    /// Each substep is chosen from the stability bound of the current state.
    Auto,
}

impl StepSize {
    /// The fixed substep, `None` for `"auto"`.
    pub fn fixed(self) -> Option<f64> {
        match self {
            StepSize::Fixed(dt) => Some(dt),
            StepSize::Auto => None,
        }
    }

    /// Whether the substep is `"auto"`.
    pub fn is_auto(self) -> bool {
        self == StepSize::Auto
    }
}

impl std::fmt::Display for StepSize {
    /// `4e-5 s` or `auto`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StepSize::Fixed(dt) => write!(f, "{dt} s"),
            StepSize::Auto => f.write_str("auto"),
        }
    }
}

impl From<f64> for StepSize {
    fn from(dt: f64) -> Self {
        StepSize::Fixed(dt)
    }
}

impl Serialize for StepSize {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            StepSize::Fixed(dt) => s.serialize_f64(*dt),
            StepSize::Auto => s.serialize_str("auto"),
        }
    }
}

impl<'de> Deserialize<'de> for StepSize {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Raw {
            Number(f64),
            Text(String),
        }
        let bad = |what: String| {
            D::Error::custom(format!(
                "must be a substep in s (a finite number > 0) or \"auto\", got {what}"
            ))
        };
        let raw = Raw::deserialize(d).map_err(|e| {
            // serde reports an absent `dt` through this deserializer: keep
            // its "missing field" message, which names the field.
            if e.to_string().starts_with("missing field") {
                e
            } else {
                bad("another type".into())
            }
        })?;
        match raw {
            Raw::Number(v) if v.is_finite() && v > 0.0 => Ok(StepSize::Fixed(v)),
            Raw::Number(v) => Err(bad(v.to_string())),
            Raw::Text(t) if t == "auto" => Ok(StepSize::Auto),
            Raw::Text(t) => Err(bad(format!("{t:?}"))),
        }
    }
}

/// A point attractor ("mouse") pulling grid velocity toward `position`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AttractorSpec {
    /// Attractor position `[x, y]` in m.
    #[serde(default = "centre", deserialize_with = "finite2")]
    pub position: [f64; 2],
    /// Acceleration magnitude in m/s^2 (at distances well above 0.01 m).
    #[serde(
        default = "default_attractor_strength",
        deserialize_with = "nonnegative"
    )]
    pub strength: f64,
    /// Whether the attractor acts.
    #[serde(default)]
    pub active: bool,
}

impl Default for AttractorSpec {
    fn default() -> Self {
        AttractorSpec {
            position: centre(),
            strength: default_attractor_strength(),
            active: false,
        }
    }
}

/// Boundary condition at the domain edges.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum WallMode {
    /// Grid velocity set to zero near the edges.
    #[default]
    Sticky,
    /// Only the outward normal velocity is removed.
    Slip,
    /// No walls: particles are only clamped to stay on the grid.
    None,
}

/// Domain walls.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Walls {
    /// `"sticky"` (default), `"slip"` or `"none"`.
    #[serde(default)]
    pub mode: WallMode,
    /// Wall thickness in cells (1 to 16, default 3).
    #[serde(default = "default_wall_cells", deserialize_with = "wall_cells")]
    pub cells: u32,
}

impl Default for Walls {
    fn default() -> Self {
        Walls {
            mode: WallMode::Sticky,
            cells: default_wall_cells(),
        }
    }
}

/// A fixed circular obstacle with Coulomb friction.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Obstacle {
    /// Centre `[x, y]` in m.
    #[serde(deserialize_with = "finite2")]
    pub center: [f64; 2],
    /// Radius in m.
    #[serde(deserialize_with = "positive")]
    pub radius: f64,
    /// Coulomb friction coefficient of the surface (default: the
    /// material's `friction_solid` where it has one, a preset's included,
    /// else 0.3).
    #[serde(
        default = "default_obstacle_friction",
        deserialize_with = "nonnegative"
    )]
    pub friction: f64,
}

/// One yarn, or `count` parallel copies of it.
///
/// Geometry is either a straight line (`start` plus `end`, or `start` plus
/// `direction` and `length`) or a polyline (`points`); it is resampled to
/// `vertices` equally spaced vertices along its arc length.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct YarnSpec {
    #[serde(default, deserialize_with = "opt_finite2")]
    /// First point of a straight yarn in m.
    pub start: Option<[f64; 2]>,
    #[serde(default, deserialize_with = "opt_finite2")]
    /// Last point of a straight yarn in m (or give `direction` and `length`).
    pub end: Option<[f64; 2]>,
    #[serde(default, deserialize_with = "opt_finite2")]
    /// Direction from `start` of a straight yarn given by `direction` and `length` (not zero).
    pub direction: Option<[f64; 2]>,
    #[serde(default, deserialize_with = "opt_positive")]
    /// Length in m of a straight yarn given by `direction` and `length`.
    pub length: Option<f64>,
    #[serde(default, deserialize_with = "opt_points")]
    /// The points of a polyline yarn in m (instead of `start`).
    pub points: Option<Vec<[f64; 2]>>,
    /// Number of type-2 vertices (2 or more).
    #[serde(deserialize_with = "vertex_count")]
    pub vertices: u32,
    /// Number of copies (default 1), each shifted by `spacing` from the previous.
    #[serde(default = "one_u32", deserialize_with = "copy_count")]
    pub count: u32,
    /// Offset between copies `[dx, dy]` in m.
    #[serde(default, deserialize_with = "finite2")]
    pub spacing: [f64; 2],
    /// Initial velocity `[vx, vy]` in m/s.
    #[serde(default, deserialize_with = "finite2")]
    pub velocity: [f64; 2],
}

impl YarnScene {
    /// Parses and validates a scene from TOML text.
    pub fn from_toml_str(text: &str) -> Result<Self, SceneError> {
        let mut scene: YarnScene = toml::from_str(text).map_err(|e| from_toml_error(text, e))?;
        scene.obstacles_take_solid_friction(text);
        scene.validate_with_source(Some(text))?;
        Ok(scene)
    }

    /// The scene as TOML text that [`YarnScene::from_toml_str`] reads back.
    pub fn to_toml_string(&self) -> String {
        toml::to_string_pretty(self).expect("a yarn scene always serializes")
    }

    /// Gives every obstacle whose entry in `text` has no `friction` the
    /// material's yarn-on-solid friction, where the material has one.
    fn obstacles_take_solid_friction(&mut self, text: &str) {
        let Some(f) = self.material.friction_solid() else {
            return;
        };
        let table: toml::Table = match toml::from_str(text) {
            Ok(t) => t,
            Err(_) => return,
        };
        let Some(toml::Value::Array(entries)) = table.get("obstacles") else {
            return;
        };
        for (o, entry) in self.obstacles.iter_mut().zip(entries) {
            if entry.get("friction").is_none() {
                o.friction = f;
            }
        }
    }

    /// Grid spacing `dx` in m.
    pub fn dx(&self) -> f64 {
        self.grid.size / self.grid.resolution as f64
    }
}

// ---- defaults -------------------------------------------------------------

fn kind_yarn() -> String {
    "yarn".into()
}
fn one_u32() -> u32 {
    1
}
fn centre() -> [f64; 2] {
    [0.5, 0.5]
}
fn default_gravity() -> [f64; 2] {
    [0.0, -9.8]
}
fn default_frame_dt() -> f64 {
    1.0 / 60.0
}
fn default_attractor_strength() -> f64 {
    20.0
}
fn default_wall_cells() -> u32 {
    3
}
fn default_obstacle_friction() -> f64 {
    0.3
}

// ---- validating field readers (the error carries the value's span) --------

use super::readers::{bounded_u32, finite2, nonnegative, one, opt_finite, opt_positive, positive};
use serde::de::Error as _;

fn kind_is_yarn<'de, D: Deserializer<'de>>(d: D) -> Result<String, D::Error> {
    let s = String::deserialize(d)?;
    if s == "yarn" {
        Ok(s)
    } else {
        Err(D::Error::custom(format!(
            "kind must be \"yarn\" for a yarn scene, got {s:?}"
        )))
    }
}

fn opt_safety<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    let v = super::readers::finite(d)?;
    if v > 0.0 && v <= 2.0 {
        Ok(Some(v))
    } else {
        Err(D::Error::custom(format!("must be in (0, 2], got {v}")))
    }
}

fn opt_finite2<'de, D: Deserializer<'de>>(d: D) -> Result<Option<[f64; 2]>, D::Error> {
    finite2(d).map(Some)
}

/// Points `[x, y]`, each exactly two numbers (serde's `[f64; 2]` would
/// drop a third).
fn opt_points<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Vec<[f64; 2]>>, D::Error> {
    let points = Vec::<Vec<f64>>::deserialize(d)?;
    points
        .iter()
        .enumerate()
        .map(|(k, p)| {
            <[f64; 2]>::try_from(p.as_slice()).map_err(|_| {
                D::Error::custom(format!(
                    "points[{k}] must be 2 numbers [x, y], got {} ({p:?})",
                    p.len()
                ))
            })
        })
        .collect::<Result<Vec<_>, _>>()
        .map(Some)
}

fn resolution<'de, D: Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    bounded_u32(d, 8, 8192)
}
fn wall_cells<'de, D: Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    bounded_u32(d, 1, 16)
}
fn vertex_count<'de, D: Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    bounded_u32(d, 2, 10_000_000)
}
fn copy_count<'de, D: Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
    bounded_u32(d, 1, 100_000)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The name tables agree with `name()` and with the spelling serde
    /// reads and writes (exact).
    #[test]
    fn name_tables_are_the_scene_files_spelling() {
        #[derive(Serialize, Deserialize)]
        struct Value<T> {
            v: T,
        }
        fn check<T>(values: &[T], names: &[&str], name: fn(&T) -> &'static str)
        where
            T: Serialize + serde::de::DeserializeOwned + PartialEq + std::fmt::Debug,
        {
            assert_eq!(values.len(), names.len());
            for (v, n) in values.iter().zip(names) {
                assert_eq!(name(v), *n);
                let text = toml::to_string(&Value { v }).unwrap();
                assert_eq!(text.trim(), format!("v = {n:?}"));
                let back: Value<T> = toml::from_str(&text).unwrap();
                assert_eq!(&back.v, v);
            }
        }
        check(
            &[TransferScheme::Flip, TransferScheme::Apic],
            &TransferScheme::NAMES,
            TransferScheme::name,
        );
        check(
            &[
                Integrator::Explicit,
                Integrator::Implicit,
                Integrator::ImplicitVertices,
                Integrator::MidpointVertices,
            ],
            &Integrator::NAMES,
            Integrator::name,
        );
    }
}
