//! `yarnsim`: run, record and benchmark yarn scenes from a terminal.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use yarnsim::scene::{Scene, DEFAULT_SCENE};
use yarnsim_cli::bench::{bench, format_bench, BenchOptions};
use yarnsim_cli::duration::parse_duration;
use yarnsim_cli::error::{CliError, EXIT_INTERRUPTED};
use yarnsim_cli::estimate::{announce, Estimate};
use yarnsim_cli::evidence::{BenchStudy, EvidenceCommand, StressArgs};
use yarnsim_cli::massspring::IntegratorArgs;
use yarnsim_cli::record::{
    parse_memory_limit, record, MemoryLimit, RecordOptions, Sink, DEFAULT_CONNECT_URL,
    DEFAULT_SERVER_MEMORY_LIMIT, DEFAULT_SERVE_PORT,
};
use yarnsim_cli::run::{run, Started};
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
/// 4 output file cannot be written, viewer unreachable or port in use,
/// 130 interrupted by Ctrl-C or SIGTERM (output so far is complete and
/// valid). `record --serve` serves on after the run until Ctrl-C or SIGTERM,
/// and then exits 0.
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
    /// List the yarn material presets (real yarns) of `[material] preset = "NAME"`.
    Materials,
    /// Run a scene and print a summary table (steps, wall time, throughput, energy, stretch).
    Run {
        #[command(flatten)]
        scene: SceneArgs,
        /// Simulated time, in seconds: 2, 2.5s or 250ms.
        #[arg(short, long, default_value = "1", value_parser = parse_duration, allow_negative_numbers = true)]
        duration: f64,
        /// Also write the diagnostics (and, for yarn scenes, the yarn endpoints) of every frame to this CSV file.
        #[arg(long, value_name = "FILE")]
        csv: Option<PathBuf>,
        #[command(flatten)]
        integrator: IntegratorFlags,
    },
    /// Record a scene for the Rerun viewer: particles, yarns or springs, obstacles, plots.
    ///
    /// Into a file (default run.rrd; open it with `rerun run.rrd`), to
    /// standard output (`-o - | rerun -`), live into a viewer (`--spawn`,
    /// `--connect`), or served to viewers that connect (`--serve`).
    /// Timelines are `frame` and `sim_time`; there is no wall-clock timeline.
    Record {
        #[command(flatten)]
        scene: SceneArgs,
        /// Simulated time, in seconds: 2, 2.5s or 250ms.
        #[arg(short, long, default_value = "1", value_parser = parse_duration, allow_negative_numbers = true)]
        duration: f64,
        /// Output file, ending in .rrd (default run.rrd), or `-` for standard
        /// output, to pipe into `rerun -`.
        #[arg(
            short,
            long,
            visible_alias = "save",
            value_name = "FILE",
            group = "sink"
        )]
        output: Option<PathBuf>,
        /// Start a Rerun viewer (`rerun` on PATH) and stream to it live.
        #[arg(long, group = "sink")]
        spawn: bool,
        /// Stream live to a running viewer (started with `rerun`), at ADDR:
        /// a rerun+http://HOST:PORT/proxy URL or HOST:PORT.
        #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = DEFAULT_CONNECT_URL, group = "sink")]
        connect: Option<String>,
        /// Host a gRPC server and stream to it live; view with `rerun
        /// --connect URL` (the URL is printed). After the run it serves on
        /// until Ctrl-C or SIGTERM (exit code 0). With --save FILE, also
        /// writes the file.
        #[arg(long, conflicts_with_all = ["spawn", "connect"])]
        serve: bool,
        /// Port of the --serve server.
        #[arg(long, value_name = "PORT", default_value_t = DEFAULT_SERVE_PORT, requires = "serve",
              value_parser = clap::value_parser!(u16).range(1..))]
        port: u16,
        /// Address the --serve server listens on (0.0.0.0: every interface).
        #[arg(long, value_name = "IP", default_value = "0.0.0.0", requires = "serve")]
        bind: std::net::IpAddr,
        /// Memory the --serve server keeps the recording in, for viewers
        /// that connect late: 16GB, 500MiB or 50% (of RAM); beyond it the
        /// oldest frames are dropped.
        #[arg(long, value_name = "X", default_value = DEFAULT_SERVER_MEMORY_LIMIT,
              value_parser = parse_memory_limit, requires = "serve")]
        server_memory_limit: MemoryLimit,
        /// Log every Nth frame only (frame 0 and the last frame always).
        #[arg(long, value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..))]
        every: u64,
        #[command(flatten)]
        integrator: IntegratorFlags,
    },
    /// Measure substep throughput in this build, with a per-pass breakdown;
    /// or run a benchmark study (precision, skip, roofline).
    ///
    /// Without a study: prints a line `<number> particle-substeps/s`.
    #[command(args_conflicts_with_subcommands = true)]
    Bench {
        #[command(subcommand)]
        study: Option<BenchStudy>,
        #[command(flatten)]
        scene: SceneArgs,
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
    /// Stability stress: largest stable dt per integrator and stiffness / yarn
    /// parameter by bisection, next to the theoretical bound.
    Stress(StressArgs),
}

/// The scene of `run`, `record` and `bench`, with its overrides.
#[derive(clap::Args, Debug, Clone)]
struct SceneArgs {
    /// Built-in scene name or scene file.
    #[arg(default_value = DEFAULT_SCENE)]
    scene: String,
    /// Override a scene field, KEY=VALUE with VALUE in TOML (repeatable):
    /// --set material.friction=0.1 --set gravity=[0,-3] --set yarns[0].count=4
    /// (an entry of a list as in error messages, `[0]`, or as `.0`).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
}

impl SceneArgs {
    fn load(&self) -> Result<Scene, CliError> {
        load_scene(&self.scene, &self.set)
    }
}

/// Integrator choice for mass-spring scenes.
#[derive(clap::Args, Debug, Clone, Default)]
struct IntegratorFlags {
    /// Mass-spring scenes only: forward-euler, symplectic-euler, trapezoidal,
    /// backward-euler (default), chebyshev-jacobi or pbd. A yarn scene's is
    /// the scene field time.integrator: --set time.integrator=implicit.
    #[arg(long, value_name = "NAME")]
    integrator: Option<String>,
    /// Mass-spring scenes only: an integrator option KEY=VALUE (repeatable), e.g.
    /// dt=0.001, cfl=0.5, preconditioner=jacobi, rho=0.99, strain-limit=0.1.
    #[arg(long = "option", value_name = "KEY=VALUE")]
    options: Vec<String>,
    /// Run a step above the stability bound instead of refusing: forward or
    /// symplectic Euler on a mass-spring scene, a yarn scene's fixed time.dt
    /// more than 2x its bound (above the bound it warns).
    #[arg(long)]
    allow_unstable: bool,
}

impl IntegratorFlags {
    fn args(self) -> IntegratorArgs {
        IntegratorArgs {
            integrator: self.integrator,
            options: self.options,
            allow_unstable: self.allow_unstable,
        }
    }
}

#[derive(Subcommand, Debug)]
enum SceneCommand {
    /// Print a scene as TOML, to save and edit as a custom scene.
    Show {
        /// Built-in scene name or scene file.
        name: String,
        /// Override a scene field, KEY=VALUE (repeatable), as for `run`.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
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
        Command::Materials => print!("{}", yarnsim_cli::materials::list_materials()),
        Command::Scene(SceneCommand::Show { name, set }) => print!("{}", show_scene(&name, &set)?),
        Command::Run {
            scene,
            duration,
            csv,
            integrator,
        } => {
            let scene = scene.load()?;
            announce(&Estimate::of(&scene, duration, None));
            let mut sim = Started::new(&scene, &integrator.args())?;
            let summary = run(&mut sim, duration, csv.as_deref())?;
            print!("{}", format_summary(&summary, Timing::Show));
            if let Some(failure) = &summary.failure {
                eprintln!("error: {failure}");
                return Ok(1);
            }
            if summary.interrupted {
                eprintln!("interrupted: the summary covers the frames run");
                return Ok(EXIT_INTERRUPTED);
            }
        }
        Command::Record {
            scene,
            duration,
            output,
            spawn,
            connect,
            serve,
            port,
            bind,
            server_memory_limit,
            every,
            integrator,
        } => {
            let sink = if serve {
                Sink::serve(bind, port, server_memory_limit, output.as_deref())?
            } else if spawn {
                Sink::Spawn
            } else if let Some(addr) = &connect {
                Sink::connect(addr)
            } else {
                Sink::output(output.as_deref().unwrap_or("run.rrd".as_ref()))?
            };
            let scene = scene.load()?;
            announce(&Estimate::of(&scene, duration, Some(every)));
            let opts = RecordOptions { sink, every };
            let mut sim = Started::new(&scene, &integrator.args())?;
            let r = record(&mut sim, duration, &opts)?;
            let o = r.outcome;
            let every_note = if every > 1 {
                format!(" (1 in {every} of {} frames)", o.last_frame + 1)
            } else {
                String::new()
            };
            let adaptive = match &r.adaptive_dt {
                Some(range) => format!(" adaptive, dt min / mean / max = {range}"),
                None => String::new(),
            };
            let text = format!(
                "recorded {} frames{every_note} ({} substeps{adaptive}, {} particles) to {} in {:.2} s of stepping",
                r.frames_logged,
                o.substeps,
                r.particles,
                opts.sink.describe(),
                o.step_seconds
            );
            // With `-o -`, standard output carries the recording itself.
            let say = |line: &str| match opts.sink {
                Sink::Stdout => eprintln!("{line}"),
                _ => println!("{line}"),
            };
            say(&text);
            match &opts.sink {
                Sink::File(path) => say(&format!("open it with: rerun {}", path.display())),
                Sink::Serve(s) => {
                    if let Some(path) = &s.save {
                        say(&format!("open the file with: rerun {}", path.display()));
                    }
                }
                _ => {}
            }
            if let Some(failure) = &r.failure {
                eprintln!("error: {failure}");
                eprintln!("the recording holds the frames before the failure");
            }
            // A failed run is served too: its last frames show what went wrong.
            if let Some(server) = r.server {
                say(&format!(
                    "still serving at {url} until Ctrl-C or SIGTERM; view it with: rerun --connect {url}",
                    url = server.url()
                ));
                server.serve_until_interrupted();
                say("stopped serving");
            }
            if let Some(failure) = r.failure {
                return Ok(failure.exit_code());
            }
            if o.interrupted {
                eprintln!("interrupted: the recording holds the frames up to the interruption");
                return Ok(EXIT_INTERRUPTED);
            }
        }
        Command::Bench {
            study: Some(study), ..
        } => return evidence(EvidenceCommand::Bench(study)),
        Command::Stress(args) => return evidence(EvidenceCommand::Stress(args)),
        Command::Bench {
            study: None,
            scene,
            steps,
            warmup,
            threads,
            integrator,
        } => {
            let scene = scene.load()?;
            announce(&Estimate::of(&scene, 0.0, None));
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
    }
    Ok(0)
}

/// Runs an evidence study under a spinner and prints its report and the
/// files it wrote.
fn evidence(cmd: EvidenceCommand) -> Result<u8, CliError> {
    let (label, note) = cmd.label();
    let spinner = yarnsim_cli::driver::spinner(label);
    spinner.set_message(note);
    let result = yarnsim_cli::evidence::execute(&cmd);
    spinner.finish_and_clear();
    let (text, files) = result?;
    let text = yarnsim_cli::table::fit_tables(&text, yarnsim_cli::table::MAX_WIDTH);
    print!("{text}");
    for f in files {
        println!("wrote {f}");
    }
    Ok(0)
}
