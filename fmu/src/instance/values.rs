//! The instance's Get and Set functions for Real, Integer, Boolean and
//! String values: the allowed-state check, then the model's values.

use super::*;

impl Instance {
    /// Values that depend on the simulated state need a built simulation.
    /// After a diverged step they are those of the last good state (at
    /// `lastSuccessfulTime`), which the failed step restored.
    fn require_built(&mut self) -> Res {
        self.model.ensure_built(self.count)
    }

    /// The refusal of `vr` where a `what` ("Real variable") was asked for:
    /// `attractor.active (value reference 4) is not a Real variable`, or
    /// `no Real variable has value reference 99`.
    fn not_a(&self, vr: u32, what: &str) -> String {
        match self.variable(vr) {
            Some(_) => {
                let a = if what.starts_with(['A', 'E', 'I', 'O', 'U']) {
                    "an"
                } else {
                    "a"
                };
                format!("{} is not {a} {what}", self.shown(vr))
            }
            None => format!("no {what} has value reference {vr}"),
        }
    }

    pub fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> Res {
        self.require(Operation::GetFloat)?;
        for (k, &vr) in vrs.iter().enumerate() {
            if self.model.physics.is_simulated_output(vr) {
                self.require_built()?;
            }
            let Some(v) = self.model.physics.get_real(vr) else {
                return error(format!(
                    "{}: {}",
                    self.op_name(Operation::GetFloat),
                    self.not_a(vr, "Real variable")
                ));
            };
            if !v.is_finite() {
                return error(format!(
                    "{}: {} is not finite ({v}) at t = {}",
                    self.op_name(Operation::GetFloat),
                    self.shown(vr),
                    self.model.clock.time
                ));
            }
            out[k] = v;
        }
        Ok(())
    }

    pub fn get_integer(&mut self, vrs: &[u32], out: &mut [c_int]) -> Res {
        self.require(Operation::GetInteger)?;
        for (k, &vr) in vrs.iter().enumerate() {
            out[k] = match vr {
                // Saturates instead of wrapping past 2^31 - 1 substeps.
                VR_SUBSTEPS => self.model.clock.substeps.min(c_int::MAX as u64) as c_int,
                VR_MAX_SUBSTEPS => self.execution.max_substeps as c_int,
                VR_THREADS => self.execution.threads as c_int,
                _ => {
                    return error(format!(
                        "{}: {}",
                        self.op_name(Operation::GetInteger),
                        self.not_a(vr, "Integer variable")
                    ))
                }
            };
        }
        Ok(())
    }

    pub fn get_boolean(&mut self, vrs: &[u32], out: &mut [c_int]) -> Res {
        self.require(Operation::GetBoolean)?;
        for (k, &vr) in vrs.iter().enumerate() {
            let Some(v) = self.model.physics.get_boolean(vr) else {
                return error(format!(
                    "{}: {}",
                    self.op_name(Operation::GetBoolean),
                    self.not_a(vr, "Boolean variable")
                ));
            };
            out[k] = v as c_int;
        }
        Ok(())
    }

    /// Returns the strings; they stay valid until the next call.
    pub fn get_string(&mut self, vrs: &[u32]) -> Res<&[CString]> {
        self.require(Operation::GetString)?;
        self.strings.clear();
        for &vr in vrs {
            let Some(v) = self.model.physics.get_string(vr) else {
                return error(format!(
                    "{}: {}",
                    self.op_name(Operation::GetString),
                    self.not_a(vr, "String variable")
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
        op: Operation,
        set: impl FnOnce(&mut dyn FmuModel, &SetContext) -> ModelResult<bool>,
    ) -> Res {
        self.require(op)?;
        let (phase, api) = (self.phase, self.api);
        let check =
            |name: &str| parameter_settable(phase, api, op, name).map_err(|f| ModelError(f.msg));
        let ctx = SetContext {
            check: &check,
            resources: &self.resources,
            bundled: &self.bundled,
        };
        let changed = set(self.model.physics.as_mut(), &ctx)?;
        self.model.clock.dirty |= changed;
        self.model.outputs_checked = false;
        Ok(())
    }

    pub fn set_real(&mut self, vrs: &[u32], vals: &[f64]) -> Res {
        if let Some((&vr, v)) = vrs.iter().zip(vals).find(|(_, v)| !v.is_finite()) {
            self.require(Operation::SetFloat)?;
            let what = match self.variable(vr) {
                Some(VarName { name, causality }) => {
                    let kind = if causality == "parameter" {
                        "parameters"
                    } else {
                        "inputs"
                    };
                    format!("{name} = {v} refused: {kind} must be finite")
                }
                None => format!("{v} for value reference {vr} refused: values must be finite"),
            };
            return error(format!("{}: {what}", self.op_name(Operation::SetFloat)));
        }
        self.set_values(Operation::SetFloat, |m, ctx| {
            m.set_real(Set { vrs, vals, ctx })
        })
    }

    /// Sets the execution parameters `max_substeps_per_step` and `threads`
    /// (fixed: only before `fmi2ExitInitializationMode`). A rejected call
    /// changes nothing.
    pub fn set_integer(&mut self, vrs: &[u32], vals: &[c_int]) -> Res {
        self.require(Operation::SetInteger)?;
        let mut e = self.execution;
        for (&vr, &v) in vrs.iter().zip(vals) {
            match vr {
                VR_MAX_SUBSTEPS | VR_THREADS => {
                    let op = Operation::SetInteger;
                    parameter_settable(self.phase, self.api, op, &self.name_of(vr))?
                }
                _ => {
                    return error(format!(
                        "{}: {}",
                        self.op_name(Operation::SetInteger),
                        self.not_a(vr, "Integer input or parameter")
                    ))
                }
            }
            if vr == VR_MAX_SUBSTEPS {
                if v < 1 {
                    return error(format!(
                        "{}: max_substeps_per_step = {v} must be at least 1",
                        self.op_name(Operation::SetInteger)
                    ));
                }
                e.max_substeps = v as u32;
            } else {
                if !(0..=MAX_THREADS as c_int).contains(&v) {
                    return error(format!(
                        "{}: threads = {v} must be 0 (all cores) to {MAX_THREADS}",
                        self.op_name(Operation::SetInteger)
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
        self.set_values(Operation::SetBoolean, |m, ctx| {
            m.set_boolean(Set {
                vrs,
                vals: &vals,
                ctx,
            })
        })
    }

    pub fn set_string(&mut self, vrs: &[u32], vals: &[Option<String>]) -> Res {
        self.set_values(Operation::SetString, |m, ctx| {
            m.set_string(Set { vrs, vals, ctx })
        })
    }
}
