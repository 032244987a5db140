//! The shell around every export of either FMI version: [`call`] (the
//! instance check, the logged failures, the caught panics) and the helpers
//! that turn C pointers into Rust values.

use std::ffi::CStr;
use std::panic::{catch_unwind, AssertUnwindSafe};

use libc::size_t;

use super::{fmi2Component, fmi2Error, fmi2Fatal, fmi2Status, fmi2String};
use crate::instance::{
    error, message_in, Instance, Phase, Res, Status, LOG_ALL, LOG_DISCARD, LOG_ERROR, LOG_FATAL,
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

/// Runs `f` on the instance behind `c`: null or foreign pointers give
/// fmi2Error, failures are logged (fmi2Error moves the instance to the error
/// state), panics are caught and give fmi2Fatal.
pub(crate) fn call(
    c: fmi2Component,
    func: &str,
    f: impl FnOnce(&mut Instance) -> Res<Status>,
) -> fmi2Status {
    // SAFETY: `c` is null or a component this FMU handed out (FMI contract);
    // the magic number rejects freed or foreign pointers in most cases.
    let Some(inst) = (unsafe { Instance::from_ptr(c) }) else {
        return fmi2Error;
    };
    if inst.phase == Phase::Fatal {
        inst.log(
            Status::Fatal,
            LOG_FATAL,
            &format!(
                "{func}: the instance is in the fatal state; only fmi2FreeInstance is allowed"
            ),
        );
        return fmi2Fatal;
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
        Ok(Ok(s)) => s as fmi2Status,
        Ok(Err(fail)) => {
            let cat = match fail.status {
                Status::Discard => LOG_DISCARD,
                Status::Fatal => LOG_FATAL,
                _ => LOG_ERROR,
            };
            // An FMI 3.0 instance's messages in FMI 3.0 words (FMI 2.0: unchanged).
            let shown = message_in(inst.api, &fail.msg);
            let msg = if shown.starts_with(func) {
                shown
            } else {
                format!("{func}: {shown}")
            };
            inst.log(fail.status, cat, &msg);
            match fail.status {
                Status::Error => inst.phase = Phase::Error,
                Status::Fatal => inst.phase = Phase::Fatal,
                _ => {}
            }
            fail.status as fmi2Status
        }
        Err(p) => {
            inst.phase = Phase::Fatal;
            inst.log(
                Status::Fatal,
                LOG_FATAL,
                &format!("{func}: internal error: {}", panic_message(&*p)),
            );
            fmi2Fatal
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
pub(crate) unsafe fn string(p: fmi2String) -> Option<String> {
    // SAFETY: non-null and NUL-terminated (the caller's contract).
    (!p.is_null()).then(|| unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
}

pub(crate) fn null(func: &str, what: &str) -> Res<Status> {
    error(format!("{func}: {what} is a null pointer"))
}
