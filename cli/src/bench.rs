//! `yarnsim bench`: substep throughput of a scene in the current build, with
//! the per-pass breakdown of [`yarnsim::mpm::PassTimes`].

use std::fmt::Write as _;
use std::time::Instant;

use yarnsim::mpm::PassTimes;
use yarnsim::scene::Scene;
use yarnsim::YarnSim;

use indicatif::ProgressBar;

use crate::driver::{progress_bar, Stepper};
use crate::error::CliError;
use crate::massspring::{IntegratorArgs, MassSpringRun};
use crate::run::start_yarn;
use crate::yarn::explain;

/// What to measure.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BenchOptions {
    /// Timed substeps.
    pub steps: u64,
    /// Untimed substeps run first (caches, page faults, the bundle starting to move).
    pub warmup: u64,
    /// Worker threads of the rayon pool; `None` keeps rayon's default (all cores).
    pub threads: Option<usize>,
}

/// One measurement.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchResult {
    pub scene: String,
    /// `yarn (MPM)` or `mass-spring, <integrator>`.
    pub model: String,
    pub particles: usize,
    pub steps: u64,
    pub warmup: u64,
    pub threads: usize,
    /// Wall-clock seconds of the timed substeps.
    pub seconds: f64,
    /// Per-pass seconds of the timed substeps (yarn scenes only).
    pub passes: Option<PassTimes>,
}

impl BenchResult {
    /// Particle-substeps per wall-clock second.
    pub fn throughput(&self) -> f64 {
        self.particles as f64 * self.steps as f64 / self.seconds.max(f64::MIN_POSITIVE)
    }
}

/// Runs the benchmark on a scene; `integrator` applies to mass-spring scenes only.
pub fn bench(
    scene: &Scene,
    opts: BenchOptions,
    integrator: &IntegratorArgs,
) -> Result<BenchResult, CliError> {
    if opts.steps == 0 {
        return Err(CliError::Usage("--steps must be at least 1".into()));
    }
    let pool = {
        let mut b = rayon::ThreadPoolBuilder::new();
        if let Some(n) = opts.threads {
            if n == 0 {
                return Err(CliError::Usage("--threads must be at least 1".into()));
            }
            b = b.num_threads(n);
        }
        b.build()
            .map_err(|e| CliError::Usage(format!("cannot start {:?} threads: {e}", opts.threads)))?
    };
    let threads = pool.current_num_threads();
    let progress = progress_bar(opts.warmup + opts.steps, &format!("bench {}", scene.name()));
    let result = match scene {
        Scene::Yarn(y) => {
            let mut sim = start_yarn(y, integrator)?;
            pool.install(|| bench_yarn(&mut sim, opts, threads, &progress))
        }
        Scene::MassSpring(l) => {
            let mut run = MassSpringRun::new(l, integrator)?;
            pool.install(|| bench_massspring(&mut run, opts, threads, &progress))
        }
    };
    progress.finish_and_clear();
    result
}

/// Runs `n` substeps in about 100 chunks, advancing the progress bar
/// between chunks (the bar's cost stays out of the timed substeps' hot loop).
fn steps_with_progress(
    n: u64,
    progress: &ProgressBar,
    mut steps: impl FnMut(u64) -> Result<(), CliError>,
) -> Result<(), CliError> {
    let chunk = (n / 100).max(1);
    let mut done = 0;
    while done < n {
        let k = chunk.min(n - done);
        steps(k)?;
        done += k;
        progress.inc(k);
    }
    Ok(())
}

fn bench_massspring(
    run: &mut MassSpringRun,
    opts: BenchOptions,
    threads: usize,
    progress: &ProgressBar,
) -> Result<BenchResult, CliError> {
    let mut steps = |k: u64| (0..k).try_for_each(|_| run.step());
    steps_with_progress(opts.warmup, progress, &mut steps)?;
    let t0 = Instant::now();
    steps_with_progress(opts.steps, progress, &mut steps)?;
    let seconds = t0.elapsed().as_secs_f64();
    Ok(BenchResult {
        scene: run.name.clone(),
        model: format!("mass-spring, {}", run.sim.integrator()),
        particles: run.num_particles(),
        steps: opts.steps,
        warmup: opts.warmup,
        threads,
        seconds,
        passes: None,
    })
}

fn bench_yarn(
    sim: &mut YarnSim,
    opts: BenchOptions,
    threads: usize,
    progress: &ProgressBar,
) -> Result<BenchResult, CliError> {
    let steps = |sim: &mut YarnSim, k: u64| sim.steps_n(k).map_err(|e| explain(sim, e));
    steps_with_progress(opts.warmup, progress, |k| steps(sim, k))?;
    sim.reset_timings();
    let t0 = Instant::now();
    steps_with_progress(opts.steps, progress, |k| steps(sim, k))?;
    let seconds = t0.elapsed().as_secs_f64();
    Ok(BenchResult {
        scene: sim.scene().name.clone(),
        model: "yarn (MPM)".into(),
        particles: sim.particles().len(),
        steps: opts.steps,
        warmup: opts.warmup,
        threads,
        seconds,
        passes: Some(sim.timings()),
    })
}

/// The report: a header line, the throughput line (exactly
/// `<number> particle-substeps/s`, for scripts), then the per-pass table.
pub fn format_bench(r: &BenchResult) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "scene {} ({}): {} particles, {} substeps after {} warm-up, {} thread{}, {:.3} s",
        r.scene,
        r.model,
        r.particles,
        r.steps,
        r.warmup,
        r.threads,
        if r.threads == 1 { "" } else { "s" },
        r.seconds
    );
    let _ = writeln!(out, "{:.0} particle-substeps/s", r.throughput());
    let Some(passes) = &r.passes else {
        return out;
    };
    let total = passes.total();
    let w = passes
        .entries()
        .iter()
        .map(|(name, _)| name.len())
        .chain([20])
        .max()
        .unwrap_or(20);
    let _ = writeln!(
        out,
        "{:<w$} {:>10} {:>7} {:>14}",
        "pass", "seconds", "share", "us/substep"
    );
    let per = |s: f64| 1e6 * s / passes.substeps.max(1) as f64;
    for (name, secs) in passes.entries() {
        let share = if total > 0.0 {
            100.0 * secs / total
        } else {
            0.0
        };
        let _ = writeln!(
            out,
            "{name:<w$} {secs:>10.4} {share:>6.1}% {:>14.2}",
            per(secs)
        );
    }
    let _ = writeln!(
        out,
        "{:<w$} {total:>10.4} {:>6.1}% {:>14.2}",
        "total (timed passes)",
        100.0,
        per(total)
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn throughput_line_has_the_documented_form() {
        let r = BenchResult {
            scene: "s".into(),
            model: "yarn (MPM)".into(),
            particles: 1000,
            steps: 50,
            warmup: 0,
            threads: 2,
            seconds: 0.5,
            passes: Some(PassTimes {
                forces: 0.1,
                scatter: 0.1,
                grid: 0.1,
                gather_vertices: 0.1,
                gather_quads: 0.1,
                substeps: 50,
            }),
        };
        let text = format_bench(&r);
        let line = text.lines().nth(1).unwrap();
        assert_eq!(line, "100000 particle-substeps/s");
        assert!(text.contains("P2G scatter"));
        assert!(text.contains("20.0%"));
    }
}
