//! The yarn-bundle physics behind the `YarnBundle` FMU: inputs, parameter
//! overrides, the [`YarnSim`] they build, the values of its variables
//! ([`variables`](mod@variables) lists them; `inputs` holds the inputs) and its part of
//! a serialized FMU state.

use std::path::Path;

use yarnsim::mpm::driver::state::DynamicState;
use yarnsim::mpm::driver::timestep::WITHOUT_PLASTICITY;
use yarnsim::mpm::{Diagnostics, SimError, YarnSim};
use yarnsim::scene::{Axial, Integrator, TransferScheme, YarnScene};

use crate::model_description::*;
use crate::models::model::{
    refuse, Checkpoint, FmuModel, ModelError, ModelResult, ModelSnapshot, Set, StepFailure, VarName,
};
use crate::models::state_bytes::{Reader, Writer};

pub mod arrays;
mod fmu_state;
mod forces;
mod inputs;
pub mod variables;

pub use forces::PinForces;
pub use inputs::{Inputs, PinInput};
use variables::*;

/// The parameters as set by the environment (`None`: the scene's value).
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    pub scene_path: String,
    /// Overrides of [`yarn_real_parameters`], in that order.
    pub reals: [Option<f64>; YARN_REAL_PARAMETERS],
    pub plasticity: Option<bool>,
    /// `transfer.scheme`.
    pub scheme: Option<TransferScheme>,
    /// `integrator` (`time.integrator`).
    pub integrator: Option<Integrator>,
    /// `time.axial`.
    pub axial: Option<Axial>,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            scene_path: SCENE_FILE.to_string(),
            reals: [None; YARN_REAL_PARAMETERS],
            plasticity: None,
            scheme: None,
            integrator: None,
            axial: None,
        }
    }
}

/// Index of the Real parameter `vr` in [`yarn_real_parameters`] and its
/// scene field.
fn real_param(vr: u32) -> Option<(usize, SceneField<YarnScene>)> {
    yarn_real_parameters()
        .enumerate()
        .find(|(_, (p, _))| *p == vr)
        .map(|(i, (_, f))| (i, f))
}

/// The name of the variable `vr` of [`YARN_VARIABLES`] (a caller that
/// matched `vr` against the table's constants).
fn name_of(vr: u32) -> &'static str {
    table_name(&YARN_VARIABLES, vr).map_or("?", |(name, _)| name)
}

/// The name of an input of `model` (its value reference if it has none).
fn name_of_input(model: &YarnModel, vr: u32) -> String {
    model
        .variable(vr)
        .map_or_else(|| format!("value reference {vr}"), |v| v.name)
}

/// The base scene with the parameter overrides applied.
fn effective_scene(base: &YarnScene, config: &Config) -> YarnScene {
    let mut s = base.clone();
    for (k, (_, field)) in yarn_real_parameters().enumerate() {
        if let Some(v) = config.reals[k] {
            (field.set)(&mut s, v);
        }
    }
    if let Some(p) = config.plasticity {
        s.material.plasticity = p;
    }
    if let Some(t) = config.scheme {
        s.transfer.scheme = t;
    }
    if let Some(i) = config.integrator {
        s.time.integrator = i;
    }
    if let Some(a) = config.axial {
        s.time.axial = a;
    }
    s
}

fn read_scene(path: &Path) -> Result<YarnScene, String> {
    let text = read_scene_text(path)?;
    YarnScene::from_toml_str(&text).map_err(|e| format!("scene file {}: {e}", path.display()))
}

/// The value of a String parameter `name` that picks one of a table's
/// values (`what`, as in "a transfer scheme"): refused when null or unknown.
fn refuse_unknown<T: Copy>(
    name: &str,
    v: &Option<String>,
    table: &[(&str, T)],
    what: &str,
) -> ModelResult<T> {
    let Some(v) = v else {
        return refuse(format!("{name} is a null pointer"));
    };
    match parse_choice(table, v) {
        Some(t) => Ok(t),
        None => refuse(format!(
            "{name} = {v:?} is not {what}: use {}",
            choice_list(table)
        )),
    }
}

/// Sets `slot` to `Some(new)`; true when that changed it.
fn replace<T: PartialEq>(slot: &mut Option<T>, new: T) -> bool {
    let changed = slot.as_ref() != Some(&new);
    *slot = Some(new);
    changed
}

/// The yarn bundle of one FMU instance.
#[derive(Clone, Debug)]
pub struct YarnModel {
    pub config: Config,
    /// The scene file as loaded (before parameter overrides).
    pub base: YarnScene,
    pub sim: YarnSim,
    pub inputs: Inputs,
    /// Diagnostics of the current state, computed on first use.
    pub diag: Option<Diagnostics>,
    /// Per pin: the force the yarn exerted on it over the substeps of the
    /// current (or last) communication step (time-weighted under
    /// `dt = "auto"`), and their number.
    pub forces: PinForces,
}

/// The yarn bundle's part of an FMU state ([`YarnModel::save`]): the
/// parameters, the scene, the inputs, the pin force sums and the
/// simulation's dynamic state, without its grid or other scratch.
#[derive(Clone, Debug)]
pub struct YarnSnapshot {
    pub config: Config,
    pub base: YarnScene,
    pub inputs: Inputs,
    pub forces: PinForces,
    pub sim: DynamicState,
}

impl YarnSnapshot {
    /// The scene its simulation runs: the base scene with the parameters.
    fn scene(&self) -> YarnScene {
        effective_scene(&self.base, &self.config)
    }
}

impl YarnModel {
    pub fn new(base: YarnScene) -> ModelResult<Self> {
        check_value_references(&base).or_else(|e| refuse(format!("scene: {e}")))?;
        let sim = YarnSim::new(&base).or_else(|e| refuse(format!("scene: {e}")))?;
        Ok(YarnModel {
            config: Config::default(),
            inputs: Inputs::from_scene(&base),
            forces: PinForces::new(base.pins.len()),
            base,
            sim,
            diag: None,
        })
    }

    /// Adds the substep's pin forces with `weight` (1, or the substep's
    /// length under `dt = "auto"`).
    fn after_substep(
        &mut self,
        step: Result<(), SimError>,
        weight: f64,
    ) -> Result<(), StepFailure> {
        step.map_err(|e| {
            let diverged = matches!(e, SimError::NonFinite { .. });
            StepFailure {
                terminal: diverged || matches!(e, SimError::Refused { .. }),
                msg: if diverged && self.sim.diverges_without_plasticity() {
                    format!("{e}; {WITHOUT_PLASTICITY}")
                } else {
                    e.to_string()
                },
            }
        })?;
        // The yarn pulls on each pin with the opposite of the pin's force.
        for (s, r) in self.forces.sum.iter_mut().zip(self.sim.pin_reactions()) {
            *s -= *r * weight;
        }
        self.forces.substeps += 1;
        self.forces.weight += weight;
        Ok(())
    }

    /// Pin `i` and offset `k` of a pin value reference.
    fn pin_vr(&self, vr: u32) -> Option<(usize, u32)> {
        let i = (vr.checked_sub(VR_PIN_BASE)? / 8) as usize;
        (i < self.forces.sum.len()).then_some((i, (vr - VR_PIN_BASE) % 8))
    }

    fn diagnostics(&mut self) -> Diagnostics {
        *self.diag.get_or_insert_with(|| self.sim.diagnostics())
    }

    /// Sets the `scene` parameter: a scene file in the FMU's resources
    /// (`ctx.resources`) or the bundled one, `bundled`; true when it changed.
    pub fn set_string(
        &mut self,
        set: Set<Option<String>>,
        bundled: &YarnScene,
    ) -> ModelResult<bool> {
        let Set { vrs, vals, ctx } = set;
        let mut changed = false;
        for (&vr, v) in vrs.iter().zip(vals) {
            if ![VR_SCENE, VR_TRANSFER_SCHEME, VR_INTEGRATOR, VR_AXIAL].contains(&vr) {
                return refuse(format!("{} is not a String parameter", self.shown(vr)));
            }
            (ctx.check)(name_of(vr))?;
            if vr == VR_INTEGRATOR {
                let i = refuse_unknown("integrator", v, &INTEGRATORS, "an integrator")?;
                changed |= replace(&mut self.config.integrator, i);
                continue;
            }
            if vr == VR_AXIAL {
                let a = refuse_unknown("time.axial", v, &AXIALS, "a fibre-stretch treatment")?;
                changed |= replace(&mut self.config.axial, a);
                continue;
            }
            if vr == VR_TRANSFER_SCHEME {
                let scheme = refuse_unknown("transfer.scheme", v, &SCHEMES, "a transfer scheme")?;
                changed |= replace(&mut self.config.scheme, scheme);
                continue;
            }
            let Some(v) = v else {
                return refuse("the scene file name is a null pointer");
            };
            let base = if v == SCENE_FILE {
                bundled.clone()
            } else {
                read_scene(&ctx.resources.join(v)).or_else(refuse)?
            };
            let yarns = num_yarns(&base);
            if yarns != num_yarns(bundled) {
                return refuse(format!(
                    "scene {v:?} creates {yarns} yarns, but this FMU has outputs for {}",
                    num_yarns(bundled)
                ));
            }
            let inputs = |s: &YarnScene| fmu_pins(s).iter().map(|p| p.input).collect::<Vec<_>>();
            if inputs(&base) != inputs(bundled) {
                return refuse(format!(
                    "scene {v:?} has other pins than the bundled scene ({} pins, driven: {:?}); this FMU's pin variables are the bundled scene's ({:?})",
                    base.pins.len(),
                    inputs(&base),
                    inputs(bundled)
                ));
            }
            self.config.scene_path = v.clone();
            self.base = base;
            changed = true;
        }
        Ok(changed)
    }

    /// This model's part of an FMU state: no grid, no scratch.
    pub fn save(&self) -> YarnSnapshot {
        YarnSnapshot {
            config: self.config.clone(),
            base: self.base.clone(),
            inputs: self.inputs.clone(),
            forces: self.forces.clone(),
            sim: self.sim.dynamic_state(),
        }
    }

    /// Puts back a [`Self::save`]: into this model's simulation when it runs
    /// the state's scene (the usual case: same parameters), else into a new
    /// simulation of that scene. A refused state changes nothing.
    pub fn load(&mut self, s: &YarnSnapshot) -> ModelResult {
        let scene = s.scene();
        if *self.sim.scene() == scene {
            self.sim
                .set_dynamic_state(&s.sim)
                .or_else(|e| refuse(e.to_string()))?;
        } else {
            let mut sim = YarnSim::new(&scene).or_else(|e| refuse(format!("state: {e}")))?;
            sim.set_dynamic_state(&s.sim)
                .or_else(|e| refuse(e.to_string()))?;
            self.sim = sim;
        }
        if self.config != s.config {
            self.config = s.config.clone();
        }
        if self.base != s.base {
            self.base = s.base.clone();
        }
        self.inputs.clone_from(&s.inputs);
        self.forces.clone_from(&s.forces);
        self.diag = None;
        Ok(())
    }
}

impl FmuModel for YarnModel {
    fn count(&self) -> usize {
        self.sim.num_yarns()
    }
    fn dt(&self) -> f64 {
        self.sim.dt()
    }
    /// Rebuilds the simulation from the scene and the parameters.
    fn rebuild(&mut self, yarns: usize) -> ModelResult {
        let scene = effective_scene(&self.base, &self.config);
        let mut sim = YarnSim::new(&scene).or_else(|e| refuse(format!("parameters: {e}")))?;
        if sim.num_yarns() != yarns {
            return refuse(format!(
                "scene {:?} creates {} yarns, but this FMU has outputs for {yarns}",
                self.config.scene_path,
                sim.num_yarns()
            ));
        }
        // The inputs the simulation holds carry over to the new one.
        sim.set_gravity(self.sim.gravity())
            .and_then(|_| sim.set_attractor(self.sim.attractor()))
            .or_else(|e| refuse(e.to_string()))?;
        self.sim = sim;
        self.diag = None;
        self.forces = PinForces::new(self.base.pins.len());
        Ok(())
    }
    /// A communication step from `since` (on the simulation's clock)
    /// begins: the pin inputs become the targets of the driven pins and
    /// the force sums restart.
    fn begin_step(&mut self, since: f64) -> Result<(), StepFailure> {
        self.inputs
            .latch_pins(&mut self.sim, since)
            .map_err(|e| StepFailure {
                terminal: false,
                msg: e.0,
            })?;
        self.forces = PinForces::new(self.forces.sum.len());
        Ok(())
    }
    /// One adaptive substep toward `until` on the simulation's clock
    /// (`dt = "auto"`), the last one landing on it.
    fn substep_toward(&mut self, until: f64) -> Result<(), StepFailure> {
        self.diag = None;
        let before = self.sim.time();
        let step = self.sim.step_toward(until).map(|_| ());
        let dt = self.sim.time() - before;
        self.after_substep(step, dt)
    }
    fn substep(&mut self, _k: u64) -> Result<(), StepFailure> {
        self.diag = None;
        let step = self.sim.step();
        self.after_substep(step, 1.0)
    }
    /// Every Real output is finite: the yarn ends, the energies and the
    /// largest stretch (the library reports divergence itself; this makes
    /// sure no step ends OK with a non-finite output). The diagnostics it
    /// computes are cached for the `fmi2GetReal` calls that follow.
    fn outputs_finite(&mut self) -> bool {
        let d = self.diagnostics();
        d.kinetic_energy.is_finite()
            && d.elastic_energy.is_finite()
            && d.max_stretch.is_finite()
            && (0..self.count()).all(|y| {
                let (l, r) = self.sim.yarn_endpoints(y);
                l.x.is_finite() && l.y.is_finite() && r.x.is_finite() && r.y.is_finite()
            })
            && (0..self.forces.sum.len()).all(|i| {
                let f = self.forces.mean(i);
                f.x.is_finite() && f.y.is_finite()
            })
    }
    fn variable(&self, vr: u32) -> Option<VarName> {
        if let Some((name, causality)) = table_name(&YARN_VARIABLES, vr) {
            return Some(VarName::new(name, causality));
        }
        if (VR_YARN_BASE..VR_PIN_BASE).contains(&vr) {
            let k = vr - VR_YARN_BASE;
            let (yarn, end) = ((k / 4) as usize, k % 4);
            let end = ["left.x", "left.y", "right.x", "right.y"][end as usize];
            return (yarn < self.count())
                .then(|| VarName::new(format!("yarn[{yarn}].{end}"), "output"));
        }
        if let Some((i, k)) = self.pin_vr(vr) {
            let (what, causality) = match k {
                0..=3 => (["x", "y", "vx", "vy"][k as usize], "input"),
                PIN_FORCE => ("force.x", "output"),
                5 => ("force.y", "output"),
                _ => return None,
            };
            return Some(VarName::new(format!("pin[{i}].{what}"), causality));
        }
        arrays::array_name(vr, self.count()).map(|n| VarName::new(n, "output"))
    }
    /// Whether the Real variable `vr` reads the simulation's values (positions,
    /// velocities, energies), which need a built simulation.
    fn is_simulated_output(&self, vr: u32) -> bool {
        matches!(vr, VR_KINETIC_ENERGY | VR_ELASTIC_ENERGY | VR_MAX_STRETCH)
            || ((VR_YARN_BASE..VR_PIN_BASE).contains(&vr)
                && ((vr - VR_YARN_BASE) / 4) < self.count() as u32)
            || matches!(self.pin_vr(vr), Some((_, k)) if k == PIN_FORCE || k == PIN_FORCE + 1)
    }
    /// The value of the Real variable `vr`, `None` if there is none.
    fn get_real(&mut self, vr: u32) -> Option<f64> {
        Some(match vr {
            VR_ATTRACTOR_X => self.sim.attractor().position.x,
            VR_ATTRACTOR_Y => self.sim.attractor().position.y,
            VR_ATTRACTOR_STRENGTH => self.sim.attractor().strength,
            VR_GRAVITY_X => self.sim.gravity().x,
            VR_GRAVITY_Y => self.sim.gravity().y,
            _ if real_param(vr).is_some() => {
                let (i, field) = real_param(vr).unwrap();
                self.config.reals[i].unwrap_or_else(|| (field.get)(&self.base))
            }
            VR_KINETIC_ENERGY => self.diagnostics().kinetic_energy,
            VR_ELASTIC_ENERGY => self.diagnostics().elastic_energy,
            VR_MAX_STRETCH => self.diagnostics().max_stretch,
            _ if self.pin_vr(vr).is_some() => {
                let (i, k) = self.pin_vr(vr).unwrap();
                match k {
                    0..=3 => {
                        let p = self.inputs.pins.iter().find(|p| p.pin == i)?;
                        [p.position[0], p.position[1], p.velocity[0], p.velocity[1]][k as usize]
                    }
                    PIN_FORCE => self.forces.mean(i).x,
                    5 => self.forces.mean(i).y,
                    _ => return None,
                }
            }
            _ if self.is_simulated_output(vr) => {
                let i = (vr - VR_YARN_BASE) as usize;
                let (l, r) = self.sim.yarn_endpoints(i / 4);
                [l.x, l.y, r.x, r.y][i % 4]
            }
            _ => return None,
        })
    }
    fn array_len(&self, vr: u32) -> Option<usize> {
        YarnModel::array_len(self, vr)
    }
    fn get_real_array(&mut self, vr: u32, out: &mut [f64]) -> bool {
        self.write_array(vr, out)
    }
    fn arrays_finite(&self) -> bool {
        self.vertices_finite()
    }
    fn get_boolean(&self, vr: u32) -> Option<bool> {
        match vr {
            VR_ATTRACTOR_ACTIVE => Some(self.sim.attractor().active),
            VR_PLASTICITY => Some(
                self.config
                    .plasticity
                    .unwrap_or(self.base.material.plasticity),
            ),
            _ => None,
        }
    }
    fn get_string(&self, vr: u32) -> Option<&str> {
        match vr {
            VR_SCENE => Some(self.config.scene_path.as_str()),
            VR_TRANSFER_SCHEME => Some(choice_name(
                &SCHEMES,
                self.config.scheme.unwrap_or(self.base.transfer.scheme),
            )),
            VR_INTEGRATOR => Some(choice_name(
                &INTEGRATORS,
                self.config.integrator.unwrap_or(self.base.time.integrator),
            )),
            VR_AXIAL => Some(choice_name(
                &AXIALS,
                self.config.axial.unwrap_or(self.base.time.axial),
            )),
            _ => None,
        }
    }
    /// Sets Real inputs and parameters; true when a parameter changed (the
    /// simulation must be rebuilt). A rejected call changes nothing.
    fn set_real(&mut self, set: Set<f64>) -> ModelResult<bool> {
        let Set { vrs, vals, ctx } = set;
        let mut inputs = self.inputs.clone();
        let mut attractor = self.sim.attractor();
        let mut gravity = self.sim.gravity();
        let mut reals = self.config.reals;
        for (&vr, &v) in vrs.iter().zip(vals) {
            match vr {
                _ if matches!(self.pin_vr(vr), Some((_, 0..=3))) => {
                    let (i, k) = self.pin_vr(vr).unwrap();
                    let Some(p) = inputs.pin_mut(i) else {
                        return refuse(format!(
                            "pin[{i}].{} (value reference {vr}) is not an input: pin {i} is not a motion = \"input\" pin",
                            ["x", "y", "vx", "vy"][k as usize]
                        ));
                    };
                    match k {
                        0 => p.position[0] = v,
                        1 => p.position[1] = v,
                        2 => p.velocity[0] = v,
                        _ => p.velocity[1] = v,
                    }
                }
                VR_ATTRACTOR_X => attractor.position.x = v,
                VR_ATTRACTOR_Y => attractor.position.y = v,
                VR_ATTRACTOR_STRENGTH => attractor.strength = v,
                VR_GRAVITY_X => gravity.x = v,
                VR_GRAVITY_Y => gravity.y = v,
                _ if real_param(vr).is_some() => {
                    let name = name_of(vr);
                    (ctx.check)(name)?;
                    let (i, field) = real_param(vr).unwrap();
                    let ok = if field.positive { v > 0.0 } else { v >= 0.0 } && v <= field.max;
                    if !ok {
                        let range = if field.positive { "> 0" } else { ">= 0" };
                        return refuse(format!(
                            "{name} = {v} is out of range (must be {range} and at most {})",
                            field.max
                        ));
                    }
                    reals[i] = Some(v);
                }
                _ => {
                    return refuse(format!(
                        "{} is not a Real input or parameter",
                        self.shown(vr)
                    ))
                }
            }
        }
        // Every value is checked (by the library's limits) before any is
        // set, so a rejected call changes nothing.
        // A refusal names the variables of the call that make up the
        // refused value ("gravity.y = 2000000 refused: ...").
        let assigned = |group: &dyn Fn(u32) -> bool| {
            vrs.iter()
                .zip(vals)
                .filter(|(&vr, _)| group(vr))
                .map(|(&vr, v)| format!("{} = {v}", name_of_input(self, vr)))
                .collect::<Vec<_>>()
                .join(", ")
        };
        YarnSim::check_gravity(gravity).or_else(|e| {
            refuse(format!(
                "{} refused: {e}",
                assigned(&|vr| vr == VR_GRAVITY_X || vr == VR_GRAVITY_Y)
            ))
        })?;
        attractor.check().or_else(|e| {
            refuse(format!(
                "{} refused: {e}",
                assigned(&|vr| (VR_ATTRACTOR_X..=VR_ATTRACTOR_STRENGTH).contains(&vr))
            ))
        })?;
        inputs.check().or_else(|e| {
            refuse(format!(
                "{} refused: {e}",
                assigned(&|vr| self.pin_vr(vr).is_some())
            ))
        })?;
        self.sim
            .set_gravity(gravity)
            .and_then(|_| self.sim.set_attractor(attractor))
            .or_else(|e| refuse(e.to_string()))?;
        self.inputs = inputs;
        let changed = reals != self.config.reals;
        self.config.reals = reals;
        Ok(changed)
    }
    /// Sets Boolean inputs and parameters; true when a parameter changed.
    fn set_boolean(&mut self, set: Set<bool>) -> ModelResult<bool> {
        let Set { vrs, vals, ctx } = set;
        let mut attractor = self.sim.attractor();
        let mut plasticity = self.config.plasticity;
        for (&vr, &v) in vrs.iter().zip(vals) {
            match vr {
                VR_ATTRACTOR_ACTIVE => attractor.active = v,
                VR_PLASTICITY => {
                    (ctx.check)(name_of(vr))?;
                    plasticity = Some(v);
                }
                _ => {
                    return refuse(format!(
                        "{} is not a Boolean input or parameter",
                        self.shown(vr)
                    ))
                }
            }
        }
        self.sim
            .set_attractor(attractor)
            .or_else(|e| refuse(e.to_string()))?;
        let changed = plasticity != self.config.plasticity;
        self.config.plasticity = plasticity;
        Ok(changed)
    }
    fn state_magic(&self) -> &'static [u8; 8] {
        crate::models::state_bytes::YARN_STATE_MAGIC
    }
    fn stable_dt(&self) -> Option<f64> {
        Some(self.sim.stable_dt())
    }
    fn warnings(&self) -> Vec<String> {
        self.sim.scene().warnings()
    }
    fn adaptive(&self) -> bool {
        self.sim.is_auto()
    }
    fn substeps_to(&self, until: f64) -> u64 {
        self.sim.substeps_to(until)
    }
    /// The library's dynamic state (`YarnSim::dynamic_state`: particles,
    /// clock, inputs; not the grid) and the pin force sums.
    fn checkpoint(&self) -> Checkpoint {
        Box::new((self.sim.dynamic_state(), self.forces.clone()))
    }
    fn restore(&mut self, c: Checkpoint) {
        let (state, forces) = *c
            .downcast::<(DynamicState, PinForces)>()
            .expect("a checkpoint of a yarn model");
        self.sim
            .set_dynamic_state(&state)
            .expect("the simulation's own dynamic state fits it");
        self.forces = forces;
        self.diag = None;
    }
    fn set_string(&mut self, set: Set<Option<String>>) -> ModelResult<bool> {
        let yarnsim::scene::Scene::Yarn(bundled) = set.ctx.bundled else {
            return Err(ModelError("a yarn model with a mass-spring scene".into()));
        };
        YarnModel::set_string(self, set, bundled)
    }
    fn save(&self) -> ModelSnapshot {
        Box::new(YarnModel::save(self))
    }
    fn load(&mut self, s: &ModelSnapshot) -> ModelResult {
        let Some(s) = s.downcast_ref::<YarnSnapshot>() else {
            return refuse("not the state of a yarn model");
        };
        YarnModel::load(self, s)
    }
    fn write(&self, s: &ModelSnapshot, w: &mut Writer) -> Result<(), String> {
        let s = s
            .downcast_ref::<YarnSnapshot>()
            .ok_or("not the state of a yarn model")?;
        YarnModel::write(self, s, w)
    }
    fn read(&self, r: &mut Reader, _built: bool, count: usize) -> Result<ModelSnapshot, String> {
        Ok(Box::new(YarnModel::read(r, self, count)?))
    }
    fn box_clone(&self) -> Box<dyn FmuModel> {
        Box::new(self.clone())
    }
}
