//! Scene descriptions: what exists in a simulation, as data. This is the
//! bottom layer: the models (`crate::mpm`, `crate::massspring`) import it,
//! it imports no model.
//!
//! A scene file is TOML; its `kind` field picks the model (`"yarn"` for the
//! MPM yarn bundle, one of [`massspring::KINDS`] for a mass-spring scene).
//! Built-in scenes are listed by [`builtin_names`].

pub mod builtin;
pub(crate) mod commented;
pub(crate) mod error;
pub mod fields;
pub mod massspring;
pub mod overrides;
pub(crate) mod readers;
pub(crate) mod yarn;

pub use yarn::{material_units, presets};

pub use builtin::{builtin, builtin_names, builtin_toml, DEFAULT_SCENE};
pub use error::SceneError;
pub use fields::{FieldDoc, MASS_SPRING_FIELDS, YARN_FIELDS};
pub use massspring::MassSpringScene;
pub use yarn::{
    AttractorSpec, Axial, ContactSpec, FieldPartition, GridSpec, Integrator, Material, Obstacle,
    PinMotionKind, PinSpec, StepSize, TimeSpec, TransferScheme, TransferSpec, WallMode, Walls,
    YarnEnd, YarnMaterial, YarnScene, YarnSpec, DEFAULT_SAFETY, MAX_DIAMETER_CELLS,
};

/// Any scene this crate can simulate.
// A scene is read once per run and matched by value everywhere; the yarn
// scene's size (about 550 bytes) costs nothing at that rate, where a box
// would change every match on it.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
pub enum Scene {
    /// A 2D MPM yarn bundle.
    Yarn(YarnScene),
    /// A 3D mass-spring wire or cloth (kinds "mass-spring", "wire", "cloth", "three-particle").
    MassSpring(MassSpringScene),
}

impl Scene {
    /// Parses a scene file's text, dispatching on its `kind` field.
    pub fn from_toml_str(text: &str) -> Result<Scene, SceneError> {
        let kind = toml_kind(text)?;
        match kind.as_deref() {
            None | Some("yarn") => YarnScene::from_toml_str(text).map(Scene::Yarn),
            Some(k) if massspring::KINDS.contains(&k) => {
                MassSpringScene::from_toml_str(text).map(Scene::MassSpring)
            }
            Some(other) => Err(kind_error(
                text,
                format!(
                    "unknown scene kind {other:?}; known kinds: \"yarn\", {}",
                    massspring::KINDS.map(|k| format!("{k:?}")).join(", ")
                ),
            )),
        }
    }

    /// Reads a scene file.
    pub fn from_file(path: impl AsRef<std::path::Path>) -> Result<Scene, SceneError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|e| SceneError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        Scene::from_toml_str(&text)
    }

    /// A built-in scene name, or else a path to a scene file.
    pub fn resolve(name_or_path: &str) -> Result<Scene, SceneError> {
        if let Some(s) = builtin(name_or_path) {
            return Ok(s);
        }
        let p = std::path::Path::new(name_or_path);
        if p.exists() || name_or_path.ends_with(".toml") {
            return Scene::from_file(p);
        }
        Err(SceneError::UnknownScene {
            name: name_or_path.to_string(),
            known: builtin_names().iter().map(|(n, _)| n.to_string()).collect(),
        })
    }

    /// The scene as TOML text.
    pub fn to_toml_string(&self) -> String {
        match self {
            Scene::Yarn(s) => s.to_toml_string(),
            Scene::MassSpring(s) => s.to_toml_string(),
        }
    }

    /// The scene's name.
    pub fn name(&self) -> &str {
        match self {
            Scene::Yarn(s) => &s.name,
            Scene::MassSpring(s) => &s.name,
        }
    }
}

impl From<YarnScene> for Scene {
    fn from(s: YarnScene) -> Self {
        Scene::Yarn(s)
    }
}

impl From<MassSpringScene> for Scene {
    fn from(s: MassSpringScene) -> Self {
        Scene::MassSpring(s)
    }
}

/// The top-level `kind` string of a scene file, if any.
fn toml_kind(text: &str) -> Result<Option<String>, SceneError> {
    let value: toml::Table = toml::from_str(text).map_err(|e| error::from_toml_error(text, e))?;
    match value.get("kind") {
        None => Ok(None),
        Some(toml::Value::String(s)) => Ok(Some(s.clone())),
        Some(_) => Err(kind_error(text, "kind must be a string".into())),
    }
}

/// An error in the scene's `kind` field, on the line that sets it.
fn kind_error(text: &str, message: String) -> SceneError {
    SceneError::Invalid {
        field: "kind".into(),
        line: text
            .lines()
            .position(|l| l.trim_start().starts_with("kind"))
            .map(|i| i + 1),
        message,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtin_scenes_start_apart() {
        for (name, _) in builtin_names() {
            match Scene::resolve(name).unwrap() {
                Scene::Yarn(y) => y.validate().unwrap(),
                Scene::MassSpring(l) => l.validate().unwrap(),
            }
        }
    }
}
