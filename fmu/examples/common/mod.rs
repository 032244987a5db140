//! What the FMU examples share: a scene written where `fmi2Instantiate` can
//! find it, and instances of it set up and initialized through the C ABI.

use std::ffi::CString;
use std::path::PathBuf;

use yarnsim::scene::Scene;
use yarnsim_fmu::fmi2::*;
use yarnsim_fmu::model_description::*;
use yarnsim_fmu::SceneFmu;

/// A scene in a resource directory of its own (under the system's temporary
/// directory, named after `tag` and the process), with the strings and
/// callbacks `fmi2Instantiate` takes.
pub struct Fixture {
    pub scene: Scene,
    pub dir: PathBuf,
    uri: CString,
    guid: CString,
    name: CString,
    cb: fmi2CallbackFunctions,
}

impl Fixture {
    /// The scene `scene_arg` (a built-in name or a file) written for the FMU.
    pub fn new(scene_arg: &str, tag: &str) -> Self {
        let scene = Scene::resolve(scene_arg).unwrap();
        let dir = std::env::temp_dir().join(format!("yarnbundle-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join(SCENE_FILE), scene.to_toml_string()).unwrap();
        Fixture {
            uri: CString::new(format!("file://{}", dir.display())).unwrap(),
            guid: CString::new(scene.guid()).unwrap(),
            name: CString::new("bench").unwrap(),
            cb: fmi2CallbackFunctions {
                logger: None,
                allocateMemory: None,
                freeMemory: None,
                stepFinished: None,
                componentEnvironment: std::ptr::null_mut(),
            },
            scene,
            dir,
        }
    }

    /// A new Co-Simulation instance, set up at t = 0 and initialized.
    ///
    /// # Safety
    /// The caller frees the instance with `fmi2FreeInstance` while `self`
    /// lives (it points at the callbacks).
    pub unsafe fn instance(&self) -> fmi2Component {
        // SAFETY: valid strings and callbacks that outlive the instance (the
        // caller's contract), then the standard's calling sequence on it.
        unsafe {
            let c = fmi2Instantiate(
                self.name.as_ptr(),
                fmi2CoSimulation,
                self.guid.as_ptr(),
                self.uri.as_ptr(),
                &self.cb,
                0,
                0,
            );
            assert!(!c.is_null());
            assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), fmi2OK);
            assert_eq!(fmi2EnterInitializationMode(c), fmi2OK);
            assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);
            c
        }
    }
}
