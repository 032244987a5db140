//! `yarnsim record`: the full simulation state, frame by frame, as a Rerun
//! recording (`.rrd`). All Rerun code of the project lives in this module.
//!
//! Layout (see the README, "Entity paths", for the full list):
//! * 2D positions are `(x, size - y)` of the library's (m), so Rerun's
//!   y-down 2D view shows +y up (see [`view2`]); no transform is involved.
//! * `world/vertices` (type-2 particles): `Points2D` in their yarn's colour,
//!   with extra per-particle values (`velocity`, `stretch`).
//! * `world/quadrature` (type-3 particles): `Points2D` coloured by stretch,
//!   with values `velocity`, `stretch`, `shear`, `r22`, `yield`, `plastic`.
//! * `world/yarns`: one line strip per yarn, one colour per yarn.
//! * `legend`: the colour scales and the domain (markdown).
//! * `world/domain`, `world/walls`, `world/obstacles`, `world/attractor`: static geometry.
//! * `plots/...`: one scalar series per diagnostic.
//! * `timing/step_time`: wall-clock seconds per substep, the only entity that
//!   differs between two recordings of the same run.
//!
//! Mass-spring scenes are 3D: `world/particles` (`Points3D`), `world/springs`
//! (one two-point line strip per spring, coloured by stretch), `world/spheres`,
//! and their own `plots/...` series.
//!
//! Timelines: `frame` (sequence) and `sim_time` (duration). The automatic
//! wall-clock `log_time` timeline is switched off, so two recordings of the
//! same scene hold the same data everywhere except under `timing/`.

use std::io::IsTerminal;
use std::net::{IpAddr, Ipv4Addr, Ipv6Addr, SocketAddr};
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::time::Duration;

use rerun::blueprint::components::PanelState;
use rerun::blueprint::{
    Blueprint, BlueprintPanel, ContainerLike, Horizontal, SelectionPanel, Spatial2DView,
    Spatial3DView, TextDocumentView, TimePanel, TimeSeriesView, Vertical,
};
use rerun::components::{Color, Scalar, Vector2D, Vector3D};
use rerun::{
    AnyValues, Boxes2D, Ellipses2D, Ellipsoids3D, LineStrips2D, LineStrips3D, Points2D, Points3D,
    RecordingStream, RecordingStreamBuilder, Scalars, SeriesLines, TextDocument, ViewCoordinates,
};
use yarnsim::math::qr::qr;
use yarnsim::scene::{Scene, WallMode};
use yarnsim::YarnSim;

use crate::driver::{
    interrupt_flag, progress_bar, run_frames, FrameInfo, FrameRun, Outcome, Stepper,
};
use crate::error::CliError;
use crate::massspring::{spring_stretches, IntegratorArgs, MassSpringRun};
use crate::run::no_integrator_for_yarn;
use crate::schedule::Schedule;

/// Rerun application id of the recordings.
pub const APP_ID: &str = "yarnsim";
/// Timeline of frame indices (frame 0 = initial state).
pub const TIMELINE_FRAME: &str = "frame";
/// Timeline of simulated time in seconds.
pub const TIMELINE_SIM_TIME: &str = "sim_time";

/// Entity paths of a yarn recording.
pub mod paths {
    pub const WORLD: &str = "world";
    pub const VERTICES: &str = "world/vertices";
    pub const QUADRATURE: &str = "world/quadrature";
    pub const YARNS: &str = "world/yarns";
    pub const DOMAIN: &str = "world/domain";
    pub const WALLS: &str = "world/walls";
    pub const OBSTACLES: &str = "world/obstacles";
    pub const ATTRACTOR: &str = "world/attractor";
    pub const KINETIC: &str = "plots/energy/kinetic";
    pub const ELASTIC: &str = "plots/energy/elastic";
    pub const POTENTIAL: &str = "plots/energy/potential";
    pub const MOMENTUM_X: &str = "plots/momentum/x";
    pub const MOMENTUM_Y: &str = "plots/momentum/y";
    pub const ANGULAR_MOMENTUM: &str = "plots/angular_momentum";
    pub const TOTAL: &str = "plots/energy/total";
    pub const MAX_STRETCH: &str = "plots/stretch/max";
    pub const MIN_STRETCH: &str = "plots/stretch/min";
    pub const MEAN_STRETCH: &str = "plots/stretch/mean";
    pub const COM_X: &str = "plots/center_of_mass/x";
    pub const COM_Y: &str = "plots/center_of_mass/y";
    pub const COM_Z: &str = "plots/center_of_mass/z";
    /// The colour scales, as a markdown document (static).
    pub const LEGEND: &str = "legend";
    /// Wall-clock seconds per substep: not reproducible, kept apart from `plots`.
    pub const STEP_TIME: &str = "timing/step_time";

    /// Mass-spring particles (`Points3D`).
    pub const MS_PARTICLES: &str = "world/particles";
    /// Mass-spring springs (`LineStrips3D`, one strip per spring).
    pub const MS_SPRINGS: &str = "world/springs";
    /// Mass-spring sphere colliders (`Ellipsoids3D`, static).
    pub const MS_SPHERES: &str = "world/spheres";
    pub const GRAVITY: &str = "plots/energy/gravity";
    pub const MOMENTUM_Z: &str = "plots/momentum/z";
    pub const ANGULAR_MOMENTUM_X: &str = "plots/angular_momentum/x";
    pub const ANGULAR_MOMENTUM_Y: &str = "plots/angular_momentum/y";
    pub const ANGULAR_MOMENTUM_Z: &str = "plots/angular_momentum/z";
    pub const MAX_STRAIN: &str = "plots/strain/max";
    /// CG iterations of the frame's last substep (implicit integrators).
    pub const CG_ITERATIONS: &str = "plots/cg_iterations";

    /// Every scalar series of a mass-spring recording, with its display name.
    pub const MS_SERIES: [(&str, &str); 16] = [
        (KINETIC, "kinetic energy [J]"),
        (ELASTIC, "elastic energy [J]"),
        (GRAVITY, "gravity energy [J]"),
        (TOTAL, "total energy [J]"),
        (MOMENTUM_X, "momentum x [kg m/s]"),
        (MOMENTUM_Y, "momentum y [kg m/s]"),
        (MOMENTUM_Z, "momentum z [kg m/s]"),
        (ANGULAR_MOMENTUM_X, "angular momentum x [kg m^2/s]"),
        (ANGULAR_MOMENTUM_Y, "angular momentum y [kg m^2/s]"),
        (ANGULAR_MOMENTUM_Z, "angular momentum z [kg m^2/s]"),
        (MAX_STRAIN, "max |l/l0 - 1|"),
        (COM_X, "centre of mass x [m]"),
        (COM_Y, "centre of mass y [m]"),
        (COM_Z, "centre of mass z [m]"),
        (STEP_TIME, "wall time per substep [s]"),
        (
            CG_ITERATIONS,
            "CG iterations per substep (last substep of the frame)",
        ),
    ];

    /// Every scalar series of a yarn recording, with its display name.
    pub const SERIES: [(&str, &str); 13] = [
        (KINETIC, "kinetic energy [J]"),
        (ELASTIC, "elastic energy [J]"),
        (POTENTIAL, "potential energy [J]"),
        (TOTAL, "total energy [J]"),
        (MOMENTUM_X, "momentum x [kg m/s]"),
        (MOMENTUM_Y, "momentum y [kg m/s]"),
        (ANGULAR_MOMENTUM, "angular momentum [kg m^2/s]"),
        (MAX_STRETCH, "max stretch"),
        (MIN_STRETCH, "min stretch"),
        (MEAN_STRETCH, "mean stretch"),
        (COM_X, "centre of mass x [m]"),
        (COM_Y, "centre of mass y [m]"),
        (STEP_TIME, "wall time per substep [s]"),
    ];
}

/// Names of the extra per-particle values logged next to the positions.
pub mod values {
    /// Velocity (m/s), a `Vector2D` per particle.
    pub const VELOCITY: &str = "velocity";
    /// Segment stretch `|x_r - x_l| / l0`; for a vertex, the mean over its segments.
    pub const STRETCH: &str = "stretch";
    /// Shear `r12` of the QR factor of the material frame `d / l0` (quadrature only).
    pub const SHEAR: &str = "shear";
    /// Normal compression `r22` of that factor; the return mapping keeps it in check (quadrature only).
    pub const R22: &str = "r22";
    /// Mohr-Coulomb yield function `gamma |r12| r22 + c_f (2 mu + lambda) log r22`
    /// (quadrature only): negative inside the elastic region, 0 on the yield surface.
    pub const YIELD: &str = "yield";
    /// Plastic state (quadrature only): 0 elastic, 1 on the yield surface
    /// (sliding), 2 separated (`r22 = 1`, cross-section in tension).
    pub const PLASTIC: &str = "plastic";
}

/// Plastic state of a quadrature particle, see [`values::PLASTIC`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlasticState {
    Elastic = 0,
    Yielding = 1,
    Separated = 2,
}

impl PlasticState {
    /// Classifies `(r12, r22)` of a particle's frame after the return mapping.
    pub fn of(energy: &yarnsim::mpm::constitutive::YarnEnergy, r12: f64, r22: f64) -> Self {
        if r22 >= 1.0 - 1e-9 {
            return PlasticState::Separated;
        }
        let f = energy.yield_function(r12, r22);
        let scale = energy.friction * energy.normal * (-r22.ln()).abs();
        if f >= -1e-6 * scale && r12 != 0.0 {
            PlasticState::Yielding
        } else {
            PlasticState::Elastic
        }
    }

    /// Colour of the state: grey elastic, orange yielding, violet separated.
    pub fn color(self) -> Color {
        match self {
            PlasticState::Elastic => Color::from_rgb(170, 170, 170),
            PlasticState::Yielding => Color::from_rgb(255, 140, 0),
            PlasticState::Separated => Color::from_rgb(160, 60, 220),
        }
    }
}

/// Address `--connect` uses without a value: a viewer started with plain `rerun`.
pub const DEFAULT_CONNECT_URL: &str = "rerun+http://127.0.0.1:9876/proxy";

pub use rerun::MemoryLimit;

/// Port `--serve` listens on without `--port`: Rerun's own default.
pub const DEFAULT_SERVE_PORT: u16 = rerun::DEFAULT_SERVER_PORT;

/// Memory limit of the `--serve` server without `--server-memory-limit`:
/// the default of Rerun's own `--serve` flag.
pub const DEFAULT_SERVER_MEMORY_LIMIT: &str = "25%";

/// Parses a `--server-memory-limit` the way Rerun does: `16GB`, `500MiB`,
/// `50%` (of the machine's memory), `0` or `unlimited`.
pub fn parse_memory_limit(text: &str) -> Result<MemoryLimit, String> {
    MemoryLimit::parse(text)
}

/// A gRPC server that the recording hosts (`--serve`): viewers connect to
/// it, during the run or after it, and get everything logged so far.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Serve {
    /// Address to listen on (`--bind`, default `0.0.0.0`: every interface).
    pub bind: IpAddr,
    /// Port to listen on (`--port`, default 9876).
    pub port: u16,
    /// How much of the recording the server keeps for viewers that connect
    /// late (`--server-memory-limit`); beyond it the oldest frames go first,
    /// static data (geometry, legend, blueprint) is always kept.
    pub memory_limit: MemoryLimit,
    /// Also save the recording to this `.rrd` file (`--save FILE`).
    pub save: Option<PathBuf>,
}

impl Serve {
    /// The URL a viewer connects to: `rerun --connect URL`. A server on
    /// every interface is reached at `127.0.0.1` on this machine.
    pub fn url(&self) -> String {
        let host = match self.bind {
            IpAddr::V4(ip) if ip.is_unspecified() => IpAddr::V4(Ipv4Addr::LOCALHOST),
            IpAddr::V6(ip) if ip.is_unspecified() => IpAddr::V6(Ipv6Addr::LOCALHOST),
            ip => ip,
        };
        format!("rerun+http://{}/proxy", SocketAddr::new(host, self.port))
    }

    /// Rerun's server starts on a thread of its own and only logs a failed
    /// start; binding the address here first turns a port in use (e.g. by a
    /// viewer started with plain `rerun`, which listens on 9876) into an error.
    fn check_address(&self) -> Result<(), CliError> {
        let addr = SocketAddr::new(self.bind, self.port);
        std::net::TcpListener::bind(addr).map(drop).map_err(|e| {
            CliError::Viewer(format!(
                "cannot serve on {addr}: {e}; is a Rerun viewer or server already listening \
                 there? Pick another port with --port, or stream into that viewer with \
                 --connect {}",
                self.url()
            ))
        })
    }
}

/// Where a recording goes: Rerun's usual sinks.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Sink {
    /// An `.rrd` file (`-o FILE`, `--save FILE`).
    File(PathBuf),
    /// Standard output (`-o -`), to pipe into `rerun -`.
    Stdout,
    /// A viewer started for this recording (`--spawn`, needs `rerun` on PATH).
    Spawn,
    /// A running viewer or server at this gRPC URL (`--connect [ADDR]`).
    Connect(String),
    /// A gRPC server of its own, for viewers to connect to (`--serve`),
    /// optionally with a copy in a file (`--serve --save FILE`).
    Serve(Serve),
}

impl Sink {
    /// The sink of `-o NAME`: `-` is standard output, anything else must be
    /// a file name ending in `.rrd` (the only format the viewer opens).
    pub fn output(name: &Path) -> Result<Sink, CliError> {
        if name.as_os_str() == "-" {
            return Ok(Sink::Stdout);
        }
        if name.extension().is_some_and(|e| e == "rrd") {
            Ok(Sink::File(name.to_path_buf()))
        } else {
            Err(CliError::Usage(format!(
                "output `{}` does not end in .rrd: Rerun recordings are .rrd files \
                 (or `-o -` for standard output, to pipe into `rerun -`)",
                name.display()
            )))
        }
    }

    /// The sink of `--connect ADDR`: a full `rerun+http://.../proxy` URL, or
    /// just `HOST:PORT`.
    pub fn connect(addr: &str) -> Sink {
        if addr.contains("://") {
            Sink::Connect(addr.to_string())
        } else {
            Sink::Connect(format!("rerun+http://{addr}/proxy"))
        }
    }

    /// The sink of `--serve`, saving to `output` too when given (`--save
    /// FILE`; standard output is refused: the server is the live stream).
    pub fn serve(
        bind: IpAddr,
        port: u16,
        memory_limit: MemoryLimit,
        output: Option<&Path>,
    ) -> Result<Sink, CliError> {
        let save = match output.map(Sink::output).transpose()? {
            None => None,
            Some(Sink::File(path)) => Some(path),
            Some(_) => {
                return Err(CliError::Usage(
                    "--serve does not write to standard output (`-o -`): connect a viewer to \
                     the server instead, or save a copy with --save FILE"
                        .into(),
                ))
            }
        };
        Ok(Sink::Serve(Serve {
            bind,
            port,
            memory_limit,
            save,
        }))
    }

    /// Where the data went, for the closing message.
    pub fn describe(&self) -> String {
        match self {
            Sink::File(p) => p.display().to_string(),
            Sink::Stdout => "standard output".into(),
            Sink::Spawn => "a new Rerun viewer".into(),
            Sink::Connect(url) => format!("the viewer at {url}"),
            Sink::Serve(s) => match &s.save {
                None => format!("the server at {}", s.url()),
                Some(p) => format!("the server at {} and {}", s.url(), p.display()),
            },
        }
    }

    /// An error of this sink, with the innermost cause only (Rerun's errors
    /// repeat the path and wrap the OS error).
    fn error(&self, e: impl std::error::Error) -> CliError {
        let cause = root_cause(&e);
        match self {
            Sink::File(p) => CliError::output(p, cause),
            Sink::Stdout => CliError::Viewer(format!("cannot write to standard output: {cause}")),
            Sink::Spawn => CliError::Viewer(format!("cannot start a Rerun viewer: {cause}")),
            Sink::Connect(url) => {
                CliError::Viewer(format!("cannot stream to the viewer at {url}: {cause}"))
            }
            Sink::Serve(s) => CliError::Viewer(format!("cannot serve at {}: {cause}", s.url())),
        }
    }
}

/// The innermost error of a chain, as text.
fn root_cause(e: &dyn std::error::Error) -> String {
    let mut e = e;
    while let Some(inner) = e.source() {
        e = inner;
    }
    e.to_string()
}

/// What to record: the sink and which frames.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RecordOptions {
    pub sink: Sink,
    /// Log every `every`-th frame (1 = all); frame 0 and the last frame are always logged.
    pub every: u64,
}

impl RecordOptions {
    /// All frames into `path` (checked like `-o`).
    pub fn file(path: &Path) -> Result<Self, CliError> {
        Ok(RecordOptions {
            sink: Sink::output(path)?,
            every: 1,
        })
    }

    fn logs(&self, frame: &FrameInfo) -> bool {
        frame.last || frame.frame.is_multiple_of(self.every.max(1))
    }
}

/// How a `record` command ended.
#[derive(Debug)]
pub struct RecordOutcome {
    pub outcome: Outcome,
    pub particles: usize,
    pub frames_logged: u64,
    /// Adaptive substeps (`dt = "auto"`): their `min / mean / max`.
    pub adaptive_dt: Option<String>,
    /// The simulation error that stopped the run early; the recording holds
    /// the frames before it and is complete.
    pub failure: Option<CliError>,
    /// The `--serve` server, still serving the recording after the run (not
    /// after an interruption: Ctrl-C during the run stops both).
    pub server: Option<Server>,
}

/// The gRPC server of a `--serve` recording, serving everything logged to
/// viewers that connect; it stops when this is dropped.
pub struct Server {
    rec: RecordingStream,
    url: String,
}

impl std::fmt::Debug for Server {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Server").field("url", &self.url).finish()
    }
}

impl Server {
    /// The URL viewers connect to (`rerun --connect URL`).
    pub fn url(&self) -> &str {
        &self.url
    }

    /// Keeps serving until Ctrl-C, SIGTERM or SIGHUP, then shuts the server
    /// down (viewers keep what they received).
    pub fn serve_until_interrupted(self) {
        let interrupt = interrupt_flag();
        while !interrupt.load(Ordering::SeqCst) {
            std::thread::sleep(Duration::from_millis(100));
        }
        drop(self.rec);
    }
}

/// Records `scene` for `duration` seconds; `integrator` applies to
/// mass-spring scenes only.
pub fn record(
    scene: &Scene,
    duration: f64,
    opts: &RecordOptions,
    integrator: &IntegratorArgs,
) -> Result<RecordOutcome, CliError> {
    match scene {
        Scene::Yarn(y) => {
            no_integrator_for_yarn(integrator)?;
            record_yarn(&mut YarnSim::new(y)?, duration, opts)
        }
        Scene::MassSpring(l) => {
            record_massspring(&mut MassSpringRun::new(l, integrator)?, duration, opts)
        }
    }
}

/// Opens the recording stream on its sink, without the wall-clock
/// `log_time` timeline.
fn open(name: &str, blueprint: Blueprint, sink: &Sink) -> Result<RecordingStream, CliError> {
    let builder = RecordingStreamBuilder::new(APP_ID)
        .recording_name(name.to_string())
        .with_blueprint(blueprint);
    let rec = match sink {
        Sink::File(path) => {
            // Rerun's own error repeats the path and nests the OS error.
            std::fs::File::create(path).map_err(|e| CliError::output(path, e))?;
            builder.save(path)
        }
        Sink::Stdout => {
            if std::io::stdout().is_terminal() {
                return Err(CliError::Usage(
                    "`-o -` writes the recording to standard output, which is a terminal here; \
                     pipe it into the viewer (`yarnsim record -o - | rerun -`) or give a file name"
                        .into(),
                ));
            }
            builder.stdout()
        }
        Sink::Spawn => builder.spawn(),
        Sink::Connect(url) => builder.connect_grpc_opts(url.clone()),
        Sink::Serve(s) => {
            s.check_address()?;
            let options = rerun::ServerOptions {
                memory_limit: s.memory_limit,
                ..Default::default()
            };
            match &s.save {
                None => builder.serve_grpc_opts(s.bind.to_string(), s.port, options),
                Some(path) => {
                    std::fs::File::create(path).map_err(|e| CliError::output(path, e))?;
                    let file = rerun::sink::FileSink::new(path)
                        .map_err(|e| CliError::output(path, root_cause(&e)))?;
                    let server = rerun::grpc_server::GrpcServerSink::new(
                        &s.bind.to_string(),
                        s.port,
                        options,
                    )
                    .map_err(|e| sink.error(e))?;
                    builder.set_sinks((server, file))
                }
            }
        }
    }
    .map_err(|e| sink.error(e))?;
    rec.set_log_time_enabled(false);
    if let Sink::Serve(s) = sink {
        // Before the first frame, so a viewer can follow the run live.
        println!(
            "serving at {url}; view it live with: rerun --connect {url}",
            url = s.url()
        );
    }
    Ok(rec)
}

/// Runs `schedule` on `sim`, logging the frames `opts` selects with `log`,
/// then flushes and closes the stream whatever happened (divergence,
/// Ctrl-C, SIGTERM), so a file ends readable.
fn record_frames<S: Stepper + Send>(
    rec: RecordingStream,
    sim: &mut S,
    schedule: &Schedule,
    label: &str,
    opts: &RecordOptions,
    mut log: impl FnMut(&RecordingStream, &S, FrameInfo) -> rerun::RecordingStreamResult<()>,
) -> Result<RecordOutcome, CliError> {
    let progress = progress_bar(schedule.total_steps, label);
    let mut frames_logged = 0;
    let result = run_frames(sim, schedule, &interrupt_flag(), &progress, |sim, frame| {
        if opts.logs(&frame) {
            log(&rec, sim, frame).map_err(|e| opts.sink.error(e))?;
            frames_logged += 1;
        }
        Ok(())
    });
    let flushed = rec.flush_blocking();
    let keep_serving = matches!(&result, Ok(run) if !run.outcome.interrupted);
    let server = match &opts.sink {
        Sink::Serve(s) if keep_serving => {
            // Completes the file of `--save` (its footer); the server stays.
            rec.finalize_deferred_sinks();
            Some(Server { rec, url: s.url() })
        }
        _ => {
            drop(rec);
            None
        }
    };
    let FrameRun { outcome, failure } = result?;
    flushed.map_err(|e| opts.sink.error(e))?;
    Ok(RecordOutcome {
        outcome,
        particles: sim.num_particles(),
        frames_logged,
        adaptive_dt: None,
        failure,
        server,
    })
}

/// Records a yarn simulation from its current state.
pub fn record_yarn(
    sim: &mut YarnSim,
    duration: f64,
    opts: &RecordOptions,
) -> Result<RecordOutcome, CliError> {
    let schedule = crate::run::yarn_schedule(sim, duration)?;
    sim.reset_dt_stats();
    let name = sim.scene().name.clone();
    let rec = open(&name, yarn_blueprint(), &opts.sink)?;
    log_yarn_static(&rec, sim).map_err(|e| opts.sink.error(e))?;
    let t0 = sim.time();
    let mut out = record_frames(rec, sim, &schedule, &name, opts, |rec, sim, frame| {
        log_yarn_frame(rec, sim, frame, sim.time() - t0)
    })?;
    let stats = sim.dt_stats();
    out.adaptive_dt = (sim.is_auto() && stats.substeps > 0).then(|| crate::run::dt_range(&stats));
    Ok(out)
}

/// Records a mass-spring simulation from its current state.
pub fn record_massspring(
    run: &mut MassSpringRun,
    duration: f64,
    opts: &RecordOptions,
) -> Result<RecordOutcome, CliError> {
    let schedule = Schedule::new(duration, run.h, run.sim.system().frame_time)?;
    let name = run.name.clone();
    let rec = open(&name, massspring_blueprint(), &opts.sink)?;
    log_massspring_static(&rec, run).map_err(|e| opts.sink.error(e))?;
    let t0 = run.time();
    record_frames(rec, run, &schedule, &name, opts, |rec, run, frame| {
        log_massspring_frame(rec, run, frame, run.time() - t0)
    })
}

/// A time-series view of the entities under `origin`.
fn plot(name: &str, origin: &str) -> TimeSeriesView {
    TimeSeriesView::new(name).with_origin(origin)
}

/// Blueprint and selection panels collapsed, so the scene gets the width;
/// the time panel collapsed to its play bar, on the `sim_time` timeline.
fn with_panels(b: Blueprint) -> Blueprint {
    b.with_blueprint_panel(BlueprintPanel::new().with_state(PanelState::Collapsed))
        .with_selection_panel(SelectionPanel::new().with_state(PanelState::Collapsed))
        .with_time_panel(
            TimePanel::new()
                .with_timeline(TIMELINE_SIM_TIME)
                .with_state(PanelState::Collapsed),
        )
}

/// The layout the recording opens with: the 2D scene and the colour scales
/// on the left, one plot per unit on the right.
pub fn yarn_blueprint() -> Blueprint {
    two_columns(
        Spatial2DView::new("scene")
            .with_origin("/")
            .with_contents(["/world/**"])
            .into(),
        &[
            ("energy [J]", "/plots/energy"),
            ("momentum [kg m/s]", "/plots/momentum"),
            ("angular momentum [kg m^2/s]", "/plots/angular_momentum"),
            ("stretch l/l0", "/plots/stretch"),
            ("centre of mass [m]", "/plots/center_of_mass"),
            ("wall time per substep [s]", "/timing"),
        ],
    )
}

/// `scene` above the colour scales on the left (3/5 of the width), one
/// time-series view per `(title, origin)` on the right; the side panels
/// collapsed ([`with_panels`]).
fn two_columns(scene: ContainerLike, plots: &[(&str, &str)]) -> Blueprint {
    with_panels(Blueprint::new(
        Horizontal::new([
            Vertical::new([
                scene,
                TextDocumentView::new("colours")
                    .with_origin(format!("/{}", paths::LEGEND))
                    .into(),
            ])
            .with_row_shares([6.0, 1.0])
            .into(),
            Vertical::new(
                plots
                    .iter()
                    .map(|&(name, origin)| plot(name, origin).into()),
            )
            .into(),
        ])
        .with_column_shares([3.0, 2.0]),
    ))
}

/// Where a library point `v` is drawn in a domain of side `size`: Rerun's 2D
/// views draw +y downwards, so y is stored as `size - y` (+y shows up). The
/// recording carries no mirror transform: labels under one landed at
/// y-mirrored places.
pub fn view2(v: &yarnsim::math::Vec2, size: f64) -> [f32; 2] {
    [v.x as f32, (size - v.y) as f32]
}

fn p2(v: &yarnsim::math::Vec2) -> [f32; 2] {
    [v.x as f32, v.y as f32]
}

/// The layout of a mass-spring recording: the 3D scene and the colour
/// scales on the left, one plot per unit on the right.
pub fn massspring_blueprint() -> Blueprint {
    two_columns(
        Spatial3DView::new("scene").with_origin("/world").into(),
        &[
            ("energy [J]", "/plots/energy"),
            ("momentum [kg m/s]", "/plots/momentum"),
            ("angular momentum [kg m^2/s]", "/plots/angular_momentum"),
            ("strain |l/l0 - 1|", "/plots/strain"),
            ("centre of mass [m]", "/plots/center_of_mass"),
            ("CG iterations", "/plots/cg_iterations"),
            ("wall time per substep [s]", "/timing"),
        ],
    )
}

/// Distinct colours for the series of one plot (Okabe-Ito palette, easy to
/// tell apart, also for colour-blind readers).
pub const SERIES_COLORS: [[u8; 3]; 4] = [
    [0, 114, 178],   // blue
    [213, 94, 0],    // vermillion
    [0, 158, 115],   // green
    [204, 121, 167], // purple
];

/// Colour of the `path`'s series: its rank among the series of its plot
/// (the entities sharing its parent), in [`SERIES_COLORS`].
pub fn series_color(series: &[(&str, &str)], path: &str) -> Color {
    let parent = |p: &str| p.rsplit_once('/').map_or("", |(a, _)| a).to_string();
    let rank = series
        .iter()
        .filter(|(p, _)| parent(p) == parent(path))
        .position(|(p, _)| *p == path)
        .unwrap_or(0);
    let [r, g, b] = SERIES_COLORS[rank % SERIES_COLORS.len()];
    Color::from_rgb(r, g, b)
}

/// The colour scales of a recording, in markdown.
pub fn legend(yarn: bool) -> String {
    let scale = "stretch `l/l0`: blue = 0.9 (10 % compressed) - light grey = 1.0 (rest length) \
                 - red = 1.1 (10 % stretched), saturating beyond";
    if yarn {
        format!(
            "**Yarns**: one colour per yarn (lines and vertices). **Quadrature points** \
             (one per segment): {scale}. Plastic state, yield value, shear are values \
             of `world/quadrature` (select a point)."
        )
    } else {
        format!(
            "**Springs**: {scale}. **Particles**: blue free, red pinned or driven. \
             Y is up."
        )
    }
}

/// Radii in grid cells: the yarn lines are the widest, so they stay
/// visible; the points sit on them, smaller.
pub const STRIP_RADIUS: f32 = 0.3;
pub const VERTEX_RADIUS: f32 = 0.15;
pub const QUADRATURE_RADIUS: f32 = 0.12;

/// Colour of a stretch value: blue when compressed, light grey at rest
/// length, red when stretched; saturates at +-10 %.
pub fn stretch_color(s: f64) -> Color {
    let t = ((s - 1.0) / 0.1).clamp(-1.0, 1.0);
    let grey = [200.0, 200.0, 200.0];
    let end = if t < 0.0 {
        [40.0, 90.0, 255.0]
    } else {
        [255.0, 50.0, 30.0]
    };
    let a = t.abs();
    let c = |i: usize| (grey[i] * (1.0 - a) + end[i] * a).round() as u8;
    Color::from_rgb(c(0), c(1), c(2))
}

/// A distinct colour per yarn (golden-angle hues).
pub fn yarn_color(i: usize) -> Color {
    let h = (i as f64 * 0.618_033_988_75).fract() * 6.0;
    let x = 1.0 - (h % 2.0 - 1.0).abs();
    let (r, g, b) = match h as u32 {
        0 => (1.0, x, 0.0),
        1 => (x, 1.0, 0.0),
        2 => (0.0, 1.0, x),
        3 => (0.0, x, 1.0),
        4 => (x, 0.0, 1.0),
        _ => (1.0, 0.0, x),
    };
    let c = |v: f64| (60.0 + 170.0 * v) as u8;
    Color::from_rgb(c(r), c(g), c(b))
}

/// Mean stretch of the segments around every vertex.
pub fn vertex_stretches(sim: &YarnSim, seg: &[f64]) -> Vec<f64> {
    let p = sim.particles();
    let none = yarnsim::mpm::particles::NONE;
    (0..p.vert.x.len())
        .map(|i| {
            let (l, r) = (p.vert.q_left[i], p.vert.q_right[i]);
            match (l != none, r != none) {
                (true, true) => 0.5 * (seg[l as usize] + seg[r as usize]),
                (true, false) => seg[l as usize],
                (false, true) => seg[r as usize],
                (false, false) => 1.0,
            }
        })
        .collect()
}

/// Scene geometry that never changes, logged once without time.
fn log_yarn_static(rec: &RecordingStream, sim: &YarnSim) -> rerun::RecordingStreamResult<()> {
    let sc = sim.scene();
    let size = sc.grid.size as f32;
    let dx = sc.dx() as f32;
    let h = sc.grid.size;
    // The domain and the wall band: shapes only; what they are is in the
    // legend (box labels sit at the box centre, on top of each other and
    // of the obstacles' labels).
    rec.log_static(
        paths::DOMAIN,
        &Boxes2D::from_mins_and_sizes([[0.0, 0.0]], [[size, size]])
            .with_colors([Color::from_rgb(120, 120, 120)]),
    )?;
    if sc.walls.mode != WallMode::None {
        let w = sc.walls.cells as f32 * dx;
        rec.log_static(
            paths::WALLS,
            &Boxes2D::from_mins_and_sizes([[w, w]], [[size - 2.0 * w, size - 2.0 * w]])
                .with_colors([Color::from_rgb(160, 120, 60)]),
        )?;
    }
    if !sc.obstacles.is_empty() {
        rec.log_static(
            paths::OBSTACLES,
            &Ellipses2D::from_centers_and_half_sizes(
                sc.obstacles
                    .iter()
                    .map(|o| view2(&yarnsim::math::Vec2::from(o.center), h)),
                sc.obstacles
                    .iter()
                    .map(|o| [o.radius as f32, o.radius as f32]),
            )
            .with_colors([Color::from_rgb(90, 200, 120)])
            .with_labels(
                sc.obstacles
                    .iter()
                    .enumerate()
                    .map(|(i, o)| format!("obstacle {i}, friction {}", o.friction)),
            ),
        )?;
    }
    let a = sim.attractor();
    if a.active {
        rec.log_static(
            paths::ATTRACTOR,
            &Points2D::new([view2(&a.position, h)])
                .with_radii([2.0 * dx])
                .with_colors([Color::from_rgb(255, 220, 0)])
                .with_labels([format!("attractor {} m/s^2", a.strength)]),
        )?;
    }
    for (path, name) in paths::SERIES {
        rec.log_static(
            path,
            &SeriesLines::new()
                .with_names([name])
                .with_colors([series_color(&paths::SERIES, path)]),
        )?;
    }
    let walls = match sc.walls.mode {
        WallMode::Sticky => format!("brown: sticky walls, {} cells", sc.walls.cells),
        WallMode::Slip => format!("brown: slip walls, {} cells", sc.walls.cells),
        WallMode::None => "no walls".into(),
    };
    let geometry = format!(
        " **Domain**: grey square, grid {0}x{0} over {1} m; {walls}. +y is up.",
        sc.grid.resolution, sc.grid.size
    );
    rec.log_static(
        paths::LEGEND,
        &TextDocument::from_markdown(legend(true) + &geometry),
    )?;
    Ok(())
}

/// Everything that changes, at frame `frame.frame` and simulated time `t`.
fn log_yarn_frame(
    rec: &RecordingStream,
    sim: &YarnSim,
    frame: FrameInfo,
    t: f64,
) -> rerun::RecordingStreamResult<()> {
    rec.set_time_sequence(TIMELINE_FRAME, frame.frame as i64);
    rec.set_duration_secs(TIMELINE_SIM_TIME, t);
    let p = sim.particles();
    let dx = sim.scene().dx() as f32;
    let seg = sim.stretches();
    let vs = vertex_stretches(sim, &seg);

    let h = sim.scene().grid.size;
    let positions: Vec<[f32; 2]> = p.vert.x.iter().map(|x| view2(x, h)).collect();
    let yv = &p.yarn_vertices;
    let vertex_colors: Vec<Color> = (0..sim.num_yarns())
        .flat_map(|y| std::iter::repeat_n(yarn_color(y), yv[y + 1] - yv[y]))
        .collect();
    rec.log(
        paths::VERTICES,
        &Points2D::new(positions.iter().copied())
            .with_radii([VERTEX_RADIUS * dx])
            .with_colors(vertex_colors),
    )?;
    rec.log(
        paths::VERTICES,
        &AnyValues::default()
            .with_component::<Vector2D>(values::VELOCITY, p.vert.v.iter().map(p2))
            .with_component::<Scalar>(values::STRETCH, vs.iter().copied()),
    )?;

    let n = seg.len();
    let energy = sim.energy_model();
    let (mut shear, mut r22) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let (mut yield_f, mut state) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for (d, l0) in p.quad.d.iter().zip(&p.quad.l0) {
        let r = qr(&(*d / *l0));
        shear.push(r.r12);
        r22.push(r.r22);
        yield_f.push(energy.yield_function(r.r12, r.r22));
        state.push(PlasticState::of(energy, r.r12, r.r22));
    }
    rec.log(
        paths::QUADRATURE,
        &Points2D::new(p.quad.x.iter().map(|x| view2(x, h)))
            .with_radii([QUADRATURE_RADIUS * dx])
            .with_colors(seg.iter().map(|&s| stretch_color(s))),
    )?;
    rec.log(
        paths::QUADRATURE,
        &AnyValues::default()
            .with_component::<Vector2D>(values::VELOCITY, p.quad.v.iter().map(p2))
            .with_component::<Scalar>(values::STRETCH, seg.iter().copied())
            .with_component::<Scalar>(values::SHEAR, shear)
            .with_component::<Scalar>(values::R22, r22)
            .with_component::<Scalar>(values::YIELD, yield_f)
            .with_component::<Scalar>(values::PLASTIC, state.iter().map(|&s| s as u8 as f64)),
    )?;

    rec.log(
        paths::YARNS,
        &LineStrips2D::new((0..sim.num_yarns()).map(|y| positions[yv[y]..yv[y + 1]].to_vec()))
            .with_radii([STRIP_RADIUS * dx])
            .with_colors((0..sim.num_yarns()).map(yarn_color)),
    )?;

    let d = sim.diagnostics();
    let scalars = [
        (paths::KINETIC, d.kinetic_energy),
        (paths::ELASTIC, d.elastic_energy),
        (paths::POTENTIAL, d.potential_energy),
        (paths::MOMENTUM_X, d.momentum.x),
        (paths::MOMENTUM_Y, d.momentum.y),
        (paths::ANGULAR_MOMENTUM, d.angular_momentum),
        (
            paths::TOTAL,
            d.kinetic_energy + d.elastic_energy + d.potential_energy,
        ),
        (paths::MAX_STRETCH, d.max_stretch),
        (paths::MIN_STRETCH, d.min_stretch),
        (paths::MEAN_STRETCH, d.mean_stretch),
        (paths::COM_X, d.center_of_mass.x),
        (paths::COM_Y, d.center_of_mass.y),
    ];
    for (path, value) in scalars {
        rec.log(path, &Scalars::single(value))?;
    }
    if frame.substeps > 0 {
        rec.log(
            paths::STEP_TIME,
            &Scalars::single(frame.step_seconds / frame.substeps as f64),
        )?;
    }
    Ok(())
}

fn p3(v: &yarnsim::massspring::V3) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

/// Mass-spring geometry that never changes: sphere colliders, series names.
fn log_massspring_static(
    rec: &RecordingStream,
    run: &MassSpringRun,
) -> rerun::RecordingStreamResult<()> {
    let sys = run.sim.system();
    if !sys.spheres.is_empty() {
        rec.log_static(
            paths::MS_SPHERES,
            &Ellipsoids3D::from_centers_and_radii(
                sys.spheres.iter().map(|s| p3(&s.center)),
                sys.spheres.iter().map(|s| s.radius as f32),
            )
            .with_colors([Color::from_rgb(90, 200, 120)]),
        )?;
    }
    for (path, name) in paths::MS_SERIES {
        rec.log_static(
            path,
            &SeriesLines::new()
                .with_names([name])
                .with_colors([series_color(&paths::MS_SERIES, path)]),
        )?;
    }
    rec.log_static(paths::LEGEND, &TextDocument::from_markdown(legend(false)))?;
    // The scenes are Y-up (gravity along -y): without this the viewer lays
    // them on its floor grid and frames them badly.
    rec.log_static(paths::WORLD, &ViewCoordinates::RIGHT_HAND_Y_UP())?;
    Ok(())
}

/// Radius for drawing mass-spring particles: a fifth of the shortest rest length.
fn ms_point_radius(run: &MassSpringRun) -> f32 {
    let l = run
        .sim
        .system()
        .springs
        .iter()
        .map(|s| s.rest_length)
        .fold(f64::INFINITY, f64::min);
    if l.is_finite() && l > 0.0 {
        (0.2 * l) as f32
    } else {
        0.02
    }
}

/// Everything of a mass-spring state that changes.
fn log_massspring_frame(
    rec: &RecordingStream,
    run: &MassSpringRun,
    frame: FrameInfo,
    t: f64,
) -> rerun::RecordingStreamResult<()> {
    rec.set_time_sequence(TIMELINE_FRAME, frame.frame as i64);
    rec.set_duration_secs(TIMELINE_SIM_TIME, t);
    let sim = &run.sim;
    let sys = sim.system();
    let x: Vec<[f32; 3]> = sim.positions().iter().map(p3).collect();
    let radius = ms_point_radius(run);
    rec.log(
        paths::MS_PARTICLES,
        &Points3D::new(x.iter().copied())
            .with_radii([radius])
            .with_colors((0..sys.len()).map(|i| {
                if sys.is_free(i) {
                    Color::from_rgb(80, 160, 255)
                } else {
                    Color::from_rgb(255, 60, 40)
                }
            })),
    )?;
    rec.log(
        paths::MS_PARTICLES,
        &AnyValues::default()
            .with_component::<Vector3D>(values::VELOCITY, sim.velocities().iter().map(p3)),
    )?;
    let stretch = spring_stretches(sim);
    rec.log(
        paths::MS_SPRINGS,
        &LineStrips3D::new(sys.springs.iter().map(|s| [x[s.a], x[s.b]]))
            .with_radii([0.3 * radius])
            .with_colors(stretch.iter().map(|&s| stretch_color(s))),
    )?;
    rec.log(
        paths::MS_SPRINGS,
        &AnyValues::default().with_component::<Scalar>(values::STRETCH, stretch),
    )?;
    let d = run.diagnostics();
    let scalars = [
        (paths::KINETIC, d.kinetic_energy),
        (paths::ELASTIC, d.elastic_energy),
        (paths::GRAVITY, d.gravity_energy),
        (paths::MOMENTUM_X, d.momentum.x),
        (paths::MOMENTUM_Y, d.momentum.y),
        (paths::MOMENTUM_Z, d.momentum.z),
        (paths::ANGULAR_MOMENTUM_X, d.angular_momentum.x),
        (paths::ANGULAR_MOMENTUM_Y, d.angular_momentum.y),
        (paths::ANGULAR_MOMENTUM_Z, d.angular_momentum.z),
        (paths::MAX_STRAIN, d.max_strain),
        (
            paths::TOTAL,
            d.kinetic_energy + d.elastic_energy + d.gravity_energy,
        ),
        (paths::COM_X, d.center_of_mass.x),
        (paths::COM_Y, d.center_of_mass.y),
        (paths::COM_Z, d.center_of_mass.z),
    ];
    for (path, value) in scalars {
        rec.log(path, &Scalars::single(value))?;
    }
    if frame.substeps > 0 {
        rec.log(
            paths::CG_ITERATIONS,
            &Scalars::single(sim.last_step().cg_iterations as f64),
        )?;
        rec.log(
            paths::STEP_TIME,
            &Scalars::single(frame.step_seconds / frame.substeps as f64),
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use yarnsim::mpm::constitutive::YarnEnergy;

    #[test]
    fn plastic_state_follows_the_return_mapping() {
        let e = YarnEnergy {
            k: 1000.0,
            gamma: 500.0,
            normal: 1400.0,
            friction: 0.3,
        };
        // Compressed, little shear: inside the yield surface.
        assert_eq!(PlasticState::of(&e, 1e-4, 0.95), PlasticState::Elastic);
        // Too much shear for the pressure: the return mapping puts it on the surface.
        let (r12, r22) = e.return_map(0.5, 0.95);
        assert!(r12 < 0.5);
        assert_eq!(PlasticState::of(&e, r12, r22), PlasticState::Yielding);
        assert_eq!(PlasticState::of(&e, -r12, r22), PlasticState::Yielding);
        // Cross-section in tension: separated.
        let (r12, r22) = e.return_map(0.1, 1.2);
        assert_eq!(PlasticState::of(&e, r12, r22), PlasticState::Separated);
    }

    #[test]
    fn stretch_colors_saturate() {
        assert_eq!(stretch_color(1.0), Color::from_rgb(200, 200, 200));
        assert_eq!(stretch_color(2.0), stretch_color(1.1));
        assert_eq!(stretch_color(0.5), Color::from_rgb(40, 90, 255));
    }
}
