//! The FMU packager (`build-fmu`), a crate of its own so that the FMU's
//! shared library does not carry it.
//!
//! Packaging: the `.fmu` zip archive (the `zip` crate, "stored" entries with
//! a fixed timestamp, so the same inputs give the same bytes), the generated
//! documentation page and the check of the shared library before it is
//! packed (the `object` crate's ELF reader: exported `fmi2*` and `fmi3*`
//! symbols, `DT_NEEDED` libraries).

use std::fmt::Write as _;
use std::io::{Cursor, Read, Write};

use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, DateTime};

use yarnsim::scene::Scene;
pub use yarnsim_fmu::fmi2::FMI2_FUNCTIONS;
pub use yarnsim_fmu::fmi3::FMI3_FUNCTIONS;
use yarnsim_fmu::model_description::{xml_escape, SCENE_FILE};
use yarnsim_fmu::SceneFmu;

/// CRC-32 (IEEE 802.3, reflected, as zip uses it), by `crc32fast` (the
/// checksum the `zip` crate writes).
pub fn crc32(data: &[u8]) -> u32 {
    crc32fast::hash(data)
}

/// A zip archive of stored (uncompressed) entries, which every unzip
/// implementation reads (FMI allows deflate or store), written by the `zip`
/// crate with a fixed timestamp (1980-01-01 00:00) and fixed unix modes, so
/// the same inputs give the same bytes.
pub struct Zip {
    writer: zip::ZipWriter<Cursor<Vec<u8>>>,
}

impl Default for Zip {
    fn default() -> Zip {
        Zip {
            writer: zip::ZipWriter::new(Cursor::new(Vec::new())),
        }
    }
}

impl Zip {
    /// Adds a file; `name` uses forward slashes. `executable` sets the unix
    /// mode 0755 instead of 0644.
    pub fn add(&mut self, name: &str, data: &[u8], executable: bool) -> Result<(), String> {
        let options = SimpleFileOptions::default()
            .compression_method(CompressionMethod::Stored)
            .last_modified_time(DateTime::default())
            .unix_permissions(if executable { 0o755 } else { 0o644 })
            .large_file(false);
        self.writer
            .start_file(name, options)
            .and_then(|()| self.writer.write_all(data).map_err(Into::into))
            .map_err(|e| format!("{name}: {e}"))
    }

    /// The archive bytes.
    pub fn finish(self) -> Vec<u8> {
        self.writer
            .finish()
            .expect("writing a zip into memory")
            .into_inner()
    }
}

/// Reads the entries of a zip archive (names and data, in archive order,
/// each checked against its CRC-32), for tests and the packager's
/// self-check.
pub fn zip_entries(zip: &[u8]) -> Result<Vec<(String, Vec<u8>)>, String> {
    let mut archive = zip::ZipArchive::new(Cursor::new(zip)).map_err(|e| e.to_string())?;
    (0..archive.len())
        .map(|i| {
            let mut entry = archive.by_index(i).map_err(|e| e.to_string())?;
            let name = entry.name().map_err(|e| e.to_string())?.into_owned();
            let mut data = Vec::with_capacity(entry.size() as usize);
            entry
                .read_to_end(&mut data)
                .map_err(|e| format!("{name}: {e}"))?;
            Ok((name, data))
        })
        .collect()
}

/// The FMI version of an FMU to pack.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FmiVersion {
    /// FMI 2.0 Co-Simulation: `binaries/linux64/`, no arrays.
    Fmi2,
    /// FMI 3.0 Co-Simulation: `binaries/x86_64-linux/`, with the array
    /// outputs.
    Fmi3,
}

impl FmiVersion {
    /// The standard's name and version, `FMI 2.0` or `FMI 3.0`.
    pub fn label(self) -> &'static str {
        match self {
            FmiVersion::Fmi2 => "FMI 2.0",
            FmiVersion::Fmi3 => "FMI 3.0",
        }
    }

    /// The modelDescription attribute the scene's hash goes into: `guid`
    /// (FMI 2.0) or `instantiationToken` (FMI 3.0).
    pub fn token_name(self) -> &'static str {
        match self {
            FmiVersion::Fmi2 => "GUID",
            FmiVersion::Fmi3 => "instantiationToken",
        }
    }

    /// `binaries/<platform>/<modelIdentifier>.so`.
    pub fn binary_path(self, identifier: &str) -> String {
        let platform = match self {
            FmiVersion::Fmi2 => "linux64",
            FmiVersion::Fmi3 => "x86_64-linux",
        };
        format!("binaries/{platform}/{identifier}.so")
    }

    /// `modelDescription.xml` of this version.
    pub fn model_description(self, scene: &Scene) -> Result<String, String> {
        match self {
            FmiVersion::Fmi2 => scene.model_description(),
            FmiVersion::Fmi3 => scene.model_description_fmi3(),
        }
    }
}

/// `documentation/index.html` of the FMI 2.0 FMU: the variables of this FMU.
pub fn documentation_html(scene: &Scene) -> Result<String, String> {
    documentation_html_of(scene, FmiVersion::Fmi2)
}

/// `documentation/index.html` of the FMU of `version`: the variables (for
/// FMI 3.0 also the arrays with their dimensions).
pub fn documentation_html_of(scene: &Scene, version: FmiVersion) -> Result<String, String> {
    let d = scene.description()?;
    let ident = d.identifier;
    let (what, details) = match scene {
        Scene::Yarn(s) => (
            "an MPM yarn bundle",
            format!(
                "{}, substep {}, grid {}<sup>2</sup>",
                scene.summary(),
                s.time.dt,
                s.grid.resolution
            ),
        ),
        Scene::MassSpring(l) => (
            "a mass-spring system",
            format!(
                "{}, frame time {} s, default integrator {}",
                scene.summary(),
                l.time.frame_time,
                yarnsim_fmu::models::massspring::DEFAULT_INTEGRATOR
            ),
        ),
    };
    let mut h = String::new();
    let _ = writeln!(
        h,
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{ident}</title></head><body>"
    );
    let fmi = match version {
        FmiVersion::Fmi2 => "FMI 2.0",
        FmiVersion::Fmi3 => "FMI 3.0",
    };
    let _ = writeln!(h, "<h1>{ident}: {fmi} Co-Simulation FMU of {what}</h1>");
    let _ = writeln!(
        h,
        "<p>{}. Scene <code>{}</code>: {details}. The scene is <code>resources/{SCENE_FILE}</code>; GUID <code>{}</code>. Each communication step runs an integer number of substeps: the substeps done by time t are round((t - startTime) / dt).</p>",
        xml_escape(&d.description),
        xml_escape(scene.name()),
        d.guid
    );
    h.push_str("<table border=\"1\"><tr><th>name</th><th>value reference</th><th>causality</th><th>variability</th><th>unit</th><th>start</th><th>description</th></tr>\n");
    for v in &d.variables {
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            xml_escape(&v.name),
            v.vr,
            v.causality,
            v.variability,
            v.unit.unwrap_or(""),
            xml_escape(v.start.as_deref().unwrap_or("")),
            xml_escape(&match version {
                FmiVersion::Fmi2 => v.description.clone(),
                FmiVersion::Fmi3 => yarnsim_fmu::model_description::fmi3_words(&v.description),
            })
        );
    }
    if version == FmiVersion::Fmi3 {
        h.push_str("<tr><td>time</td><td>0</td><td>independent</td><td>continuous</td><td>s</td><td></td><td>Simulation time</td></tr>\n");
        for a in &d.arrays {
            let dims: Vec<String> = a.dims.iter().map(|n| n.to_string()).collect();
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td>{}</td><td>output</td><td>continuous</td><td>{}</td><td>Float64 array [{}]</td><td>{}</td></tr>",
                xml_escape(&a.name),
                a.vr,
                a.unit.unwrap_or(""),
                dims.join(", "),
                xml_escape(&a.description)
            );
        }
    }
    h.push_str("</table>\n<p>Built by yarnsim-fmu; see the section on the FMUs in the README of the yarnsim repository.</p>\n</body></html>\n");
    Ok(h)
}

/// The complete `.fmu` archive for `scene` around the shared library `so`
/// (packed as `binaries/linux64/<modelIdentifier>.so`).
pub fn build_fmu(scene: &Scene, so: &[u8]) -> Result<Vec<u8>, String> {
    build_fmu_of(scene, so, FmiVersion::Fmi2)
}

/// The complete `.fmu` archive of `version` for `scene` around the shared
/// library `so` ([`FmiVersion::binary_path`]).
pub fn build_fmu_of(scene: &Scene, so: &[u8], version: FmiVersion) -> Result<Vec<u8>, String> {
    let mut z = Zip::default();
    z.add(
        "modelDescription.xml",
        version.model_description(scene)?.as_bytes(),
        false,
    )?;
    z.add(&version.binary_path(scene.identifier()), so, true)?;
    z.add(
        &format!("resources/{SCENE_FILE}"),
        scene.to_toml_string().as_bytes(),
        false,
    )?;
    z.add(
        "documentation/index.html",
        documentation_html_of(scene, version)?.as_bytes(),
        false,
    )?;
    Ok(z.finish())
}

/// What the ELF dynamic section of a shared library says.
#[derive(Debug, Default)]
pub struct ElfInfo {
    /// Defined, global dynamic symbols.
    pub exported: Vec<String>,
    /// `DT_NEEDED` entries.
    pub needed: Vec<String>,
}

/// Reads the exported dynamic symbols and `DT_NEEDED` entries of a 64-bit
/// little-endian ELF file (with the `object` crate's ELF reader).
pub fn elf_info(b: &[u8]) -> Result<ElfInfo, String> {
    use object::read::elf::{Dyn, ElfFile64, FileHeader};
    use object::{elf, LittleEndian, Object, ObjectSymbol};
    let file = ElfFile64::<LittleEndian>::parse(b)
        .map_err(|e| format!("not a 64-bit little-endian ELF file: {e}"))?;
    let mut info = ElfInfo::default();
    // Defined dynamic symbols of global or weak binding.
    for sym in file.dynamic_symbols() {
        if !sym.is_undefined() && sym.is_global() {
            info.exported
                .push(sym.name().map_err(|e| e.to_string())?.to_string());
        }
    }
    let endian = file.endian();
    let sections = file
        .elf_header()
        .sections(endian, b)
        .map_err(|e| e.to_string())?;
    if let Some((dynamic, link)) = sections.dynamic(endian, b).map_err(|e| e.to_string())? {
        let strings = sections
            .strings(endian, b, link)
            .map_err(|e| e.to_string())?;
        for d in dynamic {
            let tag = d.d_tag(endian);
            if tag == elf::DT_NULL {
                break;
            }
            if tag == elf::DT_NEEDED {
                let name = d.string(endian, strings).map_err(|e| e.to_string())?;
                info.needed.push(String::from_utf8_lossy(name).into_owned());
            }
        }
    }
    Ok(info)
}

/// Shared libraries the FMU binary may depend on: the C library (with the
/// parts older glibc versions split out), libm, the dynamic loader, and
/// libgcc_s, which Rust's std links for unwinding (needed by catch_unwind).
pub const ALLOWED_NEEDED: [&str; 7] = [
    "libc.so.6",
    "libm.so.6",
    "libgcc_s.so.1",
    "ld-linux-x86-64.so.2",
    "libpthread.so.0",
    "libdl.so.2",
    "librt.so.1",
];

/// Checks a shared library for the FMU: all 34 FMI 2.0 functions and all
/// 75 FMI 3.0 functions exported, no dependency beyond [`ALLOWED_NEEDED`].
pub fn check_library(so: &[u8]) -> Result<ElfInfo, String> {
    let info = elf_info(so)?;
    let missing: Vec<&str> = FMI2_FUNCTIONS
        .iter()
        .chain(&FMI3_FUNCTIONS)
        .copied()
        .filter(|f| !info.exported.iter().any(|e| e == f))
        .collect();
    if !missing.is_empty() {
        return Err(format!("the library does not export {missing:?}"));
    }
    let extra: Vec<&String> = info
        .needed
        .iter()
        .filter(|n| !ALLOWED_NEEDED.contains(&n.as_str()))
        .collect();
    if !extra.is_empty() {
        return Err(format!(
            "the library needs other shared libraries: {extra:?}"
        ));
    }
    Ok(info)
}
