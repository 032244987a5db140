//! The interface between the instance ([`crate::instance`]) and the models
//! it runs (as `model.h` in modelica/Reference-FMUs): [`FmuModel`], implemented by the
//! yarn bundle ([`crate::models::yarn::YarnModel`]) and the mass-spring system
//! ([`crate::models::massspring::MsModel`]). The models know nothing of FMI
//! statuses, function names or C types: they answer with typed errors
//! ([`ModelError`], [`StepFailure`]) and Rust values, and the front end turns
//! them into fmi2 and fmi3 statuses and log lines: the FMI 2.0 front end
//! ([`crate::fmi2`]) and the FMI 3.0 one ([`crate::fmi3`]) drive the same
//! models.

use std::any::Any;
use std::fmt;
use std::path::Path;

use yarnsim::scene::Scene;

use crate::models::state_bytes::{Reader, Writer};

/// A model refused a call: a value out of range, an unknown variable, a
/// scene or parameter set it cannot build. The front end answers fmi2Error
/// and logs the message (prefixed with the FMI function's name).
#[derive(Clone, Debug, PartialEq)]
pub struct ModelError(pub String);

impl fmt::Display for ModelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for ModelError {}

/// What the models' calls return.
pub type ModelResult<T = ()> = Result<T, ModelError>;

/// Refuses a call with `msg`.
pub fn refuse<T>(msg: impl Into<String>) -> ModelResult<T> {
    Err(ModelError(msg.into()))
}

/// A substep that failed: the message, and whether the simulation is lost
/// (non-finite state) rather than refused an input.
#[derive(Clone, Debug, PartialEq)]
pub struct StepFailure {
    pub terminal: bool,
    pub msg: String,
}

/// Checks that the parameter with this name may be set now (fixed
/// parameters: only before the end of initialization); the refusal names
/// the parameter.
pub type ParamCheck<'a> = &'a dyn Fn(&str) -> ModelResult;

/// A variable's name and causality (`"input"`, `"parameter"`, `"output"`,
/// `"independent"`), for the log messages: they name the variable as
/// `modelDescription.xml` does, not only its value reference.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct VarName {
    pub name: String,
    pub causality: &'static str,
}

impl VarName {
    pub fn new(name: impl Into<String>, causality: &'static str) -> Self {
        VarName {
            name: name.into(),
            causality,
        }
    }
}

/// The name of `vr` for a message: the variable's name with its value
/// reference in parentheses (`material.plasticity (value reference 17)`),
/// or `value reference 99` for one no variable has.
pub fn shown(name: Option<VarName>, vr: u32) -> String {
    match name {
        Some(v) => format!("{} (value reference {vr})", v.name),
        None => format!("value reference {vr}"),
    }
}

/// What the setters may need besides the values: the check of the
/// parameters, and for String variables the FMU's resources.
pub struct SetContext<'a> {
    /// Whether a parameter may be set now ([`ParamCheck`]).
    pub check: ParamCheck<'a>,
    /// The FMU's `resources/` folder (relative scene paths).
    pub resources: &'a Path,
    /// The scene bundled in `resources/`.
    pub bundled: &'a Scene,
}

/// One call of a setter: the value references `vrs`, their values (`vals[i]`
/// for `vrs[i]`) and what the setter may need besides ([`SetContext`]).
pub struct Set<'a, T> {
    pub vrs: &'a [u32],
    pub vals: &'a [T],
    pub ctx: &'a SetContext<'a>,
}

/// The state a failed communication step goes back to
/// ([`FmuModel::checkpoint`]); only the model that made it reads it.
pub type Checkpoint = Box<dyn Any + Send>;

/// A model's part of an FMU state (`fmi2GetFMUstate`,
/// [`FmuModel::save`]): what determines its future outputs, bit for bit
/// (the simulation's values, inputs, parameters), never scratch such as the
/// MPM grid; only a model of the kind that made it reads it.
pub type ModelSnapshot = Box<dyn Any + Send>;

/// A model behind the FMU: its outputs, inputs and parameters by value
/// reference, its substeps and its part of the FMU state.
pub trait FmuModel: fmt::Debug + Send {
    /// First bytes of a serialized FMU state of this model.
    fn state_magic(&self) -> &'static [u8; 8];
    /// Yarns or particles: the objects the outputs describe.
    fn count(&self) -> usize;
    /// The substep size in s.
    fn dt(&self) -> f64;
    /// The library's stability bound on the substep in s (`None`: none).
    fn stable_dt(&self) -> Option<f64>;
    /// What the scene does that likely is not meant (the library's scene
    /// warnings: a yarn diameter under shared fields, a yarn laid closer
    /// than its radius to an obstacle); logged at the end of
    /// initialisation with a warning status.
    fn warnings(&self) -> Vec<String> {
        Vec::new()
    }
    /// Rebuilds the simulation from the scene and the parameters; it must
    /// have `count` output objects.
    fn rebuild(&mut self, count: usize) -> ModelResult;
    /// A communication step that runs substeps begins at `since_start`
    /// seconds after the start time (after the checkpoint of the step): the
    /// model latches its inputs for the step. A failure refuses the step.
    fn begin_step(&mut self, since_start: f64) -> Result<(), StepFailure> {
        let _ = since_start;
        Ok(())
    }
    /// Substep number `k` (0-based since initialization).
    fn substep(&mut self, k: u64) -> Result<(), StepFailure>;
    /// Whether the model picks its own substeps (the yarn's `dt = "auto"`):
    /// then the front end runs [`Self::substep_toward`] instead of a fixed
    /// grid of [`Self::substep`]s.
    fn adaptive(&self) -> bool {
        false
    }
    /// Adaptive models: the estimated substeps to reach `until` seconds
    /// after the start time at the present bound (0: already there).
    fn substeps_to(&self, until: f64) -> u64 {
        let _ = until;
        0
    }
    /// Adaptive models: one substep toward `until` seconds after the start
    /// time; the last one lands on it exactly.
    fn substep_toward(&mut self, until: f64) -> Result<(), StepFailure> {
        let _ = until;
        Err(StepFailure {
            terminal: false,
            msg: "this model has fixed substeps".into(),
        })
    }
    /// Every Real output is finite.
    fn outputs_finite(&mut self) -> bool;
    /// A copy of the simulated state to go back to.
    fn checkpoint(&self) -> Checkpoint;
    /// Puts back a [`Self::checkpoint`] of this model.
    fn restore(&mut self, c: Checkpoint);
    /// The name and causality of the model's own variable `vr` (scalars of
    /// every type and the FMI 3.0 arrays; not the [`crate::model_description::COMMON_VARIABLES`],
    /// which the instance serves), `None` if it has none.
    fn variable(&self, vr: u32) -> Option<VarName>;
    /// The name of the model's own variable `vr` as a message shows it
    /// ([`shown`]).
    fn shown(&self, vr: u32) -> String {
        shown(self.variable(vr), vr)
    }
    /// Whether the Real variable `vr` reads the simulation's values (positions,
    /// velocities, energies), which need a built simulation.
    fn is_simulated_output(&self, vr: u32) -> bool;
    /// The value of the Real variable `vr`, `None` if there is none.
    fn get_real(&mut self, vr: u32) -> Option<f64>;
    /// FMI 3.0 Float64 arrays: the number of values of the array output
    /// `vr` (`None`: `vr` is not an array of this model).
    fn array_len(&self, vr: u32) -> Option<usize> {
        let _ = vr;
        None
    }
    /// Writes the array output `vr` ([`Self::array_len`] values, row-major)
    /// into `out`; false (nothing written) if `vr` is not an array of this
    /// model or `out` has another length.
    fn get_real_array(&mut self, vr: u32, out: &mut [f64]) -> bool {
        let _ = (vr, out);
        false
    }
    /// Every value of every array output is finite.
    fn arrays_finite(&self) -> bool {
        true
    }
    /// The value of the Boolean variable `vr`, `None` if there is none.
    fn get_boolean(&self, vr: u32) -> Option<bool>;
    /// The value of the String variable `vr`, `None` if there is none.
    fn get_string(&self, vr: u32) -> Option<&str>;
    /// Sets Real inputs and parameters; true when a parameter changed (the
    /// simulation must be rebuilt). A rejected call changes nothing.
    fn set_real(&mut self, set: Set<f64>) -> ModelResult<bool>;
    /// Sets Boolean inputs and parameters; true when a parameter changed.
    fn set_boolean(&mut self, set: Set<bool>) -> ModelResult<bool>;
    /// Sets String parameters (`None`: a null pointer); true when one
    /// changed.
    fn set_string(&mut self, set: Set<Option<String>>) -> ModelResult<bool>;
    /// This model's part of an FMU state (`fmi2GetFMUstate`).
    fn save(&self) -> ModelSnapshot;
    /// Puts back a [`Self::save`] of a model of this kind (`fmi2SetFMUstate`),
    /// reusing this model's simulation where the state's scene and
    /// parameters are those it was built from. A refused state changes
    /// nothing.
    fn load(&mut self, s: &ModelSnapshot) -> ModelResult;
    /// A saved state's part of a serialized FMU state; `self` (the
    /// instance's current model) may lend what the state shares with its
    /// scene.
    fn write(&self, s: &ModelSnapshot, w: &mut Writer) -> Result<(), String>;
    /// Reads what [`Self::write`] wrote into a state of this model's kind;
    /// `self` (with `built`: its simulation matches its scene and
    /// parameters) is used where the stored scene and parameters match.
    fn read(&self, r: &mut Reader, built: bool, count: usize) -> Result<ModelSnapshot, String>;
    /// A boxed copy.
    fn box_clone(&self) -> Box<dyn FmuModel>;
}

impl Clone for Box<dyn FmuModel> {
    fn clone(&self) -> Self {
        self.box_clone()
    }
}
