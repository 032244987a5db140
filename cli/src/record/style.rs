//! How things look: the 2D view transform, colours, radii and the legend.

use rerun::components::Color;
use yarnsim::mpm::constitutive::PlasticState;

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
    fn stretch_colors_saturate() {
        assert_eq!(stretch_color(1.0), Color::from_rgb(200, 200, 200));
        assert_eq!(stretch_color(2.0), stretch_color(1.1));
        assert_eq!(stretch_color(0.5), Color::from_rgb(40, 90, 255));
    }
}
