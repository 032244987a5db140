//! The yarn-bundle scene: what exists (grid, material, yarns, obstacles,
//! walls, attractor, gravity), as plain data read from TOML. How it moves is
//! the business of [`crate::mpm`].

use serde::{Deserialize, Deserializer, Serialize};

use super::error::{from_toml_error, line_of, table_line, SceneError};
use crate::math::Vec2;

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
    pub grid: GridSpec,
    pub time: TimeSpec,
    pub material: Material,
    /// Gravity acceleration `[gx, gy]` in m/s^2 (default `[0, -9.8]`).
    #[serde(default = "default_gravity", deserialize_with = "finite2")]
    pub gravity: [f64; 2],
    #[serde(default)]
    pub attractor: AttractorSpec,
    #[serde(default)]
    pub walls: Walls,
    #[serde(default)]
    pub obstacles: Vec<Obstacle>,
    /// How particles take their velocity back from the grid.
    #[serde(default)]
    pub transfer: TransferSpec,
    pub yarns: Vec<YarnSpec>,
    /// Pinned or driven yarn vertices.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub pins: Vec<PinSpec>,
}

/// The grid-to-particle velocity update (`[transfer]`); see
/// [`crate::mpm::transfer`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransferSpec {
    /// `"flip"` (default) or `"apic"`.
    #[serde(default)]
    pub scheme: TransferScheme,
    /// FLIP ratio in `[0, 1]` for `"flip"` (default 1: pure FLIP, no
    /// per-transfer dissipation); `r < 1` blends in APIC's damping.
    #[serde(default = "one", deserialize_with = "unit_interval_closed")]
    pub flip_ratio: f64,
}

impl Default for TransferSpec {
    fn default() -> Self {
        TransferSpec {
            scheme: TransferScheme::default(),
            flip_ratio: 1.0,
        }
    }
}

/// Name of a transfer scheme.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum TransferScheme {
    /// The particle keeps its velocity and adds the grid's change (blended
    /// with APIC by `flip_ratio`).
    #[default]
    Flip,
    /// APIC (the seed's): velocity and affine matrix replaced by the grid's.
    Apic,
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
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub end: Option<YarnEnd>,
    /// First vertex index within the yarn (instead of `end`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vertex: Option<u32>,
    /// How many consecutive vertices (default 1).
    #[serde(default = "one_u32", deserialize_with = "copy_count")]
    pub count: u32,
    /// `"fixed"` (default), `"line"`, `"circle"` or `"input"`.
    #[serde(default)]
    pub motion: PinMotionKind,
    /// Velocity `[vx, vy]` in m/s of a `"line"` motion.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "opt_finite2"
    )]
    pub velocity: Option<[f64; 2]>,
    /// Centre `[x, y]` in m of a `"circle"` motion.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "opt_finite2"
    )]
    pub center: Option<[f64; 2]>,
    /// Angular velocity in rad/s of a `"circle"` motion (counter-clockwise positive).
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "opt_finite"
    )]
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
    /// stability bound of the current state, see [`crate::mpm::timestep`]).
    pub dt: StepSize,
    /// Safety factor of `dt = "auto"`: the substep is `safety` times the
    /// stability bound (default [`DEFAULT_SAFETY`]; 0 < safety <= 2). Only
    /// with `dt = "auto"`.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "opt_safety"
    )]
    pub safety: Option<f64>,
    /// Largest substep of `dt = "auto"` in s (default: no cap). Only with
    /// `dt = "auto"`.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "opt_positive"
    )]
    pub dt_max: Option<f64>,
    /// Output frame interval in s (CLI frames and recordings; default 1/60).
    #[serde(default = "default_frame_dt", deserialize_with = "positive")]
    pub frame_dt: f64,
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
        match Raw::deserialize(d).map_err(|_| bad("another type".into()))? {
            Raw::Number(v) if v.is_finite() && v > 0.0 => Ok(StepSize::Fixed(v)),
            Raw::Number(v) => Err(bad(v.to_string())),
            Raw::Text(t) if t == "auto" => Ok(StepSize::Auto),
            Raw::Text(t) => Err(bad(format!("{t:?}"))),
        }
    }
}

/// Material of the yarns (per unit thickness: the 2D model has unit depth).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Fiber stretch stiffness `k` (Pa).
    #[serde(deserialize_with = "nonnegative")]
    pub k: f64,
    /// Fiber shear stiffness `gamma` (Pa).
    #[serde(deserialize_with = "nonnegative")]
    pub gamma: f64,
    /// Young's modulus `E` of the cross-section (Pa); `mu = 0.4 E`, `lambda = 0.6 E`.
    #[serde(deserialize_with = "nonnegative")]
    pub youngs_modulus: f64,
    /// Mohr-Coulomb friction coefficient `c_f` (dimensionless).
    #[serde(deserialize_with = "nonnegative")]
    pub friction: f64,
    /// Bending stiffness `B` of the rod in N m^2 per m of depth (N m): the
    /// energy is `int B / 2 kappa^2 ds` (discrete elastic rods, see
    /// [`crate::mpm::vertex_forces`]). 0 disables bending.
    #[serde(default, deserialize_with = "nonnegative")]
    pub bending: f64,
    /// Line density in kg/m (per unit depth).
    #[serde(default = "one", deserialize_with = "positive")]
    pub density: f64,
    /// Mohr-Coulomb return mapping on (default) or off.
    #[serde(default = "yes")]
    pub plasticity: bool,
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
    /// Coulomb friction coefficient of the surface (default 0.3).
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
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "opt_finite2"
    )]
    pub start: Option<[f64; 2]>,
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "opt_finite2"
    )]
    pub end: Option<[f64; 2]>,
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "opt_finite2"
    )]
    pub direction: Option<[f64; 2]>,
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "opt_positive"
    )]
    pub length: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
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
        let scene: YarnScene = toml::from_str(text).map_err(|e| from_toml_error(text, e))?;
        scene.validate_with_source(Some(text))?;
        Ok(scene)
    }

    /// The scene as TOML text that [`YarnScene::from_toml_str`] reads back.
    pub fn to_toml_string(&self) -> String {
        toml::to_string_pretty(self).expect("a yarn scene always serializes")
    }

    /// The obstacles as circles, for the overlap check.
    pub fn obstacle_circles(&self) -> Vec<super::overlap::Circle> {
        self.obstacles
            .iter()
            .map(|o| super::overlap::Circle {
                center: o.center,
                radius: o.radius,
            })
            .collect()
    }

    /// Grid spacing `dx` in m.
    pub fn dx(&self) -> f64 {
        self.grid.size / self.grid.resolution as f64
    }

    /// Checks cross-field constraints (geometry, time step against grid).
    pub fn validate(&self) -> Result<(), SceneError> {
        self.validate_with_source(None)
    }

    fn validate_with_source(&self, text: Option<&str>) -> Result<(), SceneError> {
        let yarn_line = |i: usize| table_line(text, "[[yarns]]", i);
        let obstacle_line = |i: usize| table_line(text, "[[obstacles]]", i);
        if self.yarns.is_empty() {
            return Err(SceneError::Invalid {
                field: "yarns".into(),
                line: None,
                message: "a yarn scene needs at least one [[yarns]] entry".into(),
            });
        }
        let size = self.grid.size;
        let margin = self.dx() * 1.5;
        for (i, y) in self.yarns.iter().enumerate() {
            let curves = y.curves().map_err(|message| SceneError::Invalid {
                field: format!("yarns[{i}]"),
                line: yarn_line(i),
                message,
            })?;
            for c in &curves {
                for p in c {
                    if p.x < margin || p.y < margin || p.x > size - margin || p.y > size - margin {
                        return Err(SceneError::Invalid {
                            field: format!("yarns[{i}]"),
                            line: yarn_line(i),
                            message: format!(
                                "vertex ({:.4}, {:.4}) lies outside the grid interior [{margin:.4}, {:.4}]^2",
                                p.x,
                                p.y,
                                size - margin
                            ),
                        });
                    }
                }
            }
        }
        for (i, o) in self.obstacles.iter().enumerate() {
            if o.radius > 10.0 * size {
                return Err(SceneError::Invalid {
                    field: format!("obstacles[{i}].radius"),
                    line: obstacle_line(i),
                    message: "radius is absurdly large for the domain".into(),
                });
            }
        }
        let total: u64 = self
            .yarns
            .iter()
            .map(|y| y.vertices as u64 * y.count as u64)
            .sum();
        if total > 20_000_000 {
            return Err(SceneError::Invalid {
                field: "yarns".into(),
                line: None,
                message: format!("{total} vertices in all is more than the 20 million supported"),
            });
        }
        self.validate_pins(text)?;
        self.validate_time(text)?;
        super::overlap::check_yarns_clear_of_obstacles(
            self.dx(),
            &self
                .yarns
                .iter()
                .map(|s| s.curves().ok())
                .collect::<Vec<_>>(),
            &self.obstacle_circles(),
            text,
        )?;
        Ok(())
    }

    fn validate_time(&self, text: Option<&str>) -> Result<(), SceneError> {
        let t = &self.time;
        let invalid = |field: &str, message: String| SceneError::Invalid {
            field: format!("time.{field}"),
            line: text.and_then(|text| key_line(text, "[time]", field)),
            message,
        };
        match t.dt {
            StepSize::Fixed(dt) => {
                if !(dt.is_finite() && dt > 0.0) {
                    return Err(invalid("dt", format!("must be > 0, got {dt}")));
                }
                if t.frame_dt < dt {
                    return Err(invalid(
                        "frame_dt",
                        format!(
                            "frame_dt {} is shorter than the substep dt {dt}",
                            t.frame_dt
                        ),
                    ));
                }
                for (field, set) in [
                    ("safety", t.safety.is_some()),
                    ("dt_max", t.dt_max.is_some()),
                ] {
                    if set {
                        return Err(invalid(
                            field,
                            format!("applies only to dt = \"auto\", but dt is {dt}"),
                        ));
                    }
                }
            }
            StepSize::Auto => {
                if let Some(s) = t.safety.filter(|s| !(*s > 0.0 && *s <= 2.0)) {
                    return Err(invalid("safety", format!("must be in (0, 2], got {s}")));
                }
                if let Some(m) = t.dt_max.filter(|m| !(m.is_finite() && *m > 0.0)) {
                    return Err(invalid("dt_max", format!("must be > 0, got {m}")));
                }
            }
        }
        Ok(())
    }

    /// The vertex ranges (within its yarn) of every pin, checked: the yarn
    /// exists, the range lies inside it, the motion has its fields, and no
    /// vertex is pinned twice.
    pub fn pin_ranges(&self) -> Result<Vec<(usize, std::ops::Range<usize>)>, SceneError> {
        self.validate_pins(None)?;
        Ok(self
            .pins
            .iter()
            .map(|p| self.pin_range(p).expect("validated"))
            .collect())
    }

    fn pin_range(&self, p: &PinSpec) -> Result<(usize, std::ops::Range<usize>), String> {
        let counts: Vec<usize> = self
            .yarns
            .iter()
            .flat_map(|y| std::iter::repeat_n(y.vertices as usize, y.count as usize))
            .collect();
        let y = p.yarn as usize;
        let Some(&n) = counts.get(y) else {
            return Err(format!(
                "yarn {y} does not exist: the scene has {} yarns (0 to {})",
                counts.len(),
                counts.len().saturating_sub(1)
            ));
        };
        let c = p.count as usize;
        let start = match (p.end, p.vertex) {
            (Some(YarnEnd::Start), None) => 0,
            (Some(YarnEnd::End), None) => n.saturating_sub(c),
            (None, Some(v)) => v as usize,
            _ => {
                return Err("give exactly one of `end` (\"start\" or \"end\") and `vertex`".into())
            }
        };
        if c > n || start + c > n {
            return Err(format!(
                "vertices {start}..{} are outside yarn {y}, which has {n} vertices",
                start + c
            ));
        }
        match p.motion {
            PinMotionKind::Fixed => {}
            PinMotionKind::Line if p.velocity.is_none() => {
                return Err("motion \"line\" needs `velocity`".into())
            }
            PinMotionKind::Circle if p.center.is_none() || p.angular_velocity.is_none() => {
                return Err("motion \"circle\" needs `center` and `angular_velocity`".into())
            }
            _ => {}
        }
        Ok((y, start..start + c))
    }

    fn validate_pins(&self, text: Option<&str>) -> Result<(), SceneError> {
        let pin_line = |i: usize| table_line(text, "[[pins]]", i);
        let mut seen: Vec<(usize, std::ops::Range<usize>)> = Vec::new();
        for (i, p) in self.pins.iter().enumerate() {
            let (y, r) = self.pin_range(p).map_err(|message| SceneError::Invalid {
                field: format!("pins[{i}]"),
                line: pin_line(i),
                message,
            })?;
            if let Some(k) = seen
                .iter()
                .position(|(y2, r2)| *y2 == y && r.start < r2.end && r2.start < r.end)
            {
                return Err(SceneError::Invalid {
                    field: format!("pins[{i}]"),
                    line: pin_line(i),
                    message: format!("its vertices overlap those of pins[{k}] on yarn {y}"),
                });
            }
            seen.push((y, r));
        }
        Ok(())
    }

    /// All yarn curves (one per copy), each resampled to its vertex count.
    pub fn curves(&self) -> Vec<Vec<Vec2>> {
        self.yarns
            .iter()
            .flat_map(|y| y.curves().expect("validated scene"))
            .collect()
    }

    /// Initial velocity of each yarn curve, in the order of [`YarnScene::curves`].
    pub fn curve_velocities(&self) -> Vec<Vec2> {
        self.yarns
            .iter()
            .flat_map(|y| std::iter::repeat_n(Vec2::from(y.velocity), y.count as usize))
            .collect()
    }
}

impl YarnSpec {
    /// A straight yarn from `start` to `end` with `vertices` vertices.
    pub fn straight(start: [f64; 2], end: [f64; 2], vertices: u32) -> Self {
        YarnSpec {
            start: Some(start),
            end: Some(end),
            vertices,
            count: 1,
            ..Default::default()
        }
    }

    /// The control polyline of the first copy.
    fn polyline(&self) -> Result<Vec<Vec2>, String> {
        match (
            &self.points,
            self.start,
            self.end,
            self.direction,
            self.length,
        ) {
            (Some(pts), None, None, None, None) => {
                if pts.len() < 2 {
                    return Err("`points` needs at least two points".into());
                }
                if pts.iter().flatten().any(|v| !v.is_finite()) {
                    return Err("`points` must be finite".into());
                }
                Ok(pts.iter().map(|&p| Vec2::from(p)).collect())
            }
            (None, Some(s), Some(e), None, None) => Ok(vec![s.into(), e.into()]),
            (None, Some(s), None, Some(d), Some(l)) => {
                let d = Vec2::from(d);
                let n = d.norm();
                if n == 0.0 {
                    return Err("`direction` must not be zero".into());
                }
                let s = Vec2::from(s);
                Ok(vec![s, s + d * (l / n)])
            }
            _ => Err(
                "give either `points`, or `start` and `end`, or `start`, `direction` and `length`"
                    .into(),
            ),
        }
    }

    /// The vertex positions of every copy.
    pub fn curves(&self) -> Result<Vec<Vec<Vec2>>, String> {
        let poly = self.polyline()?;
        let curve = resample(&poly, self.vertices as usize)?;
        let step = Vec2::from(self.spacing);
        Ok((0..self.count)
            .map(|c| curve.iter().map(|p| p + step * c as f64).collect())
            .collect())
    }
}

/// Line of `key = ...` inside the table `header` (e.g. `[time]`), else of
/// the header, when the text has it.
fn key_line(text: &str, header: &str, key: &str) -> Option<usize> {
    let start = text.find(header)?;
    let body = &text[start + header.len()..];
    let end = body.find("\n[").map_or(body.len(), |i| i + 1);
    let mut pos = start + header.len();
    for line in body[..end].split_inclusive('\n') {
        if line
            .trim_start()
            .strip_prefix(key)
            .is_some_and(|r| r.trim_start().starts_with('='))
        {
            return Some(line_of(text, pos));
        }
        pos += line.len();
    }
    Some(line_of(text, start))
}

/// `n` points equally spaced by arc length along the polyline `poly`.
fn resample(poly: &[Vec2], n: usize) -> Result<Vec<Vec2>, String> {
    let seg: Vec<f64> = poly.windows(2).map(|w| (w[1] - w[0]).norm()).collect();
    let total: f64 = seg.iter().sum();
    if total.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return Err("the yarn has zero length".into());
    }
    let mut out = Vec::with_capacity(n);
    let mut k = 0;
    let mut acc = 0.0;
    for i in 0..n {
        let s = total * i as f64 / (n - 1) as f64;
        while k + 1 < seg.len() && acc + seg[k] < s {
            acc += seg[k];
            k += 1;
        }
        let t = if seg[k] > 0.0 {
            ((s - acc) / seg[k]).clamp(0.0, 1.0)
        } else {
            0.0
        };
        out.push(poly[k] + (poly[k + 1] - poly[k]) * t);
    }
    Ok(out)
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

use super::readers::{
    bounded_u32, finite2, nonnegative, one, opt_finite, opt_positive, positive,
    unit_interval_closed, yes,
};
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
