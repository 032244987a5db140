//! The Rust side of `tools/fmu/fmu_check.sh`: runs a scene straight on the
//! library (no FMU) with the inputs of a CSV table, the way an FMI master
//! steps the FMU, and writes the outputs as CSV.
//!
//! ```text
//! fmu-replay --scene FILE --inputs in.csv --step H --stop T -o out.csv [--integrator NAME] [--vertices]
//! ```
//!
//! Yarn scenes (the YarnBundle FMU): `in.csv` has the header
//! `time,attractor.x,attractor.y,attractor.strength,attractor.active,
//! gravity.x,gravity.y`, then `pin[i].x,pin[i].y,pin[i].vx,pin[i].vy` for
//! every `motion = "input"` pin in `[[pins]]` order; `out.csv` holds
//! `time`, the yarn ends `yarn[i].left.x` ... `yarn[i].right.y`,
//! `kinetic_energy`, `elastic_energy`, `max_stretch`, `substeps`, then
//! `pin[i].force.x`, `pin[i].force.y` of every pin (the FMU's rule: the
//! mean of `-pin_reactions()` over the substeps of the step; the pin
//! targets are set at each communication point, as the FMU latches them);
//! with `--vertices` then the FMI 3.0 FMU's arrays flattened row-major,
//! `yarn[i].positions[j]` and `yarn[i].velocities[j]` (j = 2 v + axis for
//! vertex v) of every yarn.
//!
//! Mass-spring scenes (the MassSpring FMU, `--integrator` as its parameter,
//! default backward-euler): `in.csv` has `time,gravity.x,gravity.y,gravity.z`;
//! `out.csv` holds `time`, `kinetic_energy`, `elastic_energy`,
//! `gravity_energy`, `total_energy`, `max_strain`, `substeps`,
//! `particle[i].x` ... `particle[i].z`.
//!
//! One input row per communication point k h (k = 0, 1, ...); row k is
//! applied before the step from k h. One output row at t = 0 and one after
//! every step. Numbers are written so they read back to the same bits.

use std::fmt::Write as _;
use std::process::ExitCode;

use yarnsim::massspring::{Integrator, IntegratorOptions, MassSpringScene, Simulation, V3};
use yarnsim::math::Vec2;
use yarnsim::mpm::{Attractor, YarnSim};
use yarnsim::scene::{PinMotionKind, Scene, YarnScene};

/// The master's communication points as fmpy computes them: k h up to `stop`.
fn communication_points(h: f64, stop: f64) -> Vec<f64> {
    let mut t = 0.0;
    let mut k = 0usize;
    let mut out = Vec::new();
    while !(t > stop || (t - stop).abs() <= 1e-9 * stop.abs().max(1e-300)) {
        k += 1;
        t = k as f64 * h;
        out.push(t);
    }
    out
}

/// The input rows (after the header), each with `cols` numbers.
fn read_rows(path: &str, cols: usize) -> Result<Vec<Vec<f64>>, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{path}: {e}"))?;
    let mut rows = Vec::new();
    for (i, line) in text.lines().enumerate().skip(1) {
        let v: Vec<f64> = line
            .split(',')
            .map(|s| s.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|e| format!("{path}:{}: {e}", i + 1))?;
        if v.len() != cols {
            return Err(format!("{path}:{}: {cols} columns expected", i + 1));
        }
        rows.push(v);
    }
    if rows.is_empty() {
        return Err(format!("{path}: the input table is empty"));
    }
    Ok(rows)
}

fn run() -> Result<(), String> {
    let (mut scene, mut inputs, mut step, mut stop, mut out) = (None, None, None, None, None);
    let mut integrator: Option<String> = None;
    let mut vertices = false;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if a == "--vertices" {
            vertices = true;
            continue;
        }
        let v = args.next().ok_or(format!("{a} needs a value"))?;
        match a.as_str() {
            "--scene" => scene = Some(v),
            "--inputs" => inputs = Some(v),
            "--step" => step = Some(v.parse::<f64>().map_err(|e| format!("--step: {e}"))?),
            "--stop" => stop = Some(v.parse::<f64>().map_err(|e| format!("--stop: {e}"))?),
            "-o" => out = Some(v),
            "--integrator" => integrator = Some(v),
            _ => return Err(format!("unknown argument {a}")),
        }
    }
    let usage = "usage: fmu-replay --scene FILE --inputs in.csv --step H --stop T -o out.csv [--integrator NAME] [--vertices]";
    let (Some(scene), Some(inputs), Some(h), Some(stop), Some(out)) =
        (scene, inputs, step, stop, out)
    else {
        return Err(usage.into());
    };
    let csv = match Scene::resolve(&scene).map_err(|e| e.to_string())? {
        Scene::Yarn(s) => {
            if integrator.is_some() {
                return Err("--integrator applies to mass-spring scenes only".into());
            }
            let pins = input_pins(&s);
            let rows = read_rows(&inputs, 7 + 4 * pins.len())?;
            replay_yarn(&s, &rows, h, stop, vertices)?
        }
        Scene::MassSpring(l) => {
            let integrator = match integrator {
                Some(name) => name.parse()?,
                None => yarnsim_fmu::models::massspring::DEFAULT_INTEGRATOR,
            };
            replay_mass_spring(&l, integrator, &read_rows(&inputs, 4)?, h, stop)?
        }
    };
    std::fs::write(&out, csv).map_err(|e| format!("{out}: {e}"))?;
    Ok(())
}

/// Indices of the `motion = "input"` pins.
fn input_pins(scene: &YarnScene) -> Vec<usize> {
    scene
        .pins
        .iter()
        .enumerate()
        .filter(|(_, p)| p.motion == PinMotionKind::Input)
        .map(|(i, _)| i)
        .collect()
}

/// Appends `,value` for each value, in the shortest form that reads back
/// to the same `f64` (`{:?}`).
fn push_values(csv: &mut String, values: impl IntoIterator<Item = f64>) {
    for v in values {
        let _ = write!(csv, ",{v:?}");
    }
}

fn replay_yarn(
    scene: &YarnScene,
    rows: &[Vec<f64>],
    h: f64,
    stop: f64,
    vertices: bool,
) -> Result<String, String> {
    let mut sim = YarnSim::new(scene).map_err(|e| e.to_string())?;
    let yarns = sim.num_yarns();
    let inputs = input_pins(scene);
    let pins = scene.pins.len();
    let mut force = vec![Vec2::zeros(); pins];
    let mut csv = String::from("time");
    for i in 0..yarns {
        for c in ["left.x", "left.y", "right.x", "right.y"] {
            let _ = write!(csv, ",yarn[{i}].{c}");
        }
    }
    csv.push_str(",kinetic_energy,elastic_energy,max_stretch,substeps");
    for i in 0..pins {
        let _ = write!(csv, ",pin[{i}].force.x,pin[{i}].force.y");
    }
    if vertices {
        let r = &sim.particles().yarn_vertices;
        for i in 0..yarns {
            for what in ["positions", "velocities"] {
                for j in 0..2 * (r[i + 1] - r[i]) {
                    let _ = write!(csv, ",yarn[{i}].{what}[{j}]");
                }
            }
        }
    }
    csv.push('\n');
    let record = |csv: &mut String, t: f64, sim: &YarnSim, force: &[Vec2]| {
        let _ = write!(csv, "{t:?}");
        push_values(
            csv,
            (0..yarns).flat_map(|i| {
                let (l, r) = sim.yarn_endpoints(i);
                [l.x, l.y, r.x, r.y]
            }),
        );
        let d = sim.diagnostics();
        push_values(csv, [d.kinetic_energy, d.elastic_energy, d.max_stretch]);
        let _ = write!(csv, ",{}", sim.steps());
        push_values(csv, force.iter().flat_map(|f| [f.x, f.y]));
        if vertices {
            let p = sim.particles();
            for i in 0..yarns {
                let range = p.yarn_vertices[i]..p.yarn_vertices[i + 1];
                for field in [&p.vert.x, &p.vert.v] {
                    push_values(csv, field[range.clone()].iter().flat_map(|v| [v.x, v.y]));
                }
            }
        }
        csv.push('\n');
    };
    record(&mut csv, 0.0, &sim, &force);
    let mut now = 0.0;
    for (k, &next) in communication_points(h, stop).iter().enumerate() {
        let row = rows.get(k).unwrap_or(&rows[rows.len() - 1]);
        sim.set_gravity(Vec2::new(row[5], row[6]))
            .map_err(|e| e.to_string())?;
        sim.set_attractor(Attractor {
            position: Vec2::new(row[1], row[2]),
            strength: row[3],
            active: row[4] != 0.0,
        })
        .map_err(|e| e.to_string())?;
        // The FMU's rule: substeps done by time t are round((t - t0) / dt);
        // under dt = "auto" adaptive substeps land on every point.
        let auto = sim.is_auto();
        let target = if auto {
            0
        } else {
            (next / sim.dt()).round() as u64
        };
        if (auto && sim.time() < next) || (!auto && target > sim.steps()) {
            // The FMU latches the pin inputs when a step that runs substeps begins.
            for (j, &pin) in inputs.iter().enumerate() {
                let c = &row[7 + 4 * j..11 + 4 * j];
                sim.set_pin_target_at(pin, Vec2::new(c[0], c[1]), Vec2::new(c[2], c[3]), now)
                    .map_err(|e| e.to_string())?;
            }
            // The FMU's mean: per substep, or time-weighted under "auto".
            let mut weight = 0.0;
            let mut sum = vec![Vec2::zeros(); pins];
            loop {
                let before = sim.time();
                let stepped = if auto {
                    sim.step_toward(next).map_err(|e| e.to_string())?
                } else if sim.steps() < target {
                    sim.step().map_err(|e| e.to_string())?;
                    true
                } else {
                    false
                };
                if !stepped {
                    break;
                }
                let w = if auto { sim.time() - before } else { 1.0 };
                weight += w;
                for (s, r) in sum.iter_mut().zip(sim.pin_reactions()) {
                    *s -= *r * w;
                }
            }
            for (f, s) in force.iter_mut().zip(&sum) {
                *f = *s / weight;
            }
        }
        record(&mut csv, next, &sim, &force);
        now = next;
    }
    Ok(csv)
}

fn replay_mass_spring(
    layout: &MassSpringScene,
    integrator: Integrator,
    rows: &[Vec<f64>],
    h: f64,
    stop: f64,
) -> Result<String, String> {
    let mut sim = Simulation::new(layout, integrator, IntegratorOptions::default())
        .map_err(|e| e.to_string())?;
    let n = sim.positions().len();
    let mut csv = String::from(
        "time,kinetic_energy,elastic_energy,gravity_energy,total_energy,max_strain,substeps",
    );
    for i in 0..n {
        for c in ["x", "y", "z"] {
            let _ = write!(csv, ",particle[{i}].{c}");
        }
    }
    csv.push('\n');
    let record = |csv: &mut String, t: f64, sim: &Simulation, steps: u64| {
        let e = sim.energies();
        let _ = write!(csv, "{t:?}");
        push_values(
            csv,
            [e.kinetic, e.elastic, e.gravity, e.total(), sim.max_strain()],
        );
        let _ = write!(csv, ",{steps}");
        push_values(csv, sim.positions().iter().flat_map(|p| [p.x, p.y, p.z]));
        csv.push('\n');
    };
    // fmpy sets the inputs of t = 0 in initialization mode, before it reads
    // the first outputs (the gravitational energy depends on them).
    sim.set_gravity(V3::new(rows[0][1], rows[0][2], rows[0][3]))
        .map_err(|e| e.to_string())?;
    record(&mut csv, 0.0, &sim, 0);
    let dt = sim.dt();
    let mut steps = 0u64;
    for (k, &next) in communication_points(h, stop).iter().enumerate() {
        let row = rows.get(k).unwrap_or(&rows[rows.len() - 1]);
        sim.set_gravity(V3::new(row[1], row[2], row[3]))
            .map_err(|e| e.to_string())?;
        // The FMU's rule: substep k starts at k dt; round((t - t0) / dt) by t.
        let target = (next / dt).round() as u64;
        while steps < target {
            sim.state_mut().t = steps as f64 * dt;
            sim.step(dt).map_err(|e| e.to_string())?;
            steps += 1;
        }
        record(&mut csv, next, &sim, steps);
    }
    Ok(csv)
}

fn main() -> ExitCode {
    yarnsim_fmu::tool_exit("fmu-replay", run())
}
