//! Expansion of a [`MassSpringScene`] into its [`System`], one function per
//! scene element (explicit particles, chains, sheets, springs, pins, driven
//! particles, time step, spheres), with the checks that need the expanded
//! particles (indices, degenerate springs, overlaps). Particles are numbered
//! in file order: explicit ones, then the chains', then the sheets'.

use super::{
    ChainSpec, DrivenSpec, Kinematic, MassSpringScene, SheetSpec, Sphere, Spring, SpringSpec,
    System, V3,
};
use crate::scene::error::{table_line, SceneError};

/// The most particles a scene may expand to.
const MAX_PARTICLES: usize = 5_000_000;

/// The scene file's text, when there is one, for the lines in errors.
#[derive(Clone, Copy)]
struct Source<'a>(Option<&'a str>);

impl Source<'_> {
    /// The line of the `i`-th `header` table.
    fn table_line(self, header: &str, i: usize) -> Option<usize> {
        table_line(self.0, header, i)
    }

    /// The first line that starts with `key`.
    fn key_line(self, key: &str) -> Option<usize> {
        self.0.and_then(|t| {
            t.lines()
                .position(|l| l.trim_start().starts_with(key))
                .map(|i| i + 1)
        })
    }
}

fn invalid(field: String, line: Option<usize>, message: String) -> SceneError {
    SceneError::Invalid {
        field,
        line,
        message,
    }
}

fn out_of_range(index: usize, n_total: usize) -> String {
    format!("particle index {index} out of range: the scene has {n_total} particles")
}

/// The particles and springs expanded so far.
struct Particles {
    positions: Vec<V3>,
    velocities: Vec<V3>,
    masses: Vec<f64>,
    springs: Vec<Spring>,
}

impl Particles {
    fn with_capacity(n: usize) -> Self {
        Particles {
            positions: Vec::with_capacity(n),
            velocities: Vec::with_capacity(n),
            masses: Vec::with_capacity(n),
            springs: Vec::new(),
        }
    }

    fn push(&mut self, x: V3, v: V3, m: f64) {
        self.positions.push(x);
        self.velocities.push(v);
        self.masses.push(m);
    }
}

impl MassSpringScene {
    pub(super) fn build_with_source(&self, text: Option<&str>) -> Result<System, SceneError> {
        let src = Source(text);
        let n_total = self.checked_particle_count()?;
        let mut p = Particles::with_capacity(n_total);
        self.add_particles(&mut p);
        for (ci, c) in self.chains.iter().enumerate() {
            add_chain(&mut p, ci, c, src)?;
        }
        for (si, sh) in self.sheets.iter().enumerate() {
            add_sheet(&mut p, si, sh, src)?;
        }
        for (si, s) in self.springs.iter().enumerate() {
            add_spring(&mut p, si, s, n_total, src)?;
        }
        let mut kinematics = self.pins(&p.positions, src)?;
        for (di, d) in self.driven.iter().enumerate() {
            add_driven(&mut p, &mut kinematics, di, d, src)?;
        }
        let time_step = self.checked_time_step(src)?;
        super::overlap::check_particles_outside_spheres(&p.positions, &self.spheres, text)?;
        Ok(System {
            positions: p.positions,
            velocities: p.velocities,
            masses: p.masses,
            springs: p.springs,
            kinematics,
            spheres: self.expanded_spheres(),
            gravity: V3::from(self.gravity),
            frame_time: self.time.frame_time,
            frames: self.time.frames,
            time_step,
            cfl_number: self.time.cfl_number,
            velocity_damping: self.time.velocity_damping,
            strain_limit: self.time.strain_limit,
        })
    }

    /// The particle count, refused when zero or over [`MAX_PARTICLES`].
    fn checked_particle_count(&self) -> Result<usize, SceneError> {
        let n_total = self.particle_count();
        if n_total == 0 {
            return Err(invalid(
                "particles".into(),
                None,
                "a mass-spring scene needs at least one particle ([[particles]], [[chains]] or [[sheets]])".into(),
            ));
        }
        if n_total > MAX_PARTICLES {
            return Err(invalid(
                "particles".into(),
                None,
                format!("{n_total} particles is more than the 5 million supported"),
            ));
        }
        Ok(n_total)
    }

    /// The explicit `[[particles]]`.
    fn add_particles(&self, p: &mut Particles) {
        for s in &self.particles {
            p.push(V3::from(s.position), V3::from(s.velocity), s.mass);
        }
    }

    /// Kinematics with the `pinned` particles held at their start position.
    fn pins(&self, positions: &[V3], src: Source) -> Result<Vec<Kinematic>, SceneError> {
        let n_total = positions.len();
        let mut kinematics = vec![Kinematic::Free; n_total];
        for (k, &i) in self.pinned.iter().enumerate() {
            if i >= n_total {
                return Err(invalid(
                    format!("pinned[{k}]"),
                    src.key_line("pinned"),
                    out_of_range(i, n_total),
                ));
            }
            if !kinematics[i].is_free() {
                return Err(invalid(
                    format!("pinned[{k}]"),
                    src.key_line("pinned"),
                    format!("particle {i} is listed twice"),
                ));
            }
            kinematics[i] = Kinematic::Pinned(positions[i]);
        }
        Ok(kinematics)
    }

    /// The implicit integrators' step (default `frame_time`), refused when
    /// longer than a frame.
    fn checked_time_step(&self, src: Source) -> Result<f64, SceneError> {
        let time_step = self.time.time_step.unwrap_or(self.time.frame_time);
        if time_step > self.time.frame_time * (1.0 + 1e-12) {
            return Err(invalid(
                "time.time_step".into(),
                src.key_line("time_step"),
                format!(
                    "time_step {time_step} is longer than frame_time {}",
                    self.time.frame_time
                ),
            ));
        }
        Ok(time_step)
    }

    fn expanded_spheres(&self) -> Vec<Sphere> {
        self.spheres
            .iter()
            .map(|s| Sphere {
                center: V3::from(s.center),
                radius: s.radius,
            })
            .collect()
    }
}

/// Chain `ci`: `particles` equal masses from `start` to `end`, springs of
/// stiffness `E / l0` between neighbours.
fn add_chain(p: &mut Particles, ci: usize, c: &ChainSpec, src: Source) -> Result<(), SceneError> {
    let (s, e) = (V3::from(c.start), V3::from(c.end));
    if (e - s).norm() == 0.0 {
        return Err(invalid(
            format!("chains[{ci}]"),
            src.table_line("[[chains]]", ci),
            "start and end coincide: the chain has zero length".into(),
        ));
    }
    let n = c.particles as usize;
    let base = p.positions.len();
    for i in 0..n {
        p.push(
            s + (e - s) * (i as f64 / (n - 1) as f64),
            V3::zeros(),
            c.mass / n as f64,
        );
    }
    for i in 0..n - 1 {
        let l0 = (p.positions[base + i + 1] - p.positions[base + i]).norm();
        p.springs.push(Spring {
            a: base + i,
            b: base + i + 1,
            k: c.youngs_modulus / l0,
            damping: c.damping,
            rest_length: l0,
        });
    }
    Ok(())
}

/// Sheet `si`: an `nu x nv` grid of vertices with structural edges and,
/// optionally, one diagonal per quad.
fn add_sheet(p: &mut Particles, si: usize, sh: &SheetSpec, src: Source) -> Result<(), SceneError> {
    let (o, eu, ev) = (
        V3::from(sh.origin),
        V3::from(sh.edge_u),
        V3::from(sh.edge_v),
    );
    if eu.cross(&ev).norm() == 0.0 {
        return Err(invalid(
            format!("sheets[{si}]"),
            src.table_line("[[sheets]]", si),
            "edge_u and edge_v are parallel or zero: the sheet has no area".into(),
        ));
    }
    let (nu, nv) = (sh.nu as usize, sh.nv as usize);
    let base = p.positions.len();
    for j in 0..nv {
        for i in 0..nu {
            p.push(
                o + eu * (i as f64 / (nu - 1) as f64) + ev * (j as f64 / (nv - 1) as f64),
                V3::zeros(),
                sh.mass,
            );
        }
    }
    let mut edge = |a: usize, b: usize| {
        let (a, b) = (base + a, base + b);
        let rest_length = (p.positions[b] - p.positions[a]).norm();
        p.springs.push(Spring {
            a,
            b,
            k: sh.stiffness,
            damping: sh.damping,
            rest_length,
        });
    };
    // Edges in the order of the Unity cloth scripts' sorted unique edge list:
    // by smaller index, then larger.
    for j in 0..nv {
        for i in 0..nu {
            let v = j * nu + i;
            if i + 1 < nu {
                edge(v, v + 1);
            }
            if j + 1 < nv {
                edge(v, v + nu);
                if sh.diagonals && i + 1 < nu {
                    edge(v, v + nu + 1);
                }
            }
        }
    }
    Ok(())
}

/// Spring `si` between two of the `n_total` particles; its rest length
/// defaults to their start distance.
fn add_spring(
    p: &mut Particles,
    si: usize,
    s: &SpringSpec,
    n_total: usize,
    src: Source,
) -> Result<(), SceneError> {
    let [a, b] = s.particles;
    let line = src.table_line("[[springs]]", si);
    if a >= n_total || b >= n_total {
        return Err(invalid(
            format!("springs[{si}].particles"),
            line,
            out_of_range(a.max(b), n_total),
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
            let l = (p.positions[b] - p.positions[a]).norm();
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
    p.springs.push(Spring {
        a,
        b,
        k: s.stiffness,
        damping: s.damping,
        rest_length,
    });
    Ok(())
}

/// Driven particle `di`: moved on its circle, starting at the circle's
/// position and velocity at `t = 0`.
fn add_driven(
    p: &mut Particles,
    kinematics: &mut [Kinematic],
    di: usize,
    d: &DrivenSpec,
    src: Source,
) -> Result<(), SceneError> {
    let n_total = kinematics.len();
    let line = src.table_line("[[driven]]", di);
    if d.particle >= n_total {
        return Err(invalid(
            format!("driven[{di}].particle"),
            line,
            out_of_range(d.particle, n_total),
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
    p.positions[d.particle] = x;
    p.velocities[d.particle] = v;
    kinematics[d.particle] = k;
    Ok(())
}
