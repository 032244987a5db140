//! The commented scene files of `yarnsim scene show`
//! (`Scene::to_commented_toml`): they read back to the same scene, arrays
//! stay on one line, every field carries its unit and range, and the unit
//! table agrees with the reference tables of `docs/scene-files.md`.

use yarnsim::scene::fields::field_doc;
use yarnsim::scene::{builtin, builtin_names, FieldDoc, Scene, MASS_SPRING_FIELDS, YARN_FIELDS};

/// A yarn scene with every optional field set: `"auto"` steps with their
/// safety and cap, an implicit integrator, a polyline, a yarn by
/// direction, pins of every motion, a description with a line break
/// (`tests/data/rich-yarn.toml`).
const RICH_YARN: &str = include_str!("data/rich-yarn.toml");

/// A mass-spring scene with every element kind and optional field
/// (`tests/data/rich-mass-spring.toml`).
const RICH_MASS_SPRING: &str = include_str!("data/rich-mass-spring.toml");

/// The built-in scenes and the two rich ones.
fn scenes() -> Vec<(String, Scene)> {
    let mut v: Vec<(String, Scene)> = builtin_names()
        .iter()
        .map(|(n, _)| (n.to_string(), builtin(n).unwrap()))
        .collect();
    v.push(("rich yarn".into(), Scene::from_toml_str(RICH_YARN).unwrap()));
    v.push((
        "rich mass-spring".into(),
        Scene::from_toml_str(RICH_MASS_SPRING).unwrap(),
    ));
    v
}

fn fields_of(scene: &Scene) -> &'static [FieldDoc] {
    match scene {
        Scene::Yarn(_) => &YARN_FIELDS[..],
        Scene::MassSpring(_) => &MASS_SPRING_FIELDS[..],
    }
}

#[test]
fn commented_scene_files_read_back_to_the_same_scene() {
    for (name, scene) in scenes() {
        let text = scene.to_commented_toml();
        let back = Scene::from_toml_str(&text).unwrap_or_else(|e| panic!("{name}: {e}\n{text}"));
        assert_eq!(back, scene, "{name}:\n{text}");
        assert_eq!(back.to_commented_toml(), text, "{name}: a re-show differs");
    }
}

/// The lines of `text` that are not inside a multi-line string (the line
/// that opens one is kept).
fn outside_strings(text: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut in_string = false;
    for line in text.lines() {
        let quotes = line.matches("\"\"\"").count();
        if in_string {
            in_string = quotes % 2 == 0;
            continue;
        }
        in_string = quotes == 1;
        out.push(line);
    }
    out
}

/// `(table, key, value, comment)` of every `key = value` line.
fn field_lines(text: &str) -> Vec<(String, String, String, Option<String>)> {
    let mut section = String::new();
    let mut out = Vec::new();
    for line in outside_strings(text) {
        if line.starts_with('[') {
            section = line.trim_matches(|c| c == '[' || c == ']').to_string();
        } else if let Some((key, rest)) = line.split_once(" = ") {
            let (value, comment) = match rest.split_once("  # ") {
                Some((v, c)) => (v.trim_end().to_string(), Some(c.to_string())),
                None => (rest.to_string(), None),
            };
            out.push((section.clone(), key.to_string(), value, comment));
        }
    }
    out
}

#[test]
fn arrays_are_inline_and_every_field_states_its_unit_and_range() {
    for (name, scene) in scenes() {
        let text = scene.to_commented_toml();
        let fields = fields_of(&scene);
        let lines = field_lines(&text);
        assert!(lines.len() > 5, "{name}: {text}");
        for (section, key, value, comment) in &lines {
            let path = if section.is_empty() {
                key.clone()
            } else {
                format!("{section}.{key}")
            };
            if value.starts_with("\"\"\"") {
                continue; // a multi-line string: its lines are the value's
            }
            let doc = field_doc(fields, &path).unwrap_or_else(|| panic!("{name}: no entry {path}"));
            // An array opens and closes on its line.
            assert_eq!(
                value.matches('[').count(),
                value.matches(']').count(),
                "{name}: {path} = {value}"
            );
            assert_eq!(
                comment.clone().unwrap_or_default(),
                doc.comment(),
                "{name}: {path}"
            );
        }
        // No line of an array on its own.
        for line in outside_strings(&text) {
            let t = line.trim();
            assert!(
                !(t == "[" || t == "]" || (t.ends_with(',') && !t.contains(" = "))),
                "{name}: {line:?}"
            );
        }
    }
    // What it looks like.
    let text = builtin("yarn-reference").unwrap().to_commented_toml();
    assert!(text.starts_with("# yarnsim scene file"), "{text}");
    for want in [
        "center = [0.25, 0.6]",
        "# m/s^2",
        "resolution = 256",
        "# cells, 8 to 8192 per side",
        "# N/m, >= 0",
        "# \"sticky\", \"slip\" or \"none\"",
    ] {
        assert!(text.contains(want), "{want:?} missing:\n{text}");
    }
}

#[test]
fn unit_table_covers_every_field_once() {
    for fields in [&YARN_FIELDS[..], &MASS_SPRING_FIELDS[..]] {
        for (i, f) in fields.iter().enumerate() {
            assert!(
                fields[..i].iter().all(|g| g.key != f.key),
                "{} twice",
                f.key
            );
        }
    }
    // Every key the rich scenes write is in the table (the table is not
    // larger than the scenes either: each entry is written by one of them;
    // the yarn material's engineering fields by the rich yarn scene with a
    // per-yarn material, `specific_modulus` being the alternative to `EA`).
    let per_yarn = RICH_YARN.replace(
        "[material]\n",
        "[material]\npreset = \"cotton-20tex\"\ntex = 21.0\ndiameter = 2e-4\nEA = 60.0\n\
         EI = 1e-9\nfriction_solid = 0.2\nspacing = 3e-4\ntransverse_modulus = 4e6\n\
         shear_modulus = 1e6\n",
    );
    // `time.axial` and `transfer.flip_time` by the rich yarn scene under
    // the explicit integrator with FLIP and a relaxation time (the scope
    // of `axial = "implicit"` under FLIP)
    let axial = RICH_YARN
        .replace("integrator = \"implicit\"\n", "axial = \"implicit\"\n")
        .replace(
            "scheme = \"flip\"\nflip_ratio = 0.95\n",
            "scheme = \"flip\"\nflip_time = 0.004\n",
        );
    for (scenes, fields) in [
        (
            vec![RICH_YARN, per_yarn.as_str(), axial.as_str()],
            &YARN_FIELDS[..],
        ),
        (vec![RICH_MASS_SPRING], &MASS_SPRING_FIELDS[..]),
    ] {
        let written: Vec<String> = scenes
            .iter()
            .flat_map(|text| field_lines(&Scene::from_toml_str(text).unwrap().to_toml_string()))
            .map(|(s, k, _, _)| if s.is_empty() { k } else { format!("{s}.{k}") })
            .collect();
        for f in fields {
            let alt_end = f.key == "yarns.end"
                || f.key == "yarns.start"
                || f.key == "material.specific_modulus";
            assert!(
                written.iter().any(|w| w == f.key) || alt_end,
                "{} is not written by the rich scene",
                f.key
            );
        }
    }
}

/// The field keys and the unit of each row of the two reference tables of
/// `docs/scene-files.md`: `(kind, key of the row's first field, unit)`,
/// kind `yarn` or `mass-spring`. A row's first cell names its fields in
/// backticks, after a `[table]` or `[[array]]` prefix
/// (`` `[[obstacles]] center` ``, `` `[time] frame_time` ``); the unit is
/// the second cell's first comma-separated part without a leading shape
/// (`[x, y, z] m/s^2` is `m/s^2`), and none for `bool`, `string`, `index`,
/// `integer ...` or a shape alone.
fn documented_units() -> Vec<(&'static str, String, String)> {
    let text = include_str!("../docs/scene-files.md");
    let mut kind = "";
    let mut rows = Vec::new();
    for line in text.lines() {
        if line.starts_with("## Yarn scenes") {
            kind = "yarn";
        } else if line.starts_with("## Mass-spring scene files") {
            kind = "mass-spring";
        } else if line.starts_with("## ") || line.starts_with("### ") {
            kind = "";
        }
        if kind.is_empty() || !line.starts_with("| `") {
            continue;
        }
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        let first = cells[1];
        let name = first.split('`').nth(1).unwrap();
        let key = match name.split_once(' ') {
            Some((prefix, field)) => {
                let table = prefix.trim_matches(|c| c == '[' || c == ']');
                format!("{table}.{field}")
            }
            None => name.to_string(),
        };
        let mut unit = cells[2];
        if unit.starts_with('[') {
            unit = unit.split_once(']').map_or("", |(_, rest)| rest).trim();
        }
        let unit = unit.split(',').next().unwrap().trim();
        let unit = if ["bool", "string", "index"].contains(&unit) || unit.starts_with("integer") {
            ""
        } else {
            unit
        };
        rows.push((kind, key, unit.to_string()));
    }
    rows
}

#[test]
fn unit_table_agrees_with_the_scene_file_reference() {
    let rows = documented_units();
    assert!(rows.len() > 60, "{rows:?}");
    for (kind, key, unit) in &rows {
        let fields = if *kind == "yarn" {
            &YARN_FIELDS[..]
        } else {
            &MASS_SPRING_FIELDS[..]
        };
        let doc = field_doc(fields, key).unwrap_or_else(|| {
            panic!("docs/scene-files.md names {kind} field {key}, the code does not")
        });
        assert_eq!(
            doc.unit, unit,
            "{kind} field {key}: unit {:?} in the code, {unit:?} in docs/scene-files.md",
            doc.unit
        );
    }
    // Every field the code knows is documented (in a row of its own or
    // named in another row's cell, as `[[pins]] motion` names `velocity`).
    let text = include_str!("../docs/scene-files.md");
    for f in YARN_FIELDS.iter().chain(MASS_SPRING_FIELDS.iter()) {
        let field = f.key.rsplit('.').next().unwrap();
        assert!(
            text.contains(&format!("`{field}`")) || text.contains(&format!("{field}`")),
            "{} is not in docs/scene-files.md",
            f.key
        );
    }
}
