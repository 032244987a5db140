//! Scene files written for people (`yarnsim scene show`): every array on
//! one line (`center = [0.25, 0.6]`) and, after every field, a comment with
//! its unit and range from [`super::fields`]. The text reads back to the
//! same scene.
//!
//! [`Scene::to_toml_string`] stays the plain form: its bytes are hashed
//! into FMU GUIDs and state fingerprints.

use super::fields::{field_doc, FieldDoc, MASS_SPRING_FIELDS, YARN_FIELDS};
use super::Scene;

/// The first line of a commented scene file.
pub const HEADER: &str = "# yarnsim scene file; after each field its unit and the values it takes \
                          (docs/scene-files.md)";

/// Comments start in this column at the latest; a longer `key = value`
/// line gets its comment two spaces after it.
const COMMENT_COLUMN: usize = 36;

impl Scene {
    /// The scene as TOML with inline arrays and a trailing comment per
    /// field giving its unit and range; [`Scene::from_toml_str`] reads it
    /// back to the same scene.
    pub fn to_commented_toml(&self) -> String {
        let (text, fields) = match self {
            Scene::Yarn(s) => (toml::to_string(s), &YARN_FIELDS[..]),
            Scene::MassSpring(s) => (toml::to_string(s), &MASS_SPRING_FIELDS[..]),
        };
        // The scene types are plain structs of numbers, strings, arrays and
        // tables: serialization has nothing that can fail.
        let text = text.expect("a scene always serializes");
        let sheet = match self {
            Scene::Yarn(s) => sheet_comment(s),
            Scene::MassSpring(_) => String::new(),
        };
        format!("{HEADER}\n{sheet}{}", annotate(&text, fields))
    }
}

/// For a material given per yarn, comment lines with the sheet it stands
/// for and the model's values per metre of depth; empty otherwise.
fn sheet_comment(scene: &super::YarnScene) -> String {
    let m = &scene.material;
    let Some(s) = m.spacing() else {
        return String::new();
    };
    format!(
        "# [material] is given per yarn: a sheet of yarns at spacing {s:.4e} m ({:.1} per m of depth);\n\
         # per m of depth: k = {:.4e} N/m, density = {:.4e} kg/m^2, bending = {:.4e} N m,\n\
         # youngs_modulus = {:.4e} N/m, gamma = {:.4e} N/m. A force per m of depth (pin reactions,\n\
         # the FMU's pin[i].force) times the spacing is one yarn's, in N.\n",
        1.0 / s,
        m.k,
        m.density,
        m.bending,
        m.youngs_modulus,
        m.gamma
    )
}

/// Adds the comment of every `key = value` line of `text` (as the `toml`
/// crate writes it: one value per line, headers `[table]` and
/// `[[array]]`), aligned within each table.
pub(crate) fn annotate(text: &str, fields: &'static [FieldDoc]) -> String {
    let mut out = String::new();
    let mut block: Vec<(String, String)> = Vec::new();
    let mut section = String::new();
    // The delimiter of a multi-line string being copied, if inside one.
    let mut open_string: Option<&str> = None;
    for line in text.lines() {
        if let Some(delim) = open_string {
            block.push((line.to_string(), String::new()));
            if line.matches(delim).count() % 2 == 1 {
                open_string = None;
            }
            continue;
        }
        if line.starts_with('[') {
            flush(&mut out, &mut block);
            section = line.trim_matches(|c| c == '[' || c == ']').to_string();
            out.push_str(line);
            out.push('\n');
            continue;
        }
        let Some((key, value)) = line.split_once(" = ") else {
            block.push((line.to_string(), String::new()));
            continue;
        };
        for delim in ["\"\"\"", "'''"] {
            if value.starts_with(delim) && value.matches(delim).count() == 1 {
                open_string = Some(delim);
            }
        }
        let path = if section.is_empty() {
            key.to_string()
        } else {
            format!("{section}.{key}")
        };
        let comment = match (open_string, field_doc(fields, &path)) {
            (None, Some(doc)) => doc.comment(),
            _ => String::new(),
        };
        block.push((line.to_string(), comment));
    }
    flush(&mut out, &mut block);
    out
}

/// Writes a table's lines, their comments starting in one column.
fn flush(out: &mut String, block: &mut Vec<(String, String)>) {
    let width = block
        .iter()
        .filter(|(_, c)| !c.is_empty())
        .map(|(l, _)| l.chars().count())
        .filter(|&w| w <= COMMENT_COLUMN)
        .max()
        .unwrap_or(0);
    for (line, comment) in block.drain(..) {
        out.push_str(&line);
        if !comment.is_empty() {
            let pad = width.saturating_sub(line.chars().count());
            out.push_str(&" ".repeat(pad));
            out.push_str("  # ");
            out.push_str(&comment);
        }
        out.push('\n');
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::builtin_names;

    /// Every field the writer writes has a unit entry, for every built-in
    /// scene and a yarn scene with every optional field set.
    fn keys_written(text: &str) -> Vec<String> {
        let mut section = String::new();
        let mut keys = Vec::new();
        for line in text.lines() {
            if line.starts_with('[') {
                section = line.trim_matches(|c| c == '[' || c == ']').to_string();
            } else if let Some((key, _)) = line.split_once(" = ") {
                keys.push(if section.is_empty() {
                    key.to_string()
                } else {
                    format!("{section}.{key}")
                });
            }
        }
        keys
    }

    #[test]
    fn every_written_field_has_its_unit_entry() {
        for (name, _) in builtin_names() {
            let scene = Scene::resolve(name).unwrap();
            let fields = match scene {
                Scene::Yarn(_) => &YARN_FIELDS[..],
                Scene::MassSpring(_) => &MASS_SPRING_FIELDS[..],
            };
            let plain = scene.to_toml_string();
            for key in keys_written(&plain) {
                assert!(field_doc(fields, &key).is_some(), "{name}: {key}");
            }
        }
    }

    #[test]
    fn comments_are_aligned_and_multi_line_strings_left_alone() {
        let text =
            "a = 1\nlong_key = [1, 2]\ndescription = \"\"\"\nx = 1\n\"\"\"\n\n[grid]\nsize = 1.0\n";
        let fields: &'static [FieldDoc] = &[
            FieldDoc {
                key: "a",
                unit: "m",
                range: "",
            },
            FieldDoc {
                key: "long_key",
                unit: "s",
                range: "> 0",
            },
            FieldDoc {
                key: "grid.size",
                unit: "m",
                range: "",
            },
        ];
        let out = annotate(text, fields);
        assert_eq!(
            out,
            "a = 1              # m\nlong_key = [1, 2]  # s, > 0\ndescription = \"\"\"\nx = 1\n\"\"\"\n\n[grid]\nsize = 1.0  # m\n"
        );
    }
}
