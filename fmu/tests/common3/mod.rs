//! A small FMI 3.0 Co-Simulation master for the tests: it calls the
//! exported fmi3 functions (through the rlib; the same code as the cdylib)
//! and collects the log lines of the non-variadic fmi3 logger. A test that
//! uses it also declares `mod common;` (the resources folders).
#![allow(dead_code)]

use std::ffi::{c_char, c_int, c_void, CString};
use std::path::PathBuf;
use std::sync::Mutex;

use crate::common::resources_with;
use yarnsim::scene::Scene;
use yarnsim_fmu::fmi3::common::*;
use yarnsim_fmu::fmi3::cosim::*;
use yarnsim_fmu::fmi3::fmu_state::*;
use yarnsim_fmu::fmi3::values::*;
use yarnsim_fmu::fmi3::*;
use yarnsim_fmu::SceneFmu;

pub const SMALL_SCENE: &str = include_str!("../../scenes/small.toml");

pub use crate::common::Line;

extern "C" fn logger(
    env: *mut c_void,
    status: c_int,
    category: *const c_char,
    message: *const c_char,
) {
    // SAFETY: `env` is null or the `Mutex<Vec<Line>>` of the `Fmu3` that
    // owns the instance; the strings are valid C strings for the call.
    unsafe { crate::common::record(env, status, category, message) }
}

pub struct Fmu3 {
    pub c: fmi3Instance,
    pub log: Box<Mutex<Vec<Line>>>,
    pub dir: PathBuf,
}

// SAFETY: the instance is only used from the thread that owns the `Fmu3`,
// and the FMU keeps no thread-local state.
unsafe impl Send for Fmu3 {}

impl Fmu3 {
    /// Instantiates the FMI 3.0 FMU of the scene file `text`.
    pub fn new(text: &str) -> Fmu3 {
        let scene = Scene::from_toml_str(text).unwrap();
        Self::try_new(text, &scene.guid(), false).expect("fmi3InstantiateCoSimulation failed")
    }

    pub fn small() -> Fmu3 {
        Self::new(SMALL_SCENE)
    }

    pub fn try_new(text: &str, token: &str, event_mode: bool) -> Result<Fmu3, Vec<Line>> {
        let dir = resources_with(text);
        let log: Box<Mutex<Vec<Line>>> = Box::default();
        let res = CString::new(format!("{}/", dir.display())).unwrap();
        let name = CString::new("test3").unwrap();
        let token = CString::new(token).unwrap();
        // SAFETY: live C strings; `log`, the logger's environment, is boxed
        // and lives as long as the instance (both owned by the `Fmu3`).
        let c = unsafe {
            fmi3InstantiateCoSimulation(
                name.as_ptr(),
                token.as_ptr(),
                res.as_ptr(),
                false,
                false,
                event_mode,
                false,
                std::ptr::null(),
                0,
                &*log as *const _ as *mut c_void,
                Some(logger),
                None,
            )
        };
        if c.is_null() {
            let _ = std::fs::remove_dir_all(&dir);
            return Err(log.lock().unwrap().clone());
        }
        Ok(Fmu3 { c, log, dir })
    }

    pub fn lines(&self) -> Vec<Line> {
        self.log.lock().unwrap().clone()
    }

    pub fn last_error(&self) -> String {
        crate::common::last_error_in(&self.lines(), fmi3Discard)
    }

    /// Asserts that the last error logged contains `what`.
    pub fn assert_error_contains(&self, what: &str) {
        crate::common::assert_in_last_error(&self.last_error(), what, &self.lines());
    }

    /// Enter (start 0, no stop time) and exit initialization mode.
    pub fn init(&self) {
        // SAFETY: `self.c` is a live instance.
        unsafe {
            assert_eq!(
                fmi3EnterInitializationMode(self.c, false, 0.0, 0.0, false, 0.0),
                fmi3OK
            );
            assert_eq!(fmi3ExitInitializationMode(self.c), fmi3OK);
        }
    }

    /// `fmi3DoStep` and its flags: (status, terminateSimulation,
    /// earlyReturn, eventHandlingNeeded, lastSuccessfulTime).
    pub fn step(&self, t: f64, h: f64) -> (fmi3Status, bool, bool, bool, f64) {
        let (mut ev, mut term, mut early, mut last) = (true, true, true, f64::NAN);
        // SAFETY: `self.c` is a live instance; the flags are locals.
        let s = unsafe {
            fmi3DoStep(
                self.c, t, h, false, &mut ev, &mut term, &mut early, &mut last,
            )
        };
        (s, term, early, ev, last)
    }

    /// `fmi3GetFloat64` with `n` values.
    pub fn get(&self, vrs: &[u32], n: usize) -> (fmi3Status, Vec<f64>) {
        let mut out = vec![f64::NAN; n];
        // SAFETY: `self.c` is a live instance; the arrays are locals of
        // the given lengths.
        let s = unsafe { fmi3GetFloat64(self.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr(), n) };
        (s, out)
    }

    pub fn set(&self, vrs: &[u32], vals: &[f64]) -> fmi3Status {
        // SAFETY: as `get`.
        unsafe { fmi3SetFloat64(self.c, vrs.as_ptr(), vrs.len(), vals.as_ptr(), vals.len()) }
    }

    pub fn set_bool(&self, vr: u32, v: bool) -> fmi3Status {
        // SAFETY: a live instance; one value reference and one value.
        unsafe { fmi3SetBoolean(self.c, &vr, 1, &v, 1) }
    }

    pub fn get_state(&self) -> fmi3FMUState {
        let mut s: fmi3FMUState = std::ptr::null_mut();
        // SAFETY: `self.c` is a live instance; `s` is a local slot.
        assert_eq!(unsafe { fmi3GetFMUState(self.c, &mut s) }, fmi3OK);
        s
    }

    pub fn serialize(&self, s: fmi3FMUState) -> Vec<u8> {
        let mut n = 0usize;
        // SAFETY: `s` is a state of this instance; `n` and the buffer are locals.
        unsafe {
            assert_eq!(fmi3SerializedFMUStateSize(self.c, s, &mut n), fmi3OK);
            let mut b = vec![0u8; n];
            assert_eq!(fmi3SerializeFMUState(self.c, s, b.as_mut_ptr(), n), fmi3OK);
            b
        }
    }

    /// `fmi3DeserializeFMUState` into a new state.
    pub fn deserialize(&self, bytes: &[u8]) -> (fmi3Status, fmi3FMUState) {
        let mut s: fmi3FMUState = std::ptr::null_mut();
        // SAFETY: `bytes` is a live slice; `s` is a local slot.
        let st = unsafe { fmi3DeserializeFMUState(self.c, bytes.as_ptr(), bytes.len(), &mut s) };
        (st, s)
    }

    pub fn free_state(&self, mut s: fmi3FMUState) {
        // SAFETY: `s` is a state of this instance (or null).
        assert_eq!(unsafe { fmi3FreeFMUState(self.c, &mut s) }, fmi3OK);
    }
}

impl Drop for Fmu3 {
    fn drop(&mut self) {
        // SAFETY: the instance is freed once, here.
        unsafe { fmi3FreeInstance(self.c) };
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}
