//! The mass-spring physics behind the `MassSpring` FMU (the same shared
//! library as `YarnBundle`, packed under the modelIdentifier `MassSpring`
//! when the bundled scene is a mass-spring layout such as `wire` or
//! `cloth`): its variables, GUID and model description ([`variables`](mod@variables)),
//! its FMI 3.0 array output ([`arrays`]), the [`Simulation`] an instance
//! drives (here) and its part of an FMU state (`fmu_state.rs`); the same
//! files as the yarn bundle's ([`crate::models::yarn`]).
//!
//! Inputs `gravity.x/y/z`; parameters `dt` (0: the integrator's own step)
//! and `integrator`; outputs the energies, the largest strain, the substep
//! count and every particle's position `particle[i].x/y/z`.

use yarnsim::massspring::{Integrator, IntegratorOptions, MassSpringScene, Simulation, V3};

use crate::model_description::table_name;
use crate::models::model::{
    refuse, Checkpoint, FmuModel, ModelResult, ModelSnapshot, Set, StepFailure, VarName,
};
use crate::models::state_bytes::{Reader, Writer};

pub mod arrays;
mod fmu_state;
pub mod variables;

pub use arrays::*;
pub use variables::*;

/// The mass-spring system of one FMU instance.
#[derive(Clone, Debug)]
pub struct MsModel {
    /// The bundled layout.
    pub base: MassSpringScene,
    /// The `dt` parameter (`None`: 0, the integrator's own step).
    pub dt: Option<f64>,
    pub integrator: Integrator,
    /// The gravity inputs.
    pub gravity: [f64; 3],
    pub sim: Simulation,
}

fn build(
    base: &MassSpringScene,
    integrator: Integrator,
    dt: Option<f64>,
) -> ModelResult<Simulation> {
    let options = IntegratorOptions {
        dt,
        ..IntegratorOptions::default()
    };
    Simulation::new(base, integrator, options).or_else(|e| refuse(e.to_string()))
}

impl MsModel {
    pub fn new(base: MassSpringScene) -> ModelResult<Self> {
        let sim = build(&base, DEFAULT_INTEGRATOR, None)?;
        Ok(MsModel {
            gravity: base.gravity,
            base,
            dt: None,
            integrator: DEFAULT_INTEGRATOR,
            sim,
        })
    }
}

impl FmuModel for MsModel {
    /// Rebuilds the simulation from the layout and the parameters.
    fn rebuild(&mut self, particles: usize) -> ModelResult {
        let mut sim = build(&self.base, self.integrator, self.dt)?;
        if sim.positions().len() != particles {
            return refuse(format!(
                "the scene has {} particles, but this FMU has outputs for {particles}",
                sim.positions().len()
            ));
        }
        sim.set_gravity(V3::from(self.gravity))
            .or_else(|e| refuse(e.to_string()))?;
        self.sim = sim;
        Ok(())
    }
    fn count(&self) -> usize {
        self.sim.positions().len()
    }
    fn dt(&self) -> f64 {
        self.sim.dt()
    }
    /// Substep number `k` (0-based since initialization): the clock is set
    /// to `k dt` first, so the driven particles follow the substep grid.
    fn substep(&mut self, k: u64) -> Result<(), StepFailure> {
        let dt = self.sim.dt();
        self.sim.state_mut().t = k as f64 * dt;
        self.sim.step(dt).map(|_| ()).map_err(|e| StepFailure {
            terminal: true,
            msg: e.to_string(),
        })
    }
    /// Every Real output this model serves is finite: the positions, the
    /// four energies and the largest strain (energies overflow to inf long
    /// before the positions do).
    fn outputs_finite(&mut self) -> bool {
        let e = self.sim.energies();
        e.kinetic.is_finite()
            && e.elastic.is_finite()
            && e.gravity.is_finite()
            && e.total().is_finite()
            && self.sim.max_strain().is_finite()
            && self
                .sim
                .positions()
                .iter()
                .all(|p| p.iter().all(|c| c.is_finite()))
    }
    fn variable(&self, vr: u32) -> Option<VarName> {
        if let Some((name, causality)) = table_name(&MASS_SPRING_VARIABLES, vr) {
            return Some(VarName::new(name, causality));
        }
        if vr == VR_POSITIONS {
            return Some(VarName::new("positions", "output"));
        }
        let k = vr.checked_sub(VR_PARTICLE_BASE)? as usize;
        let axis = ["x", "y", "z"][k % 3];
        (k / 3 < self.count())
            .then(|| VarName::new(format!("particle[{}].{axis}", k / 3), "output"))
    }
    /// Whether the Real variable `vr` reads the simulation's values (positions,
    /// velocities, energies), which need a built simulation.
    fn is_simulated_output(&self, vr: u32) -> bool {
        (VR_KINETIC_ENERGY..=VR_MAX_STRAIN).contains(&vr)
            || (vr >= VR_PARTICLE_BASE && ((vr - VR_PARTICLE_BASE) / 3) < self.count() as u32)
    }
    /// The value of the Real variable `vr`, `None` if there is none.
    fn get_real(&mut self, vr: u32) -> Option<f64> {
        Some(match vr {
            VR_GRAVITY_X..=VR_GRAVITY_Z => self.gravity[(vr - VR_GRAVITY_X) as usize],
            VR_DT => self.dt.unwrap_or(0.0),
            VR_KINETIC_ENERGY => self.sim.energies().kinetic,
            VR_ELASTIC_ENERGY => self.sim.energies().elastic,
            VR_GRAVITY_ENERGY => self.sim.energies().gravity,
            VR_TOTAL_ENERGY => self.sim.energies().total(),
            VR_MAX_STRAIN => self.sim.max_strain(),
            _ if self.is_simulated_output(vr) => {
                let i = (vr - VR_PARTICLE_BASE) as usize;
                self.sim.positions()[i / 3][i % 3]
            }
            _ => return None,
        })
    }
    fn array_len(&self, vr: u32) -> Option<usize> {
        (vr == VR_POSITIONS).then(|| 3 * self.sim.positions().len())
    }
    fn get_real_array(&mut self, vr: u32, out: &mut [f64]) -> bool {
        let p = self.sim.positions();
        if vr != VR_POSITIONS || out.len() != 3 * p.len() {
            return false;
        }
        for (o, x) in out.chunks_exact_mut(3).zip(p) {
            o.copy_from_slice(&[x[0], x[1], x[2]]);
        }
        true
    }
    /// The only array, `positions`, is checked by [`Self::outputs_finite`].
    fn arrays_finite(&self) -> bool {
        true
    }
    fn get_boolean(&self, _vr: u32) -> Option<bool> {
        None
    }
    fn get_string(&self, vr: u32) -> Option<&str> {
        (vr == VR_INTEGRATOR).then_some(self.integrator.name())
    }
    /// Sets the gravity inputs and the `dt` parameter; true when the
    /// parameter changed. A rejected call changes nothing.
    fn set_real(&mut self, set: Set<f64>) -> ModelResult<bool> {
        let Set { vrs, vals, ctx } = set;
        let mut gravity = self.gravity;
        let mut dt = self.dt;
        for (&vr, &v) in vrs.iter().zip(vals) {
            match vr {
                VR_GRAVITY_X..=VR_GRAVITY_Z => gravity[(vr - VR_GRAVITY_X) as usize] = v,
                VR_DT => {
                    (ctx.check)("dt")?;
                    if !(0.0..=1e3).contains(&v) {
                        return refuse(format!(
                            "dt = {v} s is out of range (0 = automatic, else up to 1e3 s)"
                        ));
                    }
                    dt = (v > 0.0).then_some(v);
                }
                _ => {
                    return refuse(format!(
                        "{} is not a Real input or parameter",
                        self.shown(vr)
                    ))
                }
            }
        }
        if gravity != self.gravity {
            let assigned = || {
                vrs.iter()
                    .zip(vals)
                    .filter(|(vr, _)| (VR_GRAVITY_X..=VR_GRAVITY_Z).contains(vr))
                    .map(|(&vr, v)| {
                        format!(
                            "{} = {v}",
                            MASS_SPRING_VARIABLES[(vr - VR_GRAVITY_X) as usize].name
                        )
                    })
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            self.sim
                .set_gravity(V3::from(gravity))
                .or_else(|e| refuse(format!("{} refused: {e}", assigned())))?;
            self.gravity = gravity;
        }
        let changed = dt != self.dt;
        self.dt = dt;
        Ok(changed)
    }
    fn set_boolean(&mut self, set: Set<bool>) -> ModelResult<bool> {
        match set.vrs.first() {
            None => Ok(false),
            Some(&vr) => refuse(format!(
                "{} is not a Boolean input or parameter (this FMU has none)",
                self.shown(vr)
            )),
        }
    }
    /// Sets the `integrator` parameter; true when it changed.
    fn set_string(&mut self, set: Set<Option<String>>) -> ModelResult<bool> {
        let Set { vrs, vals, ctx } = set;
        let mut integrator = self.integrator;
        for (&vr, v) in vrs.iter().zip(vals) {
            if vr != VR_INTEGRATOR {
                return refuse(format!("{} is not a String parameter", self.shown(vr)));
            }
            (ctx.check)("integrator")?;
            let Some(v) = v else {
                return refuse("the integrator name is a null pointer");
            };
            integrator = v.parse::<Integrator>().or_else(|e| refuse(e.to_string()))?;
        }
        let changed = integrator != self.integrator;
        self.integrator = integrator;
        Ok(changed)
    }
    fn state_magic(&self) -> &'static [u8; 8] {
        crate::models::state_bytes::MASS_SPRING_STATE_MAGIC
    }
    fn stable_dt(&self) -> Option<f64> {
        self.sim.stable_dt()
    }
    /// A clone of the model (cheaper than its serialization).
    fn checkpoint(&self) -> Checkpoint {
        Box::new(self.clone())
    }
    fn restore(&mut self, c: Checkpoint) {
        *self = *c
            .downcast::<MsModel>()
            .expect("a checkpoint of a mass-spring model");
    }
    /// A clone of the model: the mass-spring simulation has no scratch
    /// worth leaving out.
    fn save(&self) -> ModelSnapshot {
        Box::new(self.clone())
    }
    fn load(&mut self, s: &ModelSnapshot) -> ModelResult {
        let Some(s) = s.downcast_ref::<MsModel>() else {
            return refuse("not the state of a mass-spring model");
        };
        self.clone_from(s);
        Ok(())
    }
    fn write(&self, s: &ModelSnapshot, w: &mut Writer) -> Result<(), String> {
        let s = s
            .downcast_ref::<MsModel>()
            .ok_or("not the state of a mass-spring model")?;
        s.write(w);
        Ok(())
    }
    fn read(&self, r: &mut Reader, built: bool, count: usize) -> Result<ModelSnapshot, String> {
        Ok(Box::new(MsModel::read(r, self, built, count)?))
    }
    fn box_clone(&self) -> Box<dyn FmuModel> {
        Box::new(self.clone())
    }
}
