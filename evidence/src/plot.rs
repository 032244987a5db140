//! Hand-written SVG plots: log-log line plots (work-precision, stability
//! maps) and horizontal bar charts. No plotting crate needed; the output is
//! plain SVG 1.1 that any browser opens.

use std::fmt::Write;

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

const W: f64 = 880.0;
const H: f64 = 480.0;
const LEFT: f64 = 80.0;
const RIGHT: f64 = 300.0;
const TOP: f64 = 40.0;
const BOTTOM: f64 = 60.0;

/// Escapes text for SVG.
pub fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

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
    fn frac(&self, v: f64) -> f64 {
        let v = if self.log { v.log10() } else { v };
        (v - self.lo) / (self.hi - self.lo)
    }
    fn ticks(&self) -> Vec<(f64, String)> {
        if self.log {
            let step = ((self.hi - self.lo) / 10.0).ceil().max(1.0) as i64;
            (self.lo as i64..=self.hi as i64)
                .step_by(step as usize)
                .map(|e| (10f64.powi(e as i32), format!("1e{e}")))
                .collect()
        } else {
            (0..=5)
                .map(|i| {
                    let v = self.lo + (self.hi - self.lo) * i as f64 / 5.0;
                    (v, format!("{v:.3}"))
                })
                .collect()
        }
    }
}

fn usable(log: bool, v: f64) -> bool {
    v.is_finite() && (!log || v > 0.0)
}

impl LinePlot {
    /// The plot as an SVG document.
    pub fn to_svg(&self) -> String {
        let pts = |s: &Series| -> Vec<(f64, f64)> {
            s.points
                .iter()
                .copied()
                .filter(|&(x, y)| usable(self.log_x, x) && usable(self.log_y, y))
                .collect()
        };
        let all: Vec<(f64, f64)> = self.series.iter().flat_map(pts).collect();
        let mut out = String::new();
        let _ = writeln!(
            out,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" viewBox="0 0 {W} {H}" font-family="sans-serif" font-size="12">"#
        );
        let _ = writeln!(out, r#"<rect width="{W}" height="{H}" fill="white"/>"#);
        let _ = writeln!(
            out,
            r#"<text x="{}" y="22" text-anchor="middle" font-size="15">{}</text>"#,
            (LEFT + W - RIGHT) / 2.0,
            esc(&self.title)
        );
        let pw = W - LEFT - RIGHT;
        let ph = H - TOP - BOTTOM;
        let (Some(ax), Some(ay)) = (
            Axis::new(self.log_x, all.iter().map(|p| p.0)),
            Axis::new(self.log_y, all.iter().map(|p| p.1)),
        ) else {
            let _ = writeln!(
                out,
                r#"<text x="{}" y="{}" text-anchor="middle">no finite data</text></svg>"#,
                W / 2.0,
                H / 2.0
            );
            return out;
        };
        let px = |x: f64| LEFT + ax.frac(x) * pw;
        let py = |y: f64| TOP + (1.0 - ay.frac(y)) * ph;
        // Grid and ticks.
        for (v, label) in ax.ticks() {
            let x = px(v);
            let _ = writeln!(
                out,
                r##"<line x1="{x:.1}" y1="{TOP}" x2="{x:.1}" y2="{:.1}" stroke="#ddd"/><text x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"##,
                TOP + ph,
                TOP + ph + 16.0,
                esc(&label)
            );
        }
        for (v, label) in ay.ticks() {
            let y = py(v);
            let _ = writeln!(
                out,
                r##"<line x1="{LEFT}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#ddd"/><text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"##,
                LEFT + pw,
                LEFT - 6.0,
                y + 4.0,
                esc(&label)
            );
        }
        let _ = writeln!(
            out,
            r#"<rect x="{LEFT}" y="{TOP}" width="{pw}" height="{ph}" fill="none" stroke="black"/>"#
        );
        let _ = writeln!(
            out,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
            LEFT + pw / 2.0,
            H - 18.0,
            esc(&self.x_label)
        );
        let _ = writeln!(
            out,
            r#"<text x="18" y="{:.1}" text-anchor="middle" transform="rotate(-90 18 {:.1})">{}</text>"#,
            TOP + ph / 2.0,
            TOP + ph / 2.0,
            esc(&self.y_label)
        );
        // Series.
        for (i, s) in self.series.iter().enumerate() {
            let c = PALETTE[s.color.unwrap_or(i) % PALETTE.len()];
            let dash = if s.dashed {
                r#" stroke-dasharray="6 4""#
            } else {
                ""
            };
            let p = pts(s);
            if p.len() > 1 && !s.markers_only {
                let coords: Vec<String> = p
                    .iter()
                    .map(|&(x, y)| format!("{:.1},{:.1}", px(x), py(y)))
                    .collect();
                let _ = writeln!(
                    out,
                    r#"<polyline class="series" points="{}" fill="none" stroke="{c}" stroke-width="2"{dash}/>"#,
                    coords.join(" ")
                );
            }
            let marker = |x: f64, y: f64| match (s.markers_only, s.marker) {
                (true, Marker::Circle) => format!(
                    r#"<circle cx="{x:.1}" cy="{y:.1}" r="5" fill="none" stroke="{c}" stroke-width="2"/>"#
                ),
                (false, Marker::Circle) => {
                    format!(r#"<circle cx="{x:.1}" cy="{y:.1}" r="3" fill="{c}"/>"#)
                }
                (true, Marker::Square) => format!(
                    r#"<rect x="{:.1}" y="{:.1}" width="9" height="9" fill="none" stroke="{c}" stroke-width="2"/>"#,
                    x - 4.5,
                    y - 4.5
                ),
                (false, Marker::Square) => format!(
                    r#"<rect class="marker" x="{:.1}" y="{:.1}" width="7" height="7" fill="{c}"/>"#,
                    x - 3.5,
                    y - 3.5
                ),
            };
            for &(x, y) in &p {
                let _ = writeln!(out, "{}", marker(px(x), py(y)));
            }
            let ly = TOP + 14.0 + 18.0 * i as f64;
            let lx = LEFT + pw + 12.0;
            let key = if s.markers_only {
                marker(lx + 10.0, ly)
            } else {
                let mut k = format!(
                    r#"<line x1="{lx}" y1="{ly}" x2="{}" y2="{ly}" stroke="{c}" stroke-width="3"{dash}/>"#,
                    lx + 20.0
                );
                if s.marker != Marker::Circle {
                    k.push_str(&marker(lx + 10.0, ly));
                }
                k
            };
            let _ = writeln!(
                out,
                r#"{key}<text x="{}" y="{}">{}</text>"#,
                lx + 26.0,
                ly + 4.0,
                esc(&s.name)
            );
        }
        out.push_str("</svg>\n");
        out
    }
}

/// A horizontal bar chart (one bar per label).
pub fn bar_chart(title: &str, x_label: &str, bars: &[(String, f64)]) -> String {
    let bh = 22.0;
    let left = 260.0;
    let width = 760.0;
    let height = 70.0 + bh * bars.len() as f64;
    let max = bars
        .iter()
        .map(|b| b.1)
        .filter(|v| v.is_finite())
        .fold(0.0f64, f64::max)
        .max(1e-300);
    let pw = width - left - 90.0;
    let mut out = String::new();
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" viewBox="0 0 {width} {height}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(
        out,
        r#"<rect width="{width}" height="{height}" fill="white"/><text x="{}" y="22" text-anchor="middle" font-size="15">{}</text>"#,
        width / 2.0,
        esc(title)
    );
    for (i, (label, v)) in bars.iter().enumerate() {
        let y = 40.0 + bh * i as f64;
        let w = if v.is_finite() { pw * v / max } else { 0.0 };
        let _ = writeln!(
            out,
            r##"<text x="{:.1}" y="{:.1}" text-anchor="end">{}</text><rect class="bar" x="{left}" y="{y:.1}" width="{w:.1}" height="{:.1}" fill="#1f77b4"/><text x="{:.1}" y="{:.1}">{v:.4}</text>"##,
            left - 6.0,
            y + 15.0,
            esc(label),
            bh - 4.0,
            left + w + 4.0,
            y + 15.0
        );
    }
    let _ = writeln!(
        out,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text></svg>"#,
        left + pw / 2.0,
        height - 8.0,
        esc(x_label)
    );
    out
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
        assert_eq!(
            svg.matches("<polyline").count(),
            2,
            "markers-only series has no line"
        );
        assert_eq!(
            svg.matches("stroke-dasharray").count(),
            2,
            "dashed line and its legend key"
        );
        // 3 + 2 filled markers, 1 ring in the plot and 1 in the legend
        assert_eq!(svg.matches(r#"r="3""#).count(), 5);
        assert_eq!(svg.matches(r#"r="5""#).count(), 2);
        // the twin takes palette colour 0 like the first series
        assert_eq!(svg.matches(PALETTE[0]).count(), 3 + 2 + 2 + 2);
        assert!(svg.contains("t &lt;&amp;&gt;"));
        assert!(!svg.contains("NaN") && !svg.contains("inf"));
    }

    #[test]
    fn square_markers_in_plot_and_legend() {
        let svg = plot(vec![Series {
            name: "squares".into(),
            points: vec![(1.0, 1e-3), (10.0, 1e-4)],
            marker: Marker::Square,
            ..Series::default()
        }]);
        assert_eq!(svg.matches(r#"class="marker""#).count(), 3);
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
}
