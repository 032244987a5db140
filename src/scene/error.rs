//! Errors of scene loading: every message names the field, and the line where
//! the file has one.

use std::fmt;

/// Why a scene could not be loaded or built.
#[derive(Debug, Clone, PartialEq)]
pub enum SceneError {
    /// The file could not be read.
    Io { path: String, message: String },
    /// The TOML text is malformed or a field has a bad value. `line` is 1-based.
    Parse {
        line: Option<usize>,
        field: Option<String>,
        message: String,
    },
    /// A value is valid on its own but not in combination with others.
    Invalid {
        field: String,
        line: Option<usize>,
        message: String,
    },
    /// No built-in scene has this name.
    UnknownScene { name: String, known: Vec<String> },
    /// A `--set KEY=VALUE` override (see [`crate::scene::overrides`]) is
    /// malformed or gives the scene a bad value. `argument` is the 1-based
    /// position of the override among all of them; `field` is named when it
    /// is not the override's own key.
    Override {
        argument: usize,
        text: String,
        field: Option<String>,
        message: String,
    },
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SceneError::Io { path, message } => {
                write!(f, "cannot read scene file {path}: {message}")
            }
            SceneError::Parse {
                line,
                field,
                message,
            } => {
                write!(f, "scene error")?;
                if let Some(l) = line {
                    write!(f, " at line {l}")?;
                }
                if let Some(k) = field {
                    write!(f, " in field `{k}`")?;
                }
                write!(f, ": {message}")
            }
            SceneError::Invalid {
                field,
                line,
                message,
            } => {
                write!(f, "scene error")?;
                if let Some(l) = line {
                    write!(f, " at line {l}")?;
                }
                write!(f, " in field `{field}`: {message}")
            }
            SceneError::Override {
                argument,
                text,
                field,
                message,
            } => {
                write!(f, "scene error in --set argument {argument} (`{text}`)")?;
                if let Some(k) = field {
                    write!(f, " in field `{k}`")?;
                }
                write!(f, ": {message}")
            }
            SceneError::UnknownScene { name, known } => {
                write!(
                    f,
                    "unknown scene `{name}`; built-in scenes: {}",
                    known.join(", ")
                )
            }
        }
    }
}

impl std::error::Error for SceneError {}

/// 1-based line of byte offset `pos` in `text`.
/// Line of the `i`-th `header` table (e.g. `[[yarns]]`) in `text`, when
/// there is a text and it has that many.
pub(crate) fn table_line(text: Option<&str>, header: &str, i: usize) -> Option<usize> {
    text.and_then(|t| t.match_indices(header).nth(i).map(|(p, _)| line_of(t, p)))
}

pub fn line_of(text: &str, pos: usize) -> usize {
    text.as_bytes()[..pos.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// The dotted path of the key at byte offset `pos`, best effort: the last
/// `[table]` header above it plus the key on its line.
pub fn key_at(text: &str, pos: usize) -> Option<String> {
    let pos = pos.min(text.len());
    let line_start = text[..pos].rfind('\n').map_or(0, |i| i + 1);
    let line_end = text[pos..].find('\n').map_or(text.len(), |i| pos + i);
    let line = text[line_start..line_end].trim();
    if line.starts_with('[') {
        // A table header names its own table, not the one above it.
        return Some(
            line.trim_matches(|c| c == '[' || c == ']')
                .trim()
                .to_string(),
        );
    }
    let key = line
        .split('=')
        .next()
        .map(str::trim)
        .filter(|k| !k.is_empty() && !k.starts_with('['));
    let table = text[..line_start]
        .lines()
        .rev()
        .map(str::trim)
        .find(|l| l.starts_with('['));
    let table = table.map(|t| t.trim_matches(|c| c == '[' || c == ']').trim().to_string());
    match (table, key) {
        (Some(t), Some(k)) => Some(format!("{t}.{k}")),
        (None, Some(k)) => Some(k.to_string()),
        (Some(t), None) => Some(t),
        (None, None) => None,
    }
}

/// Turns a `toml` deserialization error into a [`SceneError`] with line and field.
///
/// A missing field is named by its own dotted path: serde reports it with
/// the span of the table that lacks it (the whole document for a top-level
/// field, an empty span at its start), so the key found at that span is
/// another field's; the line is the table's header, none at top level.
pub fn from_toml_error(text: &str, err: toml::de::Error) -> SceneError {
    let span = err.span();
    let message = err.message().trim().to_string();
    if let Some(name) = missing_field(&message) {
        let table = span
            .as_ref()
            .filter(|s| s.start > 0)
            .and_then(|s| table_at(text, s.start));
        let (line, field) = match table {
            Some((line, path)) => (Some(line), format!("{path}.{name}")),
            None => (None, name.to_string()),
        };
        return SceneError::Parse {
            line,
            field: Some(field),
            message,
        };
    }
    SceneError::Parse {
        line: span.as_ref().map(|s| line_of(text, s.start)),
        field: span.as_ref().and_then(|s| key_at(text, s.start)),
        message,
    }
}

/// `X` of serde's message "missing field `X`".
fn missing_field(message: &str) -> Option<&str> {
    message
        .strip_prefix("missing field `")
        .and_then(|m| m.strip_suffix('`'))
}

/// The line and dotted path of the table whose span starts at `pos`: a
/// `[table]` or `[[table]]` header on that line or above it, or the key of
/// an inline table (`material = { ... }`) on that line.
fn table_at(text: &str, pos: usize) -> Option<(usize, String)> {
    let pos = pos.min(text.len());
    let line_start = text[..pos].rfind('\n').map_or(0, |i| i + 1);
    let before = &text[line_start..pos];
    if before.contains('=') {
        return key_at(text, line_start).map(|k| (line_of(text, pos), k));
    }
    let head_end = text[pos..].find('\n').map_or(text.len(), |i| pos + i);
    let mut start = head_end;
    for l in text[..head_end].lines().rev() {
        start -= l.len();
        let t = l.trim();
        if t.starts_with('[') {
            let name = t.trim_matches(|c| c == '[' || c == ']').trim().to_string();
            return Some((line_of(text, start), name));
        }
        start = start.saturating_sub(1);
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn key_and_line() {
        let text = "a = 1\n[grid]\nresolution = -3\n";
        let pos = text.find("-3").unwrap();
        assert_eq!(line_of(text, pos), 3);
        assert_eq!(key_at(text, pos).as_deref(), Some("grid.resolution"));
        let text = "[grid]\nresolution = 3\n[[yarns]]\nvertices = 3\n[materal]\nk = 1\n";
        let pos = text.find("[materal]").unwrap();
        assert_eq!(key_at(text, pos).as_deref(), Some("materal"));
        assert_eq!(key_at(text, pos + 3).as_deref(), Some("materal"));
    }

    #[test]
    fn a_missing_table_is_named_without_a_line() {
        let base = crate::scene::builtin("yarn-reference")
            .unwrap()
            .to_toml_string();
        for table in ["material", "time", "grid"] {
            let header = format!("[{table}]\n");
            let i = base.find(&header).unwrap();
            let rest = &base[i + header.len()..];
            let j = rest
                .find("\n[")
                .map_or(base.len(), |j| i + header.len() + j + 1);
            let text = format!("{}{}", &base[..i], &base[j..]);
            let e = crate::scene::Scene::from_toml_str(&text).unwrap_err();
            assert_eq!(
                e.to_string(),
                format!("scene error in field `{table}`: missing field `{table}`"),
            );
        }
    }

    #[test]
    fn a_missing_field_is_named_at_its_table() {
        let base = crate::scene::builtin("yarn-reference")
            .unwrap()
            .to_toml_string();
        let header = base.lines().position(|l| l == "[material]").unwrap() + 1;
        let text = base.replace("\nk = 1000.0\n", "\n");
        assert_ne!(text, base);
        let e = crate::scene::Scene::from_toml_str(&text).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!("scene error at line {header} in field `material.k`: missing field `k`"),
        );
        // The same in an array of tables and in an inline table.
        let text = "[grid]\nresolution = 64\n[time]\ndt = 1e-4\n\
                    [material]\nk = 1\ngamma = 1\nyoungs_modulus = 1\nfriction = 0\n\
                    [[yarns]]\nstart = [0.1, 0.5]\nend = [0.9, 0.5]\n";
        let e = crate::scene::Scene::from_toml_str(text).unwrap_err();
        assert_eq!(
            e.to_string(),
            "scene error at line 10 in field `yarns.vertices`: missing field `vertices`"
        );
        let text = format!(
            "time = {{ frame_dt = 0.1 }}\n{}",
            text.replace("[time]\ndt = 1e-4\n", "")
        );
        let e = crate::scene::Scene::from_toml_str(&text).unwrap_err();
        assert_eq!(
            e.to_string(),
            "scene error at line 1 in field `time.dt`: missing field `dt`"
        );
    }
}
