//! `yarnsim scenes` and `yarnsim scene show`.

use std::fmt::Write as _;

use yarnsim::scene::{builtin_names, Scene, DEFAULT_SCENE};

use crate::error::CliError;
use crate::table::MAX_WIDTH;

/// One line per built-in scene: name, then description; the default is marked.
pub fn list_scenes() -> String {
    let names = builtin_names();
    let width = names.iter().map(|(n, _)| n.len()).max().unwrap_or(0);
    let mut out = String::new();
    for (name, description) in names {
        let mark = if name == DEFAULT_SCENE { "*" } else { " " };
        // Descriptions wrap within MAX_WIDTH, continuation lines indented.
        let indent = width + 4;
        let mut line = format!("{mark} {name:<width$} ");
        for word in description.split(' ') {
            if line.len() + 1 + word.len() > MAX_WIDTH && line.len() > indent {
                let _ = writeln!(out, "{line}");
                line = " ".repeat(indent - 1);
            }
            line.push(' ');
            line.push_str(word);
        }
        let _ = writeln!(out, "{line}");
    }
    let _ = writeln!(out, "(* = default scene)");
    out
}

/// Resolves a built-in scene name or a scene file path, with the `--set
/// KEY=VALUE` overrides applied (see [`yarnsim::scene::overrides`]).
pub fn load_scene(name_or_path: &str, overrides: &[String]) -> Result<Scene, CliError> {
    Scene::resolve_with(name_or_path, overrides).map_err(CliError::from)
}

/// The scene as TOML, ready to save and edit: arrays on one line, each
/// field's unit and range in a comment after it
/// ([`Scene::to_commented_toml`]).
pub fn show_scene(name_or_path: &str, overrides: &[String]) -> Result<String, CliError> {
    Ok(load_scene(name_or_path, overrides)?.to_commented_toml())
}
