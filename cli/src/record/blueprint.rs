//! The viewer layout a recording opens with (Rerun blueprint).

use rerun::blueprint::components::PanelState;
use rerun::blueprint::{
    Blueprint, BlueprintPanel, ContainerLike, Horizontal, SelectionPanel, Spatial2DView,
    Spatial3DView, TextDocumentView, TimePanel, TimeSeriesView, Vertical,
};

use super::{paths, TIMELINE_SIM_TIME};

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
