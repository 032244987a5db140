//! Shared helpers of the CLI's integration tests: the `yarnsim` binary, its
//! output, the test scene and a scratch folder.
#![allow(dead_code)]

pub mod rrd;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs the `yarnsim` binary with `args` (without `COLUMNS`, so help texts
/// wrap alike everywhere).
pub fn yarnsim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_yarnsim"))
        .args(args)
        .env_remove("COLUMNS")
        .output()
        .expect("run yarnsim")
}

/// [`yarnsim`], which must succeed (its standard error in the panic
/// message otherwise).
pub fn yarnsim_ok(args: &[&str]) -> Output {
    let out = yarnsim(args);
    assert!(
        out.status.success(),
        "yarnsim {args:?} failed: {}",
        stderr(&out)
    );
    out
}

/// `yarnsim record SCENE --duration DURATION -o RRD`, which must succeed.
pub fn record_ok(scene: &Path, duration: &str, rrd: &Path) -> Output {
    yarnsim_ok(&[
        "record",
        scene.to_str().unwrap(),
        "--duration",
        duration,
        "-o",
        rrd.to_str().unwrap(),
    ])
}

/// `yarnsim COMMAND <the test scene> ARGS...` ([`small_scene`]).
pub fn on_small_scene(command: &str, args: &[&str]) -> Output {
    let scene = small_scene();
    let head = [command, scene.to_str().unwrap()];
    yarnsim(&head.iter().chain(args).copied().collect::<Vec<_>>())
}

pub fn stdout(out: &Output) -> String {
    String::from_utf8(out.stdout.clone()).expect("utf-8 stdout")
}

pub fn stderr(out: &Output) -> String {
    String::from_utf8(out.stderr.clone()).expect("utf-8 stderr")
}

/// The test scene `tests/data/small.toml`: 2 yarns of 30 vertices on a
/// 64^2 grid, a frame every 10 substeps, with walls, an obstacle and an
/// active attractor.
pub fn small_scene() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/small.toml")
}

/// `name` in the test target's scratch folder.
pub fn tmp(name: &str) -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join(name)
}

/// [`tmp`] with no file left there by an earlier run.
pub fn fresh_tmp(name: &str) -> PathBuf {
    let path = tmp(name);
    let _ = std::fs::remove_file(&path);
    path
}
