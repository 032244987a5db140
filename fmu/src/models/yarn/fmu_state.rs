//! The YarnBundle's part of a serialized FMU state: writing a saved
//! [`YarnSnapshot`] and reading it back ([`YarnModel::write`],
//! [`YarnModel::read`]).

use yarnsim::math::Vec2;
use yarnsim::mpm::YarnSim;
use yarnsim::scene::{Axial, Integrator, TransferScheme, YarnScene};

use super::variables::*;
use super::{effective_scene, Config, Inputs, PinForces, YarnModel, YarnSnapshot};
use crate::models::state_bytes::{Reader, Writer};

impl YarnModel {
    /// A saved state's part of a serialized FMU state: the pin inputs, the
    /// parameters, the scene text and the library's own state bytes (which
    /// carry their own header and checksum; encoded by this model's
    /// simulation when it runs the state's scene, else by one built for
    /// it).
    pub fn write(&self, s: &YarnSnapshot, w: &mut Writer) -> Result<(), String> {
        // Gravity and the attractor are in the library's state bytes.
        for p in &s.inputs.pins {
            w.f64(p.position[0]);
            w.f64(p.position[1]);
            w.f64(p.velocity[0]);
            w.f64(p.velocity[1]);
        }
        w.bytes(s.config.scene_path.as_bytes());
        for v in s.config.reals {
            w.opt_f64(v);
        }
        w.u8(s.config.plasticity.is_some() as u8);
        w.u8(s.config.plasticity.unwrap_or(false) as u8);
        w.u8(match s.config.scheme {
            None => 0,
            Some(TransferScheme::Flip) => 1,
            Some(TransferScheme::Apic) => 2,
        });
        w.u8(match s.config.integrator {
            None => 0,
            Some(Integrator::Explicit) => 1,
            Some(Integrator::Implicit) => 2,
            Some(Integrator::ImplicitVertices) => 3,
            Some(Integrator::MidpointVertices) => 4,
        });
        w.u8(match s.config.axial {
            None => 0,
            Some(Axial::Explicit) => 1,
            Some(Axial::Implicit) => 2,
        });
        w.u64(s.forces.substeps);
        w.f64(s.forces.weight);
        for f in &s.forces.sum {
            w.f64(f.x);
            w.f64(f.y);
        }
        w.bytes(s.base.to_toml_string().as_bytes());
        let scene = s.scene();
        let built;
        let sim = if *self.sim.scene() == scene {
            &self.sim
        } else {
            built = YarnSim::new(&scene).map_err(|e| format!("stored scene: {e}"))?;
            &built
        };
        w.bytes_with(sim.state_size(), |out| sim.encode_state_into(&s.sim, out))
            .map_err(|e| e.to_string())
    }

    /// Reads what [`Self::write`] wrote; the library's state bytes are
    /// checked and decoded by `current`'s simulation when it runs the
    /// stored scene with the stored parameters, else by one built for them.
    pub fn read(r: &mut Reader, current: &YarnModel, yarns: usize) -> Result<YarnSnapshot, String> {
        let mut inputs = Inputs {
            pins: current.inputs.pins.clone(),
        };
        // The pins are the bundled scene's (the `scene` parameter keeps them).
        for p in &mut inputs.pins {
            p.position = [r.f64()?, r.f64()?];
            p.velocity = [r.f64()?, r.f64()?];
        }
        inputs.check().map_err(|e| e.0)?;
        let scene_path = r.string()?;
        let mut reals = [None; YARN_REAL_PARAMETERS];
        for v in &mut reals {
            *v = r.opt_f64()?;
        }
        let has_p = r.bool()?;
        let p = r.bool()?;
        let scheme = match r.u8()? {
            0 => None,
            1 => Some(TransferScheme::Flip),
            2 => Some(TransferScheme::Apic),
            b => return Err(format!("bad transfer scheme byte {b}")),
        };
        let integrator = match r.u8()? {
            0 => None,
            1 => Some(Integrator::Explicit),
            2 => Some(Integrator::Implicit),
            3 => Some(Integrator::ImplicitVertices),
            4 => Some(Integrator::MidpointVertices),
            b => return Err(format!("bad integrator byte {b}")),
        };
        let axial = match r.u8()? {
            0 => None,
            1 => Some(Axial::Explicit),
            2 => Some(Axial::Implicit),
            b => return Err(format!("bad time.axial byte {b}")),
        };
        if let Some((i, v)) = reals.iter().enumerate().find_map(|(i, v)| {
            let (_, f) = yarn_real_parameters().nth(i).unwrap();
            v.filter(|v| !(0.0..=f.max).contains(v)).map(|v| (i, v))
        }) {
            return Err(format!("stored parameter {i} = {v} is out of range"));
        }
        let config = Config {
            scene_path,
            reals,
            plasticity: has_p.then_some(p),
            scheme,
            integrator,
            axial,
        };
        let substeps = r.u64()?;
        let weight = r.f64()?;
        if !(weight.is_finite() && weight >= 0.0) {
            return Err(format!("bad pin force weight {weight}"));
        }
        let mut sum = Vec::with_capacity(current.forces.sum.len());
        for _ in 0..current.forces.sum.len() {
            sum.push(Vec2::new(r.f64()?, r.f64()?));
        }
        let forces = PinForces {
            sum,
            substeps,
            weight,
        };
        let scene_text = r.string()?;
        let sim_bytes = r.bytes()?;
        r.finish()?;
        let base = if scene_text == current.base.to_toml_string() {
            current.base.clone()
        } else {
            YarnScene::from_toml_str(&scene_text).map_err(|e| format!("stored scene: {e}"))?
        };
        let scene = effective_scene(&base, &config);
        let sim = if *current.sim.scene() == scene {
            current.sim.decode_state(sim_bytes)
        } else {
            let sim = YarnSim::new(&scene).map_err(|e| format!("stored scene: {e}"))?;
            if sim.num_yarns() != yarns {
                return Err(format!(
                    "state has {} yarns, this FMU {yarns}",
                    sim.num_yarns()
                ));
            }
            sim.decode_state(sim_bytes)
        }
        .map_err(|e| e.to_string())?;
        Ok(YarnSnapshot {
            config,
            base,
            inputs,
            forces,
            sim,
        })
    }
}
