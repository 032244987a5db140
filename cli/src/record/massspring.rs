//! What a mass-spring recording logs: sphere colliders once, then per
//! frame the particles, the springs coloured by stretch and the diagnostics.

use rerun::components::{Color, Scalar, Vector3D};
use rerun::{
    AnyValues, Ellipsoids3D, LineStrips3D, Points3D, RecordingStream, Scalars, TextDocument,
    ViewCoordinates,
};

use super::blueprint::massspring_blueprint;
use super::frames::{
    energy_scalars, log_scalars, log_series, record_frames, RecordOptions, RecordOutcome,
};
use super::sink::open;
use super::style::{legend, p3, stretch_color};
use super::{paths, values};
use crate::driver::FrameInfo;
use crate::error::CliError;
use crate::massspring::{spring_stretches, MassSpringRun};
use crate::schedule::Schedule;

/// Records a mass-spring simulation from its current state.
pub fn record_massspring(
    run: &mut MassSpringRun,
    duration: f64,
    opts: &RecordOptions,
) -> Result<RecordOutcome, CliError> {
    let schedule = Schedule::new(duration, run.h, run.sim.system().frame_time)?;
    let name = run.name.clone();
    let rec = open(&name, &massspring_blueprint(duration), &opts.sink)?;
    log_massspring_static(&rec, run).map_err(|e| opts.sink.error(e))?;
    record_frames(rec, run, &schedule, &name, opts, log_massspring_frame)
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
    log_series(rec, &paths::MS_SERIES)?;
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
) -> rerun::RecordingStreamResult<()> {
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
    let mut scalars = energy_scalars!(&d, paths::GRAVITY, gravity_energy).to_vec();
    scalars.extend([
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
    ]);
    if frame.substeps > 0 {
        rec.log(
            paths::CG_ITERATIONS,
            &Scalars::single(sim.last_step().cg_iterations as f64),
        )?;
    }
    log_scalars(rec, &scalars, &frame)
}
