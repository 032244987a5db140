//! The packager: the .fmu archive (layout, reproducible bytes, corruption
//! detected), the zip CRC and the ELF check of the FMU's shared library
//! (all 34 `fmi2*` exports, only libc/libm/libgcc_s/loader needed); the
//! FMI 3.0 archive (`build-fmu --fmi-version 3`: `binaries/x86_64-linux/`,
//! the FMI 3.0 modelDescription with the arrays) and the 75 `fmi3*` exports.

use yarnsim::massspring::scenes::wire;
use yarnsim::scene::{Scene, YarnScene};
use yarnsim_fmu_pack::*;

// The FMU crate's test master, for `cdylib_path` (the library cargo built
// next to this test as a dependency).
#[path = "../../fmu/tests/common/mod.rs"]
mod common;
use common::cdylib_path;
use yarnsim_fmu::models::yarn::variables::*;
use yarnsim_fmu::SceneFmu;

/// The bytes that stand in for the FMU's library in an archive.
const STAND_IN: &[u8] = b"\x7fELF not really";

/// The archive of `scene` around [`STAND_IN`] and its entries, checked to
/// be the FMI 2.0 layout with the library `binaries/linux64/{library}.so`.
fn archive(scene: &Scene, library: &str) -> (Vec<u8>, Vec<(String, Vec<u8>)>) {
    archive_of(scene, library, FmiVersion::Fmi2)
}

/// The archive of `version` of `scene` around [`STAND_IN`] and its entries,
/// checked to have that version's layout (`binaries/linux64/` for FMI 2.0,
/// `binaries/x86_64-linux/` for FMI 3.0).
fn archive_of(
    scene: &Scene,
    library: &str,
    version: FmiVersion,
) -> (Vec<u8>, Vec<(String, Vec<u8>)>) {
    let zip = build_fmu_of(scene, STAND_IN, version).unwrap();
    let entries = zip_entries(&zip).unwrap();
    let names: Vec<&str> = entries.iter().map(|(n, _)| n.as_str()).collect();
    let library = version.binary_path(library);
    assert_eq!(
        names,
        [
            "modelDescription.xml",
            library.as_str(),
            "resources/scene.toml",
            "documentation/index.html"
        ]
    );
    (zip, entries)
}

/// The exported dynamic symbols of the built library that start with
/// `prefix`, sorted and without repeats.
fn exported(info: &ElfInfo, prefix: &str) -> Vec<String> {
    let mut names: Vec<String> = info
        .exported
        .iter()
        .filter(|s| s.starts_with(prefix))
        .cloned()
        .collect();
    names.sort();
    names.dedup();
    names
}

fn small_scene() -> YarnScene {
    YarnScene::from_toml_str(include_str!("../../fmu/scenes/small.toml")).unwrap()
}

#[test]
fn shared_library_exports_all_34_functions_and_needs_only_libc() {
    let path = cdylib_path();
    let so = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let info = elf_info(&so).unwrap();
    let fmi = exported(&info, "fmi2");
    let mut expected = FMI2_FUNCTIONS.to_vec();
    expected.sort();
    assert_eq!(fmi, expected);
    assert_eq!(fmi.len(), 34);
    // libc and libm (plus the loader and libgcc_s, which Rust's unwinder
    // needs for catch_unwind); nothing else.
    assert!(
        info.needed.iter().any(|n| n == "libc.so.6"),
        "{:?}",
        info.needed
    );
    for n in &info.needed {
        assert!(
            ALLOWED_NEEDED.contains(&n.as_str()),
            "unexpected dependency {n}"
        );
    }
    check_library(&so).unwrap();
}

#[test]
fn fmu_archive_layout_and_contents() {
    let scene = small_scene();
    let (zip, entries) = archive(&scene.clone().into(), "YarnBundle");
    assert_eq!(entries[0].1, model_description(&scene).into_bytes());
    assert_eq!(entries[1].1, STAND_IN);
    let packed = YarnScene::from_toml_str(std::str::from_utf8(&entries[2].1).unwrap()).unwrap();
    assert_eq!(guid(&packed), guid(&scene));
    // Reproducible: the same inputs give the same bytes.
    assert_eq!(build_fmu(&scene.clone().into(), STAND_IN).unwrap(), zip);
    // A corrupted archive is detected.
    let mut bad = zip.clone();
    let at = zip.windows(4).position(|w| w == b"kind").unwrap();
    bad[at] ^= 1;
    assert!(zip_entries(&bad).is_err());
}

#[test]
fn crc32_known_value() {
    assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    assert_eq!(crc32(b""), 0);
}

#[test]
fn mass_spring_archive_layout() {
    let scene = Scene::MassSpring(wire());
    let (_, entries) = archive(&scene, "MassSpring");
    let packed =
        yarnsim_fmu::scene_from_toml_str(std::str::from_utf8(&entries[2].1).unwrap()).unwrap();
    assert_eq!(packed.guid(), scene.guid());
    let doc = String::from_utf8(entries[3].1.clone()).unwrap();
    assert!(doc.contains("particle[10].x") && doc.contains("mass-spring"));
}

/// The FMI 3.0 archive of `scene` (entries), checked for its layout and
/// reproducible bytes.
fn archive3(scene: &Scene, library: &str) -> Vec<(String, Vec<u8>)> {
    let (zip, entries) = archive_of(scene, library, FmiVersion::Fmi3);
    assert_eq!(archive_of(scene, library, FmiVersion::Fmi3).0, zip);
    entries
}

#[test]
fn fmi3_archives_of_the_yarn_and_the_mass_spring_scenes() {
    let small =
        Scene::Yarn(YarnScene::from_toml_str(include_str!("../../fmu/scenes/small.toml")).unwrap());
    let e = archive3(&small, "YarnBundle");
    let xml = String::from_utf8(e[0].1.clone()).unwrap();
    assert_eq!(xml, small.model_description_fmi3().unwrap());
    assert!(xml.contains("fmiVersion=\"3.0\""));
    assert!(xml.contains("name=\"yarn[2].velocities\""));
    let doc = String::from_utf8(e[3].1.clone()).unwrap();
    assert!(doc.contains("FMI 3.0 Co-Simulation FMU"));
    assert!(doc.contains("Float64 array [24, 2]"));
    // the FMI 2.0 archive of the same scene keeps its layout and bytes
    assert_eq!(
        build_fmu_of(&small, b"x", FmiVersion::Fmi2).unwrap(),
        build_fmu(&small, b"x").unwrap()
    );

    let wire = Scene::MassSpring(wire());
    let e = archive3(&wire, "MassSpring");
    let xml = String::from_utf8(e[0].1.clone()).unwrap();
    let n = yarnsim_fmu::models::massspring::num_particles(&wire_layout()).unwrap();
    assert!(xml.contains(&format!(
        "name=\"positions\" valueReference=\"{}\"",
        yarnsim_fmu::models::massspring::VR_POSITIONS
    )));
    assert!(xml.contains(&format!(
        "<Dimension start=\"{n}\"/>\n      <Dimension start=\"3\"/>"
    )));
}

fn wire_layout() -> yarnsim::massspring::MassSpringScene {
    wire()
}

#[test]
fn shared_library_exports_all_75_fmi3_functions() {
    let path = cdylib_path();
    let so = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let info = check_library(&so).unwrap();
    let mut expected = FMI3_FUNCTIONS.to_vec();
    expected.sort_unstable();
    assert_eq!(exported(&info, "fmi3"), expected);
}
