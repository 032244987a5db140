//! What an FMI 3.0 instance offers beyond the FMI 2.0 operations: values
//! counted with `nValues` (arrays count with all their elements), the
//! Float64 arrays, the independent variable `time`, and the
//! `ModelStructure` dependencies of the outputs.

use super::*;
use crate::model_description::{fmi3_outputs, VR_TIME};

impl Instance {
    /// Fails unless `n_values` is the number of values of `vrs` (each a
    /// scalar of a type without arrays).
    pub fn check_scalars(&self, func: &str, vrs: &[u32], n_values: usize) -> Res {
        if n_values != vrs.len() {
            return error(format!(
                "{func}: nValues = {n_values} but the {} value references are scalars ({} values)",
                vrs.len(),
                vrs.len()
            ));
        }
        Ok(())
    }

    /// The values of `vrs` into `out`, arrays with all their elements
    /// (row-major); `out.len()` (nValues) must be their total. Never a
    /// non-finite value.
    pub fn get_float64(&mut self, vrs: &[u32], out: &mut [f64]) -> Res {
        self.require(Operation::GetFloat)?;
        let physics = &self.model.physics;
        if vrs.iter().any(|&vr| physics.array_len(vr).is_some()) {
            self.model.ensure_built(self.count)?;
        }
        let physics = &self.model.physics;
        let total: usize = vrs
            .iter()
            .map(|&vr| physics.array_len(vr).unwrap_or(1))
            .sum();
        if total != out.len() {
            return error(format!(
                "{}: nValues = {} but the {} value references have {total} values (an array counts with all its elements)",
                self.op_name(Operation::GetFloat),
                out.len(),
                vrs.len()
            ));
        }
        let mut k = 0;
        for &vr in vrs {
            let n = self.model.physics.array_len(vr);
            match n {
                Some(n) => {
                    let dst = &mut out[k..k + n];
                    if !self.model.physics.get_real_array(vr, dst) {
                        return error(format!(
                            "{}: the array {} cannot be read",
                            self.op_name(Operation::GetFloat),
                            self.shown(vr)
                        ));
                    }
                    if let Some(v) = dst.iter().find(|v| !v.is_finite()) {
                        return error(format!(
                            "{}: the array {} has a non-finite element ({v}) at t = {}",
                            self.op_name(Operation::GetFloat),
                            self.shown(vr),
                            self.model.clock.time
                        ));
                    }
                    k += n;
                }
                None if vr == VR_TIME => {
                    out[k] = self.model.clock.time;
                    k += 1;
                }
                None => {
                    self.get_real(&[vr], &mut out[k..k + 1])?;
                    k += 1;
                }
            }
        }
        Ok(())
    }

    /// Sets Float64 inputs and parameters (no array is an input).
    pub fn set_float64(&mut self, vrs: &[u32], vals: &[f64]) -> Res {
        self.require(Operation::SetFloat)?;
        if let Some(vr) = vrs
            .iter()
            .find(|&&vr| vr == VR_TIME || self.model.physics.array_len(vr).is_some())
        {
            return error(format!(
                "{}: {} is an output or the independent variable, not an input or parameter",
                self.op_name(Operation::SetFloat),
                self.shown(*vr)
            ));
        }
        self.check_scalars(self.op_name(Operation::SetFloat), vrs, vals.len())?;
        self.set_real(vrs, vals)
    }

    /// The value references the output `vr` depends on at the same instant
    /// (its `<Output dependencies>` in the FMI 3.0 modelDescription).
    pub fn variable_dependencies(&self, vr: u32) -> Res<Vec<u32>> {
        let d = self
            .bundled
            .description()
            .or_else(|e| error(format!("the bundled scene: {e}")))?;
        match fmi3_outputs(&d).into_iter().find(|(o, _, _)| *o == vr) {
            Some((_, mut step, _)) => {
                step.sort_unstable();
                Ok(step)
            }
            None => error(format!(
                "{} is not an output (ModelStructure lists the dependencies of outputs only)",
                self.shown(vr)
            )),
        }
    }
}
