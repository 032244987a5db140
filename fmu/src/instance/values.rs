//! The instance's Get and Set functions for Real, Integer, Boolean and
//! String values: the allowed-state check, then the model's values.

use super::*;

impl Instance {
    /// Values that depend on the simulated state need a built simulation.
    /// After a diverged step they are those of the last good state (at
    /// `lastSuccessfulTime`), which the failed step restored.
    fn require_state(&mut self) -> Res {
        self.model.ensure_built(self.count)
    }

    pub fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> Res {
        self.require("fmi2GetReal")?;
        for (k, &vr) in vrs.iter().enumerate() {
            if self.model.physics.is_state_output(vr) {
                self.require_state()?;
            }
            let Some(v) = self.model.physics.get_real(vr) else {
                return error(format!(
                    "fmi2GetReal: no Real variable has value reference {vr}"
                ));
            };
            if !v.is_finite() {
                return error(format!(
                    "fmi2GetReal: value reference {vr} is not finite ({v}) at t = {}",
                    self.model.clock.time
                ));
            }
            out[k] = v;
        }
        Ok(())
    }

    pub fn get_integer(&mut self, vrs: &[u32], out: &mut [c_int]) -> Res {
        self.require("fmi2GetInteger")?;
        for (k, &vr) in vrs.iter().enumerate() {
            out[k] = match vr {
                // Saturates instead of wrapping past 2^31 - 1 substeps.
                VR_SUBSTEPS => self.model.clock.substeps.min(c_int::MAX as u64) as c_int,
                VR_MAX_SUBSTEPS => self.execution.max_substeps as c_int,
                VR_THREADS => self.execution.threads as c_int,
                _ => {
                    return error(format!(
                        "fmi2GetInteger: no Integer variable has value reference {vr}"
                    ))
                }
            };
        }
        Ok(())
    }

    pub fn get_boolean(&mut self, vrs: &[u32], out: &mut [c_int]) -> Res {
        self.require("fmi2GetBoolean")?;
        for (k, &vr) in vrs.iter().enumerate() {
            let Some(v) = self.model.physics.get_boolean(vr) else {
                return error(format!(
                    "fmi2GetBoolean: no Boolean variable has value reference {vr}"
                ));
            };
            out[k] = v as c_int;
        }
        Ok(())
    }

    /// Returns the strings; they stay valid until the next call.
    pub fn get_string(&mut self, vrs: &[u32]) -> Res<&[CString]> {
        self.require("fmi2GetString")?;
        self.strings.clear();
        for &vr in vrs {
            let Some(v) = self.model.physics.get_string(vr) else {
                return error(format!(
                    "fmi2GetString: no String variable has value reference {vr}"
                ));
            };
            self.strings.push(escape_nul(v));
        }
        Ok(&self.strings)
    }

    /// Runs one of the model's setters where inputs may be set; it may set
    /// parameters only while [`parameter_settable`], and a changed parameter
    /// marks the simulation for rebuilding.
    fn set_values(
        &mut self,
        func: &str,
        set: impl FnOnce(&mut dyn FmuModel, ParamCheck, &SetContext) -> ModelResult<bool>,
    ) -> Res {
        self.require(func)?;
        let phase = self.phase;
        let check = |vr: u32| parameter_settable(phase, func, vr).map_err(|f| ModelError(f.msg));
        let ctx = SetContext {
            resources: &self.resources,
            bundled: &self.bundled,
        };
        let changed = set(self.model.physics.as_mut(), &check, &ctx)?;
        self.model.clock.dirty |= changed;
        self.model.outputs_checked = false;
        Ok(())
    }

    pub fn set_real(&mut self, vrs: &[u32], vals: &[f64]) -> Res {
        self.set_values("fmi2SetReal", |m, check, _| {
            if let Some((vr, v)) = vrs.iter().zip(vals).find(|(_, v)| !v.is_finite()) {
                return Err(ModelError(format!(
                    "value {v} for value reference {vr} is not finite"
                )));
            }
            m.set_real(vrs, vals, check)
        })
    }

    /// Sets the execution parameters `max_substeps_per_step` and `threads`
    /// (fixed: only before `fmi2ExitInitializationMode`). A rejected call
    /// changes nothing.
    pub fn set_integer(&mut self, vrs: &[u32], vals: &[c_int]) -> Res {
        self.require("fmi2SetInteger")?;
        let mut e = self.execution;
        for (&vr, &v) in vrs.iter().zip(vals) {
            match vr {
                VR_MAX_SUBSTEPS | VR_THREADS => {
                    parameter_settable(self.phase, "fmi2SetInteger", vr)?
                }
                _ => {
                    return error(format!(
                        "fmi2SetInteger: value reference {vr} is not an Integer input or parameter"
                    ))
                }
            }
            if vr == VR_MAX_SUBSTEPS {
                if v < 1 {
                    return error(format!(
                        "fmi2SetInteger: max_substeps_per_step = {v} must be at least 1"
                    ));
                }
                e.max_substeps = v as u32;
            } else {
                if !(0..=MAX_THREADS as c_int).contains(&v) {
                    return error(format!(
                        "fmi2SetInteger: threads = {v} must be 0 (all cores) to {MAX_THREADS}"
                    ));
                }
                e.threads = v as u32;
            }
        }
        self.execution = e;
        Ok(())
    }

    pub fn set_boolean(&mut self, vrs: &[u32], vals: &[c_int]) -> Res {
        let vals: Vec<bool> = vals.iter().map(|&v| v != 0).collect();
        self.set_values("fmi2SetBoolean", |m, check, _| {
            m.set_boolean(vrs, &vals, check)
        })
    }

    pub fn set_string(&mut self, vrs: &[u32], vals: &[Option<String>]) -> Res {
        self.set_values("fmi2SetString", |m, check, ctx| {
            m.set_string(vrs, vals, check, ctx)
        })
    }
}
