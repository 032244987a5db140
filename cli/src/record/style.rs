//! How things look: the 2D view transform, colours, radii and the legend.

use rerun::components::Color;
use yarnsim::mpm::laws::constitutive::PlasticState;

/// Where a library point `v` is drawn in a domain of side `size`: Rerun's 2D
/// views draw +y downwards, so y is stored as `size - y` (+y shows up). The
/// recording carries no mirror transform: labels under one landed at
/// y-mirrored places.
pub fn view2(v: &yarnsim::math::Vec2, size: f64) -> [f32; 2] {
    [v.x as f32, (size - v.y) as f32]
}

pub(super) fn p2(v: &yarnsim::math::Vec2) -> [f32; 2] {
    [v.x as f32, v.y as f32]
}

pub(super) fn p3(v: &yarnsim::massspring::V3) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

/// Distinct colours for the series of one plot (Okabe-Ito palette, easy to
/// tell apart, also for colour-blind readers), with the words the plot
/// titles use for them.
pub const SERIES_COLORS: [([u8; 3], &str); 4] = [
    ([0, 114, 178], "blue"),
    ([213, 94, 0], "orange"),  // Okabe-Ito's vermillion
    ([0, 158, 115], "green"),  // bluish green
    ([204, 121, 167], "pink"), // reddish purple
];

/// The rank of the `path`'s series among the series of its plot (the
/// entities sharing its parent), in [`SERIES_COLORS`].
fn series_rank(series: &[(&str, &str)], path: &str) -> usize {
    let parent = |p: &str| p.rsplit_once('/').map_or("", |(a, _)| a).to_string();
    let rank = series
        .iter()
        .filter(|(p, _)| parent(p) == parent(path))
        .position(|(p, _)| *p == path)
        .unwrap_or(0);
    rank % SERIES_COLORS.len()
}

/// Colour of the `path`'s series ([`SERIES_COLORS`] by its rank in its plot).
pub fn series_color(series: &[(&str, &str)], path: &str) -> Color {
    let [r, g, b] = SERIES_COLORS[series_rank(series, path)].0;
    Color::from_rgb(r, g, b)
}

/// The word for the colour of the `path`'s series (`blue`, `orange`, ...).
pub fn series_color_name(series: &[(&str, &str)], path: &str) -> &'static str {
    SERIES_COLORS[series_rank(series, path)].1
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

/// The scale of the 2D scene view, in view coordinates (see [`view2`]):
/// tick marks below and left of the domain `[0, size]^2`, every `step / 2`
/// m, the labelled ones every `step` m (1, 2 or 5 times a power of ten, 5
/// to 10 of them per side), the labels' positions and texts, and the grid
/// lines across the domain at the labelled ticks.
pub struct Scale {
    pub step: f64,
    pub ticks: Vec<[[f32; 2]; 2]>,
    pub labels: Vec<([f32; 2], String)>,
    pub grid: Vec<[[f32; 2]; 2]>,
}

/// The [`Scale`] of a domain of side `size` m.
pub fn scale(size: f64) -> Scale {
    let raw = size / 5.0;
    let p = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * p)
        .find(|s| *s >= raw * (1.0 - 1e-9))
        .unwrap_or(10.0 * p);
    let (s, h) = (size as f32, size);
    let (major, minor) = (0.03 * s, 0.015 * s);
    let mut out = Scale {
        step,
        ticks: Vec::new(),
        labels: Vec::new(),
        grid: Vec::new(),
    };
    let n = (size / (step / 2.0) + 1e-9).floor() as usize;
    for k in 0..=n {
        let v = k as f64 * step / 2.0;
        let labelled = k % 2 == 0;
        let len = if labelled { major } else { minor };
        let x = v as f32;
        let y = (h - v) as f32; // library y = v, drawn at size - v
        out.ticks.push([[x, s], [x, s + len]]);
        out.ticks.push([[0.0, y], [-len, y]]);
        if labelled {
            let text = format!("{}", (v / step).round() * step);
            let text = trim_float(&text);
            out.labels.push(([x, s + 0.06 * s], text.clone()));
            out.labels.push(([-0.07 * s, y], text));
            if k > 0 && v < size - 1e-9 * size {
                out.grid.push([[x, 0.0], [x, s]]);
                out.grid.push([[0.0, y], [s, y]]);
            }
        }
    }
    out.labels.push(([0.5 * s, s + 0.095 * s], "x [m]".into()));
    out.labels.push(([-0.11 * s, 0.5 * s], "y [m]".into()));
    out
}

/// `0.30000000000000004` as `0.3`: at most 6 decimals, trailing zeros cut.
fn trim_float(text: &str) -> String {
    match text.parse::<f64>() {
        Ok(v) => {
            let t = format!("{v:.6}");
            t.trim_end_matches('0').trim_end_matches('.').to_string()
        }
        Err(_) => text.to_string(),
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

/// Colour of a plastic state: grey elastic, orange yielding, violet separated.
pub fn plastic_color(state: PlasticState) -> Color {
    match state {
        PlasticState::Elastic => Color::from_rgb(170, 170, 170),
        PlasticState::Yielding => Color::from_rgb(255, 140, 0),
        PlasticState::Separated => Color::from_rgb(160, 60, 220),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scale_has_round_steps_and_labels_every_step() {
        for (size, step, first, last) in [
            (1.0, 0.2, "0", "1"),
            (2.0, 0.5, "0", "2"),
            (0.3, 0.1, "0", "0.3"),
            (10.0, 2.0, "0", "10"),
        ] {
            let s = scale(size);
            assert!((s.step - step).abs() < 1e-12, "{size}: {}", s.step);
            let texts: Vec<&str> = s.labels.iter().map(|(_, t)| t.as_str()).collect();
            assert_eq!(texts[0], first, "{size}: {texts:?}");
            assert!(texts.contains(&last), "{size}: {texts:?}");
            let per_side = (size / step).round() as usize + 1;
            assert_eq!(s.labels.len(), 2 * per_side + 2, "{size}: {texts:?}");
            // Every tick starts on the domain's edge and points outward.
            for [a, b] in &s.ticks {
                assert!(
                    (a[1] == size as f32 && b[1] > a[1]) || (a[0] == 0.0 && b[0] < 0.0),
                    "{a:?} {b:?}"
                );
            }
        }
        // The bottom-left label of y = 0.2 sits 0.2 above the bottom edge.
        let s = scale(1.0);
        let y02 = s
            .labels
            .iter()
            .find(|(p, t)| t == "0.2" && p[0] < 0.0)
            .unwrap();
        assert!((y02.0[1] - 0.8).abs() < 1e-6);
    }

    #[test]
    fn stretch_colors_saturate() {
        assert_eq!(stretch_color(1.0), Color::from_rgb(200, 200, 200));
        assert_eq!(stretch_color(2.0), stretch_color(1.1));
        assert_eq!(stretch_color(0.5), Color::from_rgb(40, 90, 255));
    }
}
