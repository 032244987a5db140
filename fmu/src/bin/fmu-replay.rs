//! The Rust side of `tools/fmu_check.sh`: runs a scene straight on the
//! library (no FMU) with the inputs of a CSV table, the way an FMI master
//! steps the FMU, and writes the outputs as CSV.
//!
//! ```text
//! fmu-replay --scene FILE --inputs in.csv --step H --stop T -o out.csv
//! ```
//!
//! `in.csv`: header `time,attractor.x,attractor.y,attractor.strength,
//! attractor.active,gravity.x,gravity.y`, one row per communication point
//! k h (k = 0, 1, ...); row k is applied before the step from k h.
//! `out.csv`: `time`, the yarn ends `yarn[i].left.x` ... `yarn[i].right.y`,
//! `kinetic_energy`, `elastic_energy`, `max_stretch`, `substeps`, one row at
//! t = 0 and one after every step. Numbers are written so they read back to
//! the same bits.

use std::fmt::Write as _;
use std::process::ExitCode;

use yarnsim::math::Vec2;
use yarnsim::mpm::{Attractor, YarnSim};
use yarnsim::scene::Scene;

fn run() -> Result<(), String> {
    let (mut scene, mut inputs, mut step, mut stop, mut out) = (None, None, None, None, None);
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let v = args.next().ok_or(format!("{a} needs a value"))?;
        match a.as_str() {
            "--scene" => scene = Some(v),
            "--inputs" => inputs = Some(v),
            "--step" => step = Some(v.parse::<f64>().map_err(|e| format!("--step: {e}"))?),
            "--stop" => stop = Some(v.parse::<f64>().map_err(|e| format!("--stop: {e}"))?),
            "-o" => out = Some(v),
            _ => return Err(format!("unknown argument {a}")),
        }
    }
    let usage = "usage: fmu-replay --scene FILE --inputs in.csv --step H --stop T -o out.csv";
    let (Some(scene), Some(inputs), Some(h), Some(stop), Some(out)) =
        (scene, inputs, step, stop, out)
    else {
        return Err(usage.into());
    };
    let Scene::Yarn(scene) = Scene::resolve(&scene).map_err(|e| e.to_string())? else {
        return Err("not a yarn scene".into());
    };
    let text = std::fs::read_to_string(&inputs).map_err(|e| format!("{inputs}: {e}"))?;
    let mut rows = Vec::new();
    for (i, line) in text.lines().enumerate().skip(1) {
        let v: Vec<f64> = line
            .split(',')
            .map(|s| s.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|e| format!("{inputs}:{}: {e}", i + 1))?;
        if v.len() != 7 {
            return Err(format!("{inputs}:{}: 7 columns expected", i + 1));
        }
        rows.push(v);
    }
    let mut sim = YarnSim::new(&scene).map_err(|e| e.to_string())?;
    let yarns = sim.num_yarns();
    let mut csv = String::from("time");
    for i in 0..yarns {
        for c in ["left.x", "left.y", "right.x", "right.y"] {
            let _ = write!(csv, ",yarn[{i}].{c}");
        }
    }
    csv.push_str(",kinetic_energy,elastic_energy,max_stretch,substeps\n");
    let record = |csv: &mut String, t: f64, sim: &YarnSim| {
        let _ = write!(csv, "{t:?}");
        for i in 0..yarns {
            let (l, r) = sim.yarn_endpoints(i);
            let _ = write!(csv, ",{:?},{:?},{:?},{:?}", l.x, l.y, r.x, r.y);
        }
        let d = sim.diagnostics();
        let _ = writeln!(
            csv,
            ",{:?},{:?},{:?},{}",
            d.kinetic_energy,
            d.elastic_energy,
            d.max_stretch,
            sim.steps()
        );
    };
    record(&mut csv, 0.0, &sim);
    let mut t = 0.0;
    let mut k = 0usize;
    while !(t > stop || (t - stop).abs() <= 1e-9 * stop.abs().max(1e-300)) {
        // The master's communication points, as fmpy computes them.
        let next = (k + 1) as f64 * h;
        let row = rows
            .get(k)
            .or(rows.last())
            .ok_or("the input table is empty")?;
        sim.set_gravity(Vec2::new(row[5], row[6]))
            .map_err(|e| e.to_string())?;
        sim.set_attractor(Attractor {
            position: Vec2::new(row[1], row[2]),
            strength: row[3],
            active: row[4] != 0.0,
        })
        .map_err(|e| e.to_string())?;
        // The FMU's rule: substeps done by time t are round((t - t0) / dt).
        let end = t + (next - t);
        let target = (end / sim.dt()).round() as u64;
        sim.steps_n(target - sim.steps())
            .map_err(|e| e.to_string())?;
        t = next;
        k += 1;
        record(&mut csv, t, &sim);
    }
    std::fs::write(&out, csv).map_err(|e| format!("{out}: {e}"))?;
    Ok(())
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("fmu-replay: {e}");
            ExitCode::FAILURE
        }
    }
}
