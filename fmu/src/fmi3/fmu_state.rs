//! FMI 3.0 FMU states (get, set, free, serialize, deserialize; the bytes
//! are the FMI 2.0 FMU's framing, [`crate::models::state_bytes`]) and the variable
//! dependencies of the outputs.

use libc::size_t;

use super::*;
use crate::instance::Operation;
use crate::shell::{null, slice_mut, state_exports};

state_exports! { call3(fmi3Instance) -> fmi3Status, fmi3FMUState, fmi3Byte;
    fmi3GetFMUState, fmi3SetFMUState, fmi3FreeFMUState,
    fmi3SerializedFMUStateSize, fmi3SerializeFMUState, fmi3DeserializeFMUState
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetNumberOfVariableDependencies(
    instance: fmi3Instance,
    valueReference: fmi3ValueReference,
    nDependencies: *mut size_t,
) -> fmi3Status {
    let func = "fmi3GetNumberOfVariableDependencies";
    call3(instance, func, |inst| {
        inst.require(Operation::GetNumberOfVariableDependencies)?;
        // SAFETY: null or a writable size_t (FMI contract).
        let Some(n) = (unsafe { nDependencies.as_mut() }) else {
            return null(func, "nDependencies");
        };
        *n = inst.variable_dependencies(valueReference)?.len();
        Ok(Status::Ok)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetVariableDependencies(
    instance: fmi3Instance,
    dependent: fmi3ValueReference,
    elementIndicesOfDependent: *mut size_t,
    independents: *mut fmi3ValueReference,
    elementIndicesOfIndependents: *mut size_t,
    dependencyKinds: *mut fmi3DependencyKind,
    nDependencies: size_t,
) -> fmi3Status {
    let func = "fmi3GetVariableDependencies";
    call3(instance, func, |inst| {
        inst.require(Operation::GetVariableDependencies)?;
        let deps = inst.variable_dependencies(dependent)?;
        if deps.len() != nDependencies {
            return crate::instance::error(format!(
                "{func}: nDependencies = {nDependencies}, but {} has {} (fmi3GetNumberOfVariableDependencies)",
                inst.shown(dependent),
                deps.len()
            ));
        }
        // SAFETY: FMI passes four writable arrays of `nDependencies`
        // elements (null only when it is 0, else refused).
        let arrays = unsafe {
            (
                slice_mut(elementIndicesOfDependent, nDependencies),
                slice_mut(independents, nDependencies),
                slice_mut(elementIndicesOfIndependents, nDependencies),
                slice_mut(dependencyKinds, nDependencies),
            )
        };
        let (Some(ed), Some(ind), Some(ei), Some(kinds)) = arrays else {
            return null(func, "an output array");
        };
        // Element index 0: the whole variable (no per-element dependencies).
        for (k, vr) in deps.into_iter().enumerate() {
            ed[k] = 0;
            ind[k] = vr;
            ei[k] = 0;
            kinds[k] = fmi3Dependent;
        }
        Ok(Status::Ok)
    })
}
