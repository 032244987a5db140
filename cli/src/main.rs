//! `yarnsim`: run, record and benchmark yarn scenes from a terminal.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use yarnsim::scene::DEFAULT_SCENE;
use yarnsim_cli::bench::{bench, format_bench, BenchOptions};
use yarnsim_cli::duration::parse_duration;
use yarnsim_cli::error::{CliError, EXIT_INTERRUPTED};
use yarnsim_cli::massspring::IntegratorArgs;
use yarnsim_cli::record::record;
use yarnsim_cli::run::run;
use yarnsim_cli::scenes::{list_scenes, load_scene, show_scene};
use yarnsim_cli::table::{format_summary, Timing};

/// Simulate yarn bundles (MPM) and mass-spring wires and cloth from the
/// terminal, and record them for the Rerun viewer.
///
/// SCENE is the name of a built-in scene (see `yarnsim scenes`) or the path of
/// a scene file (TOML, start from `yarnsim scene show NAME`).
///
/// Exit codes: 0 success, 1 simulation failure, 2 bad arguments (e.g. an
/// invalid duration), 3 unknown scene or unreadable/invalid scene file,
/// 4 output file cannot be written, 130 interrupted by Ctrl-C (output so far
/// is complete and valid).
#[derive(Parser, Debug)]
#[command(name = "yarnsim", version, max_term_width = 100)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// List the built-in scenes, one per line.
    Scenes,
    /// Inspect scenes.
    #[command(subcommand)]
    Scene(SceneCommand),
    /// Run a scene and print a summary table (steps, wall time, throughput, energy, stretch).
    Run {
        /// Built-in scene name or scene file.
        #[arg(default_value = DEFAULT_SCENE)]
        scene: String,
        /// Simulated time, in seconds: 2, 2.5s or 250ms.
        #[arg(short, long, default_value = "1", value_parser = parse_duration, allow_negative_numbers = true)]
        duration: f64,
        /// Also write the diagnostics (and, for yarn scenes, the yarn endpoints) of every frame to this CSV file.
        #[arg(long, value_name = "FILE")]
        csv: Option<PathBuf>,
        #[command(flatten)]
        integrator: IntegratorFlags,
    },
    /// Record a scene to a Rerun file (.rrd): particles, yarns or springs, obstacles, plots.
    ///
    /// Open the result with `rerun FILE.rrd`. Timelines are `frame` and
    /// `sim_time`; there is no wall-clock timeline.
    Record {
        /// Built-in scene name or scene file.
        #[arg(default_value = DEFAULT_SCENE)]
        scene: String,
        /// Simulated time, in seconds: 2, 2.5s or 250ms.
        #[arg(short, long, default_value = "1", value_parser = parse_duration, allow_negative_numbers = true)]
        duration: f64,
        /// Output file.
        #[arg(short, long, value_name = "FILE", default_value = "run.rrd")]
        output: PathBuf,
        #[command(flatten)]
        integrator: IntegratorFlags,
    },
    /// Measure substep throughput in this build, with a per-pass breakdown.
    ///
    /// Prints a line `<number> particle-substeps/s`.
    Bench {
        /// Built-in scene name or scene file.
        #[arg(default_value = DEFAULT_SCENE)]
        scene: String,
        /// Timed substeps.
        #[arg(short, long, default_value_t = 1000)]
        steps: u64,
        /// Untimed substeps before timing.
        #[arg(long, default_value_t = 100)]
        warmup: u64,
        /// Worker threads (default: all cores).
        #[arg(short = 'j', long)]
        threads: Option<usize>,
        #[command(flatten)]
        integrator: IntegratorFlags,
    },
    #[command(flatten)]
    Evidence(yarnsim_cli::evidence::EvidenceCommand),
}

/// Integrator choice for mass-spring scenes.
#[derive(clap::Args, Debug, Clone, Default)]
struct IntegratorFlags {
    /// Mass-spring scenes only: forward-euler, symplectic-euler, trapezoidal,
    /// backward-euler (default), chebyshev-jacobi or pbd.
    #[arg(long, value_name = "NAME")]
    integrator: Option<String>,
    /// Mass-spring scenes only: an integrator option KEY=VALUE (repeatable), e.g.
    /// dt=0.001, cfl=0.5, preconditioner=jacobi, rho=0.99, strain-limit=0.1.
    #[arg(long = "option", value_name = "KEY=VALUE")]
    options: Vec<String>,
}

impl IntegratorFlags {
    fn args(self) -> IntegratorArgs {
        IntegratorArgs {
            integrator: self.integrator,
            options: self.options,
        }
    }
}

#[derive(Subcommand, Debug)]
enum SceneCommand {
    /// Print a scene as TOML, to save and edit as a custom scene.
    Show {
        /// Built-in scene name or scene file.
        name: String,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse_from(yarnsim_cli::evidence::rewrite_args(std::env::args_os()));
    match execute(cli.command) {
        Ok(code) => ExitCode::from(code),
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}

fn execute(command: Command) -> Result<u8, CliError> {
    match command {
        Command::Scenes => print!("{}", list_scenes()),
        Command::Scene(SceneCommand::Show { name }) => print!("{}", show_scene(&name)?),
        Command::Run {
            scene,
            duration,
            csv,
            integrator,
        } => {
            let scene = load_scene(&scene)?;
            let summary = run(&scene, duration, csv.as_deref(), &integrator.args())?;
            print!("{}", format_summary(&summary, Timing::Show));
            if summary.interrupted {
                eprintln!("interrupted: the summary covers the frames run");
                return Ok(EXIT_INTERRUPTED);
            }
        }
        Command::Record {
            scene,
            duration,
            output,
            integrator,
        } => {
            let scene = load_scene(&scene)?;
            let r = record(&scene, duration, &output, &integrator.args())?;
            let o = r.outcome;
            println!(
                "recorded {} frames ({} substeps, {} particles) to {} in {:.2} s of stepping",
                r.frames_logged,
                o.substeps,
                r.particles,
                output.display(),
                o.step_seconds
            );
            println!("open it with: rerun {}", output.display());
            if o.interrupted {
                eprintln!("interrupted: the recording holds the frames up to the interruption");
                return Ok(EXIT_INTERRUPTED);
            }
        }
        Command::Bench {
            scene,
            steps,
            warmup,
            threads,
            integrator,
        } => {
            let scene = load_scene(&scene)?;
            let r = bench(
                &scene,
                BenchOptions {
                    steps,
                    warmup,
                    threads,
                },
                &integrator.args(),
            )?;
            print!("{}", format_bench(&r));
        }
        Command::Evidence(cmd) => {
            let (text, files) = yarnsim_cli::evidence::execute(&cmd)?;
            print!("{text}");
            for f in files {
                println!("wrote {f}");
            }
        }
    }
    Ok(0)
}
