//! The `yarnsim` binary as a user sees it: help texts and summary tables
//! (insta snapshots, wall-clock figures masked), CSV output, error messages
//! and exit codes.

use std::path::{Path, PathBuf};
use std::process::Output;

mod common;

use common::{on_small_scene, record_ok, small_scene, stderr, stdout, tmp, yarnsim};

/// `yarnsim run SCENE --duration 2ms --csv CSV` (CSV named `csv` in the
/// test folder), which must succeed: its output and the CSV text.
fn run_2ms_with_csv(scene: &Path, csv: &str) -> (Output, String) {
    let csv = tmp(csv);
    let out = yarnsim(&[
        "run",
        scene.to_str().unwrap(),
        "--duration",
        "2ms",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    (out, std::fs::read_to_string(&csv).unwrap())
}

/// `yarnsim bench` of the small scene, 5 steps after 1 of warm-up, which
/// must succeed: its stdout.
fn bench_small() -> String {
    let out = on_small_scene("bench", &["--steps", "5", "--warmup", "1"]);
    assert!(out.status.success(), "{}", stderr(&out));
    stdout(&out)
}

/// The small scene with `from` replaced by `to`, written as `name` in the
/// test folder.
fn small_scene_with(from: &str, to: &str, name: &str) -> PathBuf {
    let text = std::fs::read_to_string(small_scene()).unwrap();
    let scene = tmp(name);
    std::fs::write(&scene, text.replace(from, to)).unwrap();
    scene
}

/// Masks the wall-clock figures of a summary table.
fn masked(f: impl FnOnce()) {
    let mut settings = insta::Settings::clone_current();
    settings.add_filter(r"(?m)^(wall time\s+).*$", "${1}[wall time]");
    settings.add_filter(r"(?m)^(throughput\s+).*$", "${1}[throughput]");
    settings.bind(f);
}

#[test]
fn help_texts() {
    for (name, args) in [
        ("help", vec!["--help"]),
        ("help_scenes", vec!["scenes", "--help"]),
        ("help_materials", vec!["materials", "--help"]),
        ("help_scene_show", vec!["scene", "show", "--help"]),
        ("help_run", vec!["run", "--help"]),
        ("help_record", vec!["record", "--help"]),
        ("help_bench", vec!["bench", "--help"]),
        ("help_bench_precision", vec!["bench", "precision", "--help"]),
    ] {
        let out = yarnsim(&args);
        assert!(out.status.success(), "{args:?}");
        insta::assert_snapshot!(name, stdout(&out));
    }
}

#[test]
fn bench_studies_have_one_name_and_the_old_ones_still_work() {
    let top = stdout(&yarnsim(&["--help"]));
    let bench = stdout(&yarnsim(&["bench", "--help"]));
    for study in ["precision", "skip", "roofline"] {
        assert!(!top.contains(&format!("bench-{study}")), "{top}");
        assert!(
            bench.lines().any(|l| l.trim_start().starts_with(study)),
            "bench --help does not list {study}:\n{bench}"
        );
        let now = yarnsim(&["bench", study, "--help"]);
        assert!(now.status.success(), "{}", stderr(&now));
        let old = yarnsim(&[&format!("bench-{study}"), "--help"]);
        assert_eq!(stdout(&old), stdout(&now), "bench-{study}");
    }
    let alias = yarnsim(&["precision", "--help"]);
    assert_eq!(
        stdout(&alias),
        stdout(&yarnsim(&["bench", "precision", "--help"]))
    );
}

#[test]
fn scenes_lists_every_builtin() {
    let out = yarnsim(&["scenes"]);
    assert!(out.status.success());
    let text = stdout(&out);
    for (name, _) in yarnsim::scene::builtin_names() {
        assert!(text.contains(name), "{name} missing");
    }
    for line in text.lines() {
        assert!(line.chars().count() <= 100, "{line}");
    }
    insta::assert_snapshot!("scenes", text);
}

#[test]
fn materials_lists_every_preset() {
    let out = yarnsim(&["materials"]);
    assert!(out.status.success());
    let text = stdout(&out);
    for p in yarnsim::scene::presets::PRESETS {
        assert!(text.contains(p.name), "{} missing", p.name);
        assert!(text.contains(p.description), "{} missing", p.description);
    }
    for line in text.lines() {
        assert!(line.chars().count() <= 100, "{line}");
    }
    insta::assert_snapshot!("materials", text);
}

/// A hanging nylon monofilament given by its preset, 0.4 m from a pin.
const PRESET_SCENE: &str = r#"
name = "nylon"
[grid]
resolution = 32
[time]
dt = "auto"
frame_dt = 1e-3
[material]
preset = "nylon66-mono-0.30mm"
[walls]
mode = "none"
[[yarns]]
start = [0.5, 0.8]
end = [0.5, 0.4]
vertices = 20
[[pins]]
yarn = 0
end = "start"
"#;

#[test]
fn a_preset_scene_reports_its_sheet_and_pin_forces_per_yarn() {
    let scene = tmp("preset.toml");
    std::fs::write(&scene, PRESET_SCENE).unwrap();
    let out = yarnsim(&["run", scene.to_str().unwrap(), "--duration", "2ms"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(
        text.contains("yarn sheet         spacing 3.0000e-4 m (3333.3 yarns per m of depth, preset nylon66-mono-0.30mm)"),
        "{text}"
    );
    // the per-yarn row is the per-depth row times the spacing 3e-4 m (to the
    // six digits printed)
    let value = |name: &str| -> f64 {
        let line = text.lines().find(|l| l.starts_with(name)).unwrap();
        line.split_whitespace().last().unwrap().parse().unwrap()
    };
    let (depth, yarn) = (
        value("pin 0 force y [N/m]"),
        value("pin 0 force y per yarn [N]"),
    );
    assert!(depth > 0.0, "{text}");
    assert!(
        (yarn - 3e-4 * depth).abs() <= 1e-5 * yarn.abs(),
        "{yarn} against {depth}"
    );
    // scene show states the sheet in a comment and reads back
    let out = yarnsim(&["scene", "show", scene.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let shown = stdout(&out);
    assert!(
        shown.contains("# [material] is given per yarn: a sheet of yarns at spacing 3.0000e-4 m"),
        "{shown}"
    );
    assert_eq!(
        yarnsim::Scene::from_toml_str(&shown).unwrap(),
        yarnsim::Scene::from_toml_str(PRESET_SCENE).unwrap()
    );
}

#[test]
fn scene_show_round_trips() {
    // Every built-in: the printed file reads back to the same scene, and
    // showing that file prints the same text again.
    for (name, _) in yarnsim::scene::builtin_names() {
        let out = yarnsim(&["scene", "show", name]);
        assert!(out.status.success(), "{}", stderr(&out));
        let text = stdout(&out);
        let shown = yarnsim::Scene::from_toml_str(&text).expect("valid TOML scene");
        assert_eq!(shown, yarnsim::Scene::resolve(name).unwrap(), "{name}");
        let file = tmp(&format!("show-{name}.toml"));
        std::fs::write(&file, &text).unwrap();
        let again = yarnsim(&["scene", "show", file.to_str().unwrap()]);
        assert_eq!(stdout(&again), text, "{name}: a re-show differs");
    }
    // What a user reads: arrays inline, units and ranges in comments.
    insta::assert_snapshot!(
        "scene_show_yarn_drape",
        stdout(&yarnsim(&["scene", "show", "yarn-drape"]))
    );
    insta::assert_snapshot!(
        "scene_show_wire",
        stdout(&yarnsim(&["scene", "show", "wire"]))
    );
}

#[test]
fn run_summary_of_a_yarn_scene() {
    let (out, text) = run_2ms_with_csv(&small_scene(), "run-small.csv");
    masked(|| insta::assert_snapshot!("run_small", stdout(&out)));

    // One CSV row per frame (0..=5), endpoints of both yarns.
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 1 + 6);
    let header: Vec<&str> = lines[0].split(',').collect();
    assert_eq!(header.len(), 14 + 2 * 4);
    assert_eq!(header[header.len() - 1], "yarn1_right_y");
    for (k, line) in lines[1..].iter().enumerate() {
        let cols: Vec<&str> = line.split(',').collect();
        assert_eq!(cols.len(), header.len());
        assert_eq!(cols[0], k.to_string());
        assert_eq!(cols[2], (10 * k).to_string());
    }
}

#[test]
fn run_summary_of_a_massspring_scene() {
    let out = yarnsim(&[
        "run",
        "wire",
        "--duration",
        "0.25",
        "--integrator",
        "symplectic-euler",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    masked(|| insta::assert_snapshot!("run_wire_symplectic", stdout(&out)));
}

#[test]
fn bench_prints_the_throughput_line() {
    let text = bench_small();
    let line = text
        .lines()
        .find(|l| l.ends_with(" particle-substeps/s"))
        .expect("throughput line");
    let rate: f64 = line.split(' ').next().unwrap().parse().unwrap();
    assert!(rate > 0.0);
    assert!(text.contains("P2G scatter"), "{text}");
}

fn assert_fails(args: &[&str], code: i32, message: &str) {
    let out = yarnsim(args);
    assert_eq!(out.status.code(), Some(code), "{args:?}: {}", stderr(&out));
    let err = stderr(&out);
    assert!(err.contains(message), "{args:?}: {err}");
    assert!(stdout(&out).is_empty(), "{args:?} printed to stdout");
}

#[test]
fn errors_have_clear_messages_and_exit_codes() {
    let missing = tmp("no-such-scene.toml");
    let bad = tmp("bad-scene.toml");
    std::fs::write(&bad, "kind = \"yarn\"\n[grid]\nresolution = \"big\"\n").unwrap();
    let small = small_scene();
    let small = small.to_str().unwrap();
    // Unknown scene, unreadable or invalid scene file: 3.
    assert_fails(&["run", "no-such-scene"], 3, "no-such-scene");
    assert_fails(
        &["scene", "show", missing.to_str().unwrap()],
        3,
        "no-such-scene.toml",
    );
    assert_fails(&["run", bad.to_str().unwrap()], 3, "resolution");
    // Invalid duration and other bad arguments: 2.
    for d in ["0", "-1", "abc", "1h", "nan"] {
        assert_fails(&["run", small, "--duration", d], 2, "duration");
    }
    assert_fails(&["run", small, "--duration", "1us"], 2, "duration");
    assert_fails(
        &["run", "wire", "--integrator", "rk4"],
        2,
        "unknown integrator",
    );
    assert_fails(&["run", "wire", "--option", "warp=9"], 2, "warp");
    assert_fails(
        &["run", small, "--integrator", "pbd"],
        2,
        "--integrator applies to mass-spring scenes",
    );
    // Unwritable output: 4.
    let nowhere = "/nonexistent-dir/out";
    assert_fails(
        &[
            "record",
            small,
            "-d",
            "1ms",
            "-o",
            &format!("{nowhere}.rrd"),
        ],
        4,
        "cannot write output file",
    );
    assert_fails(
        &[
            "run",
            small,
            "-d",
            "1ms",
            "--csv",
            &format!("{nowhere}.csv"),
        ],
        4,
        "cannot write output file",
    );
}

/// `bench precision --implicit-duration` needs `--bundle` (without it a
/// wrongly accepted command would run the mass-spring study and fail at
/// writing to `/nonexistent`, exit code 4), a positive time no longer than
/// the ladder's 1 s, and no `--quick`; each refused naming the flag (exit
/// code 2) before any run (`--setting` matching no rung: a wrongly accepted
/// `--bundle` command runs nothing).
#[test]
fn implicit_duration_needs_bundle_and_a_positive_time() {
    let base = ["bench", "precision", "--out", "/nonexistent"];
    let with = |extra: &[&'static str]| [&base[..], extra].concat();
    assert_fails(&with(&["--implicit-duration", "0.3"]), 2, "--bundle");
    for d in ["0", "-1", "abc", "1.5"] {
        let args = with(&["--bundle", "--setting", "none", "--implicit-duration", d]);
        assert_fails(&args, 2, "--implicit-duration");
    }
    let quick = with(&["--bundle", "--quick", "--implicit-duration", "0.05"]);
    assert_fails(&quick, 2, "--implicit-duration");
}

#[test]
fn overlapping_bodies_at_the_start_are_refused_naming_both() {
    // The small scene's obstacle moved onto its first yarn.
    let scene = small_scene_with(
        "center = [0.5, 0.45]",
        "center = [0.5, 0.60]",
        "overlap.toml",
    );
    let out = yarnsim(&["run", scene.to_str().unwrap(), "-d", "1ms"]);
    assert_eq!(out.status.code(), Some(3));
    let err = stderr(&out);
    assert!(
        err.contains(
            "error: scene error at line 33 in field `obstacles[0]`: obstacle 0 (center [0.5, 0.6], \
             radius 0.1) overlaps yarn 0 (`yarns[0]` at line 38, copy 0 of 2) at the start: its \
             point [0.4979, 0.6248] (near vertex 14) lies 0.0249 m from the center, 0.0751 m \
             inside the circle"
        ),
        "{err}"
    );

    // The cloth's sphere moved up into the sheet.
    let cloth = stdout(&yarnsim(&["scene", "show", "cloth"]));
    let shown = yarnsim::Scene::from_toml_str(&cloth).unwrap();
    let yarnsim::Scene::MassSpring(mut layout) = shown else {
        panic!("mass-spring scene expected")
    };
    let x0 = layout.build().unwrap().positions[0];
    layout.spheres[0].center = [x0.x + 0.1, x0.y, x0.z];
    let scene = tmp("cloth-inside.toml");
    std::fs::write(&scene, layout.to_toml_string()).unwrap();
    let out = yarnsim(&["run", scene.to_str().unwrap(), "-d", "0.05"]);
    assert_eq!(out.status.code(), Some(3));
    let err = stderr(&out);
    assert!(err.contains("start inside sphere 0"), "{err}");
    assert!(err.contains("inside; move the sphere"), "{err}");
}

#[test]
fn an_explicit_step_above_the_stability_bound_is_refused() {
    let args = [
        "run",
        "wire",
        "-d",
        "1",
        "--integrator",
        "forward-euler",
        "--option",
        "dt=0.01",
    ];
    let out = yarnsim(&args);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(
        err.contains("x the stability bound of forward-euler"),
        "{err}"
    );
    assert!(err.contains("--allow-unstable"), "{err}");
    assert!(stdout(&out).is_empty());

    // Forced: it runs, diverges, and still prints the summary up to the
    // last frame before the failure, then fails with exit code 1.
    let mut forced = args.to_vec();
    forced.push("--allow-unstable");
    let out = yarnsim(&forced);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(err.contains("running anyway (--allow-unstable)"), "{err}");
    assert!(err.contains("error: "), "{err}");
    let summary = stdout(&out);
    assert!(
        summary.contains("stopped: the simulation failed"),
        "{summary}"
    );
    assert!(summary.contains("last frame"), "{summary}");
}

#[test]
fn clamped_and_invalid_steps_say_so_briefly() {
    let out = yarnsim(&["run", "wire", "-d", "0.1", "--option", "dt=10"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(
        err.contains(
            "--option dt=10 is longer than a frame of this scene; clamped to the frame time 0.05 s"
        ),
        "{err}"
    );
    for bad in ["dt=-1", "dt=1e999", "dt=0"] {
        let out = yarnsim(&["run", "wire", "--option", bad]);
        assert_eq!(out.status.code(), Some(2));
        let err = stderr(&out);
        assert!(err.contains("must be a positive, finite step"), "{err}");
        assert!(err.len() < 120, "long error: {err}");
    }
}

#[test]
fn output_errors_state_their_cause_once() {
    let out = on_small_scene("record", &["-d", "1ms", "-o", "/nonexistent-dir/x.rrd"]);
    assert_eq!(out.status.code(), Some(4));
    let err = stderr(&out);
    assert_eq!(err.matches("No such file or directory").count(), 1, "{err}");
    assert_eq!(err.matches("/nonexistent-dir/x.rrd").count(), 1, "{err}");
}

#[test]
fn csv_times_are_steps_times_dt_printed_shortest() {
    let (_, text) = run_2ms_with_csv(&small_scene(), "run-times.csv");
    let times: Vec<&str> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap())
        .collect();
    assert_eq!(
        times,
        ["0", "0.0004", "0.0008", "0.0012", "0.0016", "0.002"]
    );
}

#[test]
fn bench_table_fits_100_columns() {
    for line in bench_small().lines() {
        assert!(line.chars().count() <= 100, "{line}");
    }
}

/// `dt = "auto"`: `run` reports the adaptive substeps and their min / mean
/// / max, the CSV frames fall on the frame times exactly; `record` reports
/// them too.
#[test]
fn adaptive_substeps_are_reported_and_hit_every_frame() {
    let scene = small_scene_with("dt = 0.00004", "dt = \"auto\"", "small-auto.toml");
    let (out, text) = run_2ms_with_csv(&scene, "run-auto.csv");
    let s = stdout(&out);
    let line = s.lines().find(|l| l.starts_with("substeps")).unwrap();
    assert!(
        line.contains("adaptive (dt = \"auto\"), dt min / mean / max = "),
        "{line}"
    );
    let n: u64 = line.split_whitespace().nth(1).unwrap().parse().unwrap();
    assert!((5..50).contains(&n), "{line}: fixed 4e-5 s takes 50");
    let rows: Vec<Vec<&str>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    let times: Vec<&str> = rows.iter().map(|r| r[1]).collect();
    assert_eq!(
        times,
        ["0", "0.0004", "0.0008", "0.0012", "0.0016", "0.002"]
    );
    assert_eq!(rows.last().unwrap()[2], n.to_string());

    let rrd = tmp("record-auto.rrd");
    let out = record_ok(&scene, "2ms", &rrd);
    let s = stdout(&out);
    assert!(
        s.contains(&format!(
            "recorded 6 frames ({n} substeps adaptive, dt min / mean / max = "
        )),
        "{s}"
    );
}

/// The summary table of `run ARGS`, without its wall-clock lines.
fn summary(args: &[&str]) -> String {
    let out = yarnsim(args);
    assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    stdout(&out)
        .lines()
        .filter(|l| !l.starts_with("wall time") && !l.starts_with("throughput"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// `(initial, final)` of a row of the summary table.
fn row(table: &str, name: &str) -> (f64, f64) {
    let line = table
        .lines()
        .find(|l| l.starts_with(name))
        .unwrap_or_else(|| panic!("no row {name} in {table}"));
    // The last two columns; the unit (`[J]`) may follow the name.
    let v: Vec<f64> = line[name.len()..]
        .split_whitespace()
        .rev()
        .take(2)
        .map(|x| x.parse().unwrap())
        .collect();
    (v[1], v[0])
}

#[test]
fn set_overrides_scene_fields() {
    let small = small_scene();
    let small = small.to_str().unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec!["run", small, "--duration", "2ms"];
        args.extend_from_slice(extra);
        summary(&args)
    };
    let base = run(&[]);
    // A field set to the file's own value changes nothing.
    assert_eq!(
        run(&[
            "--set",
            "material.friction=0.05",
            "--set",
            "gravity=[0.0, -9.8]"
        ]),
        base
    );
    // Without gravity and attractor, and no contact in 2 ms (the yarns
    // move 2 mm, 5 cm above the obstacle, far from the walls), momentum is
    // conserved: to the 6 digits of the table.
    let free = run(&["--set", "gravity=[0,0]", "--set", "attractor.active=false"]);
    assert_ne!(free, base);
    let (p0, p1) = row(&free, "momentum y");
    assert!((p1 - p0).abs() <= 1e-6 * p0.abs(), "{p0} -> {p1}");
    let (q0, q1) = row(&base, "momentum y");
    assert!(
        (q1 - q0).abs() > 1e-2 * q0.abs(),
        "gravity acts: {q0} -> {q1}"
    );
    // Into an array of tables: one yarn instead of two.
    let one = run(&["--set", "yarns.0.count=1"]);
    assert!(
        one.contains("particles          59 (30 vertices + 29 quadrature, 1 yarn)"),
        "{one}"
    );
    // Built-in scenes, yarn and mass-spring, and `scene show`.
    let out = yarnsim(&[
        "scene",
        "show",
        "yarn-reference",
        "--set",
        "material.friction=0.1",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let shown = yarnsim::Scene::from_toml_str(&stdout(&out)).unwrap();
    let yarnsim::Scene::Yarn(y) = shown else {
        panic!("a yarn scene")
    };
    assert_eq!(y.material.friction, 0.1);
    let wire = |extra: &[&str]| {
        let mut args = vec![
            "run",
            "wire",
            "--duration",
            "0.05",
            "--integrator",
            "symplectic-euler",
        ];
        args.extend_from_slice(extra);
        summary(&args)
    };
    let (w, w0) = (wire(&[]), wire(&["--set", "gravity=[0, 0, 0]"]));
    assert_ne!(w, w0);
    // Gravity off: no gravity energy, at the start or after.
    assert_eq!(row(&w0, "gravity energy"), (0.0, 0.0), "{w0}");
    assert_eq!(row(&w, "gravity energy").0, -4.905, "{w}");
    // bench and record take it too.
    let out = yarnsim(&[
        "bench",
        small,
        "--steps",
        "2",
        "--warmup",
        "0",
        "--set",
        "yarns.0.count=1",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let rrd = tmp("set.rrd");
    let out = yarnsim(&[
        "record",
        small,
        "-d",
        "1ms",
        "-o",
        rrd.to_str().unwrap(),
        "--set",
        "yarns.0.count=1",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stdout(&out).contains("59 particles"), "{}", stdout(&out));
}

#[test]
fn bad_set_arguments_are_named_with_exit_code_3() {
    let small = small_scene();
    let small = small.to_str().unwrap();
    for cmd in ["run", "record", "bench"] {
        assert_fails(
            &[
                cmd,
                small,
                "--set",
                "gravity=[0,0]",
                "--set",
                "material.friction=abc",
            ],
            3,
            "error: scene error in --set argument 2 (`material.friction=abc`): \
             must be a number, got the string \"abc\"",
        );
    }
    assert_fails(
        &["run", "wire", "--set", "material.friction=0.1"],
        3,
        "scene error in --set argument 1 (`material.friction=0.1`): unknown field `material`",
    );
    // One bad `--set` on a yarn scene: the argument and what is wrong.
    for (set, what) in [
        ("material.frction=0.1", "unknown field `frction`"),
        ("material.friction=-1", "must be >= 0, got -1"),
        (
            "yarns.1.count=1",
            "index 1 is out of range: `yarns` has 1 entry, `yarns[0]`",
        ),
        ("material.friction", "expected KEY=VALUE"),
        ("gravity=[0,", "`[0,` is not a TOML value"),
    ] {
        assert_fails(
            &["run", small, "--set", set],
            3,
            &format!("scene error in --set argument 1 (`{set}`): {what}"),
        );
    }
    // The file's own errors keep their line.
    let bad = tmp("bad-friction.toml");
    let text = std::fs::read_to_string(small_scene()).unwrap();
    std::fs::write(&bad, text.replace("friction = 0.05", "friction = -0.05")).unwrap();
    assert_fails(
        &["run", bad.to_str().unwrap(), "--set", "gravity=[0,0]"],
        3,
        "scene error at line 19 in field `material.friction`: must be >= 0, got -0.05",
    );
}

#[test]
fn a_missing_table_is_named() {
    let text = std::fs::read_to_string(small_scene()).unwrap();
    let start = text.find("[material]").unwrap();
    let end = text.find("[attractor]").unwrap();
    let file = tmp("no-material.toml");
    std::fs::write(&file, format!("{}{}", &text[..start], &text[end..])).unwrap();
    assert_fails(
        &["run", file.to_str().unwrap()],
        3,
        "error: scene error in field `material`: missing field `material`",
    );
    let file = tmp("no-dt.toml");
    std::fs::write(&file, text.replace("dt = 0.00004\n", "")).unwrap();
    assert_fails(
        &["run", file.to_str().unwrap()],
        3,
        "error: scene error at line 11 in field `time.dt`: missing field `dt`",
    );
}
