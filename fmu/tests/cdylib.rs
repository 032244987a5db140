//! The built shared library itself, loaded with dlopen as an FMI master
//! loads it: every fmi2 function resolves, and a run through it gives the
//! same bits as the same run through the rlib.

mod common;

use std::ffi::{c_char, c_int, c_void, CString};

use common::*;
use yarnsim_fmu::fmi2::*;
use yarnsim_fmu::models::yarn::variables::*;

type Setup = unsafe extern "C" fn(fmi2Component, c_int, f64, f64, c_int, f64) -> fmi2Status;
type Unary = unsafe extern "C" fn(fmi2Component) -> fmi2Status;
type Free = unsafe extern "C" fn(fmi2Component);
type SetReal = unsafe extern "C" fn(fmi2Component, *const u32, usize, *const f64) -> fmi2Status;
type GetReal = unsafe extern "C" fn(fmi2Component, *const u32, usize, *mut f64) -> fmi2Status;
type DoStep = unsafe extern "C" fn(fmi2Component, f64, f64, c_int) -> fmi2Status;
type Version = unsafe extern "C" fn() -> *const c_char;

/// The symbol `name` of `lib` as a `T`.
///
/// # Safety
/// `lib` is a handle from `dlopen`, and `T` is the function-pointer type of
/// that symbol's C signature.
unsafe fn sym<T: Copy>(lib: *mut c_void, name: &str) -> T {
    let n = CString::new(name).unwrap();
    // SAFETY: `lib` is a live handle (the caller's contract) and `n` a
    // NUL-terminated name.
    let p = unsafe { libc::dlsym(lib, n.as_ptr()) };
    assert!(!p.is_null(), "{name} does not resolve");
    assert_eq!(std::mem::size_of::<T>(), std::mem::size_of::<*mut c_void>());
    // SAFETY: `T` is a function pointer of the symbol's signature (the
    // caller's contract), of the size of `p` (checked above).
    unsafe { std::mem::transmute_copy(&p) }
}

#[test]
fn shared_library_loads_and_runs_like_the_rlib() {
    let path = cdylib_path();
    let cpath = CString::new(path.to_str().unwrap()).unwrap();
    let scene = small_scene();
    let dir = resources(&scene);
    let h = 0.01;
    let inputs = |k: usize| [0.3 * k as f64, -9.8 + 0.5 * k as f64];
    // SAFETY: `dlopen` and `dlsym` get NUL-terminated names; each symbol is cast to the FMI 2.0
    // signature its name has in fmi2Functions.h; the instance is used only between its
    // fmi2Instantiate and fmi2FreeInstance.
    unsafe {
        let lib = libc::dlopen(cpath.as_ptr(), libc::RTLD_NOW | libc::RTLD_LOCAL);
        assert!(!lib.is_null(), "dlopen {} failed", path.display());
        for f in yarnsim_fmu::fmi2::FMI2_FUNCTIONS {
            let n = CString::new(f).unwrap();
            assert!(!libc::dlsym(lib, n.as_ptr()).is_null(), "{f}");
        }
        let version: Version = sym(lib, "fmi2GetVersion");
        assert_eq!(std::ffi::CStr::from_ptr(version()).to_str(), Ok("2.0"));
        let platform: Version = sym(lib, "fmi2GetTypesPlatform");
        assert_eq!(std::ffi::CStr::from_ptr(platform()).to_str(), Ok("default"));
        let instantiate: Instantiate = sym(lib, "fmi2Instantiate");
        let setup: Setup = sym(lib, "fmi2SetupExperiment");
        let enter: Unary = sym(lib, "fmi2EnterInitializationMode");
        let exit: Unary = sym(lib, "fmi2ExitInitializationMode");
        let set_real: SetReal = sym(lib, "fmi2SetReal");
        let get_real: GetReal = sym(lib, "fmi2GetReal");
        let do_step: DoStep = sym(lib, "fmi2DoStep");
        let free: Free = sym(lib, "fmi2FreeInstance");

        let cb = fmi2CallbackFunctions {
            logger: Some(logger_fn()),
            allocateMemory: None,
            freeMemory: None,
            stepFinished: None,
            componentEnvironment: std::ptr::null_mut(),
        };
        let name = CString::new("dl").unwrap();
        let g = CString::new(guid(&scene)).unwrap();
        let uri = CString::new(format!("file://{}", dir.display())).unwrap();
        let c = instantiate_with(instantiate, (&name, fmi2CoSimulation, &g, &uri), &cb);
        assert!(!c.is_null());
        assert_eq!(setup(c, 0, 0.0, 0.0, 0, 0.0), fmi2OK);
        assert_eq!(enter(c), fmi2OK);
        assert_eq!(exit(c), fmi2OK);
        let vrs: Vec<u32> = (0..12).map(|k| VR_YARN_BASE + k).collect();
        let gvr = [VR_GRAVITY_X, VR_GRAVITY_Y];
        let mut dl = Vec::new();
        for k in 0..5 {
            assert_eq!(set_real(c, gvr.as_ptr(), 2, inputs(k).as_ptr()), fmi2OK);
            assert_eq!(do_step(c, k as f64 * h, h, 1), fmi2OK);
            let mut out = vec![0.0; vrs.len()];
            assert_eq!(
                get_real(c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr()),
                fmi2OK
            );
            dl.extend(out.iter().map(|v| v.to_bits()));
        }
        free(c);
        free(std::ptr::null_mut());
        // The library stays loaded: its rayon worker threads may still run.

        // The same run through the rlib.
        let fmu = Fmu::initialized(&scene);
        let mut rlib = Vec::new();
        for k in 0..5 {
            assert_eq!(fmu.set_real(&gvr, &inputs(k)), fmi2OK);
            assert_eq!(fmu.do_step(k as f64 * h, h), fmi2OK);
            rlib.extend(fmu.get_real(&vrs).unwrap().iter().map(|v| v.to_bits()));
        }
        assert_eq!(dl, rlib);
        let _ = std::fs::remove_dir_all(dir);
    }
}
