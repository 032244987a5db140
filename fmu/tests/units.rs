//! One unit and one start value for every FMU variable: the generated
//! model description (what `modelDescription/*.xml` holds) against the
//! variable tables of `docs/fmu.md` (name, value reference, causality,
//! unit, start of the default scenes) and against the yarn scene-file
//! reference of `docs/scene-files.md` (the unit of the scene field a
//! variable sets, and its default as the start value of a scene that
//! leaves the field out). Every unit is declared in `UnitDefinitions`.

mod common;

use yarnsim::massspring::scenes::{cloth, wire};
use yarnsim::scene::builtin::yarn_reference;
use yarnsim::scene::YarnScene;
use yarnsim_fmu::model_description::{Variable, UNITS};
use yarnsim_fmu::models::yarn::variables::*;

const FMU_MD: &str = include_str!("../../docs/fmu.md");
const SCENE_FILES_MD: &str = include_str!("../../docs/scene-files.md");
const DRIVEN_SCENE: &str = include_str!("../scenes/driven.toml");

/// The cells of the table rows (`| a | b |`) of the lines from the first
/// line starting with `from` to the next heading.
fn table_after(doc: &str, from: &str) -> Vec<Vec<String>> {
    let start = doc
        .lines()
        .position(|l| l.starts_with(from))
        .unwrap_or_else(|| panic!("no line {from:?}"));
    doc.lines()
        .skip(start + 1)
        .take_while(|l| !l.starts_with('#'))
        .filter(|l| l.starts_with("| `"))
        .map(|l| {
            // `\|` inside a cell is a pipe of the text, not a cell border
            let l = l.replace("\\|", "\u{0}");
            l.trim_matches('|')
                .split('|')
                .map(|c| c.trim().replace('\u{0}', "|"))
                .collect()
        })
        .collect()
}

/// The names in a first cell: "`pin[i].x`, `pin[i].y`" -> both, `[i]` as `[0]`.
fn names(cell: &str) -> Vec<String> {
    cell.split(", ")
        .map(|n| n.trim_matches('`').replace("[i]", "[0]"))
        .collect()
}

/// A unit as written in either document, in one spelling: `m/s^2` and
/// `m/s2`, `N m` and `N.m` agree; "1", "bool" and "" are no unit.
fn unit_key(u: &str) -> String {
    match u {
        "" | "1" | "bool" => String::new(),
        u => u.replace(['^', ' ', '.'], ""),
    }
}

/// Two start values agree: equal numbers, or equal text.
fn same_start(doc: &str, generated: &str) -> bool {
    match (doc.parse::<f64>(), generated.parse::<f64>()) {
        (Ok(a), Ok(b)) => a == b,
        _ => doc.trim_matches('"') == generated,
    }
}

/// Checks the rows of the `nth` variable table of `docs/fmu.md` whose
/// names pass `only` against `vars`; returns the names it checked.
fn check_fmu_md_table(nth: usize, vars: &[Variable], only: fn(&str) -> bool) -> Vec<String> {
    let heading_line = FMU_MD.lines().filter(|l| *l == "### Variables").count();
    assert!(
        heading_line > nth,
        "docs/fmu.md has {heading_line} variable tables"
    );
    let mut doc = FMU_MD;
    for _ in 0..nth {
        let at = doc.find("### Variables").unwrap();
        doc = &doc[at + 1..];
    }
    let mut checked = Vec::new();
    for row in table_after(doc, "### Variables") {
        let [name, _vr, ty, causality, _variability, unit, start, ..] = &row[..] else {
            panic!("short row {row:?}");
        };
        for n in names(name).into_iter().filter(|n| only(n)) {
            let v = vars
                .iter()
                .find(|v| v.name == n)
                .unwrap_or_else(|| panic!("docs/fmu.md names {n}, the FMU has none"));
            let what = format!("docs/fmu.md, {n}");
            assert_eq!(causality, v.causality, "{what}: causality");
            assert_eq!(ty, &format!("{:?}", v.ty), "{what}: type");
            assert_eq!(unit.as_str(), v.unit.unwrap_or(""), "{what}: unit");
            match &v.start {
                Some(s) if !name.contains("[i]") || start.parse::<f64>().is_ok() => {
                    assert!(
                        same_start(start, s),
                        "{what}: start {start:?}, generated {s:?}"
                    )
                }
                Some(_) => {}
                None => assert_eq!(start, "", "{what}: an output has no start value"),
            }
            checked.push(n);
        }
    }
    checked
}

#[test]
fn docs_fmu_md_tables_match_the_generated_descriptions() {
    // YarnBundle: the default scene (modelDescription/YarnBundle.xml)
    let vars = variables(&yarn_reference());
    let checked = check_fmu_md_table(0, &vars, |n| !n.starts_with("pin["));
    for v in &vars {
        let generic = v.name.contains('[');
        if !generic {
            assert!(
                checked.contains(&v.name),
                "docs/fmu.md has no row for {}",
                v.name
            );
        }
    }
    assert!(checked.iter().any(|n| n == "yarn[0].right.y"));
    // the pin rows, with the driven scene's pins
    let driven = variables(&YarnScene::from_toml_str(DRIVEN_SCENE).unwrap());
    let checked = check_fmu_md_table(0, &driven, |n| n.starts_with("pin["));
    for pin in ["pin[0].x", "pin[0].vy", "pin[0].force.x", "pin[0].force.y"] {
        assert!(checked.iter().any(|n| n == pin), "{pin} unchecked");
    }
    // MassSpring: the wire (modelDescription/MassSpring-wire.xml)
    let vars = yarnsim_fmu::models::massspring::variables(&wire()).unwrap();
    let checked = check_fmu_md_table(1, &vars, |_| true);
    for v in vars.iter().filter(|v| !v.name.contains('[')) {
        assert!(
            checked.contains(&v.name),
            "docs/fmu.md has no row for {}",
            v.name
        );
    }
}

/// The scene field (as `docs/scene-files.md` names it) that each yarn
/// input and parameter sets, and the component of an array field.
fn scene_field(fmu_name: &str) -> Option<(&'static str, Option<usize>)> {
    Some(match fmu_name {
        "attractor.x" => ("attractor.position", Some(0)),
        "attractor.y" => ("attractor.position", Some(1)),
        "attractor.strength" => ("attractor.strength", None),
        "attractor.active" => ("attractor.active", None),
        "gravity.x" => ("gravity", Some(0)),
        "gravity.y" => ("gravity", Some(1)),
        "material.k" => ("material.k", None),
        "material.gamma" => ("material.gamma", None),
        "material.youngs_modulus" => ("material.youngs_modulus", None),
        "material.friction" => ("material.friction", None),
        "material.bending" => ("material.bending", None),
        "material.density" => ("material.density", None),
        "material.plasticity" => ("material.plasticity", None),
        "dt" => ("time.dt", None),
        "transfer.scheme" => ("transfer.scheme", None),
        "transfer.flip_ratio" => ("transfer.flip_ratio", None),
        "transfer.flip_time" => ("transfer.flip_time", None),
        "integrator" => ("time.integrator", None),
        "time.axial" => ("time.axial", None),
        _ => return None,
    })
}

#[test]
fn fmu_units_and_starts_match_the_scene_file_reference() {
    let reference: Vec<(String, String, String)> = table_after(SCENE_FILES_MD, "## Yarn scenes")
        .into_iter()
        .map(|r| {
            (
                r[0].trim_matches('`').to_string(),
                r[1].clone(),
                r[2].clone(),
            )
        })
        .collect();
    let row = |field: &str| {
        reference
            .iter()
            .find(|(f, _, _)| f == field)
            .unwrap_or_else(|| panic!("docs/scene-files.md has no row `{field}`"))
    };
    let minimal = YarnScene::from_toml_str(yarnsim::testing::MINIMAL_TOML).unwrap();
    let vars = variables(&minimal);
    let mut compared = 0;
    for v in &vars {
        if v.causality == "output"
            || v.name == "scene"
            || v.ty == yarnsim_fmu::model_description::VarType::Integer
        {
            continue; // outputs, the scene file, the execution parameters: no scene field
        }
        let (field, component) = scene_field(&v.name)
            .unwrap_or_else(|| panic!("{}: which scene field does it set?", v.name));
        let (_, unit, default) = row(field);
        assert_eq!(
            unit_key(unit),
            unit_key(v.unit.unwrap_or("")),
            "{}: unit {:?} in modelDescription, {unit:?} in docs/scene-files.md",
            v.name,
            v.unit
        );
        let default = match default.trim_matches('`') {
            // `transfer.flip_time` unset is the parameter's 0
            "unset" if field == "transfer.flip_time" => "0",
            d => d,
        };
        if default == "required" {
            continue;
        }
        let default = match component {
            Some(i) => default
                .trim_matches(['[', ']'])
                .split(',')
                .nth(i)
                .unwrap()
                .trim()
                .to_string(),
            None => default.to_string(),
        };
        let start = v.start.as_deref().unwrap();
        assert!(
            same_start(&default, start),
            "{}: start {start} for a scene without `{field}`, default {default} in docs/scene-files.md",
            v.name
        );
        compared += 1;
    }
    // attractor (4), gravity (2), bending, density, plasticity, scheme,
    // flip_ratio, flip_time, integrator, axial
    assert_eq!(compared, 14);
}

#[test]
fn every_unit_is_declared_in_unit_definitions() {
    let driven = YarnScene::from_toml_str(DRIVEN_SCENE).unwrap();
    let mut all = variables(&yarn_reference());
    all.extend(variables(&driven));
    all.extend(yarnsim_fmu::models::massspring::variables(&wire()).unwrap());
    all.extend(yarnsim_fmu::models::massspring::variables(&cloth()).unwrap());
    for v in &all {
        if let Some(u) = v.unit {
            assert!(
                UNITS.iter().any(|(n, _)| *n == u),
                "{}: unit {u} undeclared",
                v.name
            );
        }
    }
    for a in yarn_description_arrays(&driven) {
        let u = a.unit.unwrap();
        assert!(
            UNITS.iter().any(|(n, _)| *n == u),
            "{}: unit {u} undeclared",
            a.name
        );
    }
}

fn yarn_description_arrays(
    scene: &YarnScene,
) -> Vec<yarnsim_fmu::model_description::ArrayVariable> {
    description(scene).arrays
}
