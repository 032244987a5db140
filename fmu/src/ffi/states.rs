//! The FMU-state functions of FMI 2.0 (`fmi2GetFMUstate` ...
//! `fmi2DeSerializeFMUstate`) and their bodies, which the FMI 3.0 ones
//! ([`crate::fmi3::state`]) share: the same snapshots and state bytes.

use std::ffi::c_void;

use libc::size_t;

use super::{call, fmi2Byte, fmi2Component, fmi2FMUstate, fmi2Status, null, ok, slice};
use crate::instance::{error, Instance, Res, Snapshot, Status};

#[no_mangle]
pub unsafe extern "C" fn fmi2GetFMUstate(
    c: fmi2Component,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    call(c, "fmi2GetFMUstate", |inst| {
        // SAFETY: forwarded from the caller (FMI contract).
        unsafe { get_state(inst, "fmi2GetFMUstate", FMUstate) }
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetFMUstate(c: fmi2Component, FMUstate: fmi2FMUstate) -> fmi2Status {
    // SAFETY: forwarded from the caller (FMI contract).
    call(c, "fmi2SetFMUstate", |inst| unsafe {
        set_state(inst, FMUstate)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2FreeFMUstate(
    c: fmi2Component,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    // SAFETY: forwarded from the caller (FMI contract).
    call(c, "fmi2FreeFMUstate", |_| unsafe { free_state(FMUstate) })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
    c: fmi2Component,
    FMUstate: fmi2FMUstate,
    size: *mut size_t,
) -> fmi2Status {
    call(c, "fmi2SerializedFMUstateSize", |inst| {
        // SAFETY: forwarded from the caller (FMI contract).
        unsafe { state_size(inst, "fmi2SerializedFMUstateSize", FMUstate, size) }
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: fmi2Component,
    FMUstate: fmi2FMUstate,
    serializedState: *mut fmi2Byte,
    size: size_t,
) -> fmi2Status {
    call(c, "fmi2SerializeFMUstate", |inst| {
        // SAFETY: forwarded from the caller (FMI contract).
        unsafe {
            serialize_state(
                inst,
                "fmi2SerializeFMUstate",
                "fmi2SerializedFMUstateSize",
                FMUstate,
                serializedState as *mut u8,
                size,
            )
        }
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: fmi2Component,
    serializedState: *const fmi2Byte,
    size: size_t,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    call(c, "fmi2DeSerializeFMUstate", |inst| {
        // SAFETY: forwarded from the caller (FMI contract).
        unsafe {
            deserialize_state(
                inst,
                "fmi2DeSerializeFMUstate",
                serializedState as *const u8,
                size,
                FMUstate,
            )
        }
    })
}

/// `fmi2GetFMUstate` / `fmi3GetFMUState`: a new state into `*FMUstate`, or
/// the state already there overwritten.
///
/// # Safety
/// `FMUstate` is null or points to the environment's state slot, which is
/// null or holds a state this FMU handed out.
pub(crate) unsafe fn get_state(
    inst: &mut Instance,
    func: &str,
    FMUstate: *mut *mut c_void,
) -> Res<Status> {
    // SAFETY: `FMUstate` is null or points to the environment's state slot.
    let Some(slot) = (unsafe { FMUstate.as_mut() }) else {
        return null(func, "FMUstate");
    };
    let existing = if slot.is_null() {
        None
    } else {
        // SAFETY: a non-null slot holds a state this FMU handed out
        // (FMI contract); the magic number rejects others.
        match unsafe { Snapshot::from_ptr(*slot) } {
            Some(s) => Some(s),
            None => return error("*FMUstate is not an FMU state of this FMU"),
        }
    };
    if let Some(new) = inst.get_fmu_state(existing)? {
        *slot = Box::into_raw(new) as fmi2FMUstate;
    }
    Ok(Status::Ok)
}

/// `fmi2SetFMUstate` / `fmi3SetFMUState`.
///
/// # Safety
/// `FMUstate` is null or a state this FMU handed out.
pub(crate) unsafe fn set_state(inst: &mut Instance, FMUstate: *mut c_void) -> Res<Status> {
    // SAFETY: null or a state this FMU handed out (checked by its magic).
    let Some(s) = (unsafe { Snapshot::from_ptr(FMUstate) }) else {
        return error("FMUstate is null or not an FMU state of this FMU");
    };
    ok(inst.set_fmu_state(s))
}

/// `fmi2FreeFMUstate` / `fmi3FreeFMUState`: frees `*FMUstate` and clears
/// the slot; a null slot or state is a no-op.
///
/// # Safety
/// `FMUstate` is null or points to the environment's state slot.
pub(crate) unsafe fn free_state(FMUstate: *mut *mut c_void) -> Res<Status> {
    // SAFETY: `FMUstate` is null or points to the environment's state slot.
    let Some(slot) = (unsafe { FMUstate.as_mut() }) else {
        return Ok(Status::Ok);
    };
    if slot.is_null() {
        return Ok(Status::Ok);
    }
    // SAFETY: a non-null slot holds a state this FMU handed out.
    let Some(s) = (unsafe { Snapshot::from_ptr(*slot) }) else {
        return error("*FMUstate is not an FMU state of this FMU");
    };
    // SAFETY: states are made by `Box::into_raw`; the slot is cleared
    // below, so it is freed once.
    drop(unsafe { Box::from_raw(s as *mut Snapshot) });
    *slot = std::ptr::null_mut();
    Ok(Status::Ok)
}

/// `fmi2SerializedFMUstateSize` / `fmi3SerializedFMUStateSize`.
///
/// # Safety
/// `FMUstate` is null or a state this FMU handed out; `size` is null or
/// points to a writable `size_t`.
pub(crate) unsafe fn state_size(
    inst: &mut Instance,
    func: &str,
    FMUstate: *mut c_void,
    size: *mut size_t,
) -> Res<Status> {
    // SAFETY: null or a state this FMU handed out (checked by its magic).
    let Some(s) = (unsafe { Snapshot::from_ptr(FMUstate) }) else {
        return error("FMUstate is null or not an FMU state of this FMU");
    };
    // SAFETY: `size` is null or points to a writable size_t.
    let Some(size) = (unsafe { size.as_mut() }) else {
        return null(func, "size");
    };
    *size = inst.serialize(func, s)?.len();
    Ok(Status::Ok)
}

/// `fmi2SerializeFMUstate` / `fmi3SerializeFMUState` into a buffer of
/// `size` bytes (`size_func`: the function that tells the size).
///
/// # Safety
/// `FMUstate` is null or a state this FMU handed out; `buf` is null or
/// holds `size` writable bytes.
pub(crate) unsafe fn serialize_state(
    inst: &mut Instance,
    func: &str,
    size_func: &str,
    FMUstate: *mut c_void,
    buf: *mut u8,
    size: size_t,
) -> Res<Status> {
    // SAFETY: null or a state this FMU handed out (checked by its magic).
    let Some(s) = (unsafe { Snapshot::from_ptr(FMUstate) }) else {
        return error("FMUstate is null or not an FMU state of this FMU");
    };
    let bytes = inst.serialize(func, s)?;
    if size < bytes.len() {
        return error(format!(
            "buffer of {size} bytes is smaller than the state's {} ({size_func})",
            bytes.len()
        ));
    }
    if buf.is_null() {
        return null(func, "serializedState");
    }
    // SAFETY: the buffer is non-null and holds `size` >= len bytes
    // (FMI contract); it does not overlap the snapshot's own bytes.
    unsafe { std::ptr::copy_nonoverlapping(bytes.as_ptr(), buf, bytes.len()) };
    Ok(Status::Ok)
}

/// `fmi2DeSerializeFMUstate` / `fmi3DeserializeFMUState`: a new state from
/// `size` bytes into `*FMUstate` (a state already there is freed).
///
/// # Safety
/// `bytes` is null or holds `size` readable bytes; `FMUstate` is null or
/// points to the environment's state slot.
pub(crate) unsafe fn deserialize_state(
    inst: &mut Instance,
    func: &str,
    bytes: *const u8,
    size: size_t,
    FMUstate: *mut *mut c_void,
) -> Res<Status> {
    // SAFETY: FMI passes `size` bytes of a serialized state.
    let Some(bytes) = (unsafe { slice(bytes, size) }) else {
        return null(func, "serializedState");
    };
    // SAFETY: `FMUstate` is null or points to the environment's state slot.
    let Some(slot) = (unsafe { FMUstate.as_mut() }) else {
        return null(func, "FMUstate");
    };
    let old = if slot.is_null() {
        None
    } else {
        // SAFETY: a non-null slot holds a state this FMU handed out.
        match unsafe { Snapshot::from_ptr(*slot) } {
            Some(s) => Some(s as *mut Snapshot),
            None => return error("*FMUstate is not an FMU state of this FMU"),
        }
    };
    let new = inst.deserialize(bytes)?;
    if let Some(old) = old {
        // SAFETY: made by `Box::into_raw`; the slot is overwritten
        // below, so the old state is freed once.
        drop(unsafe { Box::from_raw(old) });
    }
    *slot = Box::into_raw(new) as *mut c_void;
    Ok(Status::Ok)
}
