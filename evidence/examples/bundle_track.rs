//! Records a yarn scene's trajectory (centre of mass, both ends of every
//! yarn, energy budget, every 1/60 s) to CSV, and compares two such files:
//! the convergence study of `docs/performance/bundle-convergence.md`.
//!
//! ```text
//! cargo run --release -p yarnsim-evidence --example bundle_track -- \
//!     run OUT.csv SCENE [KEY=VALUE ...]      # e.g. yarn-reference time.dt=1e-5
//! cargo run --release -p yarnsim-evidence --example bundle_track -- \
//!     compare RUN.csv REFERENCE.csv [CURVE.csv]
//! ```
//!
//! `run` simulates 1 s (the reference bundle's whole second; `DURATION=S`
//! in the environment changes it) and prints the wall time per simulated
//! second and the energies at the end. `compare` prints the largest
//! centre-of-mass and yarn-end distances over the frames, m, and writes the
//! per-frame curve to CURVE.csv if given.

use yarnsim_evidence::trajectory::{compare, record, Trajectory};

fn read(path: &str) -> Trajectory {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    Trajectory::from_csv(&text).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("run") if args.len() >= 3 => {
            let duration = std::env::var("DURATION").map_or(1.0, |d| d.parse().expect("DURATION"));
            let t = record(&args[2], &args[3..], duration, 1.0 / 60.0)
                .unwrap_or_else(|e| panic!("{e}"));
            std::fs::write(&args[1], t.to_csv()).expect("write OUT.csv");
            let e = t.frames.last().expect("a frame").energy;
            println!(
                "{}: {} substeps, {:.1} s wall, {:.2} s per simulated s; \
                 kinetic {:.3} elastic {:.3} potential {:.3} dissipated {:.3} J",
                t.label,
                t.steps,
                t.wall_s,
                t.wall_per_second(),
                e[0],
                e[1],
                e[2],
                e[3]
            );
            if let Some(st) = &t.stopped {
                println!("stopped at t = {} s: {}", st.time, st.reason);
            }
        }
        Some("compare") if args.len() >= 3 => {
            let c = compare(&read(&args[1]), &read(&args[2])).unwrap_or_else(|e| panic!("{e}"));
            println!(
                "{} vs {}: com max {:.4} m, ends max {:.4} m (over 0 to {:.4} s)",
                args[1],
                args[2],
                c.com_max,
                c.ends_max,
                c.curve.last().map_or(0.0, |p| p.0)
            );
            if let Some(out) = args.get(3) {
                let mut s = String::from("time,com,ends\n");
                for (t, a, b) in &c.curve {
                    s += &format!("{t},{a:e},{b:e}\n");
                }
                std::fs::write(out, s).expect("write CURVE.csv");
            }
        }
        _ => eprintln!("usage: bundle_track run OUT.csv SCENE [KEY=VALUE ...] | compare RUN.csv REFERENCE.csv [CURVE.csv]"),
    }
}
