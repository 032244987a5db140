//! The mass-spring physics behind the `MassSpring` FMU (the same shared
//! library as `YarnBundle`, packed under the modelIdentifier `MassSpring`
//! when the bundled scene is a mass-spring layout such as `wire` or
//! `cloth`): its variables, GUID and model description, and the
//! [`Simulation`] an instance drives.
//!
//! Inputs `gravity.x/y/z`; parameters `dt` (0: the integrator's own step)
//! and `integrator`; outputs the energies, the largest strain, the substep
//! count and every particle's position `particle[i].x/y/z`.

use yarnsim::massspring::{Integrator, IntegratorOptions, MassSpringScene, Simulation, V3};

use crate::model_description::{
    output, table_name, var, Causality::*, Description, Start, VarSpec, VarType, Variable,
};
use crate::models::model::{
    refuse, Checkpoint, FmuModel, ModelResult, ModelState, ParamCheck, SetContext, StepFailure,
    VarName,
};
use crate::models::state_bytes::{Reader, Writer};

/// The FMI model identifier of a mass-spring FMU.
pub const MODEL_IDENTIFIER: &str = "MassSpring";

/// Bumped whenever the variable layout changes; part of the GUID.
pub const INTERFACE_VERSION: u32 = 2;

/// The integrator an instance uses unless the `integrator` parameter says
/// otherwise (the CLI's default too).
pub const DEFAULT_INTEGRATOR: Integrator = Integrator::BackwardEuler;

// Value references, unique across all types.
pub const VR_GRAVITY_X: u32 = 1;
pub const VR_GRAVITY_Y: u32 = 2;
pub const VR_GRAVITY_Z: u32 = 3;
pub const VR_DT: u32 = 10;
pub const VR_INTEGRATOR: u32 = 11; // String
pub const VR_KINETIC_ENERGY: u32 = 100;
pub const VR_ELASTIC_ENERGY: u32 = 101;
pub const VR_GRAVITY_ENERGY: u32 = 102;
pub const VR_TOTAL_ENERGY: u32 = 103;
pub const VR_MAX_STRAIN: u32 = 104;
/// The substep count, common to every model ([`crate::model_description::COMMON_VARIABLES`]).
pub use crate::model_description::VR_SUBSTEPS;
/// `particle[i].x` has `VR_PARTICLE_BASE + 3 i`, then `.y`, `.z`.
pub const VR_PARTICLE_BASE: u32 = 1000;

/// Number of particles the layout creates (fixes the outputs).
pub fn num_particles(layout: &MassSpringScene) -> Result<usize, String> {
    layout
        .build()
        .map(|s| s.len())
        .map_err(|e| format!("scene {:?}: {e}", layout.name))
}

/// The MassSpring's variables before the ones every model has
/// ([`crate::model_description::COMMON_VARIABLES`]) and the per-particle outputs, in
/// `ModelVariables` order; start values come from the layout.
pub static MASS_SPRING_VARIABLES: [VarSpec<MassSpringScene>; 10] = [
    var(Input, "gravity.x", VR_GRAVITY_X, Some("m/s2"), Start::Real(|l| l.gravity[0]), "Gravity x, |g| at most 1e6"),
    var(Input, "gravity.y", VR_GRAVITY_Y, Some("m/s2"), Start::Real(|l| l.gravity[1]), "Gravity y, |g| at most 1e6"),
    var(Input, "gravity.z", VR_GRAVITY_Z, Some("m/s2"), Start::Real(|l| l.gravity[2]), "Gravity z, |g| at most 1e6"),
    var(Parameter, "dt", VR_DT, Some("s"), Start::Real(|_| 0.0), "Substep size; 0: the integrator's own (CFL-limited for the explicit schemes, the scene's time_step otherwise). A communication step runs an integer number of substeps"),
    var(Parameter, "integrator", VR_INTEGRATOR, None, Start::Text(DEFAULT_INTEGRATOR_NAME), "Time integrator: one of forward-euler, symplectic-euler, trapezoidal, backward-euler, chebyshev-jacobi, pbd"),
    output("kinetic_energy", VR_KINETIC_ENERGY, Some("J"), "Kinetic energy"),
    output("elastic_energy", VR_ELASTIC_ENERGY, Some("J"), "Elastic energy of the springs"),
    output("gravity_energy", VR_GRAVITY_ENERGY, Some("J"), "Gravitational energy -sum m g.x"),
    output("total_energy", VR_TOTAL_ENERGY, Some("J"), "Kinetic + elastic + gravitational energy"),
    output("max_strain", VR_MAX_STRAIN, None, "Largest spring strain |l / l0 - 1|"),
];

/// Name of [`DEFAULT_INTEGRATOR`] (the `integrator` start value).
const DEFAULT_INTEGRATOR_NAME: &str = "backward-euler";

/// Every variable of the FMU for this layout, in `ModelVariables` order:
/// [`MASS_SPRING_VARIABLES`], the common ones, then `particle[i].x/y/z`.
pub fn variables(layout: &MassSpringScene) -> Result<Vec<Variable>, String> {
    let n = num_particles(layout)?;
    let mut v: Vec<Variable> = MASS_SPRING_VARIABLES
        .iter()
        .map(|s| s.variable(layout))
        .collect();
    v.extend(crate::model_description::common_variables());
    for i in 0..n {
        for (k, axis) in ["x", "y", "z"].into_iter().enumerate() {
            v.push(Variable {
                name: format!("particle[{i}].{axis}"),
                vr: VR_PARTICLE_BASE + 3 * i as u32 + k as u32,
                ty: VarType::Real,
                causality: "output",
                variability: "continuous",
                unit: Some("m"),
                start: None,
                description: format!("Particle {i}, position {axis}"),
            });
        }
    }
    Ok(v)
}

#[cfg(test)]
mod table_tests {
    use super::*;

    /// `integrator`'s description lists the library's integrators.
    #[test]
    fn integrator_names_match_the_library() {
        let names = Integrator::ALL.map(|i| i.name()).join(", ");
        assert_eq!(MASS_SPRING_VARIABLES[4].name, "integrator");
        assert!(
            MASS_SPRING_VARIABLES[4].description.ends_with(&names),
            "{names}"
        );
        assert_eq!(DEFAULT_INTEGRATOR_NAME, DEFAULT_INTEGRATOR.name());
    }
}

/// The gravitational and the total energy change as soon as `gravity.*` is
/// set (`-sum m g . x` with the current gravity), at initialization and
/// between steps; every other output depends on no input and no parameter
/// at the same instant (`dt` and `integrator` act through the substeps).
pub fn dependencies() -> Vec<crate::model_description::Dependency> {
    let gravity = vec![VR_GRAVITY_X, VR_GRAVITY_Y, VR_GRAVITY_Z];
    [VR_GRAVITY_ENERGY, VR_TOTAL_ENERGY]
        .into_iter()
        .map(|output| crate::model_description::Dependency {
            output,
            step: gravity.clone(),
            initial: gravity.clone(),
        })
        .collect()
}

/// `positions`, the FMI 3.0 array of all particle positions.
pub const VR_POSITIONS: u32 = crate::model_description::VR_ARRAY_BASE;

/// The FMI 3.0 array output `positions` (`[n, 3]`, row-major: x, y, z of
/// particle 0, then of particle 1, ...) of `n` particles.
pub fn positions_array(n: usize) -> crate::model_description::ArrayVariable {
    crate::model_description::ArrayVariable {
        name: "positions".into(),
        vr: VR_POSITIONS,
        dims: vec![n, 3],
        unit: Some("m"),
        description: format!(
            "The positions of the {n} particles, x, y and z of each (row-major {n} x 3)"
        ),
        initial: Vec::new(),
    }
}

/// The GUID of the FMU for this layout: a hash of the interface version and
/// the layout's normalized TOML text.
pub fn guid(layout: &MassSpringScene) -> String {
    crate::model_description::guid_of(&format!(
        "{MODEL_IDENTIFIER} fmi2 interface {INTERFACE_VERSION}\n{}",
        layout.to_toml_string()
    ))
}

/// What `modelDescription.xml` is written from.
pub fn description(layout: &MassSpringScene) -> Result<Description, String> {
    let what = if layout.description.is_empty() {
        format!("Mass-spring scene {}", layout.name)
    } else {
        format!("Mass-spring scene {}: {}", layout.name, layout.description)
    };
    Ok(Description {
        identifier: MODEL_IDENTIFIER,
        guid: guid(layout),
        description: what,
        variables: variables(layout)?,
        stop_time: layout.time.frame_time * layout.time.frames as f64,
        step_size: layout.time.frame_time,
        dependencies: dependencies(),
        arrays: vec![positions_array(num_particles(layout)?)],
    })
}

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

    /// This model's part of a serialized FMU state: gravity, parameters, the
    /// layout text, then time, positions and velocities (the state's header
    /// checksums the whole body).
    pub fn write(&self, w: &mut Writer) {
        for g in self.gravity {
            w.f64(g);
        }
        w.opt_f64(self.dt);
        w.bytes(self.integrator.name().as_bytes());
        w.bytes(self.base.to_toml_string().as_bytes());
        let s = self.sim.state();
        w.f64(s.t);
        w.u64(s.x.len() as u64);
        for p in s.x.iter().chain(&s.v) {
            for &c in p.iter() {
                w.f64(c);
            }
        }
    }

    /// Reads what [`Self::write`] wrote; `current` (with `current_built`: its
    /// simulation matches its layout and parameters) is reused when the
    /// stored layout and parameters match.
    pub fn read(
        r: &mut Reader,
        current: &MsModel,
        current_built: bool,
        particles: usize,
    ) -> Result<MsModel, String> {
        let gravity = [r.f64()?, r.f64()?, r.f64()?];
        let dt = r.opt_f64()?;
        if dt.is_some_and(|d| !(d > 0.0 && d <= 1e3)) {
            return Err("stored dt is out of range".into());
        }
        let integrator: Integrator = r.string()?.parse()?;
        let text = r.string()?;
        let base = if text == current.base.to_toml_string() {
            current.base.clone()
        } else {
            MassSpringScene::from_toml_str(&text).map_err(|e| format!("stored scene: {e}"))?
        };
        let t = r.f64()?;
        let n = r.u64()?;
        if n != particles as u64 {
            return Err(format!("state has {n} particles, this FMU {particles}"));
        }
        let mut numbers = Vec::with_capacity(6 * particles);
        for _ in 0..6 * particles {
            numbers.push(r.f64()?);
        }
        r.finish()?;
        let same = current_built
            && base == current.base
            && dt == current.dt
            && integrator == current.integrator;
        let mut sim = if same {
            current.sim.clone()
        } else {
            build(&base, integrator, dt).map_err(|e| e.0)?
        };
        if sim.positions().len() != particles {
            return Err(format!(
                "stored scene has {} particles, this FMU {particles}",
                sim.positions().len()
            ));
        }
        sim.set_gravity(V3::from(gravity))
            .map_err(|e| e.to_string())?;
        let s = sim.state_mut();
        s.t = t;
        for i in 0..particles {
            s.x[i] = V3::from_column_slice(&numbers[3 * i..3 * i + 3]);
            s.v[i] = V3::from_column_slice(&numbers[3 * (particles + i)..3 * (particles + i) + 3]);
        }
        Ok(MsModel {
            base,
            dt,
            integrator,
            gravity,
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
    /// Whether the Real variable `vr` depends on the simulated state.
    fn is_state_output(&self, vr: u32) -> bool {
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
            _ if self.is_state_output(vr) => {
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
    fn set_real(&mut self, vrs: &[u32], vals: &[f64], param_ok: ParamCheck) -> ModelResult<bool> {
        let mut gravity = self.gravity;
        let mut dt = self.dt;
        for (&vr, &v) in vrs.iter().zip(vals) {
            match vr {
                VR_GRAVITY_X..=VR_GRAVITY_Z => gravity[(vr - VR_GRAVITY_X) as usize] = v,
                VR_DT => {
                    param_ok("dt")?;
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
    fn set_boolean(&mut self, vrs: &[u32], _vals: &[bool], _: ParamCheck) -> ModelResult<bool> {
        match vrs.first() {
            None => Ok(false),
            Some(&vr) => refuse(format!(
                "{} is not a Boolean input or parameter (this FMU has none)",
                self.shown(vr)
            )),
        }
    }
    /// Sets the `integrator` parameter; true when it changed.
    fn set_string(
        &mut self,
        vrs: &[u32],
        vals: &[Option<String>],
        param_ok: ParamCheck,
        _ctx: &SetContext,
    ) -> ModelResult<bool> {
        let mut integrator = self.integrator;
        for (&vr, v) in vrs.iter().zip(vals) {
            if vr != VR_INTEGRATOR {
                return refuse(format!("{} is not a String parameter", self.shown(vr)));
            }
            param_ok("integrator")?;
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
    fn save(&self) -> ModelState {
        Box::new(self.clone())
    }
    fn load(&mut self, s: &ModelState) -> ModelResult {
        let Some(s) = s.downcast_ref::<MsModel>() else {
            return refuse("not the state of a mass-spring model");
        };
        self.clone_from(s);
        Ok(())
    }
    fn write(&self, s: &ModelState, w: &mut Writer) -> Result<(), String> {
        let s = s
            .downcast_ref::<MsModel>()
            .ok_or("not the state of a mass-spring model")?;
        s.write(w);
        Ok(())
    }
    fn read(&self, r: &mut Reader, built: bool, count: usize) -> Result<ModelState, String> {
        Ok(Box::new(MsModel::read(r, self, built, count)?))
    }
    fn box_clone(&self) -> Box<dyn FmuModel> {
        Box::new(self.clone())
    }
}
