//! The unit and the accepted range of every scene-file field, in one place:
//! the commented scene files of [`super::commented`] (`yarnsim scene show`)
//! write them, and a test compares them with the reference tables of
//! `docs/scene-files.md`.
//!
//! A field is named by its path with array entries left out: `time.dt`,
//! `obstacles.radius` (every `[[obstacles]]` entry), `gravity`.

/// What a scene file's field means physically.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FieldDoc {
    /// Dotted path without entry indices: `material.k`, `yarns.start`.
    pub key: &'static str,
    /// SI unit (`m`, `m/s^2`, `N/m`); `1` for a dimensionless ratio, empty
    /// for counts, indices, switches and names.
    pub unit: &'static str,
    /// The values the scene accepts, as the user writes them (`> 0`,
    /// `8 to 8192`, `"flip" or "apic"`); empty where any value goes.
    pub range: &'static str,
}

const fn f(key: &'static str, unit: &'static str, range: &'static str) -> FieldDoc {
    FieldDoc { key, unit, range }
}

/// Every field of a yarn scene (`kind = "yarn"`).
pub const YARN_FIELDS: &[FieldDoc] = &[
    f("kind", "", "\"yarn\": the MPM yarn bundle"),
    f("name", "", ""),
    f("description", "", ""),
    f("gravity", "m/s^2", ""),
    f("grid.resolution", "cells", "8 to 8192 per side"),
    f("grid.size", "m", "> 0, side of the square domain"),
    f("time.dt", "s", "> 0, or \"auto\""),
    f(
        "time.safety",
        "1",
        "0 < safety <= 2, only with dt = \"auto\"",
    ),
    f("time.dt_max", "s", "> 0, only with dt = \"auto\""),
    f("time.frame_dt", "s", "> 0, >= dt"),
    f(
        "time.integrator",
        "",
        "\"explicit\", \"implicit\", \"implicit-vertices\" or \"midpoint-vertices\"",
    ),
    f("material.k", "N/m", ">= 0"),
    f("material.gamma", "N/m", ">= 0"),
    f("material.youngs_modulus", "N/m", ">= 0"),
    f("material.friction", "1", ">= 0"),
    f("material.bending", "N m", ">= 0 (N m^2 per m of depth)"),
    f("material.density", "kg/m^2", "> 0"),
    f("material.plasticity", "", "true or false"),
    f("attractor.position", "m", ""),
    f("attractor.strength", "m/s^2", ">= 0"),
    f("attractor.active", "", "true or false"),
    f("walls.mode", "", "\"sticky\", \"slip\" or \"none\""),
    f("walls.cells", "cells", "1 to 16"),
    f("obstacles.center", "m", ""),
    f("obstacles.radius", "m", "> 0"),
    f("obstacles.friction", "1", ">= 0"),
    f("transfer.scheme", "", "\"flip\" or \"apic\""),
    f("transfer.flip_ratio", "1", "0 to 1"),
    f("contact.fields", "", "\"per-yarn\" or \"held-free\""),
    f("yarns.start", "m", ""),
    f("yarns.end", "m", ""),
    f("yarns.direction", "", "not zero"),
    f("yarns.length", "m", "> 0"),
    f("yarns.points", "m", ""),
    f("yarns.vertices", "", "2 to 10000000"),
    f("yarns.count", "", "1 to 100000 copies"),
    f("yarns.spacing", "m", ""),
    f("yarns.velocity", "m/s", ""),
    f("pins.yarn", "", "yarn index"),
    f("pins.end", "", "\"start\" or \"end\""),
    f("pins.vertex", "", "vertex index"),
    f("pins.count", "", "1 to 100000 vertices"),
    f(
        "pins.motion",
        "",
        "\"fixed\", \"line\", \"circle\" or \"input\"",
    ),
    f("pins.velocity", "m/s", ""),
    f("pins.center", "m", ""),
    f(
        "pins.angular_velocity",
        "rad/s",
        "counter-clockwise positive",
    ),
];

/// Every field of a mass-spring scene (`kind = "mass-spring"`, `"wire"`,
/// `"cloth"` or `"three-particle"`).
pub const MASS_SPRING_FIELDS: &[FieldDoc] = &[
    f(
        "kind",
        "",
        "\"mass-spring\", \"wire\", \"cloth\" or \"three-particle\"",
    ),
    f("name", "", ""),
    f("description", "", ""),
    f("gravity", "m/s^2", ""),
    f("pinned", "", "particle indices"),
    f("time.frame_time", "s", "> 0"),
    f("time.frames", "", "1 to 100000000"),
    f("time.time_step", "s", "> 0, <= frame_time"),
    f("time.cfl_number", "1", "0 < cfl_number <= 1"),
    f("time.velocity_damping", "1", "0 < velocity_damping <= 1"),
    f("time.strain_limit", "1", "0 <= strain_limit < 1"),
    f("particles.position", "m", ""),
    f("particles.velocity", "m/s", ""),
    f("particles.mass", "kg", "> 0"),
    f("chains.start", "m", ""),
    f("chains.end", "m", ""),
    f("chains.particles", "", "2 to 1000000"),
    f("chains.mass", "kg", "> 0, total"),
    f("chains.youngs_modulus", "N", ">= 0"),
    f("chains.damping", "N s/m", ">= 0"),
    f("sheets.origin", "m", ""),
    f("sheets.edge_u", "m", ""),
    f("sheets.edge_v", "m", ""),
    f("sheets.nu", "", "2 to 1000000"),
    f("sheets.nv", "", "2 to 1000000"),
    f("sheets.mass", "kg", "> 0, per vertex"),
    f("sheets.stiffness", "N/m", ">= 0"),
    f("sheets.damping", "N s/m", ">= 0"),
    f("sheets.diagonals", "", "true or false"),
    f("springs.particles", "", "two particle indices"),
    f("springs.stiffness", "N/m", ">= 0"),
    f("springs.damping", "N s/m", ">= 0"),
    f("springs.rest_length", "m", "> 0"),
    f("driven.particle", "", "particle index"),
    f("driven.center", "m", ""),
    f("driven.u", "m", ""),
    f("driven.v", "m", ""),
    f("driven.period", "s", "> 0"),
    f("driven.phase", "rad", ""),
    f("spheres.center", "m", ""),
    f("spheres.radius", "m", "> 0"),
];

/// The entry of `key` in `fields`.
pub fn field_doc(fields: &'static [FieldDoc], key: &str) -> Option<&'static FieldDoc> {
    fields.iter().find(|d| d.key == key)
}

impl FieldDoc {
    /// The trailing comment of the field in a scene file: unit and range,
    /// `m/s^2`, `cells, 8 to 8192 per side`; empty when it has neither.
    pub fn comment(&self) -> String {
        match (self.unit, self.range) {
            ("", r) => r.to_string(),
            (u, "") => u.to_string(),
            (u, r) => format!("{u}, {r}"),
        }
    }
}
