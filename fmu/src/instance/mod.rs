//! One FMU instance, model- and version-neutral: the time keeping, the
//! stepping and the values around a [`FmuModel`] (the yarn bundle of
//! [`crate::models::yarn`] or the mass-spring system of
//! [`crate::models::massspring`]), independent of the C ABIs
//! ([`crate::fmi2`], [`crate::fmi3`], [`crate::shell`]). Its phase and the
//! state table keyed by [`Operation`] are in [`phase`], the FMU states
//! (snapshots and their bytes) in [`snapshot`] and `fmu_state.rs`, the
//! FMI 3.0 arrays and `nValues` counts in `arrays.rs`, the clock in
//! [`clock`], the resource location in [`resources`], the logger in
//! [`logging`]; their items are re-exported here.

use std::ffi::{c_int, c_void, CString};
use std::path::PathBuf;

mod arrays;
pub mod clock;
mod fmu_state;
pub mod logging;
pub mod phase;
pub mod resources;
pub mod snapshot;
mod values;

use yarnsim::scene::Scene;

pub use crate::models::model::{
    shown, FmuModel, ModelError, ModelResult, ModelSnapshot, ParamCheck, Set, SetContext,
    StepFailure, VarName,
};
pub use crate::models::state_bytes::*;
pub use crate::models::{new_model, SceneFmu};
pub use clock::Clock;
pub use logging::*;
pub use phase::{
    error, parameter_settable, phase_name, phase_name_in, status_name, Api, Fail, Operation, Phase,
    Res, Status,
};
use resources::read_scene;
pub use resources::resource_path;
pub use snapshot::*;

use crate::model_description::{
    DEFAULT_MAX_SUBSTEPS, DEFAULT_THREADS, LOG_CATEGORIES, MAX_THREADS, SCENE_FILE,
    VR_MAX_SUBSTEPS, VR_SUBSTEPS, VR_THREADS,
};

/// The simulation and the wrapper's time keeping: what `fmi2Reset`
/// rebuilds. An FMU state holds its [`Clock`] and the model's
/// [`FmuModel::save`].
#[derive(Clone, Debug)]
pub struct Model {
    pub physics: Box<dyn FmuModel>,
    /// Time keeping and flags (what an FMU state holds besides the model).
    pub clock: Clock,
    /// The outputs were found finite and nothing changed since (no
    /// substep, no value set); not part of the serialized state.
    pub outputs_checked: bool,
}

impl Model {
    /// The time keeping and flags of an FMU state.
    pub fn clock(&self) -> Clock {
        self.clock
    }

    fn set_clock(&mut self, c: &Clock) {
        self.clock = *c;
        self.outputs_checked = false;
    }

    fn new(scene: &Scene) -> Res<Self> {
        Ok(Model {
            physics: new_model(scene)?,
            clock: Clock::START,
            outputs_checked: false,
        })
    }

    /// Rebuilds the simulation after parameter changes.
    fn ensure_built(&mut self, count: usize) -> Res {
        if self.clock.dirty {
            self.physics.rebuild(count)?;
            self.clock.dirty = false;
        }
        Ok(())
    }
}

/// The execution parameters `max_substeps_per_step` and `threads`: how an
/// instance runs, not what it simulates, so they are not part of the FMU
/// state (`fmi2SetFMUstate` keeps the instance's own); `fmi2Reset` restores
/// the defaults.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Execution {
    pub max_substeps: u32,
    pub threads: u32,
}

impl Default for Execution {
    fn default() -> Self {
        Execution {
            max_substeps: DEFAULT_MAX_SUBSTEPS,
            threads: DEFAULT_THREADS,
        }
    }
}

/// One FMU instance.
pub struct Instance {
    magic: u64,
    pub name: CString,
    logger: Option<Logger>,
    /// The FMI 3.0 logger (an [`Api::Fmi3`] instance has no FMI 2.0 one).
    logger3: Option<Logger3>,
    /// The FMI version of the front end that made the instance: the state
    /// table rows and the names in its log messages.
    pub api: Api,
    env: *mut c_void,
    logging_on: bool,
    categories: [bool; LOG_CATEGORIES.len()],
    pub resources: PathBuf,
    /// The scene bundled in `resources/`.
    bundled: Scene,
    /// Yarns or particles: the objects the outputs describe.
    count: usize,
    pub phase: Phase,
    pub model: Model,
    pub execution: Execution,
    /// The instance's own thread pool (`threads` > 0), built at
    /// `fmi2ExitInitializationMode`; `None`: rayon's global pool.
    pool: Option<(u32, rayon::ThreadPool)>,
    /// Strings handed out by `fmi2GetString`, valid until the next call.
    pub strings: Vec<CString>,
}

const INSTANCE_MAGIC: u64 = 0x5942_494e_5354_414e;

impl Instance {
    /// Creates an instance for the scene in `resources`, checking the GUID.
    /// On failure, the message to log.
    pub fn new(
        name: &str,
        guid_arg: &str,
        resource_uri: &str,
        logger: Option<Logger>,
        env: *mut c_void,
        logging_on: bool,
    ) -> Result<Box<Instance>, String> {
        let resources = resource_path(resource_uri)?;
        Self::create(
            name,
            guid_arg,
            resources,
            (Api::Fmi2, logger, None),
            env,
            logging_on,
        )
    }

    /// Creates an FMI 3.0 instance ([`Api::Fmi3`]) for the scene in the
    /// resource folder `resource_path` (an absolute path, FMI 3.0 section
    /// 2.3.1, not a URI), checking the instantiation token (the FMI 2.0
    /// FMU's GUID of the same scene).
    pub fn new_fmi3(
        name: &str,
        token: &str,
        resource_path: &str,
        logger: Option<Logger3>,
        env: *mut c_void,
        logging_on: bool,
    ) -> Result<Box<Instance>, String> {
        let resources = PathBuf::from(resource_path);
        Self::create(
            name,
            token,
            resources,
            (Api::Fmi3, None, logger),
            env,
            logging_on,
        )
    }

    fn create(
        name: &str,
        guid_arg: &str,
        resources: PathBuf,
        (api, logger, logger3): (Api, Option<Logger>, Option<Logger3>),
        env: *mut c_void,
        logging_on: bool,
    ) -> Result<Box<Instance>, String> {
        let bundled = read_scene(&resources.join(SCENE_FILE))?;
        let expected = bundled.guid();
        if guid_arg != expected {
            let what = match api {
                Api::Fmi2 => "GUID",
                Api::Fmi3 => "instantiationToken",
            };
            return Err(format!(
                "{what} {guid_arg:?} does not match this FMU's {expected:?} (modelDescription.xml and binary/resources differ)"
            ));
        }
        let model = Model::new(&bundled).map_err(|f| f.msg)?;
        let count = model.physics.count();
        let inst = Box::new(Instance {
            magic: INSTANCE_MAGIC,
            // The instance name is an argument, not the format: no escaping.
            name: escape_nul(name),
            logger,
            logger3,
            api,
            env,
            logging_on,
            categories: [true; LOG_CATEGORIES.len()],
            resources,
            bundled,
            count,
            phase: Phase::Instantiated,
            model,
            execution: Execution::default(),
            pool: None,
            strings: Vec::new(),
        });
        inst.log(
            Status::Ok,
            LOG_EVENTS,
            &format!(
                "instantiated {name:?} ({}): scene {:?}, {count} {}, substep {} s",
                inst.bundled.identifier(),
                inst.bundled.name(),
                inst.bundled.objects(),
                inst.model.physics.dt()
            ),
        );
        Ok(inst)
    }

    /// Validates a component pointer handed back by the environment.
    ///
    /// # Safety
    /// `p` must be null or a pointer this FMU returned and has not freed.
    pub unsafe fn from_ptr<'a>(p: *mut c_void) -> Option<&'a mut Instance> {
        // SAFETY: null, or a live `Instance` this FMU handed out (the caller's
        // contract); the magic number below rejects most foreign pointers.
        let s = unsafe { (p as *mut Instance).as_mut() }?;
        (s.magic == INSTANCE_MAGIC).then_some(s)
    }

    /// Marks the instance freed (the memory is released right after).
    pub fn invalidate(&mut self) {
        self.magic = 0;
    }

    /// Yarns (YarnBundle) or particles (MassSpring): the objects the outputs describe.
    pub fn count(&self) -> usize {
        self.count
    }

    /// Sends a message to the logger: warnings, discards, errors and fatal
    /// errors always, other messages when logging is on for their category.
    pub fn log(&self, status: Status, category: usize, msg: &str) {
        if !self.has_logger() {
            return;
        }
        let always = matches!(
            status,
            Status::Warning | Status::Error | Status::Fatal | Status::Discard
        );
        if !(always || (self.logging_on && self.categories[category])) {
            return;
        }
        let cat = CString::new(LOG_CATEGORIES[category].0).expect("no NUL");
        if let Some(logger) = self.logger3 {
            let text = escape_nul(msg);
            // SAFETY: the environment's fmi3LogMessageCallback, called with
            // its instance environment and NUL-terminated strings.
            unsafe { logger(self.env, status as c_int, cat.as_ptr(), text.as_ptr()) };
            return;
        }
        let Some(logger) = self.logger else { return };
        let text = escape_log(msg);
        // SAFETY: the logger comes from the environment's callback struct;
        // the message is pre-formatted and escaped, so no varargs are read.
        unsafe {
            logger(
                self.env,
                self.name.as_ptr(),
                status as c_int,
                cat.as_ptr(),
                text.as_ptr(),
            )
        }
    }

    fn has_logger(&self) -> bool {
        self.logger.is_some() || self.logger3.is_some()
    }

    /// Whether `logAll` messages would be shown (to skip formatting them).
    pub fn log_all(&self) -> bool {
        self.has_logger() && self.logging_on && self.categories[LOG_ALL]
    }

    /// The name and causality of any variable of the instance: the model's,
    /// the common ones ([`crate::model_description::COMMON_VARIABLES`]) and, for FMI
    /// 3.0, `time`.
    pub fn variable(&self, vr: u32) -> Option<VarName> {
        if let Some((name, causality)) = crate::model_description::common_name(vr) {
            return Some(VarName::new(name, causality));
        }
        if self.api == Api::Fmi3 && vr == crate::model_description::VR_TIME {
            return Some(VarName::new("time", "independent"));
        }
        self.model.physics.variable(vr)
    }

    /// `vr` as a message shows it: `attractor.active (value reference 4)`,
    /// or `value reference 99` where no variable has it.
    pub fn shown(&self, vr: u32) -> String {
        shown(self.variable(vr), vr)
    }

    /// The name of `vr` alone (`value reference 99` where no variable has it).
    pub fn name_of(&self, vr: u32) -> String {
        self.variable(vr)
            .map_or_else(|| format!("value reference {vr}"), |v| v.name)
    }

    /// Fails unless the state table allows `op` in the current phase when
    /// the instance's FMI version calls it ([`Operation::allowed`]).
    pub fn require(&self, op: Operation) -> Res {
        phase::require(self.phase, self.api, op)
    }

    /// The name of the function that calls `op` in the instance's FMI
    /// version (`fmi2GetReal`, `fmi3GetFloat64`): what its messages say.
    pub fn op_name(&self, op: Operation) -> &'static str {
        op.name(self.api)
    }

    pub fn set_debug_logging(&mut self, on: bool, cats: &[&str]) -> Res {
        self.require(Operation::SetDebugLogging)?;
        let mut idx = Vec::new();
        for c in cats {
            match LOG_CATEGORIES.iter().position(|(n, _)| n == c) {
                Some(i) => idx.push(i),
                None => return error(format!("unknown log category {c:?}")),
            }
        }
        self.logging_on = on || self.logging_on;
        if idx.is_empty() {
            self.categories = [on; LOG_CATEGORIES.len()];
            self.logging_on = on;
        } else {
            for i in idx {
                self.categories[i] = on;
            }
        }
        Ok(())
    }

    pub fn setup_experiment(&mut self, start: f64, stop: Option<f64>) -> Res {
        self.require(Operation::SetupExperiment)?;
        if !start.is_finite() || start.abs() > 1e12 {
            return error(format!("start time {start} must be finite"));
        }
        if let Some(s) = stop {
            if !(s.is_finite() && s >= start) {
                return error(format!(
                    "stop time {s} must be finite and not before the start time {start}"
                ));
            }
        }
        let m = &mut self.model;
        m.clock.start_time = start;
        m.clock.stop_time = stop;
        m.clock.time = start;
        m.clock.last_successful_time = start;
        Ok(())
    }

    pub fn enter_initialization_mode(&mut self) -> Res {
        self.require(Operation::EnterInitializationMode)?;
        self.phase = Phase::InitializationMode;
        self.log(Status::Ok, LOG_EVENTS, "entered initialization mode");
        Ok(())
    }

    pub fn exit_initialization_mode(&mut self) -> Res<Status> {
        self.require(Operation::ExitInitializationMode)?;
        let threads = self.execution.threads;
        if threads == 0 {
            self.pool = None;
        } else if self.pool.as_ref().map(|p| p.0) != Some(threads) {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads as usize)
                .thread_name(|i| format!("yarnsim-fmu-{i}"))
                .build()
                .or_else(|e| error(format!("cannot start a pool of {threads} threads: {e}")))?;
            self.pool = Some((threads, pool));
        }
        let m = &mut self.model;
        match &self.pool {
            Some((_, pool)) => pool.install(|| m.ensure_built(self.count))?,
            None => m.ensure_built(self.count)?,
        }
        let m = &mut self.model;
        m.clock.time = m.clock.start_time;
        m.clock.last_successful_time = m.clock.start_time;
        m.clock.substeps = 0;
        m.clock.terminated = false;
        self.phase = Phase::StepComplete;
        self.log(
            Status::Ok,
            LOG_EVENTS,
            &format!(
                "initialized at t = {}: {} {}, substep {} s",
                self.model.clock.time,
                self.count,
                self.bundled.objects(),
                self.model.physics.dt()
            ),
        );
        let warnings = self.model.physics.warnings();
        for w in &warnings {
            self.log(
                Status::Warning,
                LOG_WARNING,
                &format!("{}: {w}", self.op_name(Operation::ExitInitializationMode)),
            );
        }
        let dt = self.model.physics.dt();
        if let Some(bound) = self.model.physics.stable_dt().filter(|&b| dt > b) {
            self.log(
                Status::Warning,
                LOG_WARNING,
                &format!(
                    "{}: substep dt = {dt} s exceeds the stability bound {bound:.6e} s of this {} model; the run may diverge ({} then returns {})",
                    self.op_name(Operation::ExitInitializationMode),
                    self.bundled.identifier(),
                    self.op_name(Operation::DoStep),
                    status_name(self.api, Status::Discard)
                ),
            );
            return Ok(Status::Warning);
        }
        Ok(if warnings.is_empty() {
            Status::Ok
        } else {
            Status::Warning
        })
    }

    pub fn terminate(&mut self) -> Res {
        self.require(Operation::Terminate)?;
        self.phase = Phase::Terminated;
        self.log(Status::Ok, LOG_EVENTS, "terminated");
        Ok(())
    }

    pub fn reset(&mut self) -> Res {
        self.require(Operation::Reset)?;
        self.model = Model::new(&self.bundled)?;
        self.execution = Execution::default();
        self.phase = Phase::Instantiated;
        self.log(Status::Ok, LOG_EVENTS, "reset to the instantiated state");
        Ok(())
    }

    /// One communication step from `t` to `t + h`.
    pub fn do_step(&mut self, t: f64, h: f64) -> Res<Status> {
        self.require(Operation::DoStep)?;
        let m = &mut self.model;
        if !(t.is_finite() && h.is_finite()) {
            return error(format!(
                "communication point {t} and step size {h} must be finite"
            ));
        }
        if h <= 0.0 {
            return error(format!("communication step size h = {h} must be > 0"));
        }
        let tol = 1e-9 * m.clock.time.abs().max(t.abs()).max(h);
        if (t - m.clock.time).abs() > tol {
            return error(format!(
                "communication point {t} does not match the FMU's time {} (tolerance {tol:e})",
                m.clock.time
            ));
        }
        let end = t + h;
        if let Some(stop) = m.clock.stop_time {
            if end > stop + 1e-9 * stop.abs().max(h) {
                return error(format!(
                    "step from {t} by {h} ends past the stop time {stop}"
                ));
            }
        }
        // Fixed substeps: the substep count is an integer grid from the
        // start time, so the substeps done by a given time do not depend on
        // how the master partitions its interval. Adaptive substeps
        // (`dt = "auto"`): the model steps to the communication point on its
        // own clock (seconds since the start time), landing on it exactly;
        // `needed` is then the estimate at the present stability bound.
        let budget = self.execution.max_substeps;
        let until = end - m.clock.start_time;
        let dt = m.physics.dt();
        let (target, needed) = if m.physics.adaptive() {
            (None, m.physics.substeps_to(until))
        } else {
            let target = ((end - m.clock.start_time) / dt).round();
            if !(0.0..9.0e15).contains(&target) {
                return error(format!("step to {end} needs {target} substeps of {dt} s"));
            }
            let target = target as u64;
            (Some(target), target.saturating_sub(m.clock.substeps))
        };
        if needed > budget as u64 {
            let (about, of) = match target {
                Some(_) => ("", format!("of {dt} s")),
                None => ("about ", format!("(adaptive, now {dt:.3e} s each)")),
            };
            return error(format!(
                "step from t = {t} by {h} needs {about}{needed} substeps {of}, more than max_substeps_per_step = {budget}; no substep was run (take shorter communication steps or raise the parameter)"
            ));
        }
        // The last good state: the one at the start of this communication
        // step (time t = lastSuccessfulTime). A failed step puts it back, so
        // the outputs stay readable after a Discard (one checkpoint per step
        // that runs substeps; measured in the README).
        let start_substeps = m.clock.substeps;
        let mut last_good = (needed > 0).then(|| m.physics.checkpoint());
        let mut restore = |m: &mut Model| {
            if let Some(c) = last_good.take() {
                m.physics.restore(c);
                m.clock.substeps = start_substeps;
            }
        };
        let since_start = t - m.clock.start_time;
        // Ok(false): an adaptive step ran out of its budget of substeps.
        let run = |m: &mut Model| -> Result<bool, StepFailure> {
            if needed > 0 {
                m.physics.begin_step(since_start)?;
            }
            match target {
                Some(target) => {
                    while m.clock.substeps < target {
                        m.physics.substep(m.clock.substeps)?;
                        m.clock.substeps += 1;
                    }
                }
                None => {
                    while m.physics.substeps_to(until) > 0 {
                        if m.clock.substeps - start_substeps >= budget as u64 {
                            return Ok(false);
                        }
                        m.physics.substep_toward(until)?;
                        m.clock.substeps += 1;
                    }
                }
            }
            Ok(true)
        };
        let ran = match &self.pool {
            // no substep to run: no hand-over to a pool either (it costs
            // microseconds, the call itself nanoseconds)
            _ if needed == 0 => run(m),
            Some((_, pool)) => pool.install(|| run(m)),
            // the global pool: the whole step on one of its workers, not
            // one hand-over per substep (see yarnsim::pool)
            None => yarnsim::pool::on_pool(|| run(m)),
        };
        if let Ok(false) = ran {
            restore(m);
            m.outputs_checked = false;
            return error(format!(
                "step from t = {t} by {h} needed more than max_substeps_per_step = {budget} adaptive substeps (the stability bound fell as the yarn sped up); the step was undone (take shorter communication steps or raise the parameter)"
            ));
        }
        if let Err(e) = ran {
            m.clock.terminated = true;
            restore(m);
            self.phase = Phase::StepFailed;
            let msg = if e.terminal {
                format!(
                    "step from t = {t} by {h} failed: {}; the simulation is terminated (restore a state or reset; the outputs are those of t = {t})",
                    e.msg
                )
            } else {
                format!("step from t = {t} by {h} failed: {}", e.msg)
            };
            return Err(Fail {
                status: Status::Discard,
                msg,
            });
        }
        // The libraries report divergence themselves; the outputs are
        // checked too, so a step never ends OK with a non-finite output.
        // Unchanged since the last check (no substep ran, no value was set):
        // nothing to check again.
        if m.clock.substeps > start_substeps {
            m.outputs_checked = false;
        }
        // The FMI 3.0 FMU's arrays (every vertex) are outputs too.
        let arrays = self.api == Api::Fmi3;
        if !m.outputs_checked
            && (!m.physics.outputs_finite() || (arrays && !m.physics.arrays_finite()))
        {
            m.clock.terminated = true;
            restore(m);
            self.phase = Phase::StepFailed;
            return Err(Fail {
                status: Status::Discard,
                msg: format!(
                    "step from t = {t} by {h} left non-finite outputs; the simulation is terminated (restore a state or reset; the outputs are those of t = {t})"
                ),
            });
        }
        m.outputs_checked = true;
        m.clock.time = end;
        m.clock.last_successful_time = end;
        Ok(Status::Ok)
    }

    pub fn last_successful_time(&self) -> f64 {
        self.model.clock.last_successful_time
    }

    pub fn terminated(&self) -> bool {
        self.model.clock.terminated
    }
}
