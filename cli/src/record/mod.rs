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
//!
//! Modules: [`sink`] (where the stream goes, `--serve`), [`frames`] (the
//! frame loop), [`blueprint`] (the viewer layout, written by [`layout`]), [`style`] (colours,
//! radii, legend), [`yarn`] and [`massspring`] (what is logged per frame).

pub mod blueprint;
pub mod frames;
pub mod layout;
pub mod massspring;
pub mod sink;
pub mod style;
pub mod yarn;

pub use blueprint::{
    massspring_blueprint, plot_title, time_axis_end, yarn_blueprint, LEGEND_VISIBLE,
};
pub use frames::{RecordOptions, RecordOutcome};
pub use massspring::record_massspring;
pub use sink::{
    parse_memory_limit, MemoryLimit, Serve, Server, Sink, DEFAULT_CONNECT_URL,
    DEFAULT_SERVER_MEMORY_LIMIT, DEFAULT_SERVE_PORT,
};
pub use style::{
    legend, series_color, series_color_name, stretch_color, view2, yarn_color, QUADRATURE_RADIUS,
    SERIES_COLORS, STRIP_RADIUS, VERTEX_RADIUS,
};
pub use yarn::{record_yarn, vertex_stretches};
/// Plastic state of a quadrature particle, see [`values::PLASTIC`]; the
/// library classifies it ([`yarnsim::mpm::laws::constitutive::YarnEnergy::plastic_state`]).
pub use yarnsim::mpm::laws::constitutive::PlasticState;

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
    /// The scale of the 2D view (static): tick marks outside the domain.
    pub const SCALE_TICKS: &str = "world/scale/ticks";
    /// The ticks' values in m and the axis names, as labelled points.
    pub const SCALE_LABELS: &str = "world/scale/labels";
    /// Faint grid lines across the domain at the labelled ticks.
    pub const SCALE_GRID: &str = "world/scale/grid";
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

use crate::error::CliError;
use crate::run::Started;

/// Records `sim` for `duration` seconds.
pub fn record(
    sim: &mut Started,
    duration: f64,
    opts: &RecordOptions,
) -> Result<RecordOutcome, CliError> {
    match sim {
        Started::Yarn(sim) => record_yarn(sim, duration, opts),
        Started::MassSpring(run) => record_massspring(run, duration, opts),
    }
}
