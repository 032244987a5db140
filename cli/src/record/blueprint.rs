//! The viewer layout a recording opens with (Rerun blueprint, written by
//! [`super::layout`]): the scene and the colour scales on the left, one
//! plot per unit on the right.
//!
//! The plots' own legends are switched off: in plots a sixth of the window
//! high they covered a third of the data and cut off their last entries.
//! Each plot's title names its series with their colours instead
//! (`energy [J]: kinetic blue, elastic orange, ...`); hovering a curve shows
//! its full name. The time axis spans the whole run, `[0, duration]`, and a
//! little more (the viewer's default, the recording's extent, puts the last
//! point on the edge); it is a range of `sim_time`, the timeline the layout
//! selects, in ns (on the `frame` timeline it would span that many frames).

use rerun::blueprint::components::{Corner2D, PanelState, PlayState};
use rerun::datatypes::{Range2D, TimeInt, TimeRange, TimeRangeBoundary};
use rerun::external::re_sdk_types::blueprint::archetypes::{PlotLegend, TimeAxis, VisualBounds2D};

use super::layout::{Container, Layout, Node, View};
use super::style::series_color_name;
use super::{paths, TIMELINE_SIM_TIME};

/// Where the legend of a plot would sit if shown (it is not: see the module
/// documentation); stated so that a user who switches it on in the
/// selection panel gets it in a corner.
pub const LEGEND_CORNER: Corner2D = Corner2D::LeftTop;

/// Whether the plots show their legends.
pub const LEGEND_VISIBLE: bool = false;

/// The title of the plot of the series under `origin`: `name`, then, when
/// it draws several series, each one's last path segment and colour.
pub fn plot_title(name: &str, origin: &str, series: &[(&str, &str)]) -> String {
    let origin = origin.trim_start_matches('/');
    let mine: Vec<&str> = series
        .iter()
        .map(|(p, _)| *p)
        .filter(|p| {
            p.rsplit_once('/')
                .is_some_and(|(parent, _)| parent == origin)
        })
        .collect();
    if mine.len() < 2 {
        return name.to_string();
    }
    let key: Vec<String> = mine
        .iter()
        .map(|p| {
            let short = p.rsplit('/').next().unwrap_or(p);
            format!("{short} {}", series_color_name(series, p))
        })
        .collect();
    format!("{name}: {}", key.join(", "))
}

/// The end of the plots' time axis for a run of `duration` s, in ns of
/// `sim_time`: 3 % past the run, so its last point is not on the edge.
pub fn time_axis_end(duration: f64) -> i64 {
    (duration * 1.03 * 1e9).ceil() as i64
}

/// A time-series view of the entities under `origin`, legend off, time axis
/// from 0 to [`time_axis_end`] of `sim_time`.
fn plot(name: &str, origin: &str, series: &[(&str, &str)], duration: f64) -> Node {
    let end_ns = time_axis_end(duration);
    View::new("TimeSeries", plot_title(name, origin, series), origin)
        .with_property(
            "PlotLegend",
            &PlotLegend::new()
                .with_visible(LEGEND_VISIBLE)
                .with_corner(LEGEND_CORNER),
        )
        .with_property(
            "TimeAxis",
            &TimeAxis::new().with_view_range(TimeRange {
                start: TimeRangeBoundary::Absolute(TimeInt(0)),
                end: TimeRangeBoundary::Absolute(TimeInt(end_ns)),
            }),
        )
        .into()
}

/// Blueprint and selection panels collapsed, so the scene gets the width;
/// the time panel collapsed to its play bar, on the `sim_time` timeline,
/// following the latest data: a finished recording opens at its last frame
/// with every plot drawn to its end (while playing, the plots end at the
/// time cursor); press play or drag the cursor to watch it run.
fn with_panels(root: Node) -> Layout {
    Layout {
        root,
        blueprint_panel: PanelState::Collapsed,
        selection_panel: PanelState::Collapsed,
        time_panel: PanelState::Collapsed,
        timeline: TIMELINE_SIM_TIME,
        play_state: PlayState::Following,
    }
}

/// The plots of a yarn recording: `(title, origin)`.
pub const YARN_PLOTS: [(&str, &str); 6] = [
    ("energy [J]", "/plots/energy"),
    ("momentum [kg m/s]", "/plots/momentum"),
    ("angular momentum [kg m^2/s]", "/plots/angular_momentum"),
    ("stretch l/l0", "/plots/stretch"),
    ("centre of mass [m]", "/plots/center_of_mass"),
    ("wall time per substep [s]", "/timing"),
];

/// The plots of a mass-spring recording: `(title, origin)`.
pub const MASS_SPRING_PLOTS: [(&str, &str); 7] = [
    ("energy [J]", "/plots/energy"),
    ("momentum [kg m/s]", "/plots/momentum"),
    ("angular momentum [kg m^2/s]", "/plots/angular_momentum"),
    ("strain |l/l0 - 1|", "/plots/strain"),
    ("centre of mass [m]", "/plots/center_of_mass"),
    ("CG iterations", "/plots/cg_iterations"),
    ("wall time per substep [s]", "/timing"),
];

/// The part of the 2D view shown at the start: the domain `[0, size]^2`
/// with room below and left of it for the scale's tick labels (see
/// [`super::yarn`]'s `world/scale`).
pub fn scene_bounds(size: f64) -> Range2D {
    let s = size;
    Range2D {
        x_range: [-0.14 * s, 1.03 * s].into(),
        y_range: [-0.03 * s, 1.13 * s].into(),
    }
}

/// The layout of a yarn recording of `duration` s in a domain of side
/// `size` m: the 2D scene above the colour scales on the left, one plot per
/// unit on the right.
pub fn yarn_blueprint(size: f64, duration: f64) -> Layout {
    let scene = View::new("2D", "scene", "/")
        .with_contents(&["/world/**"])
        .with_property("VisualBounds2D", &VisualBounds2D::new(scene_bounds(size)));
    two_columns(scene.into(), &YARN_PLOTS, &paths::SERIES, duration)
}

/// The layout of a mass-spring recording of `duration` s: the 3D scene and
/// the colour scales on the left, one plot per unit on the right.
pub fn massspring_blueprint(duration: f64) -> Layout {
    two_columns(
        View::new("3D", "scene", "/world").into(),
        &MASS_SPRING_PLOTS,
        &paths::MS_SERIES,
        duration,
    )
}

/// `scene` above the colour scales on the left (3/5 of the width), one
/// time-series view per `(title, origin)` on the right; the side panels
/// collapsed ([`with_panels`]).
fn two_columns(
    scene: Node,
    plots: &[(&str, &str)],
    series: &[(&str, &str)],
    duration: f64,
) -> Layout {
    let legend = View::new("TextDocument", "colours", format!("/{}", paths::LEGEND));
    with_panels(Container::horizontal(
        vec![
            Container::vertical(vec![scene, legend.into()], vec![6.0, 1.0]),
            Container::vertical(
                plots
                    .iter()
                    .map(|&(name, origin)| plot(name, origin, series, duration))
                    .collect(),
                Vec::new(),
            ),
        ],
        vec![3.0, 2.0],
    ))
}
