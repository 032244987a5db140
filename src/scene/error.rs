//! Errors of scene loading: every message names the field, and the line where
//! the file has one.

use std::fmt;

/// Why a scene could not be loaded or built.
#[derive(Debug, Clone, PartialEq)]
pub enum SceneError {
    /// The file could not be read.
    Io {
        /// The path as given.
        path: String,
        /// The operating system's message.
        message: String,
    },
    /// The TOML text is malformed or a field has a bad value. `line` is 1-based.
    Parse {
        /// 1-based line, where the file has one.
        line: Option<usize>,
        /// The field's path (`material.friction`, `yarns[2].vertices`), where known.
        field: Option<String>,
        /// What is wrong.
        message: String,
    },
    /// A value is valid on its own but not in combination with others.
    Invalid {
        /// The field's path.
        field: String,
        /// 1-based line, where the file has one.
        line: Option<usize>,
        /// What is wrong.
        message: String,
    },
    /// No built-in scene has this name.
    UnknownScene {
        /// The name asked for.
        name: String,
        /// The names of the built-ins.
        known: Vec<String>,
    },
    /// A `--set KEY=VALUE` override (see [`crate::scene::overrides`]) is
    /// malformed or gives the scene a bad value. `argument` is the 1-based
    /// position of the override among all of them; `field` is named when it
    /// is not the override's own key.
    Override {
        /// 1-based position of the override among all of them.
        argument: usize,
        /// The override as given (`KEY=VALUE`).
        text: String,
        /// The field the message is about, when it is not the override's own key.
        field: Option<String>,
        /// What is wrong.
        message: String,
    },
}

/// The rest of a scene error's message: ` at line L` and `` in field `K` ``
/// where known, then `: message`.
fn write_place(
    f: &mut fmt::Formatter<'_>,
    line: Option<usize>,
    field: Option<&str>,
    message: &str,
) -> fmt::Result {
    if let Some(l) = line {
        write!(f, " at line {l}")?;
    }
    if let Some(k) = field {
        write!(f, " in field `{k}`")?;
    }
    write!(f, ": {message}")
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
                write_place(f, *line, field.as_deref(), message)
            }
            SceneError::Invalid {
                field,
                line,
                message,
            } => {
                write!(f, "scene error")?;
                write_place(f, *line, Some(field), message)
            }
            SceneError::Override {
                argument,
                text,
                field,
                message,
            } => {
                write!(f, "scene error in --set argument {argument} (`{text}`)")?;
                write_place(f, None, field.as_deref(), message)
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

/// Line of the `i`-th `header` table (e.g. `[[yarns]]`) in `text`, when
/// there is a text and it has that many: a line that starts with the
/// header (a comment may follow it).
pub(crate) fn table_line(text: Option<&str>, header: &str, i: usize) -> Option<usize> {
    text.and_then(|t| {
        t.lines()
            .enumerate()
            .filter(|(_, l)| l.trim_start().starts_with(header))
            .nth(i)
            .map(|(n, _)| n + 1)
    })
}

/// 1-based line of byte offset `pos` in `text`.
pub fn line_of(text: &str, pos: usize) -> usize {
    text.as_bytes()[..pos.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// The path of a table header line (`[grid]`, `[[yarns]]`, with a comment
/// after it or not) as the user writes a field path: `grid`, and for an
/// entry of an array of tables its index among the headers of that name
/// up to this one, `yarns[2]`. `above` is the text before the header line.
fn header_path(above: &str, line: &str) -> Option<String> {
    let line = line.trim();
    if let Some(rest) = line.strip_prefix("[[") {
        let name = rest.split("]]").next()?.trim();
        let before = above
            .lines()
            .filter(|l| {
                l.trim()
                    .strip_prefix("[[")
                    .and_then(|r| r.split("]]").next())
                    .is_some_and(|n| n.trim() == name)
            })
            .count();
        return Some(format!("{name}[{before}]"));
    }
    let rest = line.strip_prefix('[')?;
    Some(rest.split(']').next()?.trim().to_string())
}

/// The path of the key at byte offset `pos`, best effort: the last
/// `[table]` header above it (with the entry's index under a `[[table]]`
/// header, `yarns[1]`) plus the key on its line.
pub fn key_at(text: &str, pos: usize) -> Option<String> {
    let pos = pos.min(text.len());
    let line_start = text[..pos].rfind('\n').map_or(0, |i| i + 1);
    let line_end = text[pos..].find('\n').map_or(text.len(), |i| pos + i);
    let line = text[line_start..line_end].trim();
    if line.starts_with('[') {
        // A table header names its own table, not the one above it.
        return header_path(&text[..line_start], line);
    }
    let key = line
        .split('=')
        .next()
        .map(str::trim)
        .filter(|k| !k.is_empty() && !k.starts_with('['));
    let table = text[..line_start]
        .lines()
        .enumerate()
        .filter(|(_, l)| l.trim().starts_with('['))
        .last()
        .and_then(|(n, l)| {
            let above: usize = text[..line_start]
                .split_inclusive('\n')
                .take(n)
                .map(str::len)
                .sum();
            header_path(&text[..above], l)
        });
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
    let message = plain_message(err.message().trim());
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
        field: span.as_ref().and_then(|s| field_at(text, s.start)),
        message,
    }
}

/// The path of the field at byte offset `pos`: [`key_at`]'s, or, where
/// the field sits in an inline array of tables (`yarns = [{ ... }, { ... }]`),
/// the parser's path with the entry's index (`yarns[1].vertices`), which
/// the line alone cannot give. An entry of an array of numbers keeps the
/// array's name (`gravity`), as `--set` takes it.
fn field_at(text: &str, pos: usize) -> Option<String> {
    let by_line = key_at(text, pos);
    match spanned_path(text, pos) {
        Some(p) if p.contains("].") && !by_line.as_deref().is_some_and(|l| l.contains('[')) => {
            Some(p)
        }
        _ => by_line,
    }
}

/// The path of the innermost key or value whose span holds byte offset
/// `pos`, through tables and arrays, from the TOML parser's spans; `None`
/// where the text does not parse.
fn spanned_path(text: &str, pos: usize) -> Option<String> {
    let doc = toml::de::DeTable::parse(text).ok()?;
    let mut path = String::new();
    spanned_table(doc.get_ref(), pos, &mut path);
    (!path.is_empty()).then_some(path)
}

fn spanned_table(table: &toml::de::DeTable<'_>, pos: usize, path: &mut String) {
    for (key, value) in table.iter() {
        if key.span().contains(&pos) || value.span().contains(&pos) {
            if !path.is_empty() {
                path.push('.');
            }
            path.push_str(key.get_ref());
            spanned_value(value.get_ref(), pos, path);
            return;
        }
    }
}

fn spanned_value(value: &toml::de::DeValue<'_>, pos: usize, path: &mut String) {
    match value {
        toml::de::DeValue::Table(t) => spanned_table(t, pos, path),
        toml::de::DeValue::Array(a) => {
            if let Some((i, e)) = a.iter().enumerate().find(|(_, e)| e.span().contains(&pos)) {
                path.push_str(&format!("[{i}]"));
                spanned_value(e.get_ref(), pos, path);
            }
        }
        _ => {}
    }
}

/// serde's messages in the words of a scene file: a type error names
/// the TOML type the field takes ("a number", "an integer", "a string",
/// "a boolean", "a table", "an array") instead of the Rust type
/// (`expected f64`), and an unknown field or value gets the known one it
/// is probably a misspelling of. Other messages are kept.
pub fn plain_message(message: &str) -> String {
    for prefix in ["invalid type: ", "invalid value: "] {
        if let Some((got, expected)) = message
            .strip_prefix(prefix)
            .and_then(|m| m.rsplit_once(", expected "))
        {
            return format!(
                "must be {}, got {}",
                expected_words(expected),
                got_words(got)
            );
        }
    }
    if let Some((got, expected)) = message
        .strip_prefix("invalid length ")
        .and_then(|m| m.split_once(", expected "))
    {
        let n = expected
            .strip_prefix("an array of length ")
            .or_else(|| expected.strip_prefix("a tuple of size "));
        return match n {
            Some(n) => format!("must be an array of {n} values, got {got}"),
            None => format!("must be {}, got {got} values", expected_words(expected)),
        };
    }
    let unknown = message
        .strip_prefix("unknown field `")
        .or_else(|| message.strip_prefix("unknown variant `"));
    if let Some(rest) = unknown {
        if let Some((name, known)) = rest.split_once("`, expected ") {
            let close = known
                .split('`')
                .skip(1)
                .step_by(2)
                .filter(|k| similar(name, k))
                .min_by_key(|k| edit_distance(name, k));
            if let Some(k) = close {
                return format!("{message}; did you mean `{k}`?");
            }
        }
    }
    message.to_string()
}

/// serde's expected type in TOML words.
fn expected_words(expected: &str) -> String {
    let e = expected.trim();
    let words = match e {
        "f32" | "f64" => "a number",
        "u8" | "u16" | "u32" | "u64" | "u128" | "usize" => "an integer >= 0",
        "i8" | "i16" | "i32" | "i64" | "i128" | "isize" => "an integer",
        "a string" | "a borrowed string" | "string" | "a char" => "a string",
        "a boolean" | "bool" => "a boolean",
        "a map" | "map" => "a table",
        "a sequence" | "sequence" => "an array",
        _ if e.starts_with("struct ") => "a table",
        _ if e.starts_with("an array of length ") => {
            return format!("an array of {} values", &e["an array of length ".len()..]);
        }
        _ => return e.to_string(),
    };
    words.to_string()
}

/// serde's description of the value found (`string "abc"`, ``integer `5` ``,
/// ``floating point `2.5` ``, `sequence`, `map`) in TOML words.
fn got_words(got: &str) -> String {
    let g = got.trim();
    let ticked = |prefix: &str| {
        g.strip_prefix(prefix)
            .map(|v| v.trim().trim_matches('`').to_string())
    };
    if let Some(v) = g.strip_prefix("string ") {
        return format!("the string {v}");
    }
    if let Some(v) = ticked("integer") {
        return format!("the integer {v}");
    }
    if let Some(v) = ticked("floating point") {
        return format!("the number {v}");
    }
    if let Some(v) = ticked("boolean") {
        return format!("the boolean {v}");
    }
    match g {
        "sequence" => "an array".into(),
        "map" => "a table".into(),
        _ => g.to_string(),
    }
}

/// Whether an unknown field name is probably a misspelling of `known`:
/// within two edits and half its length (`centre` for `center`, `strat`
/// for `start`).
fn similar(name: &str, known: &str) -> bool {
    let d = edit_distance(name, known);
    d > 0 && d <= 2 && 2 * d <= known.len()
}

/// Levenshtein distance of two short ASCII names.
fn edit_distance(a: &str, b: &str) -> usize {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, &ca) in a.iter().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let here = (prev + usize::from(ca != cb))
                .min(row[j] + 1)
                .min(row[j + 1] + 1);
            prev = row[j + 1];
            row[j + 1] = here;
        }
    }
    row[b.len()]
}

/// `X` of serde's message "missing field `X`".
fn missing_field(message: &str) -> Option<&str> {
    message
        .strip_prefix("missing field `")
        .and_then(|m| m.split_once('`'))
        .map(|(name, _)| name)
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
            return header_path(&text[..start], t).map(|name| (line_of(text, start), name));
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
        // An entry of an array of tables carries its index, also after a
        // header with a comment.
        let text = "[[yarns]]\nvertices = 3\n[[obstacles]]\nradius = 1\n\
                    [[yarns]]  # the second\nvertices = 4\n[[yarns]]\nvertices = 5\n";
        let at = |s: &str| key_at(text, text.find(s).unwrap());
        assert_eq!(at("3").as_deref(), Some("yarns[0].vertices"));
        assert_eq!(at("1").as_deref(), Some("obstacles[0].radius"));
        assert_eq!(at("4").as_deref(), Some("yarns[1].vertices"));
        assert_eq!(at("5").as_deref(), Some("yarns[2].vertices"));
        assert_eq!(at("[[yarns]]  #").as_deref(), Some("yarns[1]"));
        assert_eq!(table_line(Some(text), "[[yarns]]", 2), Some(7));
    }

    #[test]
    fn an_entry_of_an_inline_array_of_tables_is_named_with_its_index() {
        let text = "obstacles = [{ center = [0.5, 0.5], radius = 0.1 },\n  \
                    { center = [0.2, 0.2], radius = \"big\" }]\n";
        let pos = text.find("\"big\"").unwrap();
        assert_eq!(field_at(text, pos).as_deref(), Some("obstacles[1].radius"));
        // a [[table]] entry keeps the header's index
        let text = "[[obstacles]]\nradius = 1\n[[obstacles]]\nradius = \"big\"\n";
        let pos = text.find("\"big\"").unwrap();
        assert_eq!(field_at(text, pos).as_deref(), Some("obstacles[1].radius"));
    }

    #[test]
    fn serde_words_become_toml_words() {
        for (serde, plain) in [
            (
                "invalid type: string \"abc\", expected f64",
                "must be a number, got the string \"abc\"",
            ),
            (
                "invalid type: floating point `2.5`, expected i64",
                "must be an integer, got the number 2.5",
            ),
            (
                "invalid value: integer `-1`, expected u32",
                "must be an integer >= 0, got the integer -1",
            ),
            (
                "invalid type: integer `1`, expected a boolean",
                "must be a boolean, got the integer 1",
            ),
            (
                "invalid type: map, expected a sequence",
                "must be an array, got a table",
            ),
            (
                "invalid type: sequence, expected struct Material",
                "must be a table, got an array",
            ),
            (
                "invalid length 3, expected an array of length 2",
                "must be an array of 2 values, got 3",
            ),
            (
                "unknown field `centre`, expected one of `center`, `radius`",
                "unknown field `centre`, expected one of `center`, `radius`; did you mean `center`?",
            ),
            ("must be >= 0, got -1", "must be >= 0, got -1"),
        ] {
            assert_eq!(plain_message(serde), plain, "{serde}");
        }
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
            "scene error at line 10 in field `yarns[0].vertices`: missing field `vertices`"
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
