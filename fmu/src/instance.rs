//! One FMU instance: the FMI 2.0 Co-Simulation state machine, the time
//! keeping and the FMU-state snapshots around a [`Physics`] (the yarn bundle
//! of [`crate::yarn`] or the mass-spring system of [`crate::massspring`]),
//! independent of the C ABI (which lives in [`crate::ffi`]).

use std::ffi::{c_char, c_int, c_void, CString};
use std::path::{Path, PathBuf};

use yarnsim::mpm::state::fnv1a;

use crate::massspring::MsModel;
use crate::model::{
    FmuScene, DEFAULT_MAX_SUBSTEPS, DEFAULT_THREADS, LOG_CATEGORIES, MAX_THREADS, SCENE_FILE,
    VR_MAX_SUBSTEPS, VR_SUBSTEPS, VR_THREADS,
};
use crate::yarn::YarnModel;

/// `fmi2Status` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
#[repr(i32)]
pub enum Status {
    Ok = 0,
    Warning = 1,
    Discard = 2,
    Error = 3,
    Fatal = 4,
    Pending = 5,
}

/// A failed call: its status (Discard, Error or Fatal) and the message logged.
#[derive(Clone, Debug, PartialEq)]
pub struct Fail {
    pub status: Status,
    pub msg: String,
}

pub type Res<T = ()> = Result<T, Fail>;

pub fn error<T>(msg: impl Into<String>) -> Res<T> {
    Err(Fail {
        status: Status::Error,
        msg: msg.into(),
    })
}

/// The states of the FMI 2.0 Co-Simulation state machine this FMU can be in
/// (no asynchronous steps, so never stepInProgress or stepCanceled).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    Instantiated,
    InitializationMode,
    StepComplete,
    StepFailed,
    Terminated,
    Error,
    Fatal,
}

/// Every phase but `Fatal`: where the functions that an error must not lock
/// out are allowed (debug logging, reset, the FMU-state functions).
const NOT_FATAL: &[Phase] = &[
    Phase::Instantiated,
    Phase::InitializationMode,
    Phase::StepComplete,
    Phase::StepFailed,
    Phase::Terminated,
    Phase::Error,
];

/// Every phase with a consistent simulation (not `Error`, not `Fatal`).
const LIVE: &[Phase] = &[
    Phase::Instantiated,
    Phase::InitializationMode,
    Phase::StepComplete,
    Phase::StepFailed,
    Phase::Terminated,
];

impl Phase {
    fn code(self) -> u8 {
        self as u8
    }
    fn from_code(c: u8) -> Option<Phase> {
        use Phase::*;
        [
            Instantiated,
            InitializationMode,
            StepComplete,
            StepFailed,
            Terminated,
            Error,
            Fatal,
        ]
        .get(c as usize)
        .copied()
    }
}

/// The logger callback: `(componentEnvironment, instanceName, status, category, message, ...)`.
pub type Logger =
    unsafe extern "C" fn(*mut c_void, *const c_char, c_int, *const c_char, *const c_char, ...);

/// Log category indices into [`LOG_CATEGORIES`].
pub const LOG_EVENTS: usize = 0;
pub const LOG_WARNING: usize = 1;
pub const LOG_DISCARD: usize = 2;
pub const LOG_ERROR: usize = 3;
pub const LOG_FATAL: usize = 4;
pub const LOG_ALL: usize = 6;

/// Checks that a parameter may be set now: `(function, value reference)`.
pub type ParamCheck<'a> = &'a dyn Fn(&str, u32) -> Res;

/// A substep that failed: the message, and whether the simulation is lost
/// (non-finite state) rather than refused an input.
#[derive(Clone, Debug, PartialEq)]
pub struct StepFailure {
    pub terminal: bool,
    pub msg: String,
}

/// What an FMU simulates: the same state machine drives either model.
#[derive(Clone, Debug)]
pub enum Physics {
    Yarn(Box<YarnModel>),
    MassSpring(Box<MsModel>),
}

/// Calls the same method on either model.
macro_rules! each {
    ($p:expr, $m:ident => $e:expr) => {
        match $p {
            Physics::Yarn($m) => $e,
            Physics::MassSpring($m) => $e,
        }
    };
}

impl Physics {
    fn new(scene: &FmuScene) -> Res<Physics> {
        Ok(match scene {
            FmuScene::Yarn(s) => Physics::Yarn(Box::new(YarnModel::new(s.clone())?)),
            FmuScene::MassSpring(l) => Physics::MassSpring(Box::new(MsModel::new(l.clone())?)),
        })
    }

    /// Yarns or particles: the objects the outputs describe.
    pub fn count(&self) -> usize {
        each!(self, m => m.count())
    }

    /// The substep size in s.
    pub fn dt(&self) -> f64 {
        each!(self, m => m.dt())
    }

    fn rebuild(&mut self, count: usize) -> Res {
        each!(self, m => m.rebuild(count))
    }

    /// Substep number `k` since initialization.
    fn substep(&mut self, k: u64) -> Result<(), StepFailure> {
        match self {
            Physics::Yarn(m) => m.substep(),
            Physics::MassSpring(m) => m.substep(k),
        }
    }

    /// What a failed communication step goes back to: the yarn
    /// simulation's own state bytes (a clone of the whole `YarnSim` with its
    /// grid costs far more than its particles), the whole mass-spring model
    /// (a clone is cheaper than its serialization).
    fn checkpoint(&self) -> Checkpoint {
        match self {
            Physics::Yarn(m) => Checkpoint::Yarn(m.sim.save_state()),
            Physics::MassSpring(m) => Checkpoint::MassSpring(m.clone()),
        }
    }

    /// Puts back a [`Self::checkpoint`] of this model.
    fn restore(&mut self, c: Checkpoint) {
        match (self, c) {
            (Physics::Yarn(m), Checkpoint::Yarn(bytes)) => {
                m.sim
                    .load_state(&bytes)
                    .expect("the simulation's own state bytes load");
                m.diag = None;
            }
            (Physics::MassSpring(m), Checkpoint::MassSpring(c)) => *m = c,
            _ => unreachable!("a checkpoint of the other model"),
        }
    }

    /// The model's stability bound on the substep in s (`None`: none).
    fn stable_dt(&self) -> Option<f64> {
        match self {
            Physics::Yarn(m) => Some(m.sim.stable_dt()),
            Physics::MassSpring(m) => m.sim.stable_dt(),
        }
    }

    fn outputs_finite(&mut self) -> bool {
        each!(self, m => m.outputs_finite())
    }

    fn is_state_output(&self, vr: u32) -> bool {
        each!(self, m => m.is_state_output(vr))
    }

    fn get_real(&mut self, vr: u32) -> Option<f64> {
        each!(self, m => m.get_real(vr))
    }

    fn get_boolean(&self, vr: u32) -> Option<c_int> {
        each!(self, m => m.get_boolean(vr))
    }

    fn get_string(&self, vr: u32) -> Option<&str> {
        each!(self, m => m.get_string(vr))
    }

    /// First bytes of a serialized FMU state of this model.
    fn state_magic(&self) -> &'static [u8; 8] {
        match self {
            Physics::Yarn(_) => YARN_STATE_MAGIC,
            Physics::MassSpring(_) => MASS_SPRING_STATE_MAGIC,
        }
    }
}

/// The last good state of a communication step ([`Physics::checkpoint`]).
enum Checkpoint {
    Yarn(Vec<u8>),
    MassSpring(Box<MsModel>),
}

/// Everything an FMU state holds: what `fmi2GetFMUstate` copies and
/// `fmi2Reset` rebuilds.
#[derive(Clone, Debug)]
pub struct Model {
    pub physics: Physics,
    /// The simulation must be rebuilt from the scene and the parameters
    /// before use (a parameter changed).
    pub dirty: bool,
    pub start_time: f64,
    pub stop_time: Option<f64>,
    /// Current communication point.
    pub time: f64,
    pub last_successful_time: f64,
    /// Substeps taken since initialization.
    pub substeps: u64,
    /// Set when a step diverged (`fmi2Terminated` status).
    pub terminated: bool,
    /// The outputs were found finite and nothing changed since (no
    /// substep, no value set); not part of the serialized state.
    pub outputs_checked: bool,
}

impl Model {
    fn new(scene: &FmuScene) -> Res<Self> {
        Ok(Model {
            physics: Physics::new(scene)?,
            dirty: false,
            start_time: 0.0,
            stop_time: None,
            time: 0.0,
            last_successful_time: 0.0,
            substeps: 0,
            terminated: false,
            outputs_checked: false,
        })
    }

    /// Rebuilds the simulation after parameter changes.
    fn ensure_built(&mut self, count: usize) -> Res {
        if self.dirty {
            self.physics.rebuild(count)?;
            self.dirty = false;
        }
        Ok(())
    }
}

/// A saved FMU state (`fmi2FMUstate`).
pub struct Snapshot {
    magic: u64,
    phase: Phase,
    model: Model,
    /// Serialized form, made on first request.
    bytes: Option<Vec<u8>>,
}

const SNAPSHOT_MAGIC: u64 = 0x5942_534e_4150_5348;

impl Snapshot {
    /// Validates a pointer handed back by the environment.
    ///
    /// # Safety
    /// `p` must be null or a pointer this FMU returned and has not freed.
    pub unsafe fn from_ptr<'a>(p: *mut c_void) -> Option<&'a mut Snapshot> {
        // SAFETY: null, or a live `Snapshot` this FMU handed out (the caller's
        // contract); the magic number below rejects most foreign pointers.
        let s = unsafe { (p as *mut Snapshot).as_mut() }?;
        (s.magic == SNAPSHOT_MAGIC).then_some(s)
    }
}

impl Drop for Snapshot {
    fn drop(&mut self) {
        self.magic = 0;
    }
}

/// First bytes of a serialized FMU state of a yarn bundle.
pub const YARN_STATE_MAGIC: &[u8; 8] = b"YBFMUST\0";
/// First bytes of a serialized FMU state of a mass-spring system.
pub const MASS_SPRING_STATE_MAGIC: &[u8; 8] = b"MSFMUST\0";
/// Every state magic this library writes.
pub const STATE_MAGICS: [&[u8; 8]; 2] = [YARN_STATE_MAGIC, MASS_SPRING_STATE_MAGIC];
/// Format version of the serialized FMU state.
pub const STATE_VERSION: u32 = 1;
const STATE_HEADER: usize = 8 + 4 + 8 + 8;

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
    env: *mut c_void,
    logging_on: bool,
    categories: [bool; LOG_CATEGORIES.len()],
    pub resources: PathBuf,
    /// The scene bundled in `resources/`.
    bundled: FmuScene,
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

fn read_scene(path: &Path) -> Result<FmuScene, String> {
    let text = crate::model::read_scene_text(path)?;
    FmuScene::from_toml_str(&text).map_err(|e| format!("scene file {}: {e}", path.display()))
}

/// Escapes a message for the printf-style logger: `%` as `%%`, `#` as `##`
/// (FMI variable references), and drops NUL bytes.
pub fn escape_log(msg: &str) -> CString {
    let mut s = String::with_capacity(msg.len() + 8);
    for c in msg.chars() {
        match c {
            '%' => s.push_str("%%"),
            '#' => s.push_str("##"),
            '\0' => {}
            c => s.push(c),
        }
    }
    CString::new(s).expect("NUL bytes removed")
}

fn phase_name(p: Phase) -> &'static str {
    match p {
        Phase::Instantiated => "instantiated",
        Phase::InitializationMode => "initialization mode",
        Phase::StepComplete => "step complete",
        Phase::StepFailed => "step failed",
        Phase::Terminated => "terminated",
        Phase::Error => "error",
        Phase::Fatal => "fatal",
    }
}

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
        let bundled = read_scene(&resources.join(SCENE_FILE))?;
        let expected = bundled.guid();
        if guid_arg != expected {
            return Err(format!(
                "GUID {guid_arg:?} does not match this FMU's {expected:?} (modelDescription.xml and binary/resources differ)"
            ));
        }
        let model = Model::new(&bundled).map_err(|f| f.msg)?;
        let count = model.physics.count();
        let inst = Box::new(Instance {
            magic: INSTANCE_MAGIC,
            // The instance name is an argument, not the format: no escaping.
            name: escape_nul(name),
            logger,
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
        let Some(logger) = self.logger else { return };
        let always = matches!(
            status,
            Status::Warning | Status::Error | Status::Fatal | Status::Discard
        );
        if !(always || (self.logging_on && self.categories[category])) {
            return;
        }
        let cat = CString::new(LOG_CATEGORIES[category].0).expect("no NUL");
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

    /// Whether `logAll` messages would be shown (to skip formatting them).
    pub fn log_all(&self) -> bool {
        self.logger.is_some() && self.logging_on && self.categories[LOG_ALL]
    }

    /// Fails unless the instance is in one of `allowed`.
    pub fn require(&self, func: &str, allowed: &[Phase]) -> Res {
        if allowed.contains(&self.phase) {
            Ok(())
        } else {
            error(format!(
                "{func} is not allowed in state {:?}",
                phase_name(self.phase)
            ))
        }
    }

    pub fn set_debug_logging(&mut self, on: bool, cats: &[&str]) -> Res {
        self.require("fmi2SetDebugLogging", NOT_FATAL)?;
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
        self.require("fmi2SetupExperiment", &[Phase::Instantiated])?;
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
        m.start_time = start;
        m.stop_time = stop;
        m.time = start;
        m.last_successful_time = start;
        Ok(())
    }

    pub fn enter_initialization_mode(&mut self) -> Res {
        self.require("fmi2EnterInitializationMode", &[Phase::Instantiated])?;
        self.phase = Phase::InitializationMode;
        self.log(Status::Ok, LOG_EVENTS, "entered initialization mode");
        Ok(())
    }

    pub fn exit_initialization_mode(&mut self) -> Res<Status> {
        self.require("fmi2ExitInitializationMode", &[Phase::InitializationMode])?;
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
        m.time = m.start_time;
        m.last_successful_time = m.start_time;
        m.substeps = 0;
        m.terminated = false;
        self.phase = Phase::StepComplete;
        self.log(
            Status::Ok,
            LOG_EVENTS,
            &format!(
                "initialized at t = {}: {} {}, substep {} s",
                self.model.time,
                self.count,
                self.bundled.objects(),
                self.model.physics.dt()
            ),
        );
        let dt = self.model.physics.dt();
        if let Some(bound) = self.model.physics.stable_dt().filter(|&b| dt > b) {
            self.log(
                Status::Warning,
                LOG_WARNING,
                &format!(
                    "fmi2ExitInitializationMode: substep dt = {dt} s exceeds the stability bound {bound:.6e} s of this {} model; the run may diverge (fmi2DoStep then returns fmi2Discard)",
                    self.bundled.identifier()
                ),
            );
            return Ok(Status::Warning);
        }
        Ok(Status::Ok)
    }

    pub fn terminate(&mut self) -> Res {
        self.require("fmi2Terminate", &[Phase::StepComplete, Phase::StepFailed])?;
        self.phase = Phase::Terminated;
        self.log(Status::Ok, LOG_EVENTS, "terminated");
        Ok(())
    }

    pub fn reset(&mut self) -> Res {
        self.require("fmi2Reset", NOT_FATAL)?;
        self.model = Model::new(&self.bundled)?;
        self.execution = Execution::default();
        self.phase = Phase::Instantiated;
        self.log(Status::Ok, LOG_EVENTS, "reset to the instantiated state");
        Ok(())
    }

    /// One communication step from `t` to `t + h`.
    pub fn do_step(&mut self, t: f64, h: f64) -> Res<Status> {
        self.require("fmi2DoStep", &[Phase::StepComplete])?;
        let m = &mut self.model;
        if !(t.is_finite() && h.is_finite()) {
            return error(format!(
                "communication point {t} and step size {h} must be finite"
            ));
        }
        if h <= 0.0 {
            return error(format!("communication step size h = {h} must be > 0"));
        }
        let tol = 1e-9 * m.time.abs().max(t.abs()).max(h);
        if (t - m.time).abs() > tol {
            return error(format!(
                "communication point {t} does not match the FMU's time {} (tolerance {tol:e})",
                m.time
            ));
        }
        let end = t + h;
        if let Some(stop) = m.stop_time {
            if end > stop + 1e-9 * stop.abs().max(h) {
                return error(format!(
                    "step from {t} by {h} ends past the stop time {stop}"
                ));
            }
        }
        // The substep count is an integer grid from the start time: the
        // substeps done by a given time do not depend on how the master
        // partitions its interval.
        let dt = m.physics.dt();
        let target = ((end - m.start_time) / dt).round();
        if !(0.0..9.0e15).contains(&target) {
            return error(format!("step to {end} needs {target} substeps of {dt} s"));
        }
        let target = target as u64;
        let needed = target.saturating_sub(m.substeps);
        let budget = self.execution.max_substeps;
        if needed > budget as u64 {
            return error(format!(
                "step from t = {t} by {h} needs {needed} substeps of {dt} s, more than max_substeps_per_step = {budget}; no substep was run (take shorter communication steps or raise the parameter)"
            ));
        }
        // The last good state: the one at the start of this communication
        // step (time t = lastSuccessfulTime). A failed step puts it back, so
        // the outputs stay readable after a Discard (one checkpoint per step
        // that runs substeps; measured in the README).
        let start_substeps = m.substeps;
        let mut last_good = (m.substeps < target).then(|| m.physics.checkpoint());
        let mut restore = |m: &mut Model| {
            if let Some(c) = last_good.take() {
                m.physics.restore(c);
                m.substeps = start_substeps;
            }
        };
        let run = |m: &mut Model| -> Result<(), StepFailure> {
            while m.substeps < target {
                m.physics.substep(m.substeps)?;
                m.substeps += 1;
            }
            Ok(())
        };
        let ran = match &self.pool {
            Some((_, pool)) => pool.install(|| run(m)),
            None => run(m),
        };
        if let Err(e) = ran {
            m.terminated = true;
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
        if m.substeps > start_substeps {
            m.outputs_checked = false;
        }
        if !m.outputs_checked && !m.physics.outputs_finite() {
            m.terminated = true;
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
        m.time = end;
        m.last_successful_time = end;
        Ok(Status::Ok)
    }

    fn require_get(&self, func: &str) -> Res {
        use Phase::*;
        self.require(
            func,
            &[InitializationMode, StepComplete, StepFailed, Terminated],
        )
    }

    /// Values that depend on the simulated state need a built simulation.
    /// After a diverged step they are those of the last good state (at
    /// `lastSuccessfulTime`), which the failed step restored.
    fn require_state(&mut self) -> Res {
        self.model.ensure_built(self.count)
    }

    pub fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> Res {
        self.require_get("fmi2GetReal")?;
        for (k, &vr) in vrs.iter().enumerate() {
            if self.model.physics.is_state_output(vr) {
                self.require_state()?;
            }
            let Some(v) = self.model.physics.get_real(vr) else {
                return error(format!(
                    "fmi2GetReal: no Real variable has value reference {vr}"
                ));
            };
            if !v.is_finite() {
                return error(format!(
                    "fmi2GetReal: value reference {vr} is not finite ({v}) at t = {}",
                    self.model.time
                ));
            }
            out[k] = v;
        }
        Ok(())
    }

    pub fn get_integer(&mut self, vrs: &[u32], out: &mut [c_int]) -> Res {
        self.require_get("fmi2GetInteger")?;
        for (k, &vr) in vrs.iter().enumerate() {
            out[k] = match vr {
                // Saturates instead of wrapping past 2^31 - 1 substeps.
                VR_SUBSTEPS => self.model.substeps.min(c_int::MAX as u64) as c_int,
                VR_MAX_SUBSTEPS => self.execution.max_substeps as c_int,
                VR_THREADS => self.execution.threads as c_int,
                _ => {
                    return error(format!(
                        "fmi2GetInteger: no Integer variable has value reference {vr}"
                    ))
                }
            };
        }
        Ok(())
    }

    pub fn get_boolean(&mut self, vrs: &[u32], out: &mut [c_int]) -> Res {
        self.require_get("fmi2GetBoolean")?;
        for (k, &vr) in vrs.iter().enumerate() {
            let Some(v) = self.model.physics.get_boolean(vr) else {
                return error(format!(
                    "fmi2GetBoolean: no Boolean variable has value reference {vr}"
                ));
            };
            out[k] = v;
        }
        Ok(())
    }

    /// Returns the strings; they stay valid until the next call.
    pub fn get_string(&mut self, vrs: &[u32]) -> Res<&[CString]> {
        self.require_get("fmi2GetString")?;
        self.strings.clear();
        for &vr in vrs {
            let Some(v) = self.model.physics.get_string(vr) else {
                return error(format!(
                    "fmi2GetString: no String variable has value reference {vr}"
                ));
            };
            self.strings.push(escape_nul(v));
        }
        Ok(&self.strings)
    }

    fn require_set_input(&self, func: &str) -> Res {
        use Phase::*;
        self.require(func, &[Instantiated, InitializationMode, StepComplete])
    }

    /// Runs one of the model's setters where inputs may be set; it may set
    /// parameters only while [`parameter_settable`], and a changed parameter
    /// marks the simulation for rebuilding.
    fn set_values(
        &mut self,
        func: &str,
        set: impl FnOnce(&mut Physics, ParamCheck, &Path, &FmuScene) -> Res<bool>,
    ) -> Res {
        self.require_set_input(func)?;
        let phase = self.phase;
        let check = |func: &str, vr: u32| parameter_settable(phase, func, vr);
        let changed = set(
            &mut self.model.physics,
            &check,
            &self.resources,
            &self.bundled,
        )?;
        self.model.dirty |= changed;
        self.model.outputs_checked = false;
        Ok(())
    }

    pub fn set_real(&mut self, vrs: &[u32], vals: &[f64]) -> Res {
        self.set_values("fmi2SetReal", |physics, check, _, _| {
            if let Some((vr, v)) = vrs.iter().zip(vals).find(|(_, v)| !v.is_finite()) {
                return error(format!(
                    "fmi2SetReal: value {v} for value reference {vr} is not finite"
                ));
            }
            each!(physics, m => m.set_real(vrs, vals, check))
        })
    }

    /// Sets the execution parameters `max_substeps_per_step` and `threads`
    /// (fixed: only before `fmi2ExitInitializationMode`). A rejected call
    /// changes nothing.
    pub fn set_integer(&mut self, vrs: &[u32], vals: &[c_int]) -> Res {
        self.require_set_input("fmi2SetInteger")?;
        let mut e = self.execution;
        for (&vr, &v) in vrs.iter().zip(vals) {
            match vr {
                VR_MAX_SUBSTEPS | VR_THREADS => {
                    parameter_settable(self.phase, "fmi2SetInteger", vr)?
                }
                _ => {
                    return error(format!(
                        "fmi2SetInteger: value reference {vr} is not an Integer input or parameter"
                    ))
                }
            }
            if vr == VR_MAX_SUBSTEPS {
                if v < 1 {
                    return error(format!(
                        "fmi2SetInteger: max_substeps_per_step = {v} must be at least 1"
                    ));
                }
                e.max_substeps = v as u32;
            } else {
                if !(0..=MAX_THREADS as c_int).contains(&v) {
                    return error(format!(
                        "fmi2SetInteger: threads = {v} must be 0 (all cores) to {MAX_THREADS}"
                    ));
                }
                e.threads = v as u32;
            }
        }
        self.execution = e;
        Ok(())
    }

    pub fn set_boolean(&mut self, vrs: &[u32], vals: &[c_int]) -> Res {
        self.set_values(
            "fmi2SetBoolean",
            |physics, check, _, _| each!(physics, m => m.set_boolean(vrs, vals, check)),
        )
    }

    pub fn set_string(&mut self, vrs: &[u32], vals: &[Option<String>]) -> Res {
        self.set_values(
            "fmi2SetString",
            |physics, check, resources, bundled| match (physics, bundled) {
                (Physics::Yarn(m), FmuScene::Yarn(bundled)) => {
                    m.set_string(vrs, vals, check, resources, bundled)
                }
                (Physics::MassSpring(m), _) => m.set_string(vrs, vals, check),
                (Physics::Yarn(_), FmuScene::MassSpring(_)) => {
                    unreachable!("a yarn model from a mass-spring scene")
                }
            },
        )
    }

    pub fn get_fmu_state(&mut self, into: Option<&mut Snapshot>) -> Res<Option<Box<Snapshot>>> {
        self.require("fmi2GetFMUstate", LIVE)?;
        // A snapshot always holds a simulation built from its parameters.
        self.model.ensure_built(self.count)?;
        match into {
            Some(s) => {
                s.phase = self.phase;
                s.model = self.model.clone();
                s.bytes = None;
                Ok(None)
            }
            None => Ok(Some(Box::new(Snapshot {
                magic: SNAPSHOT_MAGIC,
                phase: self.phase,
                model: self.model.clone(),
                bytes: None,
            }))),
        }
    }

    pub fn set_fmu_state(&mut self, s: &Snapshot) -> Res {
        self.require("fmi2SetFMUstate", NOT_FATAL)?;
        let same_kind =
            std::mem::discriminant(&s.model.physics) == std::mem::discriminant(&self.model.physics);
        if !same_kind || s.model.physics.count() != self.count {
            return error(
                "fmi2SetFMUstate: the state belongs to another FMU (other model or number of outputs)",
            );
        }
        self.model = s.model.clone();
        self.phase = s.phase;
        self.log(
            Status::Ok,
            LOG_EVENTS,
            &format!("state restored: t = {}", self.model.time),
        );
        Ok(())
    }

    fn require_state_phase(&self, func: &str) -> Res {
        self.require(func, NOT_FATAL)
    }

    /// The serialized bytes of a snapshot (made once, then cached).
    pub fn serialize<'a>(&self, func: &str, s: &'a mut Snapshot) -> Res<&'a [u8]> {
        self.require_state_phase(func)?;
        if s.bytes.is_none() {
            s.bytes = Some(serialize(s.phase, &s.model));
        }
        Ok(s.bytes.as_deref().unwrap())
    }

    pub fn deserialize(&mut self, bytes: &[u8]) -> Res<Box<Snapshot>> {
        self.require_state_phase("fmi2DeSerializeFMUstate")?;
        let (phase, model) = deserialize(bytes, &self.model, self.count)
            .or_else(|e| error(format!("fmi2DeSerializeFMUstate: {e}")))?;
        Ok(Box::new(Snapshot {
            magic: SNAPSHOT_MAGIC,
            phase,
            model,
            bytes: Some(bytes.to_vec()),
        }))
    }

    pub fn last_successful_time(&self) -> f64 {
        self.model.last_successful_time
    }

    pub fn terminated(&self) -> bool {
        self.model.terminated
    }
}

/// A C string of `s` with NUL bytes dropped.
pub fn escape_nul(s: &str) -> CString {
    CString::new(s.replace('\0', "")).expect("NUL removed")
}

/// Fixed parameters can be set only before `fmi2ExitInitializationMode`.
fn parameter_settable(phase: Phase, func: &str, vr: u32) -> Res {
    use Phase::*;
    if matches!(phase, Instantiated | InitializationMode) {
        Ok(())
    } else {
        error(format!(
            "{func}: value reference {vr} is a fixed parameter, settable only before fmi2ExitInitializationMode (state is {:?})",
            phase_name(phase)
        ))
    }
}

/// Little-endian writer of a serialized FMU state.
pub struct Writer(Vec<u8>);

impl Writer {
    pub fn u8(&mut self, v: u8) {
        self.0.push(v);
    }
    pub fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    pub fn f64(&mut self, v: f64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    pub fn opt_f64(&mut self, v: Option<f64>) {
        self.u8(v.is_some() as u8);
        self.f64(v.unwrap_or(0.0));
    }
    pub fn bytes(&mut self, b: &[u8]) {
        self.u64(b.len() as u64);
        self.0.extend_from_slice(b);
    }
}

/// Reader of a serialized FMU state; every read is bounds-checked and
/// non-finite numbers are refused.
pub struct Reader<'a> {
    b: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        if self.b.len() - self.at < n {
            return Err(format!(
                "state is truncated: {} more bytes needed at offset {}",
                n, self.at
            ));
        }
        let s = &self.b[self.at..self.at + n];
        self.at += n;
        Ok(s)
    }
    pub fn u8(&mut self) -> Result<u8, String> {
        Ok(self.take(1)?[0])
    }
    pub fn bool(&mut self) -> Result<bool, String> {
        match self.u8()? {
            0 => Ok(false),
            1 => Ok(true),
            b => Err(format!("bad flag byte {b}")),
        }
    }
    pub fn u64(&mut self) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.take(8)?.try_into().unwrap()))
    }
    pub fn f64(&mut self) -> Result<f64, String> {
        let v = f64::from_le_bytes(self.take(8)?.try_into().unwrap());
        if v.is_finite() {
            Ok(v)
        } else {
            Err("state contains a non-finite number".into())
        }
    }
    pub fn opt_f64(&mut self) -> Result<Option<f64>, String> {
        let some = self.bool()?;
        let v = self.f64()?;
        Ok(some.then_some(v))
    }
    pub fn bytes(&mut self) -> Result<&'a [u8], String> {
        let n = self.u64()?;
        let n = usize::try_from(n).map_err(|_| "bad length".to_string())?;
        self.take(n)
    }
    pub fn string(&mut self) -> Result<String, String> {
        String::from_utf8(self.bytes()?.to_vec()).map_err(|_| "string is not UTF-8".to_string())
    }
    /// Fails unless every byte was read.
    pub fn finish(&self) -> Result<(), String> {
        if self.at == self.b.len() {
            Ok(())
        } else {
            Err(format!(
                "state has {} unexpected trailing bytes",
                self.b.len() - self.at
            ))
        }
    }
}

/// The FMU state as bytes: magic (one per model), version, body length,
/// FNV-1a checksum of the body; the body holds the state machine state and
/// the wrapper's time keeping, then the model's part ([`YarnModel::write`],
/// [`MsModel::write`]). No pointers.
pub fn serialize(phase: Phase, m: &Model) -> Vec<u8> {
    let mut w = Writer(Vec::new());
    w.u8(phase.code());
    w.u8(m.terminated as u8);
    w.u8(m.dirty as u8);
    w.f64(m.start_time);
    w.opt_f64(m.stop_time);
    w.f64(m.time);
    w.f64(m.last_successful_time);
    w.u64(m.substeps);
    each!(&m.physics, p => p.write(&mut w));
    let body = w.0;
    let mut out = Vec::with_capacity(STATE_HEADER + body.len());
    out.extend_from_slice(m.physics.state_magic());
    out.extend_from_slice(&STATE_VERSION.to_le_bytes());
    out.extend_from_slice(&(body.len() as u64).to_le_bytes());
    out.extend_from_slice(&fnv1a(&body).to_le_bytes());
    out.extend_from_slice(&body);
    out
}

/// Reads bytes written by [`serialize`] for an FMU of the same model with
/// `count` outputs objects; `current`'s simulation is reused when its scene
/// and parameters match, else it is rebuilt from the stored scene.
pub fn deserialize(bytes: &[u8], current: &Model, count: usize) -> Result<(Phase, Model), String> {
    if bytes.len() < STATE_HEADER {
        return Err(format!(
            "state has {} bytes, at least {STATE_HEADER} needed",
            bytes.len()
        ));
    }
    let magic = current.physics.state_magic();
    if &bytes[..8] != magic {
        let what = if STATE_MAGICS.iter().any(|m| &bytes[..8] == *m) {
            "is the state of the other kind of FMU"
        } else {
            "does not start with a yarnsim FMU state magic"
        };
        return Err(format!(
            "state {what} (expected {:?})",
            String::from_utf8_lossy(&magic[..7])
        ));
    }
    let version = u32::from_le_bytes(bytes[8..12].try_into().unwrap());
    if version != STATE_VERSION {
        return Err(format!(
            "state format version {version} is not {STATE_VERSION}"
        ));
    }
    let len = u64::from_le_bytes(bytes[12..20].try_into().unwrap());
    let sum = u64::from_le_bytes(bytes[20..28].try_into().unwrap());
    let body = &bytes[STATE_HEADER..];
    if len != body.len() as u64 {
        return Err(format!(
            "state declares {len} body bytes but has {}",
            body.len()
        ));
    }
    if fnv1a(body) != sum {
        return Err("state checksum does not match: the bytes are corrupt".into());
    }
    let mut r = Reader { b: body, at: 0 };
    let phase = Phase::from_code(r.u8()?).ok_or("bad state machine state")?;
    if matches!(phase, Phase::Error | Phase::Fatal) {
        return Err("state was saved in an error state".into());
    }
    let terminated = r.bool()?;
    let dirty = r.bool()?;
    let start_time = r.f64()?;
    let stop_time = r.opt_f64()?;
    let time = r.f64()?;
    let last_successful_time = r.f64()?;
    let substeps = r.u64()?;
    let built = !current.dirty;
    let physics = match &current.physics {
        Physics::Yarn(c) => Physics::Yarn(Box::new(YarnModel::read(&mut r, c, built, count)?)),
        Physics::MassSpring(c) => {
            Physics::MassSpring(Box::new(MsModel::read(&mut r, c, built, count)?))
        }
    };
    Ok((
        phase,
        Model {
            physics,
            dirty,
            start_time,
            stop_time,
            time,
            last_successful_time,
            substeps,
            terminated,
            outputs_checked: false,
        },
    ))
}
