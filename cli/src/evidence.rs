//! `yarnsim bench precision`, `yarnsim bench skip`, `yarnsim bench
//! roofline` (the studies under `bench`, [`BenchStudy`]) and `yarnsim
//! stress`: the evidence studies of [`yarnsim_evidence`], writing CSV, SVG
//! and a text report into a directory and printing the report.
//!
//! The old one-word spellings `bench-precision`, `precision`, `bench-skip`
//! and `bench-roofline` still work, hidden: [`rewrite_args`] maps them onto
//! the `bench` subcommands before clap parses.

use std::ffi::OsString;
use std::path::{Path, PathBuf};

use clap::Subcommand;
use yarnsim_evidence::trajectory::Trajectory;
use yarnsim_evidence::{bundle_precision, precision, roofline, skip, stress, write_report};

use crate::error::CliError;

/// The studies under `yarnsim bench` (without one, `bench` measures a
/// scene's throughput).
#[derive(Subcommand, Debug, Clone, PartialEq)]
pub enum BenchStudy {
    /// Work-precision: run time against error per scene and integrator:
    /// CSV, SVG plots, convergence orders and the fastest method per error
    /// level
    ///
    /// Mass-spring scenes per integrator against a converged reference; the
    /// yarn against the hanging-chain oracle (first-mode frequency) per
    /// transfer scheme over a dt ladder and a grid ladder, with the cheapest
    /// setting per error level 1e-1, 1e-2, 1e-3.
    Precision {
        /// Output directory for precision*.csv, precision_<scene>.svg,
        /// precision_chain.svg, precision.txt.
        // (clap prints this text as written: no Markdown)
        #[allow(rustdoc::invalid_html_tags)]
        #[arg(long, value_name = "DIR", default_value = "evidence")]
        out: PathBuf,
        /// Fewer step sizes and shorter runs (seconds instead of a minute or two).
        #[arg(long)]
        quick: bool,
        /// Also run the (slow) yarn reference scene (against a finer run of
        /// itself: self-convergence, not accuracy).
        #[arg(long)]
        yarn_reference: bool,
        /// Leave out the yarn hanging-chain study (mass-spring scenes only).
        #[arg(long)]
        no_chain: bool,
        /// Instead: the reference bundle (yarn-reference) over a ladder of
        /// settings against a reference trajectory; writes
        /// bundle_precision.csv, .svg, .txt (--quick: 0.1 s, coarse explicit
        /// steps, no grid implicit rung).
        #[arg(long)]
        bundle: bool,
        /// With --bundle: the reference trajectory CSV (default: the shipped
        /// docs/performance/bundle_reference.csv).
        #[arg(long, value_name = "FILE", requires = "bundle")]
        reference: Option<PathBuf>,
        /// With --bundle: only the settings whose name contains this (repeatable).
        #[arg(long, value_name = "NAME", requires = "bundle")]
        setting: Vec<String>,
        /// With --bundle: simulated time of the grid implicit integrator's
        /// rungs (the slow ones, minutes per simulated second), at most the
        /// ladder's 1 s; default: the whole 1 s.
        #[arg(long, value_name = "SECONDS", requires = "bundle", conflicts_with = "quick",
              value_parser = crate::duration::parse_duration, allow_negative_numbers = true)]
        implicit_duration: Option<f64>,
    },
    /// Skip what a scene doesn't need: optional passes on/off, 256^2 vs
    /// 1024^2 grid, per-pass breakdown of the reference scene.
    Skip {
        /// Output directory for skip*.csv, skip.svg, skip.txt.
        #[arg(long, value_name = "DIR", default_value = "evidence")]
        out: PathBuf,
        /// Timed substeps per variant and repeat.
        #[arg(long, default_value_t = 60)]
        steps: u64,
        /// Repeats (round-robin over the variants; the fastest is kept).
        #[arg(long, default_value_t = 12)]
        repeats: usize,
    },
    /// The limit: this core's peak flop/s and memory bandwidth
    /// (multiply-add and triad kernels), the flops and bytes per particle of
    /// each pass counted from the kernels, and where each pass of the
    /// reference scene (1 thread) sits on the roofline.
    Roofline {
        /// Output directory for roofline*.csv, roofline.txt.
        #[arg(long, value_name = "DIR", default_value = "evidence")]
        out: PathBuf,
        /// Timed substeps per repeat.
        #[arg(long, default_value_t = 200)]
        steps: u64,
        /// Repeats (substeps: the fastest is kept; peak kernels: the median).
        #[arg(long, default_value_t = 7)]
        repeats: usize,
    },
}

/// `yarnsim stress`: the stability stress study.
#[derive(clap::Args, Debug, Clone, PartialEq)]
pub struct StressArgs {
    /// Output directory for stress.csv, stress*.svg, stress.txt.
    #[arg(long, value_name = "DIR", default_value = "evidence")]
    pub out: PathBuf,
    /// Fewer configurations and bisection steps.
    #[arg(long)]
    pub quick: bool,
}

/// One evidence study to run.
#[derive(Debug, Clone, PartialEq)]
pub enum EvidenceCommand {
    /// `yarnsim bench precision | skip | roofline`.
    Bench(BenchStudy),
    /// `yarnsim stress`.
    Stress(StressArgs),
}

impl EvidenceCommand {
    /// The command as typed, and how long it takes on 2 cores (README,
    /// "Performance and accuracy evidence"), for the spinner.
    pub fn label(&self) -> (&'static str, &'static str) {
        match self {
            EvidenceCommand::Bench(BenchStudy::Precision {
                bundle: true,
                quick,
                ..
            }) => (
                "bench precision --bundle",
                if *quick {
                    "about 20 s"
                } else {
                    "tens of minutes"
                },
            ),
            EvidenceCommand::Bench(BenchStudy::Precision { quick: false, .. }) => {
                ("bench precision", "about 40 s")
            }
            EvidenceCommand::Bench(BenchStudy::Precision { quick: true, .. }) => {
                ("bench precision --quick", "about 5 s")
            }
            EvidenceCommand::Stress(StressArgs { quick: false, .. }) => ("stress", "about 50 s"),
            EvidenceCommand::Stress(StressArgs { quick: true, .. }) => {
                ("stress --quick", "about 25 s")
            }
            EvidenceCommand::Bench(BenchStudy::Skip { .. }) => {
                ("bench skip", "grows with --steps x --repeats")
            }
            EvidenceCommand::Bench(BenchStudy::Roofline { .. }) => ("bench roofline", "about 10 s"),
        }
    }
}

/// The old spellings of the `bench` studies, hidden, and what they are now.
const OLD_SPELLINGS: [(&str, &str); 4] = [
    ("bench-precision", "precision"),
    ("precision", "precision"),
    ("bench-skip", "skip"),
    ("bench-roofline", "roofline"),
];

/// Maps the old spellings `yarnsim bench-precision ...` (and `precision`,
/// `bench-skip`, `bench-roofline`) onto `yarnsim bench precision ...`;
/// other arguments pass unchanged.
pub fn rewrite_args(args: impl IntoIterator<Item = OsString>) -> Vec<OsString> {
    let mut v: Vec<OsString> = args.into_iter().collect();
    if let Some(&(_, study)) = v
        .get(1)
        .and_then(|a| OLD_SPELLINGS.iter().find(|(old, _)| a == old))
    {
        v.splice(1..2, [OsString::from("bench"), OsString::from(study)]);
    }
    v
}

fn write(out: &Path, files: &[(String, String)]) -> Result<Vec<String>, CliError> {
    write_report(out, files).map_err(|e| CliError::output(out, e))
}

/// Runs one evidence command; returns the report text and the files written.
pub fn execute(cmd: &EvidenceCommand) -> Result<(String, Vec<String>), CliError> {
    match cmd {
        EvidenceCommand::Bench(BenchStudy::Precision {
            out,
            quick,
            bundle: true,
            reference,
            setting,
            implicit_duration,
            ..
        }) => {
            let reference = match reference {
                Some(p) => std::fs::read_to_string(p)
                    .map_err(|e| CliError::Usage(format!("--reference {}: {e}", p.display())))?,
                None => bundle_precision::SHIPPED_REFERENCE.to_string(),
            };
            let reference = Trajectory::from_csv(&reference)
                .map_err(|e| CliError::Usage(format!("--reference: {e}")))?;
            let duration = if *quick { 0.1 } else { 1.0 };
            let implicit = implicit_duration.unwrap_or(duration);
            if implicit > duration {
                return Err(CliError::Usage(format!(
                    "--implicit-duration {implicit} s is longer than the ladder's {duration} s"
                )));
            }
            let ladder = bundle_precision::ladder(duration, implicit, *quick);
            let r = bundle_precision::run(&ladder, &reference, setting);
            let written = write(out, &r.files())?;
            if !r.failed.is_empty() {
                let each: Vec<String> = r.failed.iter().map(|(n, e)| format!("{n}: {e}")).collect();
                return Err(CliError::Failed(format!(
                    "{} of the ladder's settings failed ({}); the others' results are written to {}",
                    r.failed.len(),
                    each.join("; "),
                    out.display()
                )));
            }
            Ok((r.to_text(), written))
        }
        EvidenceCommand::Bench(BenchStudy::Precision {
            out,
            quick,
            yarn_reference,
            no_chain,
            ..
        }) => {
            let r = precision::run(&precision::PrecisionOptions {
                quick: *quick,
                yarn_reference: *yarn_reference,
                no_chain: *no_chain,
            })
            .map_err(CliError::Failed)?;
            Ok((r.to_text(), write(out, &r.files())?))
        }
        EvidenceCommand::Stress(StressArgs { out, quick }) => {
            let r = stress::run(&stress::StressOptions { quick: *quick });
            Ok((r.to_text(), write(out, &r.files())?))
        }
        EvidenceCommand::Bench(BenchStudy::Skip {
            out,
            steps,
            repeats,
        }) => {
            steps_and_repeats(*steps, *repeats)?;
            let r = skip::run(&skip::SkipOptions {
                steps: *steps,
                warmup: 20,
                repeats: *repeats,
            })
            .map_err(CliError::Failed)?;
            Ok((r.to_text(), write(out, &r.files())?))
        }
        EvidenceCommand::Bench(BenchStudy::Roofline {
            out,
            steps,
            repeats,
        }) => {
            steps_and_repeats(*steps, *repeats)?;
            let r = roofline::run(&roofline::RooflineOptions {
                steps: *steps,
                repeats: *repeats,
                ..Default::default()
            })
            .map_err(CliError::Failed)?;
            Ok((r.to_text(), write(out, &r.files())?))
        }
    }
}

/// `--steps` and `--repeats` of the benchmarks: both at least 1.
fn steps_and_repeats(steps: u64, repeats: usize) -> Result<(), CliError> {
    if steps == 0 || repeats == 0 {
        return Err(CliError::Usage(
            "--steps and --repeats must be at least 1".into(),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn os(v: &[&str]) -> Vec<OsString> {
        v.iter().map(OsString::from).collect()
    }

    #[test]
    fn old_spellings_are_rewritten_to_the_bench_subcommands() {
        assert_eq!(
            rewrite_args(os(&["yarnsim", "bench-precision", "--out", "d"])),
            os(&["yarnsim", "bench", "precision", "--out", "d"])
        );
        assert_eq!(
            rewrite_args(os(&["yarnsim", "precision", "--quick"])),
            os(&["yarnsim", "bench", "precision", "--quick"])
        );
        assert_eq!(
            rewrite_args(os(&["yarnsim", "bench-skip"])),
            os(&["yarnsim", "bench", "skip"])
        );
        assert_eq!(
            rewrite_args(os(&["yarnsim", "bench-roofline", "--steps", "5"])),
            os(&["yarnsim", "bench", "roofline", "--steps", "5"])
        );
        // The current spelling, a scene named `precision` after `run` and
        // plain `bench` pass unchanged.
        for args in [
            vec!["yarnsim", "bench", "precision", "--quick"],
            vec!["yarnsim", "bench", "yarn-reference"],
            vec!["yarnsim", "run", "precision"],
            vec!["yarnsim", "bench"],
            vec!["yarnsim"],
        ] {
            assert_eq!(rewrite_args(os(&args)), os(&args));
        }
    }

    #[test]
    #[cfg_attr(debug_assertions, ignore = "runs the quick studies; release only")]
    fn quick_precision_writes_csv_and_svg() {
        let dir = std::env::temp_dir().join(format!("yarnsim-evidence-{}", std::process::id()));
        let (text, files) = execute(&EvidenceCommand::Bench(BenchStudy::Precision {
            out: dir.clone(),
            quick: true,
            yarn_reference: false,
            no_chain: false,
            bundle: false,
            reference: None,
            setting: Vec::new(),
            implicit_duration: None,
        }))
        .unwrap();
        assert!(text.contains("Fastest method per error level"));
        assert!(text.contains("Cheapest setting per error level"));
        let chain = std::fs::read_to_string(dir.join("precision_chain.svg")).unwrap();
        assert!(chain.starts_with("<svg") && chain.contains("polyline"));
        assert!(files
            .iter()
            .any(|f| f.ends_with("precision_chain_summary.csv")));
        assert!(files.iter().any(|f| f.ends_with("precision.csv")));
        let svg = std::fs::read_to_string(dir.join("precision_wire.svg")).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("polyline"));
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// `--bundle --quick` against the shipped reference given as a file:
    /// the CSV has one row per quick setting, each 0.1 s long; every run,
    /// at dt 4e-5 or `auto` (16x or more the reference's 2.5e-6), is a
    /// nonzero distance from it, and the reference against itself is
    /// exactly 0.
    #[test]
    #[cfg_attr(debug_assertions, ignore = "runs the quick studies; release only")]
    fn quick_bundle_writes_csv_svg_and_compares() {
        use yarnsim_evidence::bundle_precision::{ladder, measure, SHIPPED_REFERENCE};
        let dir = std::env::temp_dir().join(format!("yarnsim-bundle-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let reference = dir.join("reference.csv");
        std::fs::write(&reference, SHIPPED_REFERENCE).unwrap();
        let (text, files) = execute(&EvidenceCommand::Bench(BenchStudy::Precision {
            out: dir.clone(),
            quick: true,
            yarn_reference: false,
            no_chain: false,
            bundle: true,
            reference: Some(reference),
            setting: Vec::new(),
            implicit_duration: None,
        }))
        .unwrap();
        assert!(text.contains("compared over 1.0000e-1 s only"), "{text}");
        assert_eq!(files.len(), 3);
        let csv = std::fs::read_to_string(dir.join("bundle_precision.csv")).unwrap();
        let mut lines = csv.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
        let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
        assert_eq!(rows.len(), ladder(0.1, 0.1, true).len());
        for r in &rows {
            let window: f64 = r[col("window_s")].parse().unwrap();
            assert!((window - 0.1).abs() < 1e-3, "{r:?}");
            let com: f64 = r[col("com_max_m")].parse().unwrap();
            let ends: f64 = r[col("ends_max_m")].parse().unwrap();
            let wall: f64 = r[col("wall_s_per_sim_s")].parse().unwrap();
            assert!(com > 0.0 && ends > 0.0 && wall > 0.0, "{r:?}");
        }
        let svg = std::fs::read_to_string(dir.join("bundle_precision.svg")).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("flip per-yarn 4e-5 com"));
        let r = Trajectory::from_csv(SHIPPED_REFERENCE).unwrap();
        let s = &ladder(1.0, 0.1, false)[0];
        let same = measure(s, &r, &r).unwrap();
        assert_eq!((same.com_max, same.ends_max), (0.0, 0.0));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
