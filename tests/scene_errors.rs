//! Scene-file errors as a user reads them: the field path with the index of
//! its list entry (`obstacles[1].radius`, as `--set` takes it), the line,
//! the TOML type a field takes ("a number", not `f64`), the field's own
//! spelling, and the yarn and point of an out-of-grid or overlapping yarn
//! as the file gives them.

use yarnsim::scene::{Integrator, Scene, TimeSpec, YarnScene};

/// A yarn scene with two obstacles, two `[[yarns]]` entries (the second
/// with three copies) and two pins; line numbers in the comments.
const SCENE: &str = concat!(
    "kind = \"yarn\"\n",
    yarnsim::small_yarn_tables!(), // lines 2 to 10
    r#"
[[obstacles]]
center = [0.5, 0.2]
radius = 0.05

[[obstacles]]  # line 16
center = [0.2, 0.2]
radius = 0.05

[[yarns]]
start = [0.2, 0.6]
end = [0.8, 0.6]
vertices = 20

[[yarns]]  # line 25
start = [0.2, 0.7]
end = [0.8, 0.7]
vertices = 20
count = 3
spacing = [0.0, 0.05]

[[pins]]
yarn = 0
end = "start"

[[pins]]  # line 36
yarn = 1
end = "start"
"#
);

/// The error message of `text` with `from` replaced by `to` (which must
/// change it).
fn message(from: &str, to: &str) -> String {
    let text = SCENE.replacen(from, to, 1);
    assert_ne!(text, SCENE, "{from}");
    Scene::from_toml_str(&text)
        .map(|_| panic!("must be rejected: {to}"))
        .unwrap_err()
        .to_string()
}

/// `from` replaced by `to` in the part of [`SCENE`] from `after` on.
fn message_after(after: &str, from: &str, to: &str) -> String {
    let i = SCENE.find(after).unwrap();
    let text = format!("{}{}", &SCENE[..i], SCENE[i..].replacen(from, to, 1));
    assert_ne!(text, SCENE, "{from}");
    Scene::from_toml_str(&text)
        .expect_err("must be rejected")
        .to_string()
}

#[test]
fn the_scene_itself_loads() {
    let s = YarnScene::from_toml_str(SCENE).unwrap();
    assert_eq!((s.yarns.len(), s.obstacles.len(), s.pins.len()), (2, 2, 2));
}

#[test]
fn every_error_in_a_list_entry_names_its_index() {
    let second_obstacle = "[[obstacles]]  # line 16";
    assert_eq!(
        message_after(second_obstacle, "radius = 0.05", "radius = -0.05"),
        "scene error at line 18 in field `obstacles[1].radius`: must be > 0, got -0.05"
    );
    assert_eq!(
        message_after("[[pins]]  # line 36", "end = \"start\"", "end = \"middle\""),
        "scene error at line 38 in field `pins[1].end`: \
         unknown variant `middle`, expected `start` or `end`"
    );
    // A missing field at its entry's header line.
    assert_eq!(
        message_after("[[yarns]]  # line 25", "vertices = 20\n", ""),
        "scene error at line 25 in field `yarns[1].vertices`: missing field `vertices`"
    );
    // The validators' own checks.
    assert_eq!(
        message_after("[[pins]]  # line 36", "yarn = 1", "yarn = 9"),
        "scene error at line 36 in field `pins[1]`: \
         yarn 9 does not exist: the scene has 4 yarns (0 to 3)"
    );
    assert_eq!(
        message_after(second_obstacle, "radius = 0.05", "radius = 50.0"),
        "scene error at line 16 in field `obstacles[1].radius`: \
         radius is absurdly large for the domain"
    );
}

#[test]
fn a_misspelt_field_is_pointed_to_its_own_spelling() {
    assert_eq!(
        message("center = [0.5, 0.2]", "centre = [0.5, 0.2]"),
        "scene error at line 13 in field `obstacles[0].centre`: unknown field `centre`, \
         expected one of `center`, `radius`, `friction`; did you mean `center`?"
    );
    assert_eq!(
        message("end = \"start\"", "end = \"strat\""),
        "scene error at line 34 in field `pins[0].end`: \
         unknown variant `strat`, expected `start` or `end`; did you mean `start`?"
    );
    // No guess when nothing is close.
    let m = message("friction = 0.05", "friction = 0.05\nstickiness = 1");
    assert!(m.ends_with("`bending`, `density`, `plasticity`"), "{m}");
}

#[test]
fn type_errors_name_the_toml_type() {
    for (from, to, expected) in [
        (
            "friction = 0.05",
            "friction = \"abc\"",
            "scene error at line 10 in field `material.friction`: \
             must be a number, got the string \"abc\"",
        ),
        (
            "resolution = 64",
            "resolution = 64.5",
            "scene error at line 3 in field `grid.resolution`: \
             must be an integer, got the number 64.5",
        ),
        (
            "friction = 0.05",
            "friction = 0.05\nplasticity = 1",
            "scene error at line 11 in field `material.plasticity`: \
             must be a boolean, got the integer 1",
        ),
        (
            "kind = \"yarn\"",
            "kind = \"yarn\"\nname = 5",
            "scene error at line 2 in field `name`: must be a string, got the integer 5",
        ),
        (
            "kind = \"yarn\"",
            "kind = \"yarn\"\ngravity = \"down\"",
            "scene error at line 2 in field `gravity`: \
             must be an array, got the string \"down\"",
        ),
        (
            "kind = \"yarn\"",
            "kind = \"yarn\"\ngravity = [0.0, true]",
            "scene error at line 2 in field `gravity`: \
             must be a number, got the boolean true",
        ),
        (
            "yarn = 0",
            "yarn = -1",
            "scene error at line 33 in field `pins[0].yarn`: \
             must be an integer >= 0, got the integer -1",
        ),
        (
            "kind = \"yarn\"",
            "kind = \"yarn\"\nattractor = 3",
            "scene error at line 2 in field `attractor`: must be a table, got the integer 3",
        ),
    ] {
        assert_eq!(message(from, to), expected, "{to}");
    }
    // A table where the file needs an array of tables: the entry's header.
    let m = message(
        "[[pins]]\nyarn = 0\nend = \"start\"\n\n[[pins]]  # line 36",
        "[pins]",
    );
    assert_eq!(
        m,
        "scene error at line 32 in field `pins`: must be an array, got a table"
    );
    // A point of two numbers given three (serde's `[f64; 2]` dropped the third).
    let m = message(
        "start = [0.2, 0.6]\nend = [0.8, 0.6]",
        "points = [[0.2, 0.6], [0.8, 0.6, 0.0]]",
    );
    assert_eq!(
        m,
        "scene error at line 21 in field `yarns[0].points`: \
         points[1] must be 2 numbers [x, y], got 3 ([0.8, 0.6, 0.0])"
    );
    // No message in Rust words is left.
    for word in ["f64", "u32", "i64", "usize", "sequence", "map"] {
        for (from, to) in [
            ("friction = 0.05", "friction = [1]"),
            ("friction = 0.05", "friction = { a = 1 }"),
            ("vertices = 20", "vertices = \"many\""),
            ("yarn = 0", "yarn = 0.5"),
            ("spacing = [0.0, 0.05]", "spacing = 0.05"),
        ] {
            let m = message(from, to);
            assert!(!m.contains(word), "{to}: {m}");
            assert!(m.contains("must be "), "{to}: {m}");
        }
    }
}

#[test]
fn a_yarn_outside_the_grid_is_named_with_its_point_as_written() {
    // The first entry's end, as the file gives it.
    assert_eq!(
        message("end = [0.8, 0.6]", "end = [0.995, 0.6]"),
        "scene error at line 20 in field `yarns[0].end`: yarn 0 ends at [0.995, 0.6], \
         outside the grid interior: x and y must be within [0.023438, 0.976562] m, \
         1.5 grid cells inside the domain [0, 1] m"
    );
    assert_eq!(
        message("start = [0.2, 0.6]", "start = [-0.1, 0.6]"),
        "scene error at line 20 in field `yarns[0].start`: yarn 0 starts at [-0.1, 0.6], \
         outside the grid interior: x and y must be within [0.023438, 0.976562] m, \
         1.5 grid cells inside the domain [0, 1] m"
    );
    // A copy of the second entry: its yarn index, the copy and the shift.
    let m = message("spacing = [0.0, 0.05]", "spacing = [0.0, 0.14]");
    assert_eq!(
        m,
        "scene error at line 25 in field `yarns[1].start`: yarn 3 (copy 2 of this entry's 3, \
         shifted by 2 x spacing [0, 0.14]) starts at [0.2, 0.98], outside the grid interior: \
         x and y must be within [0.023438, 0.976562] m, 1.5 grid cells inside the domain \
         [0, 1] m"
    );
    // A polyline's point and the end of `start`, `direction`, `length`.
    assert_eq!(
        message(
            "start = [0.2, 0.6]\nend = [0.8, 0.6]",
            "points = [[0.2, 0.6], [0.5, 1.05], [0.8, 0.6]]"
        ),
        "scene error at line 20 in field `yarns[0].points[1]`: yarn 0 passes through \
         points[1] = [0.5, 1.05], outside the grid interior: x and y must be within \
         [0.023438, 0.976562] m, 1.5 grid cells inside the domain [0, 1] m"
    );
    assert_eq!(
        message("end = [0.8, 0.6]", "direction = [1.0, 0.0]\nlength = 0.9"),
        "scene error at line 20 in field `yarns[0].length`: yarn 0 ends (start + length * \
         direction) at [1.1, 0.6], outside the grid interior: x and y must be within \
         [0.023438, 0.976562] m, 1.5 grid cells inside the domain [0, 1] m"
    );
    // On a domain of 0.5 m, in m.
    let m = message("resolution = 64", "resolution = 64\nsize = 0.5");
    assert_eq!(
        m,
        "scene error at line 21 in field `yarns[0].start`: yarn 0 starts at [0.2, 0.6], \
         outside the grid interior: x and y must be within [0.011719, 0.488281] m, \
         1.5 grid cells inside the domain [0, 0.5] m"
    );
}

#[test]
fn a_yarn_through_an_obstacle_is_named_with_its_entry_and_point() {
    // The second obstacle moved onto the first copy of the second entry.
    let m = message_after(
        "[[obstacles]]  # line 16",
        "center = [0.2, 0.2]",
        "center = [0.5, 0.73]",
    );
    assert_eq!(
        m,
        "scene error at line 16 in field `obstacles[1]`: obstacle 1 (center [0.5, 0.73], \
         radius 0.05) overlaps yarn 1 (`yarns[1]` at line 25, copy 0 of 3) at the start: its \
         point [0.5, 0.7] (near vertex 9) lies 0.03 m from the center, 0.02 m inside the circle (more than \
         half a grid cell); move the obstacle or the yarn apart"
    );
}

#[test]
fn integrator_names_are_the_scene_file_values() {
    for name in Integrator::NAMES {
        let t: TimeSpec = toml::from_str(&format!("dt = 1e-4\nintegrator = \"{name}\"")).unwrap();
        assert_eq!(t.integrator.name(), name);
    }
}

#[test]
fn mass_spring_list_entries_are_named_with_their_index() {
    let base = yarnsim::scene::builtin("three-particle")
        .unwrap()
        .to_toml_string();
    let err = |text: &str| Scene::from_toml_str(text).unwrap_err().to_string();
    // A third index of a spring, which `[usize; 2]` used to drop.
    let first = "particles = [\n    0,\n    1,\n]";
    let line = base[..base.find(first).unwrap()].lines().count() + 1;
    assert_eq!(
        err(&base.replacen(first, "particles = [0, 1, 2]", 1)),
        format!(
            "scene error at line {line} in field `springs[0].particles`: \
             must be 2 particle indices, got 3 ([0, 1, 2])"
        )
    );
    let second = base.match_indices("stiffness = 50.0").nth(1).unwrap().0;
    let text = format!(
        "{}stiffness = \"stiff\"{}",
        &base[..second],
        &base[second + "stiffness = 50.0".len()..]
    );
    let line = base[..second].lines().count() + 1;
    assert_eq!(
        err(&text),
        format!(
            "scene error at line {line} in field `springs[1].stiffness`: \
             must be a number, got the string \"stiff\""
        )
    );
    // An entry of the `pinned` list.
    let text = base.replacen("kind = ", "pinned = [0, 7]\nkind = ", 1);
    assert_eq!(
        err(&text),
        "scene error at line 1 in field `pinned[1]`: \
         particle index 7 out of range: the scene has 3 particles"
    );
}

/// A list written inline (`obstacles = [{ ... }, { ... }]`) names the entry
/// by its index as a `[[obstacles]]` entry would be named.
#[test]
fn an_inline_list_entry_is_named_by_its_index() {
    let inline = "obstacles = [{ center = [0.5, 0.2], radius = 0.05 },\n    \
                  { center = [0.2, 0.2], radius = \"wide\" }]\n";
    let text = SCENE.replacen(
        "kind = \"yarn\"\n",
        &format!("kind = \"yarn\"\n{inline}"),
        1,
    );
    // drop the [[obstacles]] tables: the inline list replaces them
    let text = text
        .replace("[[obstacles]]\ncenter = [0.5, 0.2]\nradius = 0.05\n\n", "")
        .replace(
            "[[obstacles]]  # line 16\ncenter = [0.2, 0.2]\nradius = 0.05\n\n",
            "",
        );
    assert!(!text.contains("[[obstacles]]"), "{text}");
    let err = Scene::from_toml_str(&text).unwrap_err().to_string();
    assert!(err.contains("`obstacles[1].radius`"), "{err}");
    assert!(err.contains("a number"), "{err}");
}

/// `transfer.flip_time` (a relaxation time, s) is a positive number and
/// takes the place of `transfer.flip_ratio`: the two together are refused
/// at the line of `flip_time`, naming the ratio given.
#[test]
fn a_flip_time_is_positive_and_not_given_beside_a_ratio() {
    let with = |table: &str| {
        Scene::from_toml_str(&format!("{SCENE}\n[transfer]\n{table}"))
            .map(|_| ())
            .map_err(|e| e.to_string())
    };
    let first = SCENE.lines().count() + 3;
    assert_eq!(with("flip_time = 0.004\n"), Ok(()));
    assert_eq!(
        with("flip_time = -0.004\n").unwrap_err(),
        format!(
            "scene error at line {first} in field `transfer.flip_time`: must be > 0, got -0.004"
        )
    );
    assert_eq!(
        with("flip_ratio = 0.9\nflip_time = 0.004\n").unwrap_err(),
        format!(
            "scene error at line {} in field `transfer.flip_time`: give transfer.flip_ratio \
             (a blend per substep) or transfer.flip_time (a relaxation time), not both; \
             flip_ratio is 0.9",
            first + 1
        )
    );
}
