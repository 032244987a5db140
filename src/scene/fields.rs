//! The unit and the accepted range of every scene-file field, in one place:
//! the commented scene files of `super::commented` (`yarnsim scene show`)
//! write them, and a test compares them with the reference tables of
//! `docs/scene-files.md`.
//!
//! A field is named by its path with array entries left out: `time.dt`,
//! `obstacles.radius` (every `[[obstacles]]` entry), `gravity`.

use std::sync::LazyLock;

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

/// Every field of a yarn scene (`kind = "yarn"`): the table
/// `src/scene/fields/yarn.txt`.
pub static YARN_FIELDS: LazyLock<Vec<FieldDoc>> =
    LazyLock::new(|| parse_table(include_str!("fields/yarn.txt")));

/// Every field of a mass-spring scene (`kind = "mass-spring"`, `"wire"`,
/// `"cloth"` or `"three-particle"`): the table
/// `src/scene/fields/mass_spring.txt`.
pub static MASS_SPRING_FIELDS: LazyLock<Vec<FieldDoc>> =
    LazyLock::new(|| parse_table(include_str!("fields/mass_spring.txt")));

/// The rows of a field table: one field a line, `key | unit | range`, each
/// cell trimmed; `#` lines and blank lines are comments.
///
/// # Panics
/// On a row without three cells (the tables are part of the library).
fn parse_table(text: &'static str) -> Vec<FieldDoc> {
    text.lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .map(|l| {
            let mut cells = l.splitn(3, '|').map(str::trim);
            let mut cell = || {
                cells
                    .next()
                    .unwrap_or_else(|| panic!("field table row {l:?}: not `key | unit | range`"))
            };
            FieldDoc {
                key: cell(),
                unit: cell(),
                range: cell(),
            }
        })
        .collect()
}

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
