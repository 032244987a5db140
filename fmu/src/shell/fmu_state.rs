//! The bodies of the FMU-state functions both versions export
//! (`fmi2GetFMUstate` ... `fmi2DeSerializeFMUstate`, [`crate::fmi2::fmu_state`];
//! `fmi3GetFMUState` ... `fmi3DeserializeFMUState`, [`crate::fmi3::fmu_state`]):
//! the same snapshots and state bytes.

use std::ffi::c_void;

use libc::size_t;

use super::{null, ok, slice};
use crate::instance::{error, Instance, Operation, Res, Snapshot, Status};

/// Exports the six FMU-state functions of either version over the bodies
/// below: `call(instance type) -> status type, state type, byte type; get,
/// set, free, size, serialize, deserialize`.
macro_rules! state_exports {
    ($call:ident($inst:ty) -> $status:ty, $state:ty, $byte:ty;
     $get:ident, $set:ident, $free:ident, $size:ident, $ser:ident, $deser:ident) => {
        $crate::shell::exports! { $call($inst) -> $status;
            $get(FMUstate: *mut $state) |inst| {
                // SAFETY: forwarded from the caller (FMI contract).
                unsafe { $crate::shell::get_state(inst, stringify!($get), FMUstate) }
            };
            $set(FMUstate: $state) |inst| {
                // SAFETY: forwarded from the caller (FMI contract).
                unsafe { $crate::shell::set_state(inst, FMUstate) }
            };
            $free(FMUstate: *mut $state) |_| {
                // SAFETY: forwarded from the caller (FMI contract).
                unsafe { $crate::shell::free_state(FMUstate) }
            };
            $size(FMUstate: $state, size: *mut libc::size_t) |inst| {
                // SAFETY: forwarded from the caller (FMI contract).
                unsafe { $crate::shell::state_size(inst, stringify!($size), FMUstate, size) }
            };
            $ser(FMUstate: $state, serializedState: *mut $byte, size: libc::size_t) |inst| {
                let (func, size_func) = (stringify!($ser), stringify!($size));
                let buf = serializedState.cast::<u8>();
                // SAFETY: forwarded from the caller (FMI contract).
                unsafe { $crate::shell::serialize_state(inst, func, size_func, FMUstate, buf, size) }
            };
            $deser(serializedState: *const $byte, size: libc::size_t, FMUstate: *mut $state) |inst| {
                let bytes = serializedState.cast::<u8>();
                // SAFETY: forwarded from the caller (FMI contract).
                unsafe { $crate::shell::deserialize_state(inst, stringify!($deser), bytes, size, FMUstate) }
            };
        }
    };
}
pub(crate) use state_exports;

/// The environment's state slot and the state already in it (none where
/// the slot holds null), for the functions that write a state into it.
///
/// # Safety
/// `FMUstate` is null or points to the environment's state slot, which is
/// null or holds a state this FMU handed out.
unsafe fn state_slot<'a>(
    func: &str,
    FMUstate: *mut *mut c_void,
) -> Res<(&'a mut *mut c_void, Option<&'a mut Snapshot>)> {
    // SAFETY: `FMUstate` is null or points to the environment's state slot.
    let Some(slot) = (unsafe { FMUstate.as_mut() }) else {
        return null(func, "FMUstate");
    };
    if slot.is_null() {
        return Ok((slot, None));
    }
    // SAFETY: a non-null slot holds a state this FMU handed out
    // (FMI contract); the magic number rejects others.
    match unsafe { Snapshot::from_ptr(*slot) } {
        Some(s) => Ok((slot, Some(s))),
        None => error("*FMUstate is not an FMU state of this FMU"),
    }
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
    // SAFETY: as this function's contract.
    let (slot, existing) = unsafe { state_slot(func, FMUstate) }?;
    if let Some(new) = inst.get_fmu_state(existing)? {
        *slot = Box::into_raw(new) as *mut c_void;
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
    *size = inst.serialize(Operation::SerializedFmuStateSize, s)?.len();
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
    let bytes = inst.serialize(Operation::SerializeFmuState, s)?;
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
    // SAFETY: as this function's contract.
    let (slot, old) = unsafe { state_slot(func, FMUstate) }?;
    let old = old.map(|s| s as *mut Snapshot);
    let new = inst.deserialize(bytes)?;
    if let Some(old) = old {
        // SAFETY: made by `Box::into_raw`; the slot is overwritten
        // below, so the old state is freed once.
        drop(unsafe { Box::from_raw(old) });
    }
    *slot = Box::into_raw(new) as *mut c_void;
    Ok(Status::Ok)
}
