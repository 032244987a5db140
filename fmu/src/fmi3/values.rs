//! The FMI 3.0 getters and setters of the types this FMU has: Float64
//! (scalars and the array outputs, `nValues` checked against the sum of the
//! array sizes), Int32 (the substep count and the execution parameters),
//! Boolean (a C `bool`) and String. The table is that of the FMI 2.0 ones
//! (`crate::shell::value_exports`), with `nValues`.

use std::ffi::c_int;

use super::*;
use crate::instance::Res;
use crate::shell::{get_strings, ok, set_strings, value_exports};

/// The FMI 3.0 C `bool`s as the FMI 2.0 `int`s that [`Instance`] reads.
fn ints_of(vals: &[u8]) -> Vec<c_int> {
    vals.iter().map(|&b| c_int::from(b != 0)).collect()
}

/// `fmi3GetBoolean`: the FMI 2.0 `int`s as C `bool`s.
fn get_bools(inst: &mut Instance, vrs: &[u32], out: &mut [fmi3Boolean]) -> Res<Status> {
    let mut ints: Vec<c_int> = vec![0; vrs.len()];
    inst.get_boolean(vrs, &mut ints)?;
    for (o, i) in out.iter_mut().zip(ints) {
        *o = i != 0;
    }
    Ok(Status::Ok)
}

value_exports! { call3(fmi3Instance) -> fmi3Status, "valueReferences or values", [nValues];
    fmi3GetFloat64(*mut fmi3Float64, get_args) |inst, _f, vrs, out| ok(inst.get_float64(vrs, out));
    fmi3SetFloat64(*const fmi3Float64, set_args) |inst, _f, vrs, vals| ok(inst.set_float64(vrs, vals));
    fmi3GetInt32(*mut fmi3Int32, get_args) |inst, func, vrs, out| {
        inst.check_scalars(func, vrs, out.len())?;
        ok(inst.get_integer(vrs, out))
    };
    fmi3SetInt32(*const fmi3Int32, set_args) |inst, func, vrs, vals| {
        inst.check_scalars(func, vrs, vals.len())?;
        ok(inst.set_integer(vrs, vals))
    };
    fmi3GetBoolean(*mut fmi3Boolean, get_args) |inst, func, vrs, out| {
        inst.check_scalars(func, vrs, out.len())?;
        get_bools(inst, vrs, out)
    };
    fmi3SetBoolean(*const fmi3Boolean as *const u8, set_args) |inst, func, vrs, vals| {
        inst.check_scalars(func, vrs, vals.len())?;
        ok(inst.set_boolean(vrs, &ints_of(vals)))
    };
    fmi3GetString(*mut fmi3String, get_args) |inst, func, vrs, out| {
        inst.check_scalars(func, vrs, out.len())?;
        get_strings(inst, vrs, out)
    };
    fmi3SetString(*const fmi3String, set_args) |inst, func, vrs, vals| {
        inst.check_scalars(func, vrs, vals.len())?;
        // SAFETY: each value is null or a NUL-terminated string (FMI contract).
        unsafe { set_strings(inst, vrs, vals) }
    };
}
