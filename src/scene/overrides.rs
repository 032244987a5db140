//! Overrides of scene fields, `KEY=VALUE` (the CLI's `--set`), applied to
//! the scene's TOML table before it is deserialized, so an overridden value
//! is validated by the same code, with the same messages, as one in a file.
//!
//! * `KEY` is a dotted path of bare TOML keys (`A-Z a-z 0-9 _ -`):
//!   `gravity`, `material.friction`. An index `[N]` (the form errors
//!   print) or a segment `.N` picks an entry of an array, of tables
//!   (`yarns[0].count` = `yarns.0.count`, `obstacles[1].radius`) or of
//!   values (`gravity[1]`); the entry must exist. Missing tables on the way
//!   are created (`attractor.active=true` on a scene without `[attractor]`).
//! * `VALUE` is a TOML value: `0.1`, `true`, `"apic"`, `[0, -3]`,
//!   `{ mode = "slip" }`. A bare word that is not TOML (`apic`, `auto`) is
//!   taken as a string, so `--set transfer.scheme=apic` needs no quotes.
//!
//! An error names the override by its position and text (`argument 2`,
//! `material.friction=abc`), never a line of the re-written TOML.

use super::error::SceneError;
use super::{builtin, Scene};

/// One parsed `KEY=VALUE` override.
#[derive(Clone, Debug, PartialEq)]
pub struct Override {
    /// 1-based position among the overrides, for error messages.
    pub argument: usize,
    /// The argument as given.
    pub text: String,
    /// Key path segments (`["yarns", "0", "count"]`).
    pub path: Vec<String>,
    /// The new value.
    pub value: toml::Value,
}

impl Override {
    /// Parses the `argument`-th (1-based) override `text`.
    pub fn parse(argument: usize, text: &str) -> Result<Override, SceneError> {
        let err = |message: String| SceneError::Override {
            argument,
            text: text.to_string(),
            field: None,
            message,
        };
        let Some((key, value)) = text.split_once('=') else {
            return Err(err("expected KEY=VALUE, e.g. material.friction=0.1".into()));
        };
        let key = key.trim();
        let path = key_path(key).map_err(err)?;
        let value = parse_value(value.trim()).map_err(err)?;
        Ok(Override {
            argument,
            text: text.to_string(),
            path,
            value,
        })
    }

    /// The key as errors print it, with indices in brackets (`yarns[0].count`).
    pub fn key(&self) -> String {
        self.path
            .iter()
            .fold(String::new(), |walked, seg| join(&walked, seg))
    }

    /// Sets the value in `table`, creating missing tables on the way.
    pub fn apply(&self, table: &mut toml::Table) -> Result<(), SceneError> {
        let err = |message: String| SceneError::Override {
            argument: self.argument,
            text: self.text.clone(),
            field: None,
            message,
        };
        let (last, inner) = self.path.split_last().expect("a key has a segment");
        let mut here = Slot::Table(table);
        let mut walked = String::new();
        for seg in inner {
            here = here.child(seg, &walked).map_err(err)?;
            walked = join(&walked, seg);
        }
        here.set(last, self.value.clone(), &walked).map_err(err)
    }
}

/// Where the walk down a key path stands.
enum Slot<'a> {
    Table(&'a mut toml::Table),
    Array(&'a mut Vec<toml::Value>),
}

impl<'a> Slot<'a> {
    /// The table or array at `seg`; `walked` is the path so far, for messages.
    fn child(self, seg: &str, walked: &str) -> Result<Slot<'a>, String> {
        let v = match self {
            Slot::Table(t) => t
                .entry(seg.to_string())
                .or_insert_with(|| toml::Value::Table(toml::Table::new())),
            Slot::Array(a) => element(a, seg, walked)?,
        };
        let here = join(walked, seg);
        match v {
            toml::Value::Table(t) => Ok(Slot::Table(t)),
            toml::Value::Array(a) => Ok(Slot::Array(a)),
            other => Err(format!(
                "`{here}` is {}, not a table or array",
                value_words(other)
            )),
        }
    }

    fn set(self, seg: &str, value: toml::Value, walked: &str) -> Result<(), String> {
        match self {
            Slot::Table(t) => {
                t.insert(seg.to_string(), value);
            }
            Slot::Array(a) => *element(a, seg, walked)? = value,
        }
        Ok(())
    }
}

/// Element `seg` (an index) of the array at `walked`.
fn element<'a>(
    a: &'a mut [toml::Value],
    seg: &str,
    walked: &str,
) -> Result<&'a mut toml::Value, String> {
    let n = a.len();
    let i: usize = seg
        .parse()
        .map_err(|_| format!("`{walked}` is an array; `{seg}` is not an index"))?;
    a.get_mut(i).ok_or_else(|| {
        let has = match n {
            0 => "no entries".to_string(),
            1 => format!("1 entry, `{walked}[0]`"),
            _ => format!("{n} entries, `{walked}[0]` to `{walked}[{}]`", n - 1),
        };
        format!("index {i} is out of range: `{walked}` has {has}")
    })
}

/// `walked` extended by `seg`: `yarns` and `0` give `yarns[0]`, `yarns[0]`
/// and `count` give `yarns[0].count`.
fn join(walked: &str, seg: &str) -> String {
    if walked.is_empty() {
        seg.to_string()
    } else if is_index(seg) {
        format!("{walked}[{seg}]")
    } else {
        format!("{walked}.{seg}")
    }
}

fn is_index(seg: &str) -> bool {
    !seg.is_empty() && seg.chars().all(|c| c.is_ascii_digit())
}

/// The segments of a key: `yarns[0].count` and `yarns.0.count` both give
/// `["yarns", "0", "count"]`.
fn key_path(key: &str) -> Result<Vec<String>, String> {
    let bad = |what: &str| {
        format!(
            "{what}; a key joins names (letters, digits, `_` and `-`) with `.`, with `[N]` \
             (or `.N`) for entry N of a list, e.g. yarns[0].count"
        )
    };
    let mut path = Vec::new();
    for part in key.split('.') {
        let part = part.trim();
        let (name, mut rest) = part.split_at(part.find('[').unwrap_or(part.len()));
        let name = name.trim();
        if name.is_empty() && rest.is_empty() {
            return Err(format!("empty key segment in `{key}`"));
        }
        if !name.is_empty() {
            if !is_bare_key(name) {
                return Err(bad(&format!("`{name}` is not a key")));
            }
            path.push(name.to_string());
        } else if path.is_empty() {
            return Err(bad(&format!("`{part}` has no name before its index")));
        }
        while !rest.is_empty() {
            let index = rest
                .strip_prefix('[')
                .and_then(|r| r.split_once(']'))
                .filter(|(i, _)| is_index(i.trim()));
            let Some((i, after)) = index else {
                return Err(bad(&format!("`{part}` is not a key")));
            };
            path.push(i.trim().to_string());
            rest = after.trim_start();
        }
    }
    Ok(path)
}

/// The TOML type of a value in the words of the scene errors.
fn value_words(v: &toml::Value) -> &'static str {
    match v {
        toml::Value::String(_) => "a string",
        toml::Value::Integer(_) => "an integer",
        toml::Value::Float(_) => "a number",
        toml::Value::Boolean(_) => "a boolean",
        toml::Value::Datetime(_) => "a date-time",
        toml::Value::Array(_) => "an array",
        toml::Value::Table(_) => "a table",
    }
}

fn is_bare_key(s: &str) -> bool {
    !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}

/// A TOML value, or a bare word taken as a string.
fn parse_value(text: &str) -> Result<toml::Value, String> {
    if text.is_empty() {
        return Err("empty value; give a TOML value, e.g. 0.1, true, \"apic\" or [0, -3]".into());
    }
    match format!("v = {text}").parse::<toml::Table>() {
        Ok(mut t) if t.len() == 1 => Ok(t.remove("v").expect("the one key")),
        Ok(_) => Err(format!("`{text}` is more than one TOML value")),
        Err(_) if is_bare_key(text) && text.starts_with(|c: char| c.is_ascii_alphabetic()) => {
            Ok(toml::Value::String(text.to_string()))
        }
        Err(e) => Err(format!(
            "`{text}` is not a TOML value: {}",
            e.message().trim()
        )),
    }
}

/// Parses every `KEY=VALUE` of `args` (numbered from 1).
pub fn parse_all(args: &[String]) -> Result<Vec<Override>, SceneError> {
    args.iter()
        .enumerate()
        .map(|(i, a)| Override::parse(i + 1, a))
        .collect()
}

/// `text` (a scene file's TOML) with `overrides` applied, parsed and
/// validated like a file. `text` itself must be a valid scene: its own
/// errors are reported first, with their lines, by [`Scene::from_toml_str`].
pub fn apply_to_text(text: &str, overrides: &[Override]) -> Result<Scene, SceneError> {
    let base = Scene::from_toml_str(text)?;
    if overrides.is_empty() {
        return Ok(base);
    }
    let table: toml::Table = text
        .parse()
        .expect("a text that parsed as a scene is a TOML table");
    let parse = |n: usize| -> Result<Result<Scene, SceneError>, SceneError> {
        let mut t = table.clone();
        for o in &overrides[..n] {
            o.apply(&mut t)?;
        }
        let text = toml::to_string(&t).map_err(|e| SceneError::Override {
            argument: overrides[n - 1].argument,
            text: overrides[n - 1].text.clone(),
            field: None,
            message: e.to_string(),
        })?;
        Ok(Scene::from_toml_str(&text))
    };
    let err = match parse(overrides.len())? {
        Ok(scene) => return Ok(scene),
        Err(e) => e,
    };
    // Blame the last override whose key the error's field is about; else
    // the first one after which the overridden scene is invalid.
    let field = error_field(&err);
    let blamed = field.as_deref().and_then(|f| {
        overrides
            .iter()
            .rev()
            .find(|o| same_field(&o.key(), f))
            .map(|o| (o, err.clone()))
    });
    let (o, e) = match blamed {
        Some(b) => b,
        None => {
            let mut found = None;
            for n in 1..=overrides.len() {
                if let Err(e) = parse(n)? {
                    found = Some((&overrides[n - 1], e));
                    break;
                }
            }
            found.expect("all overrides together give an error")
        }
    };
    // The field is named when it is not the key or a part of it.
    let field = error_field(&e).filter(|f| !same_field(&o.key(), f));
    Err(SceneError::Override {
        argument: o.argument,
        text: o.text.clone(),
        field,
        message: error_message(&e),
    })
}

/// The field an error names, if any.
fn error_field(e: &SceneError) -> Option<String> {
    match e {
        SceneError::Parse { field, .. } => field.clone(),
        SceneError::Invalid { field, .. }
        | SceneError::Override {
            field: Some(field), ..
        } => Some(field.clone()),
        _ => None,
    }
}

/// The message of an error without its line and field (those refer to the
/// re-written TOML, not to anything the user wrote).
fn error_message(e: &SceneError) -> String {
    match e {
        SceneError::Parse { message, .. }
        | SceneError::Invalid { message, .. }
        | SceneError::Override { message, .. } => message.clone(),
        other => other.to_string(),
    }
}

/// Segments of a field path, indices included: `yarns[0].count` and
/// `yarns.0.count` give `yarns`, `0`, `count`.
fn segments(path: &str) -> Vec<&str> {
    path.split(['.', '[', ']'])
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .collect()
}

/// Whether an override of `key` is about the error's `field`: one path is a
/// prefix of the other (`material` set as a whole and `material.k` missing;
/// `yarns[0].count` set and `yarns[0]` refused, but not `yarns[1]`).
fn same_field(key: &str, field: &str) -> bool {
    let (k, f) = (segments(key), segments(field));
    let n = k.len().min(f.len());
    n > 0 && k[..n] == f[..n]
}

impl Scene {
    /// [`Scene::resolve`] with `overrides` (`KEY=VALUE`, see the module
    /// documentation) applied to the scene's TOML: a built-in scene's
    /// [`Scene::to_toml_string`] or the file's text. Without overrides the
    /// scene is exactly [`Scene::resolve`]'s.
    pub fn resolve_with(name_or_path: &str, overrides: &[String]) -> Result<Scene, SceneError> {
        let overrides = parse_all(overrides)?;
        if overrides.is_empty() {
            return Scene::resolve(name_or_path);
        }
        let text = match builtin(name_or_path) {
            Some(s) => s.to_toml_string(),
            None => {
                let p = std::path::Path::new(name_or_path);
                if !(p.exists() || name_or_path.ends_with(".toml")) {
                    // Unknown name: the same error as without overrides.
                    return Scene::resolve(name_or_path);
                }
                std::fs::read_to_string(p).map_err(|e| SceneError::Io {
                    path: p.display().to_string(),
                    message: e.to_string(),
                })?
            }
        };
        apply_to_text(&text, &overrides)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reference() -> String {
        builtin("yarn-reference").unwrap().to_toml_string()
    }

    fn set(text: &str, args: &[&str]) -> Result<Scene, SceneError> {
        let args: Vec<String> = args.iter().map(|s| s.to_string()).collect();
        apply_to_text(text, &parse_all(&args)?)
    }

    fn yarn(s: Scene) -> crate::scene::YarnScene {
        match s {
            Scene::Yarn(y) => y,
            Scene::MassSpring(_) => panic!("not a yarn scene"),
        }
    }

    #[test]
    fn values_reach_the_scene() {
        let s = yarn(
            set(
                &reference(),
                &[
                    "material.friction=0.1",
                    "gravity=[0,-3]",
                    "yarns.0.count=3",
                    "obstacles.2.radius = 0.05",
                    "transfer.scheme=apic",
                    "time.dt=\"auto\"",
                    "time.safety=0.5",
                    "walls.cells=4",
                    "gravity.0=0.5",
                ],
            )
            .unwrap(),
        );
        assert_eq!(s.material.friction, 0.1);
        assert_eq!(s.gravity, [0.5, -3.0]);
        assert_eq!(s.yarns[0].count, 3);
        assert_eq!(s.obstacles[2].radius, 0.05);
        assert_eq!(s.transfer.scheme, crate::scene::TransferScheme::Apic);
        assert!(s.time.dt.is_auto());
        assert_eq!(s.time.safety, Some(0.5));
        assert_eq!(s.walls.cells, 4);
        // Everything else as in the scene.
        let mut r = yarn(Scene::from_toml_str(&reference()).unwrap());
        r.material.friction = 0.1;
        r.gravity = [0.5, -3.0];
        r.yarns[0].count = 3;
        r.obstacles[2].radius = 0.05;
        r.transfer.scheme = crate::scene::TransferScheme::Apic;
        r.time.dt = crate::scene::StepSize::Auto;
        r.time.safety = Some(0.5);
        r.walls.cells = 4;
        assert_eq!(s, r);
    }

    #[test]
    fn no_override_is_the_scene_itself() {
        for (name, _) in crate::scene::builtin_names() {
            let s = Scene::resolve_with(name, &[]).unwrap();
            assert_eq!(s, Scene::resolve(name).unwrap(), "{name}");
        }
    }

    #[test]
    fn missing_tables_are_created_and_later_overrides_win() {
        let s = yarn(
            set(
                &reference(),
                &[
                    "attractor.active=true",
                    "material.friction=0.2",
                    "material.friction=0.4",
                ],
            )
            .unwrap(),
        );
        assert!(s.attractor.active);
        assert_eq!(s.material.friction, 0.4);
    }

    #[test]
    fn mass_spring_scenes_take_overrides() {
        for name in ["wire", "cloth", "three-particle"] {
            let text = builtin(name).unwrap().to_toml_string();
            let base = Scene::from_toml_str(&text).unwrap();
            let key = if text.contains("\ngravity") {
                "gravity=[0,0,-1]"
            } else {
                continue;
            };
            let s = set(&text, &[key]).unwrap();
            assert_ne!(s, base, "{name}");
            assert!(s
                .to_toml_string()
                .contains("gravity = [\n    0.0,\n    0.0,\n    -1.0,\n]"));
        }
    }

    fn message(text: &str, args: &[&str]) -> String {
        set(text, args).unwrap_err().to_string()
    }

    #[test]
    fn bad_values_name_the_argument_and_the_check() {
        let r = reference();
        assert_eq!(
            message(&r, &["gravity=[0,-3]", "material.friction=abc"]),
            "scene error in --set argument 2 (`material.friction=abc`): \
             must be a number, got the string \"abc\""
        );
        assert_eq!(
            message(&r, &["material.friction=-1"]),
            "scene error in --set argument 1 (`material.friction=-1`): must be >= 0, got -1"
        );
        assert_eq!(
            message(&r, &["yarns.0.count=0"]),
            "scene error in --set argument 1 (`yarns.0.count=0`): \
             must be an integer from 1 to 100000, got 0"
        );
    }

    #[test]
    fn bad_keys_are_named() {
        let r = reference();
        let wire = builtin("wire").unwrap().to_toml_string();
        let m = message(&wire, &["gravity=[0,0,0]", "material.friction=0.1"]);
        assert!(
            m.starts_with(
                "scene error in --set argument 2 (`material.friction=0.1`): \
                 unknown field `material`, expected one of `kind`"
            ),
            "{m}"
        );
        let m = message(&r, &["material.frction=0.1"]);
        assert!(
            m.starts_with(
                "scene error in --set argument 1 (`material.frction=0.1`): unknown field `frction`"
            ),
            "{m}"
        );
        assert_eq!(
            message(&r, &["yarns.3.count=2"]),
            "scene error in --set argument 1 (`yarns.3.count=2`): \
             index 3 is out of range: `yarns` has 1 entry, `yarns[0]`"
        );
        assert_eq!(
            message(&r, &["gravity.x=2"]),
            "scene error in --set argument 1 (`gravity.x=2`): \
             `gravity` is an array; `x` is not an index"
        );
        assert_eq!(
            message(&r, &["material.friction.x=2"]),
            "scene error in --set argument 1 (`material.friction.x=2`): \
             `material.friction` is a number, not a table or array"
        );
    }

    #[test]
    fn an_index_is_written_in_brackets_or_as_a_segment() {
        let r = reference();
        for args in [
            [
                "yarns[0].count=3",
                "gravity[1]=-3",
                "obstacles[2].radius=0.05",
            ],
            ["yarns.0.count=3", "gravity.1=-3", "obstacles.2.radius=0.05"],
            [
                "yarns [0] . count=3",
                "gravity[1] = -3",
                "obstacles.2 .radius=0.05",
            ],
        ] {
            let s = yarn(set(&r, &args).unwrap());
            assert_eq!(s.yarns[0].count, 3, "{args:?}");
            assert_eq!(s.gravity[1], -3.0, "{args:?}");
            assert_eq!(s.obstacles[2].radius, 0.05, "{args:?}");
        }
        for text in ["yarns.0.count=3", "yarns[0].count=3"] {
            let o = Override::parse(1, text).unwrap();
            assert_eq!(o.path, ["yarns", "0", "count"]);
            assert_eq!(o.key(), "yarns[0].count");
        }
        // Messages print the bracket form, whichever form was given.
        for key in ["yarns.0.start.x", "yarns[0].start.x"] {
            assert_eq!(
                message(&r, &[&format!("{key}=1")]),
                format!(
                    "scene error in --set argument 1 (`{key}=1`): \
                     `yarns[0].start` is an array; `x` is not an index"
                )
            );
        }
        assert_eq!(
            message(&r, &["obstacles[5].radius=0.1"]),
            "scene error in --set argument 1 (`obstacles[5].radius=0.1`): \
             index 5 is out of range: `obstacles` has 3 entries, `obstacles[0]` to `obstacles[2]`"
        );
        // A check on an entry's field names it with its index.
        assert_eq!(
            message(&r, &["yarns[0].vertices=2.5"]),
            "scene error in --set argument 1 (`yarns[0].vertices=2.5`): \
             must be an integer, got the number 2.5"
        );
        assert_eq!(
            message(&r, &["gravity=[0,-3]", "obstacles[1].friction=true"]),
            "scene error in --set argument 2 (`obstacles[1].friction=true`): \
             must be a number, got the boolean true"
        );
        for bad in [
            "yarns[x].count=1",
            "yarns[0.count=1",
            "[0].count=1",
            "yarns[0]x.count=1",
        ] {
            let m = message(&r, &[bad]);
            assert!(
                m.contains("with `[N]` (or `.N`) for entry N of a list"),
                "{m}"
            );
        }
    }

    #[test]
    fn bad_syntax_is_named() {
        let r = reference();
        assert_eq!(
            message(&r, &["gravity=[0,-3]", "material.friction"]),
            "scene error in --set argument 2 (`material.friction`): \
             expected KEY=VALUE, e.g. material.friction=0.1"
        );
        assert_eq!(
            message(&r, &["material..friction=1"]),
            "scene error in --set argument 1 (`material..friction=1`): \
             empty key segment in `material..friction`"
        );
        assert_eq!(
            message(&r, &["=1"]),
            "scene error in --set argument 1 (`=1`): empty key segment in ``"
        );
        assert_eq!(
            message(&r, &["material.friction="]),
            "scene error in --set argument 1 (`material.friction=`): \
             empty value; give a TOML value, e.g. 0.1, true, \"apic\" or [0, -3]"
        );
        let m = message(&r, &["gravity=[0,"]);
        assert!(
            m.starts_with(
                "scene error in --set argument 1 (`gravity=[0,`): `[0,` is not a TOML value"
            ),
            "{m}"
        );
    }

    #[test]
    fn a_combination_blames_the_override_that_breaks_it() {
        // `safety` needs `dt = "auto"`: the error is the scene's own check,
        // blamed on the override that made the scene invalid.
        let r = reference();
        let m = message(&r, &["material.friction=0.2", "time.safety=0.5"]);
        assert!(
            m.starts_with("scene error in --set argument 2 (`time.safety=0.5`): "),
            "{m}"
        );
        // A check on another field than the one set names that field.
        assert_eq!(
            message(&r, &["gravity=[0,-3]", "time.dt=0.1"]),
            "scene error in --set argument 2 (`time.dt=0.1`) in field `time.frame_dt`: \
             frame_dt 0.016666666666666666 is shorter than the substep dt 0.1"
        );
        // In the other order the pair is fine.
        assert!(set(&r, &["time.dt=auto", "time.safety=0.5"]).is_ok());
    }

    #[test]
    fn a_bad_file_is_reported_with_its_own_line() {
        let text = reference().replace("friction = 0.05", "friction = -0.05");
        let m = message(&text, &["gravity=[0,-3]"]);
        assert!(m.starts_with("scene error at line "), "{m}");
        assert!(m.contains("in field `material.friction`"), "{m}");
    }
}
