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
pub fn from_toml_error(text: &str, err: toml::de::Error) -> SceneError {
    let span = err.span();
    SceneError::Parse {
        line: span.as_ref().map(|s| line_of(text, s.start)),
        field: span.as_ref().and_then(|s| key_at(text, s.start)),
        message: err.message().trim().to_string(),
    }
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
    }
}
