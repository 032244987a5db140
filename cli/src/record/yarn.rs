//! What a yarn recording logs: the static geometry once, then per frame
//! the particles with their values, the yarns and the diagnostics.

use rerun::components::{Color, Scalar, Vector2D};
use rerun::{
    AnyValues, Boxes2D, Ellipses2D, LineStrips2D, Points2D, RecordingStream, TextDocument,
};
use yarnsim::math::qr::qr;
use yarnsim::scene::WallMode;
use yarnsim::YarnSim;

use super::blueprint::yarn_blueprint;
use super::frames::{
    energy_scalars, log_scalars, log_series, record_frames, RecordOptions, RecordOutcome,
};
use super::sink::open;
use super::style::{
    legend, p2, scale, stretch_color, view2, yarn_color, QUADRATURE_RADIUS, STRIP_RADIUS,
    VERTEX_RADIUS,
};
use super::{paths, values};
use crate::driver::FrameInfo;
use crate::error::CliError;

/// Records a yarn simulation from its current state.
pub fn record_yarn(
    sim: &mut YarnSim,
    duration: f64,
    opts: &RecordOptions,
) -> Result<RecordOutcome, CliError> {
    let schedule = crate::run::yarn_schedule(sim, duration)?;
    sim.reset_dt_stats();
    let name = sim.scene().name.clone();
    let layout = yarn_blueprint(sim.scene().grid.size, duration);
    let rec = open(&name, &layout, &opts.sink)?;
    log_yarn_static(&rec, sim).map_err(|e| opts.sink.error(e))?;
    let mut out = record_frames(rec, sim, &schedule, &name, opts, log_yarn_frame)?;
    let stats = sim.dt_stats();
    out.adaptive_dt = (sim.is_auto() && stats.substeps > 0).then(|| crate::run::dt_range(&stats));
    Ok(out)
}

/// Mean stretch of the segments around every vertex.
pub fn vertex_stretches(sim: &YarnSim, seg: &[f64]) -> Vec<f64> {
    let p = sim.particles();
    let none = yarnsim::mpm::machinery::particles::NONE;
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
    log_series(rec, &paths::SERIES)?;
    log_scale(rec, sc.grid.size)?;
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

/// The scale of the scene view: ticks and labels in m outside the domain,
/// faint grid lines inside it, drawn behind everything else.
fn log_scale(rec: &RecordingStream, size: f64) -> rerun::RecordingStreamResult<()> {
    let s = scale(size);
    let thin = 0.0015 * size as f32;
    rec.log_static(
        paths::SCALE_TICKS,
        &LineStrips2D::new(s.ticks)
            .with_radii([thin])
            .with_colors([Color::from_rgb(170, 170, 170)]),
    )?;
    rec.log_static(
        paths::SCALE_LABELS,
        &Points2D::new(s.labels.iter().map(|(p, _)| *p))
            .with_radii([0.0])
            .with_colors([Color::from_rgb(200, 200, 200)])
            .with_labels(s.labels.iter().map(|(_, t)| t.clone()))
            .with_show_labels(true),
    )?;
    rec.log_static(
        paths::SCALE_GRID,
        &LineStrips2D::new(s.grid)
            .with_radii([0.5 * thin])
            .with_colors([Color::from_rgb(55, 55, 55)])
            .with_draw_order(0.0),
    )?;
    Ok(())
}

/// Everything that changes, at frame `frame.frame`.
fn log_yarn_frame(
    rec: &RecordingStream,
    sim: &YarnSim,
    frame: FrameInfo,
) -> rerun::RecordingStreamResult<()> {
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
        state.push(energy.plastic_state(r.r12, r.r22));
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
    let mut scalars = energy_scalars!(&d, paths::POTENTIAL, potential_energy).to_vec();
    scalars.extend([
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
    ]);
    log_scalars(rec, &scalars, &frame)
}
