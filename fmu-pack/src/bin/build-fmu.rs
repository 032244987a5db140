//! Packs the YarnBundle FMU, or a MassSpring FMU for a mass-spring scene.
//!
//! ```text
//! cargo run --release -p yarnsim-fmu-pack --bin build-fmu -- [--scene NAME_OR_FILE] [-o OUT.fmu]
//!     [--lib libyarnsim_fmu.so | --no-build] [--model-description FILE] [--fmi-version 2|3]
//! ```
//!
//! Without `--scene` it packs the default scene (`yarn-reference`) into
//! `<target>/fmu/YarnBundle.fmu`; another scene goes to
//! `<target>/fmu/<modelIdentifier>-<scene name>.fmu` unless `-o` says
//! otherwise (`wire` gives `MassSpring-wire.fmu`).
//! The packager first builds the cdylib (`cargo build -p yarnsim-fmu --lib`,
//! same profile) unless `--lib` names one or `--no-build` is given.
//! `--model-description FILE` only writes the generated modelDescription.xml
//! (used to refresh `modelDescription/YarnBundle.xml`).
//! `--fmi-version 3` packs the FMI 3.0 FMU of the scene instead (default 2):
//! `binaries/x86_64-linux/`, the array outputs, and `-fmi3` before `.fmu` in
//! the default file name (`YarnBundle-fmi3.fmu`, `MassSpring-wire-fmi3.fmu`).

use std::path::PathBuf;
use std::process::ExitCode;

use yarnsim::scene::{Scene, DEFAULT_SCENE};
use yarnsim_fmu::{SceneFmu, MODEL_IDENTIFIER};
use yarnsim_fmu_pack::{build_fmu_of, check_library, zip_entries, FmiVersion};

const USAGE: &str = "usage: build-fmu [--scene NAME_OR_FILE] [-o OUT.fmu] [--lib libyarnsim_fmu.so | --no-build] [--model-description FILE] [--fmi-version 2|3]";

fn run() -> Result<(), String> {
    let mut scene_arg: Option<String> = None;
    let mut out: Option<PathBuf> = None;
    let mut lib: Option<PathBuf> = None;
    let mut xml_only: Option<PathBuf> = None;
    let mut no_build = false;
    let mut version = FmiVersion::Fmi2;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = |what: &str| args.next().ok_or(format!("{a} needs {what}\n{USAGE}"));
        match a.as_str() {
            "--scene" | "-s" => scene_arg = Some(value("a scene name or file")?),
            "-o" | "--output" => out = Some(value("a file name")?.into()),
            "--lib" => lib = Some(value("a shared library")?.into()),
            "--model-description" => xml_only = Some(value("a file name")?.into()),
            "--no-build" => no_build = true,
            "--fmi-version" => {
                version = match value("2 or 3")?.as_str() {
                    "2" | "2.0" => FmiVersion::Fmi2,
                    "3" | "3.0" => FmiVersion::Fmi3,
                    v => return Err(format!("--fmi-version {v:?}: use 2 or 3\n{USAGE}")),
                }
            }
            "-h" | "--help" => {
                println!("{USAGE}");
                return Ok(());
            }
            _ => return Err(format!("unknown argument {a:?}\n{USAGE}")),
        }
    }
    let name = scene_arg.as_deref().unwrap_or(DEFAULT_SCENE);
    let scene = Scene::resolve(name).map_err(|e| e.to_string())?;
    // The scene must run as the FMU will run it.
    match &scene {
        Scene::Yarn(s) => yarnsim::mpm::YarnSim::new(s)
            .map(|_| ())
            .map_err(|e| e.to_string()),
        Scene::MassSpring(l) => yarnsim_fmu::models::massspring::MsModel::new(l.clone())
            .map(|_| ())
            .map_err(|e| e.0),
    }
    .map_err(|e| format!("{name}: {e}"))?;
    let xml = version.model_description(&scene)?;
    if let Some(path) = xml_only {
        std::fs::write(&path, xml).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        println!(
            "wrote {} ({} modelDescription.xml of {})",
            path.display(),
            version.label(),
            scene.identifier()
        );
        return Ok(());
    }
    // The cdylib sits next to this executable (target/<profile>/).
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let exe_dir = exe.parent().ok_or("no executable directory")?.to_path_buf();
    let lib = match lib {
        Some(l) => l,
        None => {
            if !no_build {
                build_cdylib(&exe_dir)?;
            }
            exe_dir.join(yarnsim_fmu::LIBRARY_FILE)
        }
    };
    let so = std::fs::read(&lib).map_err(|e| {
        format!(
            "cannot read {}: {e} (build it with `cargo build --release -p yarnsim-fmu`)",
            lib.display()
        )
    })?;
    let info = check_library(&so).map_err(|e| format!("{}: {e}", lib.display()))?;
    let suffix = match version {
        FmiVersion::Fmi2 => "",
        FmiVersion::Fmi3 => "-fmi3",
    };
    let out = out.unwrap_or_else(|| {
        let dir = exe_dir.parent().unwrap_or(&exe_dir).join("fmu");
        if scene_arg.is_none() {
            dir.join(format!("{MODEL_IDENTIFIER}{suffix}.fmu"))
        } else {
            let tag: String = scene
                .name()
                .chars()
                .map(|c| {
                    if c.is_ascii_alphanumeric() || c == '-' {
                        c
                    } else {
                        '_'
                    }
                })
                .collect();
            let tag = if tag.is_empty() {
                "scene".to_string()
            } else {
                tag
            };
            dir.join(format!("{}-{tag}{suffix}.fmu", scene.identifier()))
        }
    });
    let zip = build_fmu_of(&scene, &so, version)?;
    zip_entries(&zip)?;
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    }
    std::fs::write(&out, &zip).map_err(|e| format!("cannot write {}: {e}", out.display()))?;
    println!(
        "wrote {} ({} bytes): {} Co-Simulation FMU {}, scene {:?}, {}, {} {}, library needs {}",
        out.display(),
        zip.len(),
        version.label(),
        scene.identifier(),
        scene.name(),
        scene.summary(),
        version.token_name(),
        scene.guid(),
        info.needed.join(" ")
    );
    Ok(())
}

/// `cargo run --bin build-fmu` builds the library only as an rlib, so the
/// packager builds the cdylib itself (same profile and target folder as this
/// executable) before packing it; `--no-build` skips this.
fn build_cdylib(exe_dir: &std::path::Path) -> Result<(), String> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut cmd = std::process::Command::new(cargo);
    cmd.current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["build", "-p", "yarnsim-fmu", "--lib"]);
    if exe_dir.file_name().is_some_and(|n| n == "release") {
        cmd.arg("--release");
    }
    if let Some(target) = exe_dir.parent() {
        cmd.env("CARGO_TARGET_DIR", target);
    }
    let status = cmd
        .status()
        .map_err(|e| format!("cannot run cargo to build the library: {e} (or pass --lib)"))?;
    if !status.success() {
        return Err(format!("building the library failed: {status}"));
    }
    Ok(())
}

fn main() -> ExitCode {
    yarnsim_fmu::tool_exit("build-fmu", run())
}
