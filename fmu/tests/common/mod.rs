//! A small FMI 2.0 master for the tests: it calls the exported C functions
//! (through the rlib; the same code as the cdylib) and collects log lines.
#![allow(dead_code)]

use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use yarnsim::scene::YarnScene;
use yarnsim_fmu::fmi2::*;
use yarnsim_fmu::instance::Logger;
use yarnsim_fmu::model_description::*;
use yarnsim_fmu::models::yarn::variables::*;

pub const SMALL_SCENE: &str = include_str!("../../scenes/small.toml");

/// The cdylib cargo built for this test run: `deps/libyarnsim_fmu.so` next to
/// the test executable (`cargo test` does not copy it up to `target/<profile>/`;
/// a `cargo build` does, which is the fallback).
pub fn cdylib_path() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let deps = exe.parent().unwrap();
    let name = yarnsim_fmu::LIBRARY_FILE;
    [deps.join(name), deps.parent().unwrap().join(name)]
        .into_iter()
        .find(|p| p.exists())
        .unwrap_or_else(|| panic!("{name} was not built next to {}", deps.display()))
}

/// The library's values of the FMU's outputs in [`Fmu::outputs`] order:
/// every yarn's ends, then kinetic energy, elastic energy, largest stretch.
pub fn library_outputs(sim: &yarnsim::YarnSim) -> Vec<f64> {
    let mut out = Vec::new();
    for y in 0..sim.num_yarns() {
        let (l, r) = sim.yarn_endpoints(y);
        out.extend([l.x, l.y, r.x, r.y]);
    }
    let d = sim.diagnostics();
    out.extend([d.kinetic_energy, d.elastic_energy, d.max_stretch]);
    out
}

/// Bit patterns, for exact comparisons of runs.
pub fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

pub fn small_scene() -> YarnScene {
    YarnScene::from_toml_str(SMALL_SCENE).unwrap()
}

/// A fresh resources folder holding `scene` as `scene.toml`, as the
/// packager writes it.
pub fn resources(scene: &YarnScene) -> PathBuf {
    resources_with(&scene.to_toml_string())
}

/// A fresh resources folder holding `text` as `scene.toml`.
pub fn resources_with(text: &str) -> PathBuf {
    static N: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!(
        "yarnbundle-test-{}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join(SCENE_FILE), text).unwrap();
    dir
}

/// One log line: status, category, message.
pub type Line = (c_int, String, String);

/// The logger as the environment supplies it. FMI declares it variadic; the
/// FMU passes a pre-formatted message and no extra arguments, so a
/// non-variadic function with the fixed parameters receives it correctly
/// on the SysV x86-64 ABI.
extern "C" fn logger(
    env: *mut c_void,
    _name: *const c_char,
    status: c_int,
    category: *const c_char,
    message: *const c_char,
) {
    // SAFETY: the logger's own arguments (see `record`).
    unsafe { record(env, status, category, message) }
}

/// `fmi2Instantiate` or a pointer to it (as `dlsym` gives it).
pub type Instantiate = unsafe extern "C" fn(
    fmi2String,
    fmi2Type,
    fmi2String,
    fmi2String,
    *const fmi2CallbackFunctions,
    fmi2Boolean,
    fmi2Boolean,
) -> fmi2Component;

/// A new instance of `fmu_type` through `instantiate`, not visible and
/// with logging off.
///
/// # Safety
/// `cb` is null or points to callbacks valid for the instance's life.
pub unsafe fn instantiate_with(
    instantiate: Instantiate,
    (name, fmu_type, guid, uri): (&CStr, fmi2Type, &CStr, &CStr),
    cb: *const fmi2CallbackFunctions,
) -> fmi2Component {
    // SAFETY: live NUL-terminated strings; `cb` as the caller's contract.
    unsafe {
        instantiate(
            name.as_ptr(),
            fmu_type,
            guid.as_ptr(),
            uri.as_ptr(),
            cb,
            fmi2False,
            fmi2False,
        )
    }
}

/// Asserts that `what` is in `last_error` (the whole log `lines` in the
/// panic message otherwise): both versions' `assert_error_contains`.
pub fn assert_in_last_error(last_error: &str, what: &str, lines: &[Line]) {
    assert!(
        last_error.contains(what),
        "{what:?} not in the last error; log {lines:?}"
    );
}

/// Asserts that a deserialization (`what`: the bytes it was given) was
/// refused: the version's `error` status, no state, `func` in the last
/// error.
pub fn assert_refused_state(
    what: &str,
    (status, state): (c_int, *mut c_void),
    error: c_int,
    last_error: &str,
    func: &str,
) {
    assert_eq!(status, error, "{what}");
    assert!(state.is_null(), "{what}");
    assert!(last_error.contains(func), "{what}: {last_error}");
}

/// The message of the last line logged with a status of at least `discard`
/// (the Discard status of either FMI version), or "".
pub fn last_error_in(lines: &[Line], discard: c_int) -> String {
    lines
        .iter()
        .rev()
        .find(|l| l.0 >= discard)
        .map(|l| l.2.clone())
        .unwrap_or_default()
}

/// Adds a log line to the `Mutex<Vec<Line>>` behind `env` (a test that
/// passes no environment does not collect log lines).
///
/// # Safety
/// `env` is null or the `Mutex<Vec<Line>>` of the live master that owns the
/// instance; `category` and `message` are valid C strings.
pub unsafe fn record(
    env: *mut c_void,
    status: c_int,
    category: *const c_char,
    message: *const c_char,
) {
    if env.is_null() {
        return;
    }
    // SAFETY: the caller's contract.
    unsafe {
        let lines = &*(env as *const Mutex<Vec<Line>>);
        let cat = CStr::from_ptr(category).to_string_lossy().into_owned();
        let msg = CStr::from_ptr(message).to_string_lossy().into_owned();
        lines.lock().unwrap().push((status, cat, msg));
    }
}

pub fn logger_fn() -> Logger {
    // SAFETY: see `logger`: same fixed parameters, no variadic part is read.
    unsafe {
        std::mem::transmute::<
            extern "C" fn(*mut c_void, *const c_char, c_int, *const c_char, *const c_char),
            Logger,
        >(logger)
    }
}

pub struct Fmu {
    pub c: fmi2Component,
    pub log: Box<Mutex<Vec<Line>>>,
    /// Yarns (YarnBundle) or particles (MassSpring).
    pub yarns: usize,
    pub dir: PathBuf,
}

// SAFETY: the component is only used from the thread that owns the `Fmu`, and the FMU keeps no
// thread-local state.
unsafe impl Send for Fmu {}

impl Fmu {
    /// Instantiates the FMU for `scene` (GUID from the scene).
    pub fn new(scene: &YarnScene) -> Fmu {
        Self::try_new(scene, &guid(scene), "test").expect("fmi2Instantiate failed")
    }

    /// [`Self::new`], set up and through initialization ([`Self::init`]).
    pub fn initialized(scene: &YarnScene) -> Fmu {
        let f = Fmu::new(scene);
        f.init();
        f
    }

    /// [`Self::new`] with the string parameter `vr` set to `value` (fmi2OK)
    /// before initialization ([`Self::init`]).
    pub fn initialized_with(scene: &YarnScene, vr: u32, value: &str) -> Fmu {
        let f = Fmu::new(scene);
        assert_eq!(f.set_string(vr, value), fmi2OK);
        f.init();
        f
    }

    /// [`Self::initialized`] and set to the serialized state `bytes` (the
    /// state made from them is freed).
    pub fn initialized_from(scene: &YarnScene, bytes: &[u8]) -> Fmu {
        let f = Fmu::initialized(scene);
        let d = f.set_state_from(bytes);
        f.free_state(d);
        f
    }

    pub fn try_new(scene: &YarnScene, guid: &str, name: &str) -> Result<Fmu, Vec<Line>> {
        Self::try_with(&scene.to_toml_string(), num_yarns(scene), guid, name)
    }

    /// Instantiates the mass-spring FMU for `layout`.
    pub fn mass_spring(layout: &yarnsim::massspring::MassSpringScene) -> Fmu {
        let n = yarnsim_fmu::models::massspring::num_particles(layout).unwrap();
        let guid = yarnsim_fmu::models::massspring::guid(layout);
        Self::try_with(&layout.to_toml_string(), n, &guid, "test").expect("fmi2Instantiate failed")
    }

    /// Instantiates the FMU for the scene file `text` with `count` yarns
    /// or particles.
    pub fn try_with(text: &str, count: usize, guid: &str, name: &str) -> Result<Fmu, Vec<Line>> {
        let dir = resources_with(text);
        let log: Box<Mutex<Vec<Line>>> = Box::default();
        let cb = fmi2CallbackFunctions {
            logger: Some(logger_fn()),
            allocateMemory: None,
            freeMemory: None,
            stepFinished: None,
            componentEnvironment: &*log as *const _ as *mut c_void,
        };
        let uri = CString::new(format!("file://{}", dir.display())).unwrap();
        let name = CString::new(name).unwrap();
        let guid = CString::new(guid).unwrap();
        // SAFETY: the strings are live `CString`s and `cb` outlives the call; `log`, the logger's
        // environment, is boxed and lives as long as the instance (both are owned by the `Fmu`).
        let c = unsafe {
            instantiate_with(fmi2Instantiate, (&name, fmi2CoSimulation, &guid, &uri), &cb)
        };
        if c.is_null() {
            let _ = std::fs::remove_dir_all(&dir);
            return Err(log.lock().unwrap().clone());
        }
        Ok(Fmu {
            c,
            log,
            yarns: count,
            dir,
        })
    }

    pub fn lines(&self) -> Vec<Line> {
        self.log.lock().unwrap().clone()
    }

    pub fn last_error(&self) -> String {
        last_error_in(&self.lines(), fmi2Discard)
    }

    /// Asserts that the last error logged contains `what` (the whole log
    /// in the panic message otherwise).
    pub fn assert_error_contains(&self, what: &str) {
        assert_in_last_error(&self.last_error(), what, &self.lines());
    }

    pub fn setup(&self, start: f64, stop: Option<f64>) -> fmi2Status {
        // SAFETY: `self.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
        // pointer argument is a local that outlives the call.
        unsafe {
            fmi2SetupExperiment(
                self.c,
                fmi2False,
                0.0,
                start,
                stop.is_some() as c_int,
                stop.unwrap_or(0.0),
            )
        }
    }

    /// Setup at 0 without stop time, enter and exit initialization.
    pub fn init(&self) {
        assert_eq!(self.setup(0.0, None), fmi2OK);
        self.init_mode();
    }

    pub fn init_mode(&self) {
        // SAFETY: `self.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
        // pointer argument is a local that outlives the call.
        unsafe {
            assert_eq!(fmi2EnterInitializationMode(self.c), fmi2OK);
            assert_eq!(
                fmi2ExitInitializationMode(self.c),
                fmi2OK,
                "{:?}",
                self.lines()
            );
        }
    }

    /// Setup at 0 without stop time, enter initialization (fmi2OK) and
    /// exit it; returns the exit's status (an error the scene's checks
    /// raise there, a warning, or fmi2OK).
    pub fn init_status(&self) -> fmi2Status {
        assert_eq!(self.setup(0.0, None), fmi2OK);
        // SAFETY: `self.c` came from `fmi2Instantiate` and lives until its `Fmu` drops.
        unsafe {
            assert_eq!(fmi2EnterInitializationMode(self.c), fmi2OK);
            fmi2ExitInitializationMode(self.c)
        }
    }

    /// [`Self::init_status`], which may warn (a scene warning,
    /// `YarnScene::warnings`) but not fail; returns the exit status.
    pub fn init_warned(&self) -> fmi2Status {
        let status = self.init_status();
        assert!(status <= fmi2Warning, "{status}: {:?}", self.lines());
        status
    }

    pub fn set_real(&self, vr: &[u32], v: &[f64]) -> fmi2Status {
        assert_eq!(vr.len(), v.len());
        // SAFETY: `self.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
        // pointer argument is a local that outlives the call.
        unsafe { fmi2SetReal(self.c, vr.as_ptr(), vr.len(), v.as_ptr()) }
    }

    pub fn set_bool(&self, vr: u32, v: bool) -> fmi2Status {
        let v = v as fmi2Boolean;
        // SAFETY: `self.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
        // pointer argument is a local that outlives the call.
        unsafe { fmi2SetBoolean(self.c, &vr, 1, &v) }
    }

    pub fn set_string(&self, vr: u32, v: &str) -> fmi2Status {
        let s = CString::new(v).unwrap();
        let p = s.as_ptr();
        // SAFETY: `self.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
        // pointer argument is a local that outlives the call.
        unsafe { fmi2SetString(self.c, &vr, 1, &p) }
    }

    pub fn set_integer(&self, vr: u32, v: c_int) -> fmi2Status {
        // SAFETY: `self.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
        // pointer argument is a local that outlives the call.
        unsafe { fmi2SetInteger(self.c, &vr, 1, &v) }
    }

    pub fn get_string(&self, vr: u32) -> String {
        let mut p: fmi2String = std::ptr::null();
        // SAFETY: `self.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
        // pointer argument is a local that outlives the call.
        assert_eq!(unsafe { fmi2GetString(self.c, &vr, 1, &mut p) }, fmi2OK);
        // SAFETY: `fmi2GetString` returned OK, so `p` is a NUL-terminated string the instance
        // keeps until its next call.
        unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
    }

    /// After a step that returned fmi2Discard: the log names
    /// `logStatusDiscard`, the instance reports itself terminated, and its
    /// last successful time is `t`.
    pub fn assert_discarded_at(&self, t: f64) {
        assert!(self
            .lines()
            .iter()
            .any(|l| l.0 == fmi2Discard && l.1 == "logStatusDiscard"));
        let mut term = 0;
        assert_eq!(
            // SAFETY: `self.c` came from `fmi2Instantiate` and lives until its `Fmu` drops;
            // every pointer argument is a local that outlives the call.
            unsafe { fmi2GetBooleanStatus(self.c, fmi2Terminated, &mut term) },
            fmi2OK
        );
        assert_eq!(term, fmi2True);
        let mut lst = -1.0;
        assert_eq!(
            // SAFETY: `self.c` came from `fmi2Instantiate` and lives until its `Fmu` drops;
            // every pointer argument is a local that outlives the call.
            unsafe { fmi2GetRealStatus(self.c, fmi2LastSuccessfulTime, &mut lst) },
            fmi2OK
        );
        assert_eq!(lst, t);
    }

    pub fn get_real(&self, vr: &[u32]) -> Result<Vec<f64>, fmi2Status> {
        let mut out = vec![f64::NAN; vr.len()];
        // SAFETY: `self.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
        // pointer argument is a local that outlives the call.
        match unsafe { fmi2GetReal(self.c, vr.as_ptr(), vr.len(), out.as_mut_ptr()) } {
            s if s == fmi2OK => Ok(out),
            s => Err(s),
        }
    }

    pub fn substeps(&self) -> i32 {
        let mut v = -1;
        assert_eq!(
            // SAFETY: `self.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
            // pointer argument is a local that outlives the call.
            unsafe { fmi2GetInteger(self.c, &VR_SUBSTEPS, 1, &mut v) },
            fmi2OK
        );
        v
    }

    pub fn do_step(&self, t: f64, h: f64) -> fmi2Status {
        // SAFETY: `self.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
        // pointer argument is a local that outlives the call.
        unsafe { fmi2DoStep(self.c, t, h, fmi2True) }
    }

    /// Communication steps `steps` of `h` each (step k from t = k h), every
    /// one fmi2OK (the log in the panic message otherwise).
    pub fn steps_ok(&self, steps: std::ops::Range<u32>, h: f64) {
        for k in steps {
            assert_eq!(self.do_step(k as f64 * h, h), fmi2OK, "{:?}", self.lines());
        }
    }

    /// The bits of [`Self::outputs`] after each of the communication steps
    /// `steps` of `h` (each one fmi2OK), concatenated.
    pub fn output_bits(&self, steps: std::ops::Range<u32>, h: f64) -> Vec<u64> {
        let mut bits = Vec::new();
        for k in steps {
            self.steps_ok(k..k + 1, h);
            bits.extend(self.outputs().iter().map(|v| v.to_bits()));
        }
        bits
    }

    /// Value references of every yarn end coordinate.
    pub fn yarn_vrs(&self) -> Vec<u32> {
        (0..4 * self.yarns as u32)
            .map(|k| VR_YARN_BASE + k)
            .collect()
    }

    /// Yarn ends followed by kinetic energy, elastic energy, max stretch.
    pub fn outputs(&self) -> Vec<f64> {
        let mut vrs = self.yarn_vrs();
        vrs.extend([VR_KINETIC_ENERGY, VR_ELASTIC_ENERGY, VR_MAX_STRETCH]);
        self.get_real(&vrs)
            .unwrap_or_else(|s| panic!("fmi2GetReal: {s} {:?}", self.lines()))
    }

    pub fn get_state(&self) -> fmi2FMUstate {
        let mut s: fmi2FMUstate = std::ptr::null_mut();
        // SAFETY: `self.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
        // pointer argument is a local that outlives the call.
        assert_eq!(unsafe { fmi2GetFMUstate(self.c, &mut s) }, fmi2OK);
        assert!(!s.is_null());
        s
    }

    pub fn serialize(&self, s: fmi2FMUstate) -> Vec<u8> {
        let mut n = 0usize;
        assert_eq!(
            // SAFETY: `self.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
            // pointer argument is a local that outlives the call.
            unsafe { fmi2SerializedFMUstateSize(self.c, s, &mut n) },
            fmi2OK
        );
        let mut buf = vec![0u8; n];
        assert_eq!(
            // SAFETY: `self.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
            // pointer argument is a local that outlives the call.
            unsafe { fmi2SerializeFMUstate(self.c, s, buf.as_mut_ptr() as *mut c_char, n) },
            fmi2OK
        );
        buf
    }

    /// The instance's state now, serialized (the state taken is freed).
    pub fn state_bytes(&self) -> Vec<u8> {
        let s = self.get_state();
        let bytes = self.serialize(s);
        self.free_state(s);
        bytes
    }

    /// Deserializes into a new state; the status and the state (null on failure).
    pub fn deserialize(&self, bytes: &[u8]) -> (fmi2Status, fmi2FMUstate) {
        let mut s: fmi2FMUstate = std::ptr::null_mut();
        // SAFETY: `self.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
        // pointer argument is a local that outlives the call.
        let st = unsafe {
            fmi2DeSerializeFMUstate(self.c, bytes.as_ptr() as *const c_char, bytes.len(), &mut s)
        };
        (st, s)
    }

    /// Sets the instance to the state `s` (a state of this FMU that has not
    /// been freed), which must give fmi2OK.
    pub fn set_state(&self, s: fmi2FMUstate) {
        // SAFETY: `self.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; the
        // caller passes a state this FMU made and has not freed.
        let status = unsafe { fmi2SetFMUstate(self.c, s) };
        assert_eq!(status, fmi2OK, "{:?}", self.lines());
    }

    /// Deserializes `bytes` and sets the instance to that state (both
    /// fmi2OK); returns the state, for the caller to free.
    pub fn set_state_from(&self, bytes: &[u8]) -> fmi2FMUstate {
        let (st, d) = self.deserialize(bytes);
        assert_eq!(st, fmi2OK, "{:?}", self.lines());
        self.set_state(d);
        d
    }

    pub fn free_state(&self, mut s: fmi2FMUstate) {
        // SAFETY: `self.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
        // pointer argument is a local that outlives the call.
        assert_eq!(unsafe { fmi2FreeFMUstate(self.c, &mut s) }, fmi2OK);
        assert!(s.is_null());
    }
}

impl Drop for Fmu {
    fn drop(&mut self) {
        // SAFETY: `self.c` came from `fmi2Instantiate` and is freed once, here, when the `Fmu`
        // drops.
        unsafe { fmi2FreeInstance(self.c) };
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// Formats outputs for snapshots: 9 significant digits, so the snapshot pins
/// the trajectory without depending on the last bits of libm.
pub fn fmt_row(t: f64, v: &[f64]) -> String {
    let mut s = format!("t={t:.3}");
    for x in v {
        s.push_str(&format!(" {x:+.8e}"));
    }
    s
}
