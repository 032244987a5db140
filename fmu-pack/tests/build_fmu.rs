//! The `build-fmu` command as a user runs it: its closing line names the
//! FMI version it packed (FMI 2.0 or 3.0), the model, the scene and the
//! attribute the scene's hash went into; the archive has that version's
//! layout.

use std::path::PathBuf;
use std::process::Command;

use yarnsim_fmu_pack::zip_entries;

// The FMU crate's test helpers, for `cdylib_path` (the library cargo built
// next to this test as a dependency).
#[path = "../../fmu/tests/common/mod.rs"]
mod common;

/// Runs `build-fmu --no-build --lib <the test's cdylib> ARGS -o OUT`, which
/// must succeed: its standard output and the archive's entry names.
fn build_fmu(args: &[&str], out: &str) -> (String, Vec<String>) {
    let out = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(out);
    let result = Command::new(env!("CARGO_BIN_EXE_build-fmu"))
        .args(args)
        .arg("--lib")
        .arg(common::cdylib_path())
        .arg("-o")
        .arg(&out)
        .output()
        .expect("run build-fmu");
    let stdout = String::from_utf8(result.stdout).unwrap();
    assert!(
        result.status.success(),
        "build-fmu {args:?}: {}{stdout}",
        String::from_utf8_lossy(&result.stderr)
    );
    let zip = std::fs::read(&out).unwrap();
    let names = zip_entries(&zip)
        .unwrap()
        .into_iter()
        .map(|(n, _)| n)
        .collect();
    (stdout, names)
}

#[test]
fn the_closing_line_names_the_fmi_version_it_wrote() {
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/../fmu/scenes/small.toml");
    let (two, files2) = build_fmu(&["--scene", scene], "msg-small.fmu");
    let (three, files3) = build_fmu(
        &["--scene", scene, "--fmi-version", "3"],
        "msg-small-fmi3.fmu",
    );
    assert!(
        two.contains("FMI 2.0 Co-Simulation FMU YarnBundle, scene \"yarn-small\", 3 yarns, GUID {"),
        "{two}"
    );
    assert!(
        three.contains(
            "FMI 3.0 Co-Simulation FMU YarnBundle, scene \"yarn-small\", 3 yarns, instantiationToken {"
        ),
        "{three}"
    );
    assert!(files2.iter().any(|f| f.starts_with("binaries/linux64/")));
    assert!(files3
        .iter()
        .any(|f| f.starts_with("binaries/x86_64-linux/")));

    // One yarn is `1 yarn`; a mass-spring scene counts particles.
    let (drape, _) = build_fmu(&["--scene", "yarn-drape"], "msg-drape.fmu");
    assert!(drape.contains(", 1 yarn, GUID"), "{drape}");
    let (wire, _) = build_fmu(&["--scene", "wire", "--fmi-version", "3"], "msg-wire.fmu");
    assert!(
        wire.contains("FMI 3.0 Co-Simulation FMU MassSpring, scene \"wire\", 11 particles"),
        "{wire}"
    );
}
