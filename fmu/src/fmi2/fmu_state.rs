//! The FMI 2.0 FMU-state functions (`fmi2GetFMUstate` ...
//! `fmi2DeSerializeFMUstate`) over the bodies both versions share
//! (`shell/fmu_state.rs`).

use super::*;
use crate::shell::state_exports;

state_exports! { call(fmi2Component) -> fmi2Status, fmi2FMUstate, fmi2Byte;
    fmi2GetFMUstate, fmi2SetFMUstate, fmi2FreeFMUstate,
    fmi2SerializedFMUstateSize, fmi2SerializeFMUstate, fmi2DeSerializeFMUstate
}
