//! The viewer layout of a recording, decoded from the `.rrd`: every plotted
//! series has a name and is named in its plot's title, the plots' legends
//! are off (they covered the data), the time axes span the whole run, and
//! the 2D scene view has a scale and starts framed on the domain.

use std::collections::BTreeMap;
use std::path::Path;

use rerun::blueprint::components::{TimeRange, ViewClass, ViewOrigin, VisualBounds2D};
use rerun::components::{Name, Position2D, Scalar, Text, Visible};
use rerun::datatypes::{TimeInt, TimeRangeBoundary};
use rerun::log::Chunk;
use rerun::StoreKind;

mod common;

use common::rrd::{all_values, decode_store};
use common::{fresh_tmp, record_ok, small_scene, yarnsim_ok};

/// One view of the blueprint.
#[derive(Debug)]
struct ViewInfo {
    class: String,
    name: String,
    origin: String,
    /// `view/<id>/<property>` chunks by property name.
    properties: BTreeMap<String, Vec<Chunk>>,
}

/// Every view of the recording's blueprint.
fn views(rrd: &Path) -> Vec<ViewInfo> {
    let bp = decode_store(rrd, StoreKind::Blueprint);
    let mut out = Vec::new();
    for (path, chunks) in &bp {
        let parts: Vec<&str> = path.split('/').collect();
        if parts.len() != 2 || parts[0] != "view" {
            continue;
        }
        let one = |what: Vec<String>| what.into_iter().next().unwrap_or_default();
        let properties = bp
            .iter()
            .filter_map(|(p, c)| {
                p.strip_prefix(&format!("{path}/"))
                    .map(|name| (name.to_string(), c.clone()))
            })
            .collect();
        out.push(ViewInfo {
            class: one(all_values::<ViewClass>(chunks)
                .iter()
                .map(|c| c.0.to_string())
                .collect()),
            name: one(all_values::<Name>(chunks)
                .iter()
                .map(|n| n.as_str().to_string())
                .collect()),
            origin: one(all_values::<ViewOrigin>(chunks)
                .iter()
                .map(|o| o.0.to_string())
                .collect()),
            properties,
        });
    }
    out
}

/// Entities holding plotted scalars (`Scalars` under `plots/` and
/// `timing/`; per-particle values under `world/` are not plotted), with
/// their series names.
fn series(rrd: &Path) -> BTreeMap<String, Vec<String>> {
    decode_store(rrd, StoreKind::Recording)
        .into_iter()
        .filter(|(path, chunks)| {
            !all_values::<Scalar>(chunks).is_empty() && !path.starts_with("world/")
        })
        .map(|(path, chunks)| {
            let names = all_values::<Name>(&chunks)
                .iter()
                .map(|n| n.as_str().to_string())
                .collect();
            (path, names)
        })
        .collect()
}

/// Checks the plots of a recording of `duration` s: every scalar entity
/// is named, shown by exactly one plot whose title names it (when the plot
/// draws several), legends off, time axis `[0, duration]`.
fn check_plots(rrd: &Path, duration: f64) -> Vec<ViewInfo> {
    let views = views(rrd);
    let plots: Vec<&ViewInfo> = views.iter().filter(|v| v.class == "TimeSeries").collect();
    assert!(plots.len() >= 6, "{views:?}");
    let series = series(rrd);
    assert!(series.len() >= 8, "{series:?}");
    for (path, names) in &series {
        assert_eq!(names.len(), 1, "{path}: series names {names:?}");
        assert!(!names[0].is_empty(), "{path}: empty series name");
        let shown_by: Vec<&&ViewInfo> = plots
            .iter()
            .filter(|v| {
                let o = v.origin.trim_start_matches('/');
                path == o || path.starts_with(&format!("{o}/"))
            })
            .collect();
        assert_eq!(shown_by.len(), 1, "{path} is in {shown_by:?}");
        let plot = shown_by[0];
        let origin = plot.origin.trim_start_matches('/');
        let siblings = series
            .keys()
            .filter(|p| p.strip_prefix(&format!("{origin}/")).is_some())
            .count();
        if siblings > 1 {
            let short = path.rsplit('/').next().unwrap();
            assert!(
                plot.name.contains(&format!("{short} ")),
                "plot {:?} does not name {path}",
                plot.name
            );
        }
    }
    // The energy plot names all four energies, the total too.
    let energy = plots
        .iter()
        .find(|v| v.origin.ends_with("plots/energy"))
        .expect("an energy plot");
    assert!(energy.name.contains("total pink"), "{}", energy.name);
    // The axis ends a little after the run (3 %), not before it.
    let end = TimeInt(yarnsim_cli::record::time_axis_end(duration));
    assert!(end.0 as f64 >= duration * 1e9 && end.0 as f64 <= duration * 1.05e9);
    for plot in &plots {
        let legend = &plot.properties["PlotLegend"];
        let visible: Vec<bool> = all_values::<Visible>(legend)
            .iter()
            .map(|v| v.0 .0)
            .collect();
        // Off, as designed: the titles name the series instead.
        assert_eq!(visible, vec![false], "{}", plot.name);
        let range = all_values::<TimeRange>(&plot.properties["TimeAxis"]);
        assert_eq!(range.len(), 1, "{}", plot.name);
        assert_eq!(range[0].0.start, TimeRangeBoundary::Absolute(TimeInt(0)));
        assert_eq!(range[0].0.end, TimeRangeBoundary::Absolute(end));
    }
    views
}

#[test]
fn yarn_plots_are_named_legend_free_and_span_the_run() {
    let rrd = fresh_tmp("blueprint-yarn.rrd");
    record_ok(&small_scene(), "2ms", &rrd);
    let views = check_plots(&rrd, 0.002);

    // The scene view starts on the domain [0, 1]^2 with its scale around it.
    let scene = views.iter().find(|v| v.class == "2D").expect("a 2D view");
    let bounds = all_values::<VisualBounds2D>(&scene.properties["VisualBounds2D"]);
    let b = bounds[0].0;
    let data = decode_store(&rrd, StoreKind::Recording);
    let labels = all_values::<Text>(&data["world/scale/labels"]);
    let texts: Vec<&str> = labels.iter().map(|t| t.as_str()).collect();
    for want in ["0", "0.2", "0.4", "0.6", "0.8", "1", "x [m]", "y [m]"] {
        assert!(texts.contains(&want), "{want} missing in {texts:?}");
    }
    let inside = |p: [f32; 2]| {
        (b.x_range.0[0] as f32..=b.x_range.0[1] as f32).contains(&p[0])
            && (b.y_range.0[0] as f32..=b.y_range.0[1] as f32).contains(&p[1])
    };
    for p in all_values::<Position2D>(&data["world/scale/labels"]) {
        assert!(inside(p.0 .0), "label at {:?} outside {b:?}", p.0 .0);
    }
    for corner in [[0.0, 0.0], [1.0, 1.0]] {
        assert!(inside(corner), "{corner:?} outside {b:?}");
    }
    assert!(!all_values::<rerun::components::LineStrip2D>(&data["world/scale/ticks"]).is_empty());
}

#[test]
fn mass_spring_plots_are_named_legend_free_and_span_the_run() {
    let rrd = fresh_tmp("blueprint-wire.rrd");
    yarnsim_ok(&["record", "wire", "-d", "0.1", "-o", rrd.to_str().unwrap()]);
    let views = check_plots(&rrd, 0.1);
    let angular = views
        .iter()
        .find(|v| v.origin.ends_with("plots/angular_momentum"))
        .unwrap();
    assert_eq!(
        angular.name,
        "angular momentum [kg m^2/s]: x blue, y orange, z green"
    );
}
