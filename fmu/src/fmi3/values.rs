//! The FMI 3.0 getters and setters of the types this FMU has: Float64
//! (scalars and the array outputs, `nValues` checked against the sum of the
//! array sizes), Int32 (the substep count and the execution parameters),
//! Boolean (a C `bool`) and String.

use std::ffi::c_int;

use libc::size_t;

use super::*;
use crate::ffi::{null, ok, slice, slice_mut, string};

/// The value references and a mutable value array from C, or the
/// null-pointer failure.
///
/// # Safety
/// As [`slice`] and [`slice_mut`].
unsafe fn get_args<'a, T>(
    func: &str,
    vr: *const fmi3ValueReference,
    nvr: size_t,
    values: *mut T,
    n_values: size_t,
) -> Result<(&'a [u32], &'a mut [T]), crate::instance::Fail> {
    // SAFETY: FMI passes `nvr` value references and a writable array of
    // `n_values` values (null only when the count is 0, else refused).
    match unsafe { (slice(vr, nvr), slice_mut(values, n_values)) } {
        (Some(v), Some(o)) => Ok((v, o)),
        _ => Err(null(func, "valueReferences or values").unwrap_err()),
    }
}

/// The value references and a value array from C, or the null-pointer
/// failure.
///
/// # Safety
/// As [`slice`].
unsafe fn set_args<'a, T>(
    func: &str,
    vr: *const fmi3ValueReference,
    nvr: size_t,
    values: *const T,
    n_values: size_t,
) -> Result<(&'a [u32], &'a [T]), crate::instance::Fail> {
    // SAFETY: FMI passes `nvr` value references and `n_values` values
    // (null only when the count is 0, else refused).
    match unsafe { (slice(vr, nvr), slice(values, n_values)) } {
        (Some(v), Some(o)) => Ok((v, o)),
        _ => Err(null(func, "valueReferences or values").unwrap_err()),
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetFloat64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: size_t,
    values: *mut fmi3Float64,
    nValues: size_t,
) -> fmi3Status {
    let func = "fmi3GetFloat64";
    call3(instance, func, |inst| {
        // SAFETY: the caller's arrays (FMI contract).
        let (vrs, out) =
            unsafe { get_args(func, valueReferences, nValueReferences, values, nValues) }?;
        ok(inst.get_float64(vrs, out))
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetFloat64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: size_t,
    values: *const fmi3Float64,
    nValues: size_t,
) -> fmi3Status {
    let func = "fmi3SetFloat64";
    call3(instance, func, |inst| {
        // SAFETY: the caller's arrays (FMI contract).
        let (vrs, vals) =
            unsafe { set_args(func, valueReferences, nValueReferences, values, nValues) }?;
        ok(inst.set_float64(vrs, vals))
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetInt32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: size_t,
    values: *mut fmi3Int32,
    nValues: size_t,
) -> fmi3Status {
    let func = "fmi3GetInt32";
    call3(instance, func, |inst| {
        // SAFETY: the caller's arrays (FMI contract).
        let (vrs, out) =
            unsafe { get_args(func, valueReferences, nValueReferences, values, nValues) }?;
        inst.check_scalars(func, vrs, out.len())?;
        ok(inst.get_integer(vrs, out))
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetInt32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: size_t,
    values: *const fmi3Int32,
    nValues: size_t,
) -> fmi3Status {
    let func = "fmi3SetInt32";
    call3(instance, func, |inst| {
        // SAFETY: the caller's arrays (FMI contract).
        let (vrs, vals) =
            unsafe { set_args(func, valueReferences, nValueReferences, values, nValues) }?;
        inst.check_scalars(func, vrs, vals.len())?;
        ok(inst.set_integer(vrs, vals))
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetBoolean(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: size_t,
    values: *mut fmi3Boolean,
    nValues: size_t,
) -> fmi3Status {
    let func = "fmi3GetBoolean";
    call3(instance, func, |inst| {
        // SAFETY: the caller's arrays (FMI contract).
        let (vrs, out) =
            unsafe { get_args(func, valueReferences, nValueReferences, values, nValues) }?;
        inst.check_scalars(func, vrs, out.len())?;
        let mut ints: Vec<c_int> = vec![0; vrs.len()];
        inst.get_boolean(vrs, &mut ints)?;
        for (o, i) in out.iter_mut().zip(ints) {
            *o = i != 0;
        }
        Ok(Status::Ok)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetBoolean(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: size_t,
    values: *const fmi3Boolean,
    nValues: size_t,
) -> fmi3Status {
    let func = "fmi3SetBoolean";
    call3(instance, func, |inst| {
        // SAFETY: the caller's arrays (FMI contract); a C `bool` holds 0 or
        // 1, read as bytes so that another byte value cannot be undefined
        // behaviour.
        let (vrs, vals) = unsafe {
            set_args(
                func,
                valueReferences,
                nValueReferences,
                values as *const u8,
                nValues,
            )
        }?;
        inst.check_scalars(func, vrs, vals.len())?;
        let ints: Vec<c_int> = vals.iter().map(|&b| c_int::from(b != 0)).collect();
        ok(inst.set_boolean(vrs, &ints))
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetString(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: size_t,
    values: *mut fmi3String,
    nValues: size_t,
) -> fmi3Status {
    let func = "fmi3GetString";
    call3(instance, func, |inst| {
        // SAFETY: the caller's arrays (FMI contract).
        let (vrs, out) =
            unsafe { get_args(func, valueReferences, nValueReferences, values, nValues) }?;
        inst.check_scalars(func, vrs, out.len())?;
        let strings = inst.get_string(vrs)?;
        for (o, s) in out.iter_mut().zip(strings) {
            *o = s.as_ptr();
        }
        Ok(Status::Ok)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetString(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: size_t,
    values: *const fmi3String,
    nValues: size_t,
) -> fmi3Status {
    let func = "fmi3SetString";
    call3(instance, func, |inst| {
        // SAFETY: the caller's arrays (FMI contract).
        let (vrs, vals) =
            unsafe { set_args(func, valueReferences, nValueReferences, values, nValues) }?;
        inst.check_scalars(func, vrs, vals.len())?;
        // SAFETY: each value is null or a NUL-terminated string (FMI contract).
        let vals: Vec<Option<String>> = vals.iter().map(|&p| unsafe { string(p) }).collect();
        ok(inst.set_string(vrs, &vals))
    })
}
