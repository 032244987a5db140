//! The FMU packager (`build-fmu`), a crate of its own so that the FMU's
//! shared library does not carry it.
//!
//! Packaging: the `.fmu` zip archive (written here, "stored" entries with a
//! fixed timestamp, so the same inputs give the same bytes), the generated
//! documentation page and a small ELF reader that checks the shared library
//! before it is packed (exported `fmi2*` symbols, `DT_NEEDED` libraries).

use std::fmt::Write as _;

use yarnsim::scene::Scene;
pub use yarnsim_fmu::fmi2::FMI2_FUNCTIONS;
pub use yarnsim_fmu::fmi3::FMI3_FUNCTIONS;
use yarnsim_fmu::model_description::{xml_escape, SCENE_FILE};
use yarnsim_fmu::SceneFmu;

/// CRC-32 (IEEE 802.3, reflected, as zip uses it).
pub fn crc32(data: &[u8]) -> u32 {
    let mut table = [0u32; 256];
    for (i, t) in table.iter_mut().enumerate() {
        let mut c = i as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
        }
        *t = c;
    }
    let mut crc = !0u32;
    for &b in data {
        crc = table[((crc ^ b as u32) & 0xff) as usize] ^ (crc >> 8);
    }
    !crc
}

/// A zip archive of stored (uncompressed) entries, which every unzip
/// implementation reads (FMI allows deflate or store).
#[derive(Default)]
pub struct Zip {
    out: Vec<u8>,
    central: Vec<u8>,
    entries: u16,
}

/// 1980-01-01 00:00 in DOS format: a fixed timestamp keeps builds reproducible.
const DOS_TIME: u16 = 0;
const DOS_DATE: u16 = (1 << 5) | 1;

impl Zip {
    /// Adds a file; `name` uses forward slashes. `executable` sets the unix
    /// mode 0755 instead of 0644.
    pub fn add(&mut self, name: &str, data: &[u8], executable: bool) -> Result<(), String> {
        if data.len() > u32::MAX as usize - 1 || self.out.len() + data.len() > u32::MAX as usize - 1
        {
            return Err(format!("{name}: too large for a zip without zip64"));
        }
        let crc = crc32(data);
        let offset = self.out.len() as u32;
        let n = name.len() as u16;
        let size = data.len() as u32;
        let o = &mut self.out;
        o.extend_from_slice(&0x0403_4b50u32.to_le_bytes());
        for v in [20u16, 0, 0, DOS_TIME, DOS_DATE] {
            o.extend_from_slice(&v.to_le_bytes());
        }
        for v in [crc, size, size] {
            o.extend_from_slice(&v.to_le_bytes());
        }
        o.extend_from_slice(&n.to_le_bytes());
        o.extend_from_slice(&0u16.to_le_bytes());
        o.extend_from_slice(name.as_bytes());
        o.extend_from_slice(data);

        let mode: u32 = if executable { 0o100755 } else { 0o100644 };
        let c = &mut self.central;
        c.extend_from_slice(&0x0201_4b50u32.to_le_bytes());
        // Made by: unix (3), spec 2.0; needed: 2.0.
        for v in [0x0314u16, 20, 0, 0, DOS_TIME, DOS_DATE] {
            c.extend_from_slice(&v.to_le_bytes());
        }
        for v in [crc, size, size] {
            c.extend_from_slice(&v.to_le_bytes());
        }
        for v in [n, 0, 0, 0, 0] {
            c.extend_from_slice(&v.to_le_bytes());
        }
        c.extend_from_slice(&(mode << 16).to_le_bytes());
        c.extend_from_slice(&offset.to_le_bytes());
        c.extend_from_slice(name.as_bytes());
        self.entries += 1;
        Ok(())
    }

    /// The archive bytes.
    pub fn finish(mut self) -> Vec<u8> {
        let cd_offset = self.out.len() as u32;
        let cd_size = self.central.len() as u32;
        self.out.extend_from_slice(&self.central);
        self.out.extend_from_slice(&0x0605_4b50u32.to_le_bytes());
        for v in [0u16, 0, self.entries, self.entries] {
            self.out.extend_from_slice(&v.to_le_bytes());
        }
        self.out.extend_from_slice(&cd_size.to_le_bytes());
        self.out.extend_from_slice(&cd_offset.to_le_bytes());
        self.out.extend_from_slice(&0u16.to_le_bytes());
        self.out
    }
}

/// Reads the names of a stored zip's entries (central directory), for tests
/// and the packager's self-check.
pub fn zip_entries(zip: &[u8]) -> Result<Vec<(String, Vec<u8>)>, String> {
    let eocd = zip
        .len()
        .checked_sub(22)
        .filter(|&i| zip[i..i + 4] == 0x0605_4b50u32.to_le_bytes())
        .ok_or("no end of central directory record")?;
    let u16_at = |i: usize| u16::from_le_bytes([zip[i], zip[i + 1]]) as usize;
    let u32_at = |i: usize| u32::from_le_bytes(zip[i..i + 4].try_into().unwrap()) as usize;
    let count = u16_at(eocd + 10);
    let mut at = u32_at(eocd + 16);
    let mut out = Vec::with_capacity(count);
    for _ in 0..count {
        if at + 46 > zip.len() || u32_at(at) != 0x0201_4b50 {
            return Err("bad central directory header".into());
        }
        let size = u32_at(at + 20);
        let n = u16_at(at + 28);
        let skip = n + u16_at(at + 30) + u16_at(at + 32);
        let name = String::from_utf8_lossy(&zip[at + 46..at + 46 + n]).into_owned();
        let local = u32_at(at + 42);
        let data_at = local + 30 + u16_at(local + 26) + u16_at(local + 28);
        let data = zip
            .get(data_at..data_at + size)
            .ok_or("entry data out of bounds")?
            .to_vec();
        if crc32(&data) != u32_at(at + 16) as u32 {
            return Err(format!("{name}: CRC mismatch"));
        }
        out.push((name, data));
        at += 46 + skip;
    }
    Ok(out)
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
/// little-endian ELF file.
pub fn elf_info(b: &[u8]) -> Result<ElfInfo, String> {
    if b.len() < 64 || &b[..4] != b"\x7fELF" || b[4] != 2 || b[5] != 1 {
        return Err("not a 64-bit little-endian ELF file".into());
    }
    let get = |at: usize, n: usize| -> Result<u64, String> {
        let s = b.get(at..at + n).ok_or("ELF read out of bounds")?;
        let mut v = [0u8; 8];
        v[..n].copy_from_slice(s);
        Ok(u64::from_le_bytes(v))
    };
    let shoff = get(0x28, 8)? as usize;
    let shentsize = get(0x3a, 2)? as usize;
    let shnum = get(0x3c, 2)? as usize;
    // (type, offset, size, link, entsize) of every section.
    let mut sections = Vec::with_capacity(shnum);
    for i in 0..shnum {
        let s = shoff + i * shentsize;
        sections.push((
            get(s + 4, 4)? as u32,
            get(s + 0x18, 8)? as usize,
            get(s + 0x20, 8)? as usize,
            get(s + 0x28, 4)? as usize,
            get(s + 0x38, 8)? as usize,
        ));
    }
    let cstr = |strtab: usize, off: usize| -> Result<String, String> {
        let (_, o, size, _, _) = *sections.get(strtab).ok_or("bad string table")?;
        let s = b.get(o + off..o + size).ok_or("bad string offset")?;
        let end = s.iter().position(|&c| c == 0).unwrap_or(s.len());
        Ok(String::from_utf8_lossy(&s[..end]).into_owned())
    };
    let mut info = ElfInfo::default();
    for &(ty, off, size, link, entsize) in &sections {
        match ty {
            // SHT_DYNSYM
            11 => {
                let entsize = entsize.max(24);
                for k in 1..size / entsize {
                    let e = off + k * entsize;
                    let name = get(e, 4)? as usize;
                    let bind = b[e + 4] >> 4;
                    let shndx = get(e + 6, 2)?;
                    if shndx != 0 && (bind == 1 || bind == 2) {
                        info.exported.push(cstr(link, name)?);
                    }
                }
            }
            // SHT_DYNAMIC
            6 => {
                for k in 0..size / 16 {
                    let tag = get(off + 16 * k, 8)?;
                    let val = get(off + 16 * k + 8, 8)? as usize;
                    match tag {
                        0 => break,
                        1 => info.needed.push(cstr(link, val)?),
                        _ => {}
                    }
                }
            }
            _ => {}
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
