//! The FMI 2.0 getters and setters: Real, Integer, Boolean (a C `int`) and
//! String, as many values as value references; the table is the one the
//! FMI 3.0 getters and setters share (`crate::shell::value_exports`).

use super::*;
use crate::shell::{get_strings, ok, set_strings, value_exports};

value_exports! { call(fmi2Component) -> fmi2Status, "vr or value", [];
    fmi2GetReal(*mut fmi2Real, get_args) |inst, _f, vrs, out| ok(inst.get_real(vrs, out));
    fmi2GetInteger(*mut fmi2Integer, get_args) |inst, _f, vrs, out| ok(inst.get_integer(vrs, out));
    fmi2GetBoolean(*mut fmi2Boolean, get_args) |inst, _f, vrs, out| ok(inst.get_boolean(vrs, out));
    fmi2GetString(*mut fmi2String, get_args) |inst, _f, vrs, out| get_strings(inst, vrs, out);
    fmi2SetReal(*const fmi2Real, set_args) |inst, _f, vrs, vals| ok(inst.set_real(vrs, vals));
    fmi2SetInteger(*const fmi2Integer, set_args) |inst, _f, vrs, vals| ok(inst.set_integer(vrs, vals));
    fmi2SetBoolean(*const fmi2Boolean, set_args) |inst, _f, vrs, vals| ok(inst.set_boolean(vrs, vals));
    // SAFETY: each value is null or a NUL-terminated string (FMI contract).
    fmi2SetString(*const fmi2String, set_args) |inst, _f, vrs, vals| unsafe { set_strings(inst, vrs, vals) };
}
