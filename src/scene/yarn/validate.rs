//! Checks of a yarn scene beyond its field types: grid and time step,
//! pins against their yarns, and start-up overlap with the obstacles; each
//! error names its field and, given the file, its line.

use super::*;

/// The largest yarn diameter (`material.diameter`), in cells of the grid,
/// that yarn-on-yarn contact carries: two velocity fields share a node
/// only within the kernel support (3 cells between the centre lines), and
/// a yarn pressed onto another is held only where enough of its stencil
/// shares nodes with the other's: measured, it rests within 15 % of `d`
/// from 0.5 to 1.8 cells and at 2.3 cells sinks to 1.64 cells (-29 %;
/// `docs/obstacle-contact.md`, "Yarn diameter").
pub const MAX_DIAMETER_CELLS: f64 = 1.75;

impl YarnScene {
    /// Checks cross-field constraints (geometry, time step against grid).
    pub fn validate(&self) -> Result<(), SceneError> {
        self.validate_with_source(None)
    }

    pub(super) fn validate_with_source(&self, text: Option<&str>) -> Result<(), SceneError> {
        let yarn_line = |i: usize| table_line(text, "[[yarns]]", i);
        let obstacle_line = |i: usize| table_line(text, "[[obstacles]]", i);
        if self.yarns.is_empty() {
            return Err(SceneError::Invalid {
                field: "yarns".into(),
                line: None,
                message: "a yarn scene needs at least one [[yarns]] entry".into(),
            });
        }
        let mut first_yarn = 0;
        for (i, y) in self.yarns.iter().enumerate() {
            let curves = y.curves().map_err(|message| SceneError::Invalid {
                field: format!("yarns[{i}]"),
                line: yarn_line(i),
                message,
            })?;
            for (copy, c) in curves.iter().enumerate() {
                if c.iter().any(|&p| !self.in_grid_interior(p)) {
                    return Err(self.outside_grid(i, y, copy, first_yarn + copy, yarn_line(i)));
                }
            }
            first_yarn += curves.len();
        }
        for (i, o) in self.obstacles.iter().enumerate() {
            if o.radius > 10.0 * self.grid.size {
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
        self.validate_gridless(text)?;
        self.validate_diameter(text)?;
        overlap::check_yarns_clear_of_obstacles(self, text)?;
        Ok(())
    }

    /// Yarns in contact with each other (two or more yarns, in per-yarn
    /// fields or with a held one): a diameter of at most
    /// [`MAX_DIAMETER_CELLS`] cells; the grid follows the diameter, so the
    /// error names the resolution that would carry it.
    fn validate_diameter(&self, text: Option<&str>) -> Result<(), SceneError> {
        let Some(d) = self.material.diameter() else {
            return Ok(());
        };
        let cells = d / self.dx();
        if !self.yarn_contact() || cells <= MAX_DIAMETER_CELLS {
            return Ok(());
        }
        let most = (MAX_DIAMETER_CELLS * self.grid.size / d).floor();
        Err(SceneError::Invalid {
            field: "material.diameter".into(),
            line: text.and_then(|t| {
                key_line(t, "[material]", "diameter").or(key_line(t, "[material]", "preset"))
            }),
            message: format!(
                "the yarn diameter {d} m is {cells:.2} cells of the grid (grid.resolution {}), \
                 more than the {MAX_DIAMETER_CELLS} cells yarn-on-yarn contact can carry (two \
                 yarns' velocity fields meet only within the kernel's 3 cells): set \
                 grid.resolution to at most {most} for this diameter",
                self.grid.resolution
            ),
        })
    }

    /// How many yarns the scene makes: every `[[yarns]]` entry's copies.
    pub fn yarn_count(&self) -> u64 {
        self.yarns.iter().map(|y| y.count as u64).sum()
    }

    /// Whether yarns touch each other through the contact of velocity
    /// fields: two or more yarns, each free yarn in a field of its own
    /// (`[contact] fields = "per-yarn"`) or a held yarn next to free ones.
    pub fn yarn_contact(&self) -> bool {
        self.yarn_count() >= 2
            && (self.contact.fields == FieldPartition::PerYarn || !self.pins.is_empty())
    }

    /// A warning for a scene whose yarn diameter does not act between its
    /// free yarns: with `[contact] fields = "held-free"` they share one
    /// velocity field and their separation is the cross-section's, not the
    /// diameter (which still keeps them `d / 2` off the obstacles and, with
    /// a held yarn, `d` from it).
    pub fn diameter_warning(&self) -> Option<String> {
        let d = self.material.diameter()?;
        (self.yarn_count() >= 2 && self.contact.fields == FieldPartition::HeldFree).then(|| {
            format!(
                "material.diameter = {d} m does not act between free yarns: with [contact] \
                 fields = \"held-free\" (the default) they share one velocity field; set \
                 [contact] fields = \"per-yarn\" for contact at the diameter"
            )
        })
    }

    /// A yarn that starts within `material.diameter / 2` of an obstacle's
    /// surface (`overlap::start_gap_warning`); `None` without a diameter.
    pub fn start_gap_warning(&self) -> Option<String> {
        overlap::start_gap_warning(self, self.material.diameter()?)
    }

    /// The warnings of a scene that runs but likely not as meant
    /// ([`YarnScene::diameter_warning`], [`YarnScene::start_gap_warning`]):
    /// the CLI prints them, the FMU logs them when it is initialised.
    pub fn warnings(&self) -> Vec<String> {
        self.diameter_warning()
            .into_iter()
            .chain(self.start_gap_warning())
            .collect()
    }

    /// The grid interior a yarn must start in, in m: 1.5 cells inside the
    /// domain `[0, size]^2` on every side.
    fn grid_interior(&self) -> (f64, f64) {
        let margin = self.dx() * 1.5;
        (margin, self.grid.size - margin)
    }

    fn in_grid_interior(&self, p: Vec2) -> bool {
        let (lo, hi) = self.grid_interior();
        p.x >= lo && p.y >= lo && p.x <= hi && p.y <= hi
    }

    /// The error of copy `copy` (yarn `yarn` of the run) of the `[[yarns]]`
    /// entry `i`, which has a vertex outside the grid interior. It names a
    /// point of the entry as the file gives it (`start`, `end`,
    /// `points[k]`): the vertices lie on the polyline between those points
    /// and the interior is convex, so one of them lies outside too.
    fn outside_grid(
        &self,
        i: usize,
        y: &YarnSpec,
        copy: usize,
        yarn: usize,
        line: Option<usize>,
    ) -> SceneError {
        let (lo, hi) = self.grid_interior();
        let shift = Vec2::from(y.spacing) * copy as f64;
        let (field, what, at) = y
            .control_points()
            .into_iter()
            .map(|(field, what, p)| (field, what, p + shift))
            .find(|(_, _, p)| !self.in_grid_interior(*p))
            .expect("a vertex outside the convex interior has a control point outside");
        let point = |p: Vec2| format!("[{}, {}]", short(p.x), short(p.y));
        let whose = if y.count == 1 {
            format!("yarn {yarn}")
        } else if copy == 0 {
            format!("yarn {yarn} (copy 0 of this entry's {})", y.count)
        } else {
            format!(
                "yarn {yarn} (copy {copy} of this entry's {}, shifted by {copy} x spacing {})",
                y.count,
                point(Vec2::from(y.spacing))
            )
        };
        let which = if field.starts_with("points") {
            format!(" {field} =")
        } else {
            String::new()
        };
        SceneError::Invalid {
            field: format!("yarns[{i}].{field}"),
            line,
            message: format!(
                "{whose} {what}{which} {}, outside the grid interior: x and y \
                 must be within [{}, {}] m, 1.5 grid cells inside the domain [0, {}] m",
                point(at),
                short(lo),
                short(hi),
                short(self.grid.size)
            ),
        }
    }

    /// `[transfer]`: a `flip_time` is positive (the reader checks it in a
    /// file; a scene built in code too) and not given beside a
    /// `flip_ratio` other than 1.
    fn validate_transfer(&self, text: Option<&str>) -> Result<(), SceneError> {
        let tr = &self.transfer;
        let Some(tau) = tr.flip_time else {
            return Ok(());
        };
        let invalid = |message: String| SceneError::Invalid {
            field: "transfer.flip_time".into(),
            line: text.and_then(|t| key_line(t, "[transfer]", "flip_time")),
            message,
        };
        if !(tau.is_finite() && tau > 0.0) {
            return Err(invalid(format!("must be > 0, got {tau}")));
        }
        if tr.flip_ratio != 1.0 {
            return Err(invalid(format!(
                "give transfer.flip_ratio (a blend per substep) or transfer.flip_time (a \
                 relaxation time), not both; flip_ratio is {}",
                tr.flip_ratio
            )));
        }
        Ok(())
    }

    fn validate_time(&self, text: Option<&str>) -> Result<(), SceneError> {
        let t = &self.time;
        let invalid = |field: &str, message: String| SceneError::Invalid {
            field: format!("time.{field}"),
            line: text.and_then(|text| key_line(text, "[time]", field)),
            message,
        };
        if t.axial.is_implicit() && !t.integrator.is_explicit() {
            return Err(invalid(
                "axial",
                format!(
                    "axial = \"implicit\" applies only to integrator = \"explicit\", but integrator is \"{}\" (which treats the fibre stretch implicitly already)",
                    t.integrator.name()
                ),
            ));
        }
        // before the axial check below, which reads `flip_time`
        self.validate_transfer(text)?;
        let tr = &self.transfer;
        if t.axial.is_implicit() && tr.scheme == TransferScheme::Flip && tr.flip_time.is_none() {
            return Err(invalid(
                "axial",
                "axial = \"implicit\" under [transfer] scheme = \"flip\" needs \
                 transfer.flip_time (for example 0.002 s), or scheme = \"apic\": a FLIP particle \
                 keeps the vertex-scale part of the axial solve's velocity change, which its \
                 position never follows; pure FLIP gains energy from it, and a fixed flip_ratio \
                 damps it per substep, so by an amount that changes with dt"
                    .into(),
            ));
        }
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

    /// The scope of `integrator = "implicit-vertices"` (backward Euler on a
    /// single yarn's vertices, without the grid): one yarn, no shear or
    /// cross-section stiffness (the energies that need the grid), no walls.
    fn validate_gridless(&self, text: Option<&str>) -> Result<(), SceneError> {
        if !self.time.integrator.is_gridless() {
            return Ok(());
        }
        let why = "integrator = \"implicit-vertices\" or \"midpoint-vertices\" steps a single yarn on its vertices, without the grid";
        let at = |field: &str, header: &str, key: &str, message: String| SceneError::Invalid {
            field: field.into(),
            line: text.and_then(|t| key_line(t, header, key)),
            message: format!("{message} ({why}; integrator = \"implicit\" runs this scene)"),
        };
        let yarns = self.yarn_count();
        if yarns != 1 {
            return Err(SceneError::Invalid {
                field: "yarns".into(),
                line: table_line(text, "[[yarns]]", usize::from(self.yarns.len() > 1)),
                message: format!("{yarns} yarns; it needs exactly one ({why}, with no yarn-yarn contact; integrator = \"implicit\" runs this scene)"),
            });
        }
        let m = &self.material;
        if m.gamma != 0.0 {
            return Err(at(
                "material.gamma",
                "[material]",
                "gamma",
                format!(
                    "gamma is {}; it needs 0 (the shear energy lives on the grid)",
                    m.gamma
                ),
            ));
        }
        if m.youngs_modulus != 0.0 {
            return Err(at(
                "material.youngs_modulus",
                "[material]",
                "youngs_modulus",
                format!(
                    "youngs_modulus is {}; it needs 0 (the cross-section energy lives on the grid)",
                    m.youngs_modulus
                ),
            ));
        }
        if self.walls.mode != super::WallMode::None {
            return Err(at(
                "walls.mode",
                "[walls]",
                "mode",
                "the walls act on grid nodes; it needs mode = \"none\"".into(),
            ));
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
}

/// A coordinate in m for a message: at most 6 decimals, without trailing
/// zeros (`0.29`, not `0.29000000000000004`).
fn short(x: f64) -> String {
    short_to(x, 6)
}

/// `x` with at most `places` decimals, without trailing zeros (`-0`
/// written `0`).
pub(super) fn short_to(x: f64, places: usize) -> String {
    let s = format!("{x:.places$}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
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
