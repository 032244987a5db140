//! The models behind the FMUs, chosen by the bundled scene
//! ([`yarnsim::scene::Scene`]): a yarn scene runs the yarn bundle of
//! [`crate::models::yarn`] (`YarnBundle`), a mass-spring scene the system of
//! [`crate::models::massspring`] (`MassSpring`), each a folder of the same
//! files. This module is the one place that knows both; the model-neutral
//! ones ([`crate::model_description`], [`model`], [`state_bytes`]) know
//! neither.

use yarnsim::scene::Scene;

pub mod massspring;
pub mod model;
pub mod state_bytes;
pub mod yarn;

use crate::model_description::{
    write_model_description, write_model_description_fmi3, Description,
};
use crate::models::massspring::MsModel;
use crate::models::model::{FmuModel, ModelResult};
use crate::models::yarn::variables::{
    check_value_references, description, guid, num_yarns, MODEL_IDENTIFIER,
};
use crate::models::yarn::YarnModel;

/// What an FMU needs of its bundled scene: its identifier, GUID and model
/// description.
pub trait SceneFmu {
    /// The FMI modelIdentifier: `YarnBundle` or `MassSpring`.
    fn identifier(&self) -> &'static str;
    /// The GUID of the FMU of this scene.
    fn guid(&self) -> String;
    /// What the model description is written from; an error for a
    /// mass-spring scene that does not build.
    fn description(&self) -> Result<Description, String>;
    /// `modelDescription.xml`.
    fn model_description(&self) -> Result<String, String> {
        self.description().map(|d| write_model_description(&d))
    }
    /// The FMI 3.0 `modelDescription.xml` (with the array outputs).
    fn model_description_fmi3(&self) -> Result<String, String> {
        self.description().map(|d| write_model_description_fmi3(&d))
    }
    /// What the outputs describe: `"yarns"` or `"particles"`.
    fn objects(&self) -> &'static str;
    /// How many of them: `"12 yarns"`, `"441 particles"` (a mass-spring
    /// scene is expanded to count them).
    fn summary(&self) -> String;
}

impl SceneFmu for Scene {
    fn identifier(&self) -> &'static str {
        match self {
            Scene::Yarn(_) => MODEL_IDENTIFIER,
            Scene::MassSpring(_) => crate::models::massspring::MODEL_IDENTIFIER,
        }
    }

    fn guid(&self) -> String {
        match self {
            Scene::Yarn(s) => guid(s),
            Scene::MassSpring(l) => crate::models::massspring::guid(l),
        }
    }

    fn description(&self) -> Result<Description, String> {
        match self {
            Scene::Yarn(s) => check_value_references(s).map(|_| description(s)),
            Scene::MassSpring(l) => crate::models::massspring::description(l),
        }
    }

    fn objects(&self) -> &'static str {
        match self {
            Scene::Yarn(_) => "yarns",
            Scene::MassSpring(_) => "particles",
        }
    }

    fn summary(&self) -> String {
        let n = match self {
            Scene::Yarn(s) => Ok(num_yarns(s)),
            Scene::MassSpring(l) => crate::models::massspring::num_particles(l),
        };
        match n {
            // `1 yarn`, `12 yarns`.
            Ok(1) => format!("1 {}", self.objects().trim_end_matches('s')),
            Ok(n) => format!("{n} {}", self.objects()),
            Err(e) => e,
        }
    }
}

/// Reads a scene file's text (either kind), the error as text.
pub fn scene_from_toml_str(text: &str) -> Result<Scene, String> {
    Scene::from_toml_str(text).map_err(|e| e.to_string())
}

/// The model an FMU's bundled scene makes.
pub fn new_model(scene: &Scene) -> ModelResult<Box<dyn FmuModel>> {
    Ok(match scene {
        Scene::Yarn(s) => Box::new(YarnModel::new(s.clone())?),
        Scene::MassSpring(l) => Box::new(MsModel::new(l.clone())?),
    })
}
