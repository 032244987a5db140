//! SVG plots drawn with `plotters` (its SVG backend): log-log line plots
//! (work-precision, stability maps) and horizontal bar charts, as plain SVG
//! 1.1 that any browser opens. A logarithmic axis is drawn over the
//! decimal logarithm of the data, its ticks labelled `1eN`.

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

/// One line of a [`LinePlot`].
#[derive(Clone, Debug, Default)]
pub struct Series {
    pub name: String,
    /// `(x, y)` points, drawn in the given order; non-finite or non-positive
    /// values (on a log axis) are skipped.
    pub points: Vec<(f64, f64)>,
    /// Draw hollow markers only, no connecting line (e.g. theoretical
    /// bounds next to measured lines).
    pub markers_only: bool,
    /// Palette index; `None` takes the series' position in the plot.
    pub color: Option<usize>,
    /// Dashed line (to tell apart two series of the same colour).
    pub dashed: bool,
    /// Marker shape of the points (filled circle by default).
    pub marker: Marker,
}

/// Marker shape of a [`Series`]' points.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Marker {
    #[default]
    Circle,
    Square,
}

/// A line plot with optional logarithmic axes.
#[derive(Clone, Debug, Default)]
pub struct LinePlot {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub log_x: bool,
    pub log_y: bool,
    pub series: Vec<Series>,
}

/// Colours of successive series.
const PALETTE: [&str; 10] = [
    "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf",
    "#7f7f7f", "#bcbd22",
];

const W: u32 = 880;
const H: u32 = 480;
/// Width of the legend to the right of the plot.
const RIGHT: u32 = 300;
/// Font sizes as plotters takes them (its SVG backend writes `size / 1.24`
/// px): 15 px titles, 12 px labels.
const TITLE: f64 = 15.0 * 1.24;
const LABEL: f64 = 12.0 * 1.24;

/// One axis: linear, or the decimal logarithm of the data.
struct Axis {
    log: bool,
    lo: f64,
    hi: f64,
}

impl Axis {
    fn new(log: bool, vals: impl Iterator<Item = f64>) -> Option<Axis> {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for v in vals {
            let v = if log { v.log10() } else { v };
            lo = lo.min(v);
            hi = hi.max(v);
        }
        if !(lo.is_finite() && hi.is_finite()) {
            return None;
        }
        if log {
            lo = lo.floor();
            hi = hi.ceil();
            if hi <= lo {
                hi = lo + 1.0;
            }
        } else {
            if hi <= lo {
                lo -= 0.5;
                hi += 0.5;
            }
            let pad = 0.05 * (hi - lo);
            lo -= pad;
            hi += pad;
        }
        Some(Axis { log, lo, hi })
    }
    /// The plotted coordinate of a data value.
    fn at(&self, v: f64) -> f64 {
        if self.log {
            v.log10()
        } else {
            v
        }
    }
    /// How many tick labels: one per decade (at most 11) on a log axis.
    fn labels(&self) -> usize {
        if self.log {
            ((self.hi - self.lo) as usize + 1).min(11)
        } else {
            6
        }
    }
    fn label(&self, v: f64) -> String {
        if self.log {
            format!("1e{}", v.round() as i64)
        } else {
            format!("{v:.3}")
        }
    }
}

fn usable(log: bool, v: f64) -> bool {
    v.is_finite() && (!log || v > 0.0)
}

fn color(i: usize) -> RGBColor {
    let hex = PALETTE[i % PALETTE.len()];
    let c = |k: usize| u8::from_str_radix(&hex[k..k + 2], 16).unwrap_or(0);
    RGBColor(c(1), c(3), c(5))
}

/// Draws the markers of a series at `points` of `area`'s coordinates: a
/// filled circle (r 3) or square (7 px), or, for markers-only series, a
/// ring (r 5) or hollow square (9 px).
fn draw_markers<DB: DrawingBackend, CT: CoordTranslate>(
    area: &DrawingArea<DB, CT>,
    points: &[CT::From],
    s: &Series,
    c: RGBColor,
) -> Result<(), String>
where
    CT::From: Clone,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    for q in points {
        let at = EmptyElement::at(q.clone());
        match (s.markers_only, s.marker) {
            (true, Marker::Circle) => area.draw(&(at + Circle::new((0, 0), 5, c.stroke_width(2)))),
            (false, Marker::Circle) => area.draw(&(at + Circle::new((0, 0), 3, c.filled()))),
            (true, Marker::Square) => {
                area.draw(&(at + Rectangle::new([(-4, -4), (5, 5)], c.stroke_width(2))))
            }
            (false, Marker::Square) => {
                area.draw(&(at + Rectangle::new([(-3, -3), (4, 4)], c.filled())))
            }
        }
        .map_err(err)?;
    }
    Ok(())
}

impl LinePlot {
    /// The plot as an SVG document.
    pub fn to_svg(&self) -> String {
        let mut out = String::new();
        {
            let root = SVGBackend::with_string(&mut out, (W, H)).into_drawing_area();
            // Writing into a String does not fail.
            let _ = self.draw(root);
        }
        out
    }

    fn draw(&self, root: DrawingArea<SVGBackend<'_>, Shift>) -> Result<(), String> {
        let err = |e: DrawingAreaErrorKind<_>| e.to_string();
        root.fill(&WHITE).map_err(err)?;
        let pts = |s: &Series| -> Vec<(f64, f64)> {
            s.points
                .iter()
                .copied()
                .filter(|&(x, y)| usable(self.log_x, x) && usable(self.log_y, y))
                .collect()
        };
        let all: Vec<(f64, f64)> = self.series.iter().flat_map(pts).collect();
        let (Some(ax), Some(ay)) = (
            Axis::new(self.log_x, all.iter().map(|p| p.0)),
            Axis::new(self.log_y, all.iter().map(|p| p.1)),
        ) else {
            root.draw(&Text::new(
                "no finite data",
                (W as i32 / 2, H as i32 / 2),
                ("sans-serif", LABEL).into_font().color(&BLACK),
            ))
            .map_err(err)?;
            return root.present().map_err(err);
        };
        let (plot_area, legend) = root.split_horizontally(W - RIGHT);
        let mut chart = ChartBuilder::on(&plot_area)
            .caption(&self.title, ("sans-serif", TITLE))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(ax.lo..ax.hi, ay.lo..ay.hi)
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .label_style(("sans-serif", LABEL))
            .axis_desc_style(("sans-serif", LABEL))
            .x_desc(&self.x_label)
            .y_desc(&self.y_label)
            .x_labels(ax.labels())
            .y_labels(ay.labels())
            .x_label_formatter(&|v| ax.label(*v))
            .y_label_formatter(&|v| ay.label(*v))
            .max_light_lines(0)
            .bold_line_style(RGBColor(0xdd, 0xdd, 0xdd))
            .draw()
            .map_err(|e| e.to_string())?;
        for (i, s) in self.series.iter().enumerate() {
            let c = color(s.color.unwrap_or(i));
            let p: Vec<(f64, f64)> = pts(s)
                .into_iter()
                .map(|(x, y)| (ax.at(x), ay.at(y)))
                .collect();
            if p.len() > 1 && !s.markers_only {
                let r = if s.dashed {
                    chart.draw_series(DashedLineSeries::new(
                        p.iter().copied(),
                        6,
                        4,
                        c.stroke_width(2),
                    ))
                } else {
                    chart.draw_series(LineSeries::new(p.iter().copied(), c.stroke_width(2)))
                };
                r.map_err(|e| e.to_string())?;
            }
            draw_markers(chart.plotting_area(), &p, s, c)?;
            // The legend key: the line (dashed as the series), with the
            // marker where it is not the plain circle, or the marker alone.
            let (lx, ly) = (12, 54 + 18 * i as i32);
            if !s.markers_only {
                let key = [(lx, ly), (lx + 20, ly)];
                let style = c.stroke_width(3);
                if s.dashed {
                    legend
                        .draw(&DashedPathElement::new(key, 6, 4, style))
                        .map_err(err)?;
                } else {
                    legend.draw(&PathElement::new(key, style)).map_err(err)?;
                }
            }
            if s.markers_only || s.marker != Marker::Circle {
                draw_markers(&legend, &[(lx + 10, ly)], s, c)?;
            }
            legend
                .draw(&Text::new(
                    s.name.as_str(),
                    (lx + 26, ly - 6),
                    ("sans-serif", LABEL).into_font().color(&BLACK),
                ))
                .map_err(err)?;
        }
        root.present().map_err(err)
    }
}

/// A horizontal bar chart (one bar per label, top down, its value written
/// after it).
pub fn bar_chart(title: &str, x_label: &str, bars: &[(String, f64)]) -> String {
    let (width, height) = (760u32, 90 + 22 * bars.len() as u32);
    let max = bars
        .iter()
        .map(|b| b.1)
        .filter(|v| v.is_finite())
        .fold(0.0f64, f64::max)
        .max(1e-300);
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, (width, height)).into_drawing_area();
        // Writing into a String does not fail.
        let _ = draw_bars(&root, title, x_label, bars, max);
    }
    out
}

fn draw_bars(
    root: &DrawingArea<SVGBackend<'_>, Shift>,
    title: &str,
    x_label: &str,
    bars: &[(String, f64)],
    max: f64,
) -> Result<(), String> {
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let n = bars.len();
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", TITLE))
        .margin(10)
        .margin_right(90)
        .x_label_area_size(30)
        .y_label_area_size(250)
        .build_cartesian_2d(0.0..max, (0..n).into_segmented())
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .disable_mesh()
        .label_style(("sans-serif", LABEL))
        .axis_desc_style(("sans-serif", LABEL))
        .x_desc(x_label)
        .y_labels(n.max(1))
        .y_label_formatter(&|v| match v {
            SegmentValue::CenterOf(r) if *r < n => bars[n - 1 - r].0.clone(),
            _ => String::new(),
        })
        .draw()
        .map_err(|e| e.to_string())?;
    let fill = color(0).filled();
    // The first bar on top: bar `i` in row `n - 1 - i` (rows count upwards).
    let row = |i: usize| n - 1 - i;
    let width = |v: f64| if v.is_finite() { v } else { 0.0 };
    chart
        .draw_series(bars.iter().enumerate().map(|(i, (_, v))| {
            let mut r = Rectangle::new(
                [
                    (0.0, SegmentValue::Exact(row(i))),
                    (width(*v), SegmentValue::Exact(row(i) + 1)),
                ],
                fill,
            );
            r.set_margin(2, 2, 0, 0);
            r
        }))
        .map_err(|e| e.to_string())?;
    chart
        .draw_series(bars.iter().enumerate().map(|(i, (_, v))| {
            Text::new(
                format!("{v:.4}"),
                (width(*v), SegmentValue::CenterOf(row(i))),
                ("sans-serif", LABEL).into_font().color(&BLACK),
            )
        }))
        .map_err(|e| e.to_string())?;
    root.present().map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plot(series: Vec<Series>) -> String {
        LinePlot {
            title: "t <&>".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            log_x: true,
            log_y: true,
            series,
        }
        .to_svg()
    }

    #[test]
    fn line_plot_draws_lines_rings_and_dashes_as_asked() {
        let svg = plot(vec![
            Series {
                name: "measured".into(),
                points: vec![(1.0, 1e-3), (10.0, 1e-4), (100.0, 1e-5)],
                ..Series::default()
            },
            Series {
                name: "dashed twin".into(),
                points: vec![(1.0, 2e-3), (10.0, 2e-4)],
                color: Some(0),
                dashed: true,
                ..Series::default()
            },
            Series {
                name: "bound".into(),
                // the non-positive and non-finite points are skipped on log axes
                points: vec![(1.0, 5e-3), (10.0, 0.0), (f64::NAN, 1.0)],
                markers_only: true,
                ..Series::default()
            },
        ]);
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        // plotters writes colours in upper case
        let (c0, c2) = (PALETTE[0].to_uppercase(), PALETTE[2].to_uppercase());
        let lines = |color: &str, width: u32| {
            let key = format!(
                r#"<polyline fill="none" opacity="1" stroke="{color}" stroke-width="{width}""#
            );
            svg.matches(&key).count()
        };
        assert_eq!(
            lines(&c2, 2) + lines(&c2, 3),
            0,
            "markers-only series has no line"
        );
        // the solid line is one polyline through its 3 points; the dashed
        // twin's line is drawn as dashes (many short polylines), and so is
        // its legend key (2 dashes of 6 px over 20 px beside the solid key)
        let solid = svg
            .lines()
            .filter(|l| l.contains(&format!(r#"stroke="{c0}" stroke-width="2""#)))
            .filter(|l| l.matches(',').count() == 3)
            .count();
        assert_eq!(solid, 1);
        assert!(lines(&c0, 2) > 1 + 10, "{}", lines(&c0, 2));
        assert_eq!(lines(&c0, 3), 1 + 2, "solid legend key and the dashed one");
        // 3 + 2 filled markers, 1 ring in the plot and 1 in the legend
        assert_eq!(svg.matches(r#"r="3""#).count(), 5);
        assert_eq!(svg.matches(r#"r="5""#).count(), 2);
        // the twin takes palette colour 0 like the first series
        assert_eq!(svg.matches(&format!(r#"fill="{c0}""#)).count(), 3 + 2);
        assert_eq!(svg.matches(&format!(r#"stroke="{c2}""#)).count(), 2);
        assert!(svg.contains("t &lt;&amp;&gt;"));
        assert!(!svg.contains("NaN") && !svg.contains("inf"));
        // the decades of both log axes are labelled
        for tick in ["1e0", "1e1", "1e2", "1e-5", "1e-4", "1e-3", "1e-2"] {
            assert!(svg.contains(&format!("\n{tick}\n")), "{tick}");
        }
    }

    #[test]
    fn square_markers_in_plot_and_legend() {
        let svg = plot(vec![Series {
            name: "squares".into(),
            points: vec![(1.0, 1e-3), (10.0, 1e-4)],
            marker: Marker::Square,
            ..Series::default()
        }]);
        // 2 filled squares in the plot, 1 in the legend
        let fill = format!(r#"fill="{}""#, PALETTE[0].to_uppercase());
        let squares = svg
            .lines()
            .filter(|l| l.starts_with("<rect") && l.contains(r#"width="7" height="7""#))
            .filter(|l| l.contains(&fill))
            .count();
        assert_eq!(squares, 3);
        assert_eq!(svg.matches("<circle").count(), 0);
    }

    #[test]
    fn line_plot_without_finite_data_says_so() {
        let svg = plot(vec![Series {
            name: "empty".into(),
            points: vec![(0.0, 1.0), (f64::INFINITY, 2.0)],
            ..Series::default()
        }]);
        assert!(svg.contains("no finite data"));
    }

    #[test]
    fn bar_chart_draws_one_bar_per_label_top_down() {
        let svg = bar_chart(
            "bars <&>",
            "seconds",
            &[
                ("a".into(), 1.0),
                ("b & c".into(), 0.25),
                ("nan".into(), f64::NAN),
            ],
        );
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        let fill = format!(r#"fill="{}""#, PALETTE[0].to_uppercase());
        // (y, width) of each bar, in drawing order
        let bars: Vec<(f64, f64)> = svg
            .lines()
            .filter(|l| l.starts_with("<rect") && l.contains(&fill))
            .map(|l| {
                let attr = |name: &str| -> f64 {
                    let v = l.split(&format!(r#" {name}=""#)).nth(1).unwrap();
                    v[..v.find('"').unwrap()].parse().unwrap()
                };
                (attr("y"), attr("width"))
            })
            .collect();
        assert_eq!(bars.len(), 3);
        // the first label on top, widths in proportion, the NaN bar empty
        assert!(bars[0].0 < bars[1].0 && bars[1].0 < bars[2].0, "{bars:?}");
        assert!((bars[1].1 / bars[0].1 - 0.25).abs() < 0.01, "{bars:?}");
        assert_eq!(bars[2].1, 0.0);
        for text in [
            "bars &lt;&amp;&gt;",
            "seconds",
            "\nb &amp; c\n",
            "1.0000",
            "0.2500",
            "NaN",
        ] {
            assert!(svg.contains(text), "{text}");
        }
    }
}
