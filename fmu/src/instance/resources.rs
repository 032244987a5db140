//! The FMU's resources: the resource location URI handed to
//! `fmi2Instantiate` and the bundled scene file read from it (size and file
//! type limits in [`crate::model_description::read_scene_text`]).

use std::path::{Path, PathBuf};

use yarnsim::scene::Scene;

use crate::models::scene_from_toml_str;

/// Turns a resource location URI (`file:///a/b`, `file:/a/b`,
/// `file://localhost/a/b`, with `%xx` escapes) or a plain path into a path.
pub fn resource_path(uri: &str) -> Result<PathBuf, String> {
    let rest = if let Some(r) = uri.strip_prefix("file://localhost/") {
        format!("/{r}")
    } else if let Some(r) = uri.strip_prefix("file:///") {
        format!("/{r}")
    } else if let Some(r) = uri.strip_prefix("file://") {
        return Err(format!(
            "resource location {uri:?} names a remote host ({})",
            r.split('/').next().unwrap_or("")
        ));
    } else if let Some(r) = uri.strip_prefix("file:") {
        r.to_string()
    } else if uri.contains("://") {
        return Err(format!("resource location {uri:?} is not a file URI"));
    } else {
        return Ok(PathBuf::from(uri));
    };
    let bytes = rest.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok());
            match hex {
                Some(b) => {
                    out.push(b);
                    i += 3;
                    continue;
                }
                None => return Err(format!("resource location {uri:?} has a bad % escape")),
            }
        }
        out.push(bytes[i]);
        i += 1;
    }
    use std::os::unix::ffi::OsStringExt;
    Ok(PathBuf::from(std::ffi::OsString::from_vec(out)))
}

pub fn read_scene(path: &Path) -> Result<Scene, String> {
    let text = crate::model_description::read_scene_text(path)?;
    scene_from_toml_str(&text).map_err(|e| format!("scene file {}: {e}", path.display()))
}
