//! The shell around every export of either FMI version, model- and
//! version-neutral: `call` (the instance check, the logged failures, the
//! caught panics), the helpers that turn C pointers into Rust values, the
//! export macros both front ends ([`crate::fmi2`], [`crate::fmi3`]) build
//! their tables with, and the bodies of the FMU-state functions
//! (`fmu_state`). The C types it takes are those the two versions share:
//! an instance is a `void*`, a status a C `int` of the same values, a
//! string a `const char*`.

#![allow(non_snake_case)]

use std::ffi::{c_char, c_int, c_void, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};

use libc::size_t;

mod fmu_state;

pub(crate) use fmu_state::*;

/// An instance as both versions pass it (`fmi2Component`, `fmi3Instance`).
type Component = *mut c_void;
/// A status as both versions return it (`fmi2Status`, `fmi3Status`).
type CStatus = c_int;
/// A C string (`fmi2String`, `fmi3String`).
type CText = *const c_char;
const STATUS_ERROR: CStatus = Status::Error as CStatus;
const STATUS_FATAL: CStatus = Status::Fatal as CStatus;

use crate::instance::{
    error, Instance, Operation, Phase, Res, Status, LOG_ALL, LOG_DISCARD, LOG_ERROR, LOG_FATAL,
};

pub(crate) fn panic_message(p: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = p.downcast_ref::<&str>() {
        s.to_string()
    } else if let Some(s) = p.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown panic".to_string()
    }
}

/// Runs `f` on the instance behind `c`: null or foreign pointers give an
/// error status, failures are logged (an error moves the instance to the
/// error state), panics are caught and give a fatal status.
pub(crate) fn call(
    c: Component,
    func: &str,
    f: impl FnOnce(&mut Instance) -> Res<Status>,
) -> CStatus {
    // SAFETY: `c` is null or a component this FMU handed out (FMI contract);
    // the magic number rejects freed or foreign pointers in most cases.
    let Some(inst) = (unsafe { Instance::from_ptr(c) }) else {
        return STATUS_ERROR;
    };
    if inst.phase == Phase::Fatal {
        let free = inst.op_name(Operation::FreeInstance);
        inst.log(
            Status::Fatal,
            LOG_FATAL,
            &format!("{func}: the instance is in the fatal state; only {free} is allowed"),
        );
        return STATUS_FATAL;
    }
    if inst.log_all() {
        inst.log(Status::Ok, LOG_ALL, func);
    }
    let ptr: *mut Instance = inst;
    // SAFETY: `ptr` stays valid for the whole call; the closure is the only user.
    let result = catch_unwind(AssertUnwindSafe(|| f(unsafe { &mut *ptr })));
    // SAFETY: as above; the closure has returned.
    let inst = unsafe { &mut *ptr };
    match result {
        Ok(Ok(s)) => s as CStatus,
        Ok(Err(fail)) => {
            let cat = match fail.status {
                Status::Discard => LOG_DISCARD,
                Status::Fatal => LOG_FATAL,
                _ => LOG_ERROR,
            };
            let msg = if fail.msg.starts_with(func) {
                fail.msg
            } else {
                format!("{func}: {}", fail.msg)
            };
            inst.log(fail.status, cat, &msg);
            match fail.status {
                Status::Error => inst.phase = Phase::Error,
                Status::Fatal => inst.phase = Phase::Fatal,
                _ => {}
            }
            fail.status as CStatus
        }
        Err(p) => {
            inst.phase = Phase::Fatal;
            inst.log(
                Status::Fatal,
                LOG_FATAL,
                &format!("{func}: internal error: {}", panic_message(&*p)),
            );
            STATUS_FATAL
        }
    }
}

pub(crate) fn ok(r: Res) -> Res<Status> {
    r.map(|_| Status::Ok)
}

/// A slice from a C array; `None` for a null pointer with a nonzero length.
///
/// # Safety
/// `p` must be null or point to `n` initialized, aligned elements that stay
/// valid and unchanged for `'a` (the FMI contract for the arrays it passes).
pub(crate) unsafe fn slice<'a, T>(p: *const T, n: size_t) -> Option<&'a [T]> {
    if n == 0 {
        Some(&[])
    } else if p.is_null() {
        None
    } else {
        // SAFETY: non-null, `n` elements valid for `'a` (the caller's contract).
        Some(unsafe { std::slice::from_raw_parts(p, n) })
    }
}

/// A mutable slice from a C array; `None` for a null pointer with a nonzero
/// length.
///
/// # Safety
/// `p` must be null or point to `n` aligned elements, writable and not
/// aliased for `'a`.
pub(crate) unsafe fn slice_mut<'a, T>(p: *mut T, n: size_t) -> Option<&'a mut [T]> {
    if n == 0 {
        Some(&mut [])
    } else if p.is_null() {
        None
    } else {
        // SAFETY: non-null, `n` writable unaliased elements (the caller's contract).
        Some(unsafe { std::slice::from_raw_parts_mut(p, n) })
    }
}

/// A C string as an owned Rust string (invalid UTF-8 replaced); `None` for null.
///
/// # Safety
/// `p` must be null or point to a NUL-terminated string valid for the call.
pub(crate) unsafe fn string(p: CText) -> Option<String> {
    // SAFETY: non-null and NUL-terminated (the caller's contract).
    (!p.is_null()).then(|| unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
}

pub(crate) fn null<T>(func: &str, what: &str) -> Res<T> {
    error(format!("{func}: {what} is a null pointer"))
}

/// The value references and a writable array of `n_values` values from C,
/// or the null-pointer failure (`what`: the arguments' names in its message).
///
/// # Safety
/// As [`slice`] and [`slice_mut`].
pub(crate) unsafe fn get_args<'a, T>(
    func: &str,
    what: &str,
    vr: *const u32,
    nvr: size_t,
    values: *mut T,
    n_values: size_t,
) -> Res<(&'a [u32], &'a mut [T])> {
    // SAFETY: FMI passes `nvr` value references and a writable array of
    // `n_values` values (null only when the count is 0, else refused).
    match unsafe { (slice(vr, nvr), slice_mut(values, n_values)) } {
        (Some(v), Some(o)) => Ok((v, o)),
        _ => null(func, what),
    }
}

/// The value references and an array of `n_values` values from C, or the
/// null-pointer failure (`what`: the arguments' names in its message).
///
/// # Safety
/// As [`slice`].
pub(crate) unsafe fn set_args<'a, T>(
    func: &str,
    what: &str,
    vr: *const u32,
    nvr: size_t,
    values: *const T,
    n_values: size_t,
) -> Res<(&'a [u32], &'a [T])> {
    // SAFETY: FMI passes `nvr` value references and `n_values` values
    // (null only when the count is 0, else refused).
    match unsafe { (slice(vr, nvr), slice(values, n_values)) } {
        (Some(v), Some(o)) => Ok((v, o)),
        _ => null(func, what),
    }
}

/// The string getter of either version: pointers to the instance's strings.
pub(crate) fn get_strings(inst: &mut Instance, vrs: &[u32], out: &mut [CText]) -> Res<Status> {
    let strings = inst.get_string(vrs)?;
    for (o, s) in out.iter_mut().zip(strings) {
        *o = s.as_ptr();
    }
    Ok(Status::Ok)
}

/// The string setter of either version.
///
/// # Safety
/// Each value is null or a NUL-terminated string valid for the call.
pub(crate) unsafe fn set_strings(inst: &mut Instance, vrs: &[u32], vals: &[CText]) -> Res<Status> {
    // SAFETY: each value is null or a NUL-terminated string (FMI contract).
    let vals: Vec<Option<String>> = vals.iter().map(|&p| unsafe { string(p) }).collect();
    ok(inst.set_string(vrs, &vals))
}

/// `fmi2SetDebugLogging` / `fmi3SetDebugLogging`: the categories from C,
/// then [`Instance::set_debug_logging`].
///
/// # Safety
/// `categories` is null or holds `n` pointers, each null or a
/// NUL-terminated string.
pub(crate) unsafe fn debug_logging(
    inst: &mut Instance,
    func: &str,
    on: bool,
    categories: *const CText,
    n: size_t,
) -> Res<Status> {
    // SAFETY: FMI passes `nCategories` category strings.
    let Some(cats) = (unsafe { slice(categories, n) }) else {
        return null(func, "categories");
    };
    let mut names = Vec::with_capacity(cats.len());
    for &p in cats {
        // SAFETY: each category is null or a NUL-terminated string.
        match unsafe { string(p) } {
            Some(s) => names.push(s),
            None => return null(func, "a category"),
        }
    }
    let refs: Vec<&str> = names.iter().map(|s| s.as_str()).collect();
    ok(inst.set_debug_logging(on, &refs))
}

/// Exports functions of either version whose body runs on the instance:
/// `call(instance type) -> status type;` then `name(args) |inst| body;`
/// (the first argument, the instance, is implicit; `call` is [`call`] or
/// `call3`, which checks the instance's version and names the function).
macro_rules! exports {
    ($call:ident($inst:ty) -> $status:ty;
     $($name:ident($($arg:ident: $ty:ty),*) |$i:pat_param| $body:expr;)*) => {$(
        #[no_mangle]
        pub unsafe extern "C" fn $name(instance: $inst, $($arg: $ty),*) -> $status {
            $call(instance, stringify!($name), |$i| $body)
        }
    )*};
}
pub(crate) use exports;

/// Exports getters and setters of either version from one table:
/// `call(instance type) -> status type, "the null-pointer message's
/// names", [nValues];` then `name(value pointer, get_args or set_args)
/// |inst, func, vrs, values| body;`. The FMI 3.0 ones have the number of
/// values as a fifth argument (`[nValues]`); the FMI 2.0 ones as many
/// values as value references (`[]`). `value pointer as *const u8` reads a
/// C `bool` as bytes, so that another byte value cannot be undefined
/// behaviour.
macro_rules! value_exports {
    (@count $nvr:ident) => { $nvr };
    (@count $nvr:ident $nv:ident) => { $nv };
    (@one $call:ident($inst:ty) -> $status:ty, $what:literal, [$($nv:ident)?];
     $name:ident($ptr:ty $(as $cast:ty)?, $args:ident)
     |$i:ident, $func:ident, $vrs:ident, $vals:ident| $body:expr) => {
        #[no_mangle]
        pub unsafe extern "C" fn $name(
            instance: $inst,
            vr: *const u32,
            nvr: libc::size_t,
            values: $ptr,
            $($nv: libc::size_t,)?
        ) -> $status {
            let $func = stringify!($name);
            $call(instance, $func, |$i| {
                let n_values = $crate::shell::value_exports!(@count nvr $($nv)?);
                // SAFETY: FMI passes `nvr` value references and an array of
                // `n_values` values (null only when a count is 0, else refused).
                let ($vrs, $vals) = unsafe {
                    $crate::shell::$args($func, $what, vr, nvr, values $(as $cast)?, n_values)
                }?;
                $body
            })
        }
    };
    ($call:ident($inst:ty) -> $status:ty, $what:literal, $nv:tt;
     $($name:ident($ptr:ty $(as $cast:ty)?, $args:ident)
       |$i:ident, $func:ident, $vrs:ident, $vals:ident| $body:expr;)*) => {$(
        $crate::shell::value_exports! { @one $call($inst) -> $status, $what, $nv;
            $name($ptr $(as $cast)?, $args) |$i, $func, $vrs, $vals| $body
        }
    )*};
}
pub(crate) use value_exports;

/// The body of `fmi2Instantiate` and `fmi3InstantiateCoSimulation`: the
/// instance name (not empty), the version's own `checks`, the token and the
/// resource location from C (`what`: their names in the null-pointer
/// messages), then `make`; a panic is caught and becomes the message.
///
/// # Safety
/// `token` and `res` are null or NUL-terminated strings valid for the call.
pub(crate) unsafe fn instantiate(
    name: Option<&str>,
    token: CText,
    res: CText,
    what: (&str, &str),
    checks: impl FnOnce() -> Result<(), String>,
    make: impl FnOnce(&str, &str, &str) -> Result<Box<Instance>, String>,
) -> Result<Box<Instance>, String> {
    let result = catch_unwind(AssertUnwindSafe(|| {
        let Some(name) = name.filter(|n| !n.is_empty()) else {
            return Err("the instance name is null or empty".to_string());
        };
        checks()?;
        // SAFETY: null or NUL-terminated strings (FMI contract).
        let Some(token) = (unsafe { string(token) }) else {
            return Err(format!("{} is a null pointer", what.0));
        };
        // SAFETY: as above.
        let Some(res) = (unsafe { string(res) }) else {
            return Err(format!("{} is a null pointer", what.1));
        };
        make(name, &token, &res)
    }));
    result.unwrap_or_else(|p| Err(format!("internal error: {}", panic_message(&*p))))
}

/// `fmi2FreeInstance` / `fmi3FreeInstance`: frees the instance behind `c`
/// (null or a foreign pointer: a no-op).
///
/// # Safety
/// `c` is null or an instance this FMU handed out and the environment has
/// not freed; the magic number rejects foreign pointers in most cases.
pub(crate) unsafe fn free_instance(c: Component) {
    // SAFETY: the caller's contract.
    let Some(inst) = (unsafe { Instance::from_ptr(c) }) else {
        return;
    };
    inst.invalidate();
    // SAFETY: the instance was made by `Box::into_raw` at instantiation and
    // is freed once (the magic is cleared above).
    let b = unsafe { Box::from_raw(inst as *mut Instance) };
    let _ = catch_unwind(AssertUnwindSafe(move || drop(b)));
}
