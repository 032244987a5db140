//! `yarnsim run`: run a scene, print a summary table, optionally write a CSV
//! of the yarn endpoints and diagnostics per frame.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use yarnsim::mpm::Diagnostics;
use yarnsim::scene::{Scene, YarnScene};
use yarnsim::YarnSim;

use crate::driver::run_frames_shown;
use crate::error::CliError;
use crate::massspring::{IntegratorArgs, MassSpringRun, MsDiagnostics};
use crate::schedule::Schedule;
use crate::table::{count, energy_rows, yarn_rows, DiagRow, Summary};
use crate::yarn::YarnFlags;

/// A scene's simulation, started with the command's integrator flags, for
/// `run` and `record`.
pub enum Started {
    Yarn(Box<YarnSim>),
    MassSpring(Box<MassSpringRun>),
}

impl Started {
    /// Starts `scene`. `integrator`: the mass-spring integrator, and
    /// `allow_unstable` for both kinds of scene (see [`start_yarn`]).
    pub fn new(scene: &Scene, integrator: &IntegratorArgs) -> Result<Self, CliError> {
        Ok(match scene {
            Scene::Yarn(y) => Started::Yarn(Box::new(start_yarn(y, integrator)?)),
            Scene::MassSpring(l) => {
                Started::MassSpring(Box::new(MassSpringRun::new(l, integrator)?))
            }
        })
    }
}

/// Runs `sim` for `duration` seconds; writes the CSV to `csv` if given.
pub fn run(sim: &mut Started, duration: f64, csv: Option<&Path>) -> Result<Summary, CliError> {
    match sim {
        Started::Yarn(sim) => run_yarn(sim, duration, csv),
        Started::MassSpring(run) => run_massspring(run, duration, csv),
    }
}

/// Runs a mass-spring simulation from its current state for `duration` seconds.
pub fn run_massspring(
    run: &mut MassSpringRun,
    duration: f64,
    csv: Option<&Path>,
) -> Result<Summary, CliError> {
    let sys = run.sim.system();
    let schedule = Schedule::new(duration, run.h, sys.frame_time)?;
    let mut csv = CsvWriter::create_with(csv, &ms_csv_header())?;
    let (particles, springs, spheres) = (sys.len(), sys.springs.len(), sys.spheres.len());
    let fixed = sys.len() - sys.free_count();
    let initial = run.diagnostics();
    let mut last = initial;
    let name = run.name.clone();
    let frames = run_frames_shown(run, &schedule, &name, |run, frame| {
        last = run.diagnostics();
        csv.ms_row(frame.frame, &last)
    })?;
    csv.finish()?;
    Ok(Summary {
        scene: run.name.clone(),
        model: format!("mass-spring, {}", run.sim.integrator()),
        particles,
        particles_detail: format!(
            "{fixed} pinned or driven, {}, {}",
            count(springs, "spring"),
            count(spheres, "sphere")
        ),
        dt: run.h,
        adaptive_dt: None,
        diagnostics: ms_rows(&initial, &last),
        ..Summary::of_run(frames, last.time - initial.time)
    })
}

/// The summary rows of a mass-spring run.
pub fn ms_rows(a: &MsDiagnostics, b: &MsDiagnostics) -> Vec<DiagRow> {
    let mut rows = energy_rows!(a, b, "time [s]", gravity_energy, "gravity energy");
    rows.extend([
        ("momentum z", a.momentum.z, b.momentum.z),
        (
            "ang. momentum x",
            a.angular_momentum.x,
            b.angular_momentum.x,
        ),
        (
            "ang. momentum y",
            a.angular_momentum.y,
            b.angular_momentum.y,
        ),
        (
            "ang. momentum z",
            a.angular_momentum.z,
            b.angular_momentum.z,
        ),
        ("max strain", a.max_strain, b.max_strain),
    ]);
    rows
}

/// The simulation of a yarn scene for `run`, `record` and `bench`, with
/// the command's integrator flags: `--integrator` and `--option` refused
/// with a pointer to the scene field, a fixed `time.dt` checked against the
/// stable bound ([`crate::yarn::start`]).
pub fn start_yarn(scene: &YarnScene, args: &IntegratorArgs) -> Result<YarnSim, CliError> {
    crate::yarn::start(
        scene,
        YarnFlags {
            integrator: args.integrator.as_deref(),
            options: &args.options,
            allow_unstable: args.allow_unstable,
        },
    )
}

/// The frame schedule of a yarn run: fixed substeps, or adaptive ones
/// landing on every frame time under `dt = "auto"`.
pub fn yarn_schedule(sim: &YarnSim, duration: f64) -> Result<Schedule, CliError> {
    let frame_dt = sim.scene().time.frame_dt;
    if sim.is_auto() {
        Schedule::adaptive(duration, sim.dt(), frame_dt)
    } else {
        Schedule::new(duration, sim.dt(), frame_dt)
    }
}

/// `"min / mean / max"` of the substeps a run took under `dt = "auto"`.
pub fn dt_range(stats: &yarnsim::mpm::DtStats) -> String {
    format!(
        "{:.3e} / {:.3e} / {:.3e} s",
        stats.min,
        stats.mean(),
        stats.max
    )
}

/// Runs a yarn simulation from its current state for `duration` seconds.
pub fn run_yarn(sim: &mut YarnSim, duration: f64, csv: Option<&Path>) -> Result<Summary, CliError> {
    let sc = sim.scene();
    let schedule = yarn_schedule(sim, duration)?;
    let mut csv = CsvWriter::create(csv, sim.num_yarns())?;
    let initial = sim.diagnostics();
    let mut last = initial;
    let name = sc.name.clone();
    let dt = sim.dt();
    sim.reset_dt_stats();
    let frames = run_frames_shown(sim, &schedule, &name, |sim, frame| {
        last = sim.diagnostics();
        csv.row(frame.frame, sim, &last, dt)
    })?;
    csv.finish()?;
    let p = sim.particles();
    Ok(Summary {
        scene: sim.scene().name.clone(),
        model: yarn_model(sim.scene()),
        particles: p.len(),
        particles_detail: format!(
            "{} vertices + {} quadrature, {}",
            p.vert.x.len(),
            p.quad.x.len(),
            count(sim.num_yarns(), "yarn")
        ),
        dt: sim.dt(),
        adaptive_dt: sim
            .is_auto()
            .then(|| sim.dt_stats())
            .filter(|s| s.substeps > 0)
            .map(|s| dt_range(&s)),
        diagnostics: yarn_rows(&initial, &last),
        sheet: sheet_line(sim.scene()),
        forces: per_yarn_forces(sim),
        ..Summary::of_run(frames, last.time - initial.time)
    })
}

/// The model line of a yarn run's summary: under `[time] axial =
/// "implicit"` it says which waves bound the explicit substep.
pub fn yarn_model(scene: &YarnScene) -> String {
    if scene.time.axial.is_implicit() {
        "yarn (MPM), axial = \"implicit\": fibre stretch k by backward Euler on the vertices; \
         dt bound by the shear, cross-section and bending waves, not sqrt(k / rho)"
            .into()
    } else {
        "yarn (MPM)".into()
    }
}

/// The sheet a yarn material given per yarn stands for: its spacing, the
/// yarns per metre of depth, the preset's name; `None` for a material
/// given per metre of depth.
pub fn sheet_line(scene: &YarnScene) -> Option<String> {
    let s = scene.material.spacing()?;
    let preset = scene
        .material
        .yarn
        .as_ref()
        .and_then(|y| y.preset.as_deref())
        .map(|p| format!(", preset {p}"))
        .unwrap_or_default();
    Some(format!(
        "spacing {s:.4e} m ({:.1} yarns per m of depth{preset})",
        1.0 / s
    ))
}

/// Each pin's force on its yarn over the last substep, per metre of depth
/// (N/m) and per yarn (N, times the sheet spacing), for a material given
/// per yarn; none otherwise. The initial column is 0 (no substep yet).
fn per_yarn_forces(sim: &YarnSim) -> Vec<(String, f64, f64)> {
    let Some(s) = sim.scene().material.spacing() else {
        return Vec::new();
    };
    let mut rows = Vec::new();
    for (i, f) in sim.pin_reactions().iter().enumerate() {
        for (axis, v) in [("x", f.x), ("y", f.y)] {
            rows.push((format!("pin {i} force {axis} [N/m]"), 0.0, v));
            rows.push((
                format!("pin {i} force {axis} per yarn [N]"),
                0.0,
                yarnsim::scene::material_units::per_yarn(v, s),
            ));
        }
    }
    rows
}

/// A number for the CSV: shortest form that reads back to the same `f64`,
/// in scientific notation for very small or large magnitudes.
pub fn csv_num(x: f64) -> String {
    if x == 0.0 || (1e-4..1e7).contains(&x.abs()) || !x.is_finite() {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// A time for the CSV: `t` rounded to 15 significant digits, then printed
/// shortest, so `steps * dt` prints `0.05`, not `0.05000000000000001`.
pub fn csv_time(t: f64) -> String {
    let tidy: f64 = format!("{t:.14e}").parse().unwrap_or(t);
    csv_num(tidy)
}

/// The per-frame CSV: frame, time, diagnostics, then both endpoints of every
/// yarn; made without a path, it writes nothing (a run without `--csv`).
pub struct CsvWriter {
    out: Option<BufWriter<File>>,
    path: String,
}

/// CSV column names of a mass-spring run.
pub fn ms_csv_header() -> Vec<String> {
    [
        "frame",
        "time",
        "steps",
        "kinetic_energy",
        "elastic_energy",
        "gravity_energy",
        "momentum_x",
        "momentum_y",
        "momentum_z",
        "angular_momentum_x",
        "angular_momentum_y",
        "angular_momentum_z",
        "max_strain",
        "com_x",
        "com_y",
        "com_z",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect()
}

/// CSV column names for `yarns` yarns.
pub fn csv_header(yarns: usize) -> Vec<String> {
    let mut h: Vec<String> = [
        "frame",
        "time",
        "steps",
        "kinetic_energy",
        "elastic_energy",
        "potential_energy",
        "momentum_x",
        "momentum_y",
        "angular_momentum",
        "min_stretch",
        "max_stretch",
        "mean_stretch",
        "com_x",
        "com_y",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    for y in 0..yarns {
        for end in ["left", "right"] {
            h.push(format!("yarn{y}_{end}_x"));
            h.push(format!("yarn{y}_{end}_y"));
        }
    }
    h
}

impl CsvWriter {
    /// Creates the file (if a path is given) and writes the header.
    pub fn create(path: Option<&Path>, yarns: usize) -> Result<Self, CliError> {
        Self::create_with(path, &csv_header(yarns))
    }

    /// Creates the file (if a path is given) and writes the given header.
    pub fn create_with(path: Option<&Path>, header: &[String]) -> Result<Self, CliError> {
        let Some(path) = path else {
            return Ok(CsvWriter {
                out: None,
                path: String::new(),
            });
        };
        let file = File::create(path).map_err(|e| CliError::output(path, e))?;
        let mut w = CsvWriter {
            out: Some(BufWriter::new(file)),
            path: path.display().to_string(),
        };
        w.line(&header.join(","))?;
        Ok(w)
    }

    fn line(&mut self, text: &str) -> Result<(), CliError> {
        let Some(out) = self.out.as_mut() else {
            return Ok(());
        };
        writeln!(out, "{text}").map_err(|e| CliError::Output {
            path: self.path.clone(),
            message: e.to_string(),
        })
    }

    /// Writes one frame; numbers read back exactly (see [`csv_num`]), the
    /// time is `steps * dt` (see [`csv_time`]).
    pub fn row(
        &mut self,
        frame: u64,
        sim: &YarnSim,
        d: &Diagnostics,
        dt: f64,
    ) -> Result<(), CliError> {
        if self.out.is_none() {
            return Ok(());
        }
        // Fixed substeps: steps * dt; adaptive ones land on the frame
        // times, so the clock itself.
        let time = if sim.is_auto() {
            d.time
        } else {
            d.steps as f64 * dt
        };
        let mut cols: Vec<String> = vec![frame.to_string(), csv_time(time), d.steps.to_string()];
        cols.extend(
            [
                d.kinetic_energy,
                d.elastic_energy,
                d.potential_energy,
                d.momentum.x,
                d.momentum.y,
                d.angular_momentum,
                d.min_stretch,
                d.max_stretch,
                d.mean_stretch,
                d.center_of_mass.x,
                d.center_of_mass.y,
            ]
            .iter()
            .map(|&x| csv_num(x)),
        );
        for y in 0..sim.num_yarns() {
            let (l, r) = sim.yarn_endpoints(y);
            cols.extend([l.x, l.y, r.x, r.y].iter().map(|&x| csv_num(x)));
        }
        self.line(&cols.join(","))
    }

    /// Writes one mass-spring frame.
    pub fn ms_row(&mut self, frame: u64, d: &MsDiagnostics) -> Result<(), CliError> {
        if self.out.is_none() {
            return Ok(());
        }
        let mut cols: Vec<String> = vec![frame.to_string(), csv_time(d.time), d.steps.to_string()];
        cols.extend(
            [
                d.kinetic_energy,
                d.elastic_energy,
                d.gravity_energy,
                d.momentum.x,
                d.momentum.y,
                d.momentum.z,
                d.angular_momentum.x,
                d.angular_momentum.y,
                d.angular_momentum.z,
                d.max_strain,
                d.center_of_mass.x,
                d.center_of_mass.y,
                d.center_of_mass.z,
            ]
            .iter()
            .map(|&x| csv_num(x)),
        );
        self.line(&cols.join(","))
    }

    /// Flushes the file.
    pub fn finish(self) -> Result<(), CliError> {
        let Some(mut out) = self.out else {
            return Ok(());
        };
        out.flush().map_err(|e| CliError::Output {
            path: self.path.clone(),
            message: e.to_string(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_times_print_shortest() {
        assert_eq!(csv_time(1250.0 * 4e-5), "0.05");
        assert_eq!(csv_time(3.0 * 0.1), "0.3");
        assert_eq!(csv_time(0.0), "0");
        assert_eq!(csv_time(2.5e-5), "2.5e-5");
    }
}
