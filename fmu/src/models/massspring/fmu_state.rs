//! The MassSpring model's part of a serialized FMU state: writing it and
//! reading it back ([`MsModel::write`], [`MsModel::read`]).

use yarnsim::massspring::{Integrator, MassSpringScene, V3};

use super::{build, MsModel};
use crate::models::state_bytes::{Reader, Writer};

impl MsModel {
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
