//! Expansion of a [`MassSpringScene`] into its [`System`], with the checks
//! that need the expanded particles (indices, degenerate springs, overlaps).

use super::{Kinematic, MassSpringScene, Sphere, Spring, System, V3};
use crate::scene::error::{table_line, SceneError};

impl MassSpringScene {
    pub(super) fn build_with_source(&self, text: Option<&str>) -> Result<System, SceneError> {
        let table_line = |header: &str, i: usize| table_line(text, header, i);
        let key_line = |key: &str| {
            text.and_then(|t| {
                t.lines()
                    .position(|l| l.trim_start().starts_with(key))
                    .map(|i| i + 1)
            })
        };
        let invalid = |field: String, line: Option<usize>, message: String| SceneError::Invalid {
            field,
            line,
            message,
        };
        let n_total = self.particle_count();
        if n_total == 0 {
            return Err(invalid(
                "particles".into(),
                None,
                "a mass-spring scene needs at least one particle ([[particles]], [[chains]] or [[sheets]])".into(),
            ));
        }
        if n_total > 5_000_000 {
            return Err(invalid(
                "particles".into(),
                None,
                format!("{n_total} particles is more than the 5 million supported"),
            ));
        }
        let mut positions = Vec::with_capacity(n_total);
        let mut velocities = Vec::with_capacity(n_total);
        let mut masses = Vec::with_capacity(n_total);
        let mut springs = Vec::new();
        for p in &self.particles {
            positions.push(V3::from(p.position));
            velocities.push(V3::from(p.velocity));
            masses.push(p.mass);
        }
        for (ci, c) in self.chains.iter().enumerate() {
            let (s, e) = (V3::from(c.start), V3::from(c.end));
            if (e - s).norm() == 0.0 {
                return Err(invalid(
                    format!("chains[{ci}]"),
                    table_line("[[chains]]", ci),
                    "start and end coincide: the chain has zero length".into(),
                ));
            }
            let n = c.particles as usize;
            let base = positions.len();
            for i in 0..n {
                positions.push(s + (e - s) * (i as f64 / (n - 1) as f64));
                velocities.push(V3::zeros());
                masses.push(c.mass / n as f64);
            }
            for i in 0..n - 1 {
                let l0 = (positions[base + i + 1] - positions[base + i]).norm();
                springs.push(Spring {
                    a: base + i,
                    b: base + i + 1,
                    k: c.youngs_modulus / l0,
                    damping: c.damping,
                    rest_length: l0,
                });
            }
        }
        for (si, sh) in self.sheets.iter().enumerate() {
            let (o, eu, ev) = (
                V3::from(sh.origin),
                V3::from(sh.edge_u),
                V3::from(sh.edge_v),
            );
            if eu.cross(&ev).norm() == 0.0 {
                return Err(invalid(
                    format!("sheets[{si}]"),
                    table_line("[[sheets]]", si),
                    "edge_u and edge_v are parallel or zero: the sheet has no area".into(),
                ));
            }
            let (nu, nv) = (sh.nu as usize, sh.nv as usize);
            let base = positions.len();
            for j in 0..nv {
                for i in 0..nu {
                    positions.push(
                        o + eu * (i as f64 / (nu - 1) as f64) + ev * (j as f64 / (nv - 1) as f64),
                    );
                    velocities.push(V3::zeros());
                    masses.push(sh.mass);
                }
            }
            let edge = |a: usize, b: usize, springs: &mut Vec<Spring>| {
                let (a, b) = (base + a, base + b);
                springs.push(Spring {
                    a,
                    b,
                    k: sh.stiffness,
                    damping: sh.damping,
                    rest_length: (positions[b] - positions[a]).norm(),
                });
            };
            // Edges in the order of seed 001's sorted unique edge list:
            // by smaller index, then larger.
            for j in 0..nv {
                for i in 0..nu {
                    let v = j * nu + i;
                    if i + 1 < nu {
                        edge(v, v + 1, &mut springs);
                    }
                    if j + 1 < nv {
                        edge(v, v + nu, &mut springs);
                        if sh.diagonals && i + 1 < nu {
                            edge(v, v + nu + 1, &mut springs);
                        }
                    }
                }
            }
        }
        for (si, s) in self.springs.iter().enumerate() {
            let [a, b] = s.particles;
            let line = table_line("[[springs]]", si);
            if a >= n_total || b >= n_total {
                return Err(invalid(
                    format!("springs[{si}].particles"),
                    line,
                    format!(
                        "particle index {} out of range: the scene has {n_total} particles",
                        a.max(b)
                    ),
                ));
            }
            if a == b {
                return Err(invalid(
                    format!("springs[{si}].particles"),
                    line,
                    "a spring needs two different particles".into(),
                ));
            }
            let rest_length = match s.rest_length {
                Some(l) => l,
                None => {
                    let l = (positions[b] - positions[a]).norm();
                    if l == 0.0 {
                        return Err(invalid(
                            format!("springs[{si}].rest_length"),
                            line,
                            "the particles coincide, so the rest length must be given".into(),
                        ));
                    }
                    l
                }
            };
            springs.push(Spring {
                a,
                b,
                k: s.stiffness,
                damping: s.damping,
                rest_length,
            });
        }
        let mut kinematics = vec![Kinematic::Free; n_total];
        for &p in &self.pinned {
            if p >= n_total {
                return Err(invalid(
                    "pinned".into(),
                    key_line("pinned"),
                    format!("particle index {p} out of range: the scene has {n_total} particles"),
                ));
            }
            if !kinematics[p].is_free() {
                return Err(invalid(
                    "pinned".into(),
                    key_line("pinned"),
                    format!("particle {p} is listed twice"),
                ));
            }
            kinematics[p] = Kinematic::Pinned(positions[p]);
        }
        for (di, d) in self.driven.iter().enumerate() {
            let line = table_line("[[driven]]", di);
            if d.particle >= n_total {
                return Err(invalid(
                    format!("driven[{di}].particle"),
                    line,
                    format!(
                        "particle index {} out of range: the scene has {n_total} particles",
                        d.particle
                    ),
                ));
            }
            if !kinematics[d.particle].is_free() {
                return Err(invalid(
                    format!("driven[{di}].particle"),
                    line,
                    format!("particle {} is already pinned or driven", d.particle),
                ));
            }
            let k = Kinematic::Circle {
                center: V3::from(d.center),
                u: V3::from(d.u),
                v: V3::from(d.v),
                omega: 2.0 * std::f64::consts::PI / d.period,
                phase: d.phase,
            };
            let (x, v) = k.at(0.0).expect("driven");
            positions[d.particle] = x;
            velocities[d.particle] = v;
            kinematics[d.particle] = k;
        }
        let time_step = self.time.time_step.unwrap_or(self.time.frame_time);
        if time_step > self.time.frame_time * (1.0 + 1e-12) {
            return Err(invalid(
                "time.time_step".into(),
                key_line("time_step"),
                format!(
                    "time_step {time_step} is longer than frame_time {}",
                    self.time.frame_time
                ),
            ));
        }
        crate::scene::overlap::check_particles_outside_spheres(&positions, &self.spheres, text)?;
        Ok(System {
            positions,
            velocities,
            masses,
            springs,
            kinematics,
            spheres: self
                .spheres
                .iter()
                .map(|s| Sphere {
                    center: V3::from(s.center),
                    radius: s.radius,
                })
                .collect(),
            gravity: V3::from(self.gravity),
            frame_time: self.time.frame_time,
            frames: self.time.frames,
            time_step,
            cfl_number: self.time.cfl_number,
            velocity_damping: self.time.velocity_damping,
            strain_limit: self.time.strain_limit,
        })
    }
}
