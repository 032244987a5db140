//! The yarn-bundle physics behind the `YarnBundle` FMU: inputs, parameter
//! overrides, the [`YarnSim`] they build, the values of its variables
//! ([`crate::model`] lists them) and its part of a serialized FMU state.

use std::path::Path;

use yarnsim::math::Vec2;
use yarnsim::mpm::{Attractor, Diagnostics, SimError, YarnSim};
use yarnsim::scene::YarnScene;

use crate::fmu_model::{
    refuse, Checkpoint, FmuModel, ModelError, ModelResult, ParamCheck, SetContext, StepFailure,
};
use crate::model::*;
use crate::state_bytes::{Reader, Writer};

/// Values of the inputs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inputs {
    pub attractor: [f64; 2],
    pub strength: f64,
    pub active: bool,
    pub gravity: [f64; 2],
}

impl Inputs {
    fn from_scene(s: &YarnScene) -> Self {
        Inputs {
            attractor: s.attractor.position,
            strength: s.attractor.strength,
            active: s.attractor.active,
            gravity: s.gravity,
        }
    }

    /// Checks the inputs the way the library does, then hands them to `sim`.
    fn apply(&self, sim: &mut YarnSim) -> ModelResult {
        sim.set_gravity(Vec2::from(self.gravity))
            .and_then(|_| {
                sim.set_attractor(Attractor {
                    position: Vec2::from(self.attractor),
                    strength: self.strength,
                    active: self.active,
                })
            })
            .or_else(|e| refuse(e.to_string()))
    }

    /// The library's input limits, without a simulation at hand.
    fn check(&self) -> ModelResult {
        let g = Vec2::from(self.gravity);
        if g.norm() > 1e6 {
            return refuse(format!(
                "gravity ({}, {}) is absurd (|g| above 1e6 m/s2)",
                g.x, g.y
            ));
        }
        if !(0.0..=1e6).contains(&self.strength) {
            return refuse(format!(
                "attractor strength {} must be in [0, 1e6] m/s2",
                self.strength
            ));
        }
        if self.attractor.iter().any(|c| c.abs() > 1e6) {
            return refuse(format!(
                "attractor position ({}, {}) is absurd (beyond 1e6 m)",
                self.attractor[0], self.attractor[1]
            ));
        }
        Ok(())
    }
}

/// The parameters as set by the environment (`None`: the scene's value).
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    pub scene_path: String,
    /// Overrides of [`yarn_real_parameters`], in that order.
    pub reals: [Option<f64>; YARN_REAL_PARAMETERS],
    pub plasticity: Option<bool>,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            scene_path: SCENE_FILE.to_string(),
            reals: [None; YARN_REAL_PARAMETERS],
            plasticity: None,
        }
    }
}

/// Index of the Real parameter `vr` in [`yarn_real_parameters`] and its
/// scene field.
fn real_param(vr: u32) -> Option<(usize, SceneField)> {
    yarn_real_parameters()
        .enumerate()
        .find(|(_, (p, _))| *p == vr)
        .map(|(i, (_, f))| (i, f))
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
    s
}

fn read_scene(path: &Path) -> Result<YarnScene, String> {
    let text = read_scene_text(path)?;
    YarnScene::from_toml_str(&text).map_err(|e| format!("scene file {}: {e}", path.display()))
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
}

impl YarnModel {
    pub fn new(base: YarnScene) -> ModelResult<Self> {
        let sim = YarnSim::new(&base).or_else(|e| refuse(format!("scene: {e}")))?;
        Ok(YarnModel {
            config: Config::default(),
            inputs: Inputs::from_scene(&base),
            base,
            sim,
            diag: None,
        })
    }

    /// Rebuilds the simulation from the scene and the parameters.
    pub fn rebuild(&mut self, yarns: usize) -> ModelResult {
        let scene = effective_scene(&self.base, &self.config);
        let mut sim = YarnSim::new(&scene).or_else(|e| refuse(format!("parameters: {e}")))?;
        if sim.num_yarns() != yarns {
            return refuse(format!(
                "scene {:?} creates {} yarns, but this FMU has outputs for {yarns}",
                self.config.scene_path,
                sim.num_yarns()
            ));
        }
        self.inputs.apply(&mut sim)?;
        self.sim = sim;
        self.diag = None;
        Ok(())
    }

    pub fn count(&self) -> usize {
        self.sim.num_yarns()
    }

    pub fn dt(&self) -> f64 {
        self.sim.dt()
    }

    pub fn substep(&mut self) -> Result<(), StepFailure> {
        self.diag = None;
        self.sim.step().map_err(|e| StepFailure {
            terminal: matches!(e, SimError::NonFinite { .. }),
            msg: e.to_string(),
        })
    }

    /// Every Real output is finite: the yarn ends, the energies and the
    /// largest stretch (the library reports divergence itself; this makes
    /// sure no step ends OK with a non-finite output). The diagnostics it
    /// computes are cached for the `fmi2GetReal` calls that follow.
    pub fn outputs_finite(&mut self) -> bool {
        let d = self.diagnostics();
        d.kinetic_energy.is_finite()
            && d.elastic_energy.is_finite()
            && d.max_stretch.is_finite()
            && (0..self.count()).all(|y| {
                let (l, r) = self.sim.yarn_endpoints(y);
                l.x.is_finite() && l.y.is_finite() && r.x.is_finite() && r.y.is_finite()
            })
    }

    fn diagnostics(&mut self) -> Diagnostics {
        *self.diag.get_or_insert_with(|| self.sim.diagnostics())
    }

    /// Whether the Real variable `vr` depends on the simulated state.
    pub fn is_state_output(&self, vr: u32) -> bool {
        matches!(vr, VR_KINETIC_ENERGY | VR_ELASTIC_ENERGY | VR_MAX_STRETCH)
            || (vr >= VR_YARN_BASE && ((vr - VR_YARN_BASE) / 4) < self.count() as u32)
    }

    /// The value of the Real variable `vr`, `None` if there is none.
    pub fn get_real(&mut self, vr: u32) -> Option<f64> {
        Some(match vr {
            VR_ATTRACTOR_X => self.inputs.attractor[0],
            VR_ATTRACTOR_Y => self.inputs.attractor[1],
            VR_ATTRACTOR_STRENGTH => self.inputs.strength,
            VR_GRAVITY_X => self.inputs.gravity[0],
            VR_GRAVITY_Y => self.inputs.gravity[1],
            _ if real_param(vr).is_some() => {
                let (i, field) = real_param(vr).unwrap();
                self.config.reals[i].unwrap_or_else(|| (field.get)(&self.base))
            }
            VR_KINETIC_ENERGY => self.diagnostics().kinetic_energy,
            VR_ELASTIC_ENERGY => self.diagnostics().elastic_energy,
            VR_MAX_STRETCH => self.diagnostics().max_stretch,
            _ if self.is_state_output(vr) => {
                let i = (vr - VR_YARN_BASE) as usize;
                let (l, r) = self.sim.yarn_endpoints(i / 4);
                [l.x, l.y, r.x, r.y][i % 4]
            }
            _ => return None,
        })
    }

    pub fn get_boolean(&self, vr: u32) -> Option<bool> {
        match vr {
            VR_ATTRACTOR_ACTIVE => Some(self.inputs.active),
            VR_PLASTICITY => Some(
                self.config
                    .plasticity
                    .unwrap_or(self.base.material.plasticity),
            ),
            _ => None,
        }
    }

    pub fn get_string(&self, vr: u32) -> Option<&str> {
        (vr == VR_SCENE).then_some(self.config.scene_path.as_str())
    }

    /// Sets Real inputs and parameters; true when a parameter changed (the
    /// simulation must be rebuilt). A rejected call changes nothing.
    pub fn set_real(
        &mut self,
        vrs: &[u32],
        vals: &[f64],
        param_ok: ParamCheck,
    ) -> ModelResult<bool> {
        let mut inputs = self.inputs;
        let mut reals = self.config.reals;
        for (&vr, &v) in vrs.iter().zip(vals) {
            match vr {
                VR_ATTRACTOR_X => inputs.attractor[0] = v,
                VR_ATTRACTOR_Y => inputs.attractor[1] = v,
                VR_ATTRACTOR_STRENGTH => inputs.strength = v,
                VR_GRAVITY_X => inputs.gravity[0] = v,
                VR_GRAVITY_Y => inputs.gravity[1] = v,
                _ if real_param(vr).is_some() => {
                    param_ok(vr)?;
                    let (i, field) = real_param(vr).unwrap();
                    let ok = if field.positive { v > 0.0 } else { v >= 0.0 } && v <= 1e12;
                    if !ok {
                        return refuse(format!(
                            "parameter value reference {vr} = {v} is out of range"
                        ));
                    }
                    reals[i] = Some(v);
                }
                _ => {
                    return refuse(format!(
                        "value reference {vr} is not a Real input or parameter"
                    ))
                }
            }
        }
        inputs.check()?;
        if inputs != self.inputs {
            self.inputs = inputs;
            inputs.apply(&mut self.sim)?;
        }
        let changed = reals != self.config.reals;
        self.config.reals = reals;
        Ok(changed)
    }

    /// Sets Boolean inputs and parameters; true when a parameter changed.
    pub fn set_boolean(
        &mut self,
        vrs: &[u32],
        vals: &[bool],
        param_ok: ParamCheck,
    ) -> ModelResult<bool> {
        let mut active = self.inputs.active;
        let mut plasticity = self.config.plasticity;
        for (&vr, &v) in vrs.iter().zip(vals) {
            match vr {
                VR_ATTRACTOR_ACTIVE => active = v,
                VR_PLASTICITY => {
                    param_ok(vr)?;
                    plasticity = Some(v);
                }
                _ => {
                    return refuse(format!(
                        "value reference {vr} is not a Boolean input or parameter"
                    ))
                }
            }
        }
        if active != self.inputs.active {
            self.inputs.active = active;
            let inputs = self.inputs;
            inputs.apply(&mut self.sim)?;
        }
        let changed = plasticity != self.config.plasticity;
        self.config.plasticity = plasticity;
        Ok(changed)
    }

    /// Sets the `scene` parameter: a scene file in `resources` (or the
    /// bundled one, `bundled`); true when it changed.
    pub fn set_string(
        &mut self,
        vrs: &[u32],
        vals: &[Option<String>],
        param_ok: ParamCheck,
        resources: &Path,
        bundled: &YarnScene,
    ) -> ModelResult<bool> {
        let mut changed = false;
        for (&vr, v) in vrs.iter().zip(vals) {
            if vr != VR_SCENE {
                return refuse(format!("value reference {vr} is not a String parameter"));
            }
            param_ok(vr)?;
            let Some(v) = v else {
                return refuse("the scene file name is a null pointer");
            };
            let base = if v == SCENE_FILE {
                bundled.clone()
            } else {
                read_scene(&resources.join(v)).or_else(refuse)?
            };
            let yarns = num_yarns(&base);
            if yarns != num_yarns(bundled) {
                return refuse(format!(
                    "scene {v:?} creates {yarns} yarns, but this FMU has outputs for {}",
                    num_yarns(bundled)
                ));
            }
            self.config.scene_path = v.clone();
            self.base = base;
            changed = true;
        }
        Ok(changed)
    }

    /// This model's part of a serialized FMU state: the inputs, the
    /// parameters, the scene text and the library's own state bytes (which
    /// carry their own header and checksum).
    pub fn write(&self, w: &mut Writer) {
        let i = &self.inputs;
        w.f64(i.attractor[0]);
        w.f64(i.attractor[1]);
        w.f64(i.strength);
        w.u8(i.active as u8);
        w.f64(i.gravity[0]);
        w.f64(i.gravity[1]);
        w.bytes(self.config.scene_path.as_bytes());
        for v in self.config.reals {
            w.opt_f64(v);
        }
        w.u8(self.config.plasticity.is_some() as u8);
        w.u8(self.config.plasticity.unwrap_or(false) as u8);
        w.bytes(self.base.to_toml_string().as_bytes());
        w.bytes(&self.sim.save_state());
    }

    /// Reads what [`Self::write`] wrote; `current` (with `current_built`: its
    /// simulation matches its scene and parameters) is reused when the stored
    /// scene and parameters match, else the simulation is rebuilt.
    pub fn read(
        r: &mut Reader,
        current: &YarnModel,
        current_built: bool,
        yarns: usize,
    ) -> Result<YarnModel, String> {
        let inputs = Inputs {
            attractor: [r.f64()?, r.f64()?],
            strength: r.f64()?,
            active: r.bool()?,
            gravity: [r.f64()?, r.f64()?],
        };
        inputs.check().map_err(|e| e.0)?;
        let scene_path = r.string()?;
        let mut reals = [None; YARN_REAL_PARAMETERS];
        for v in &mut reals {
            *v = r.opt_f64()?;
        }
        let has_p = r.bool()?;
        let p = r.bool()?;
        let config = Config {
            scene_path,
            reals,
            plasticity: has_p.then_some(p),
        };
        let scene_text = r.string()?;
        let sim_bytes = r.bytes()?;
        r.finish()?;
        let base = if scene_text == current.base.to_toml_string() {
            current.base.clone()
        } else {
            YarnScene::from_toml_str(&scene_text).map_err(|e| format!("stored scene: {e}"))?
        };
        let mut sim = if current_built && base == current.base && config == current.config {
            current.sim.clone()
        } else {
            YarnSim::new(&effective_scene(&base, &config))
                .map_err(|e| format!("stored scene: {e}"))?
        };
        if sim.num_yarns() != yarns {
            return Err(format!(
                "state has {} yarns, this FMU {yarns}",
                sim.num_yarns()
            ));
        }
        sim.load_state(sim_bytes).map_err(|e| e.to_string())?;
        Ok(YarnModel {
            config,
            base,
            sim,
            inputs,
            diag: None,
        })
    }
}

impl FmuModel for YarnModel {
    fn state_magic(&self) -> &'static [u8; 8] {
        crate::state_bytes::YARN_STATE_MAGIC
    }
    fn count(&self) -> usize {
        YarnModel::count(self)
    }
    fn dt(&self) -> f64 {
        YarnModel::dt(self)
    }
    fn stable_dt(&self) -> Option<f64> {
        Some(self.sim.stable_dt())
    }
    fn rebuild(&mut self, count: usize) -> ModelResult {
        YarnModel::rebuild(self, count)
    }
    fn substep(&mut self, _k: u64) -> Result<(), StepFailure> {
        YarnModel::substep(self)
    }
    fn outputs_finite(&mut self) -> bool {
        YarnModel::outputs_finite(self)
    }
    /// The library's state bytes: a clone of the whole `YarnSim` with its
    /// grid costs far more than its particles.
    fn checkpoint(&self) -> Checkpoint {
        Box::new(self.sim.save_state())
    }
    fn restore(&mut self, c: Checkpoint) {
        let bytes = c
            .downcast::<Vec<u8>>()
            .expect("a checkpoint of a yarn model");
        self.sim
            .load_state(&bytes)
            .expect("the simulation's own state bytes load");
        self.diag = None;
    }
    fn is_state_output(&self, vr: u32) -> bool {
        YarnModel::is_state_output(self, vr)
    }
    fn get_real(&mut self, vr: u32) -> Option<f64> {
        YarnModel::get_real(self, vr)
    }
    fn get_boolean(&self, vr: u32) -> Option<bool> {
        YarnModel::get_boolean(self, vr)
    }
    fn get_string(&self, vr: u32) -> Option<&str> {
        YarnModel::get_string(self, vr)
    }
    fn set_real(&mut self, vrs: &[u32], vals: &[f64], check: ParamCheck) -> ModelResult<bool> {
        YarnModel::set_real(self, vrs, vals, check)
    }
    fn set_boolean(&mut self, vrs: &[u32], vals: &[bool], check: ParamCheck) -> ModelResult<bool> {
        YarnModel::set_boolean(self, vrs, vals, check)
    }
    fn set_string(
        &mut self,
        vrs: &[u32],
        vals: &[Option<String>],
        check: ParamCheck,
        ctx: &SetContext,
    ) -> ModelResult<bool> {
        let crate::model::FmuScene::Yarn(bundled) = ctx.bundled else {
            return Err(ModelError("a yarn model with a mass-spring scene".into()));
        };
        YarnModel::set_string(self, vrs, vals, check, ctx.resources, bundled)
    }
    fn write(&self, w: &mut Writer) {
        YarnModel::write(self, w)
    }
    fn read(&self, r: &mut Reader, built: bool, count: usize) -> Result<Box<dyn FmuModel>, String> {
        Ok(Box::new(YarnModel::read(r, self, built, count)?))
    }
    fn box_clone(&self) -> Box<dyn FmuModel> {
        Box::new(self.clone())
    }
}
