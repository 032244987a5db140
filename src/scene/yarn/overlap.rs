//! Start-up overlap check of a yarn scene: a yarn that starts through an
//! obstacle is refused, because the contact handling would push it out
//! violently in the first step (a yarn through an obstacle gained 40x its
//! energy in 0.01 s). The error names both objects (the yarn by its index,
//! its `[[yarns]]` entry and that entry's line), the point of the yarn
//! nearest the obstacle's center in m, and the distance.

use super::validate::short_to;
use super::YarnScene;
use crate::math::Vec2;
use crate::scene::error::{table_line, SceneError};

/// The point of the segment `a`-`b` nearest to `c`, and the fraction
/// along the segment where it lies.
fn nearest_on_segment(c: Vec2, a: Vec2, b: Vec2) -> (Vec2, f64) {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        ((c - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * t, t)
}

/// The point of `curve` nearest to `c`, its distance, and the vertex
/// nearest to that point.
fn nearest_on_curve(curve: &[Vec2], c: Vec2) -> Option<(Vec2, f64, usize)> {
    match curve.len() {
        0 => None,
        1 => Some((curve[0], (curve[0] - c).norm(), 0)),
        _ => curve
            .windows(2)
            .enumerate()
            .map(|(k, s)| {
                let (p, t) = nearest_on_segment(c, s[0], s[1]);
                (p, (p - c).norm(), k + usize::from(t > 0.5))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1)),
    }
}

/// Every yarn of `scene` at the start, numbered as in the simulation, the
/// CSV and the recording (copies of a `[[yarns]]` entry one after another):
/// `(yarn, entry, copy, vertices)`. An entry whose geometry does not build
/// gives none (the geometry checks report it).
fn yarn_copies(scene: &YarnScene) -> impl Iterator<Item = (usize, usize, usize, Vec<Vec2>)> + '_ {
    scene
        .yarns
        .iter()
        .enumerate()
        .flat_map(|(entry, spec)| {
            let curves = spec.curves().unwrap_or_default();
            curves
                .into_iter()
                .enumerate()
                .map(move |(copy, curve)| (entry, copy, curve))
        })
        .enumerate()
        .map(|(yarn, (entry, copy, curve))| (yarn, entry, copy, curve))
}

/// A coordinate in m for a message: 4 decimals without trailing zeros.
fn short(x: f64) -> String {
    short_to(x, 4)
}

/// Refuses a yarn scene in which a yarn passes through an obstacle at the
/// start: closer to its center than its radius less half a grid cell (the
/// contact's resolution; a yarn laid on the surface, whose chords cut the
/// circle by their sagitta, is fine). Yarns are numbered as in the
/// simulation, the CSV and the recording: copies of a `[[yarns]]` entry one
/// after another. `text` (the scene file) gives the obstacle's line and
/// that of the yarn's entry.
pub fn check_yarns_clear_of_obstacles(
    scene: &YarnScene,
    text: Option<&str>,
) -> Result<(), SceneError> {
    let tolerance = 0.5 * scene.dx();
    for (yarn, entry, copy, curve) in yarn_copies(scene) {
        let count = scene.yarns[entry].count;
        for (j, o) in scene.obstacles.iter().enumerate() {
            let c = Vec2::from(o.center);
            let Some((p, d, vertex)) = nearest_on_curve(&curve, c) else {
                continue;
            };
            if d < o.radius - tolerance {
                let line = match table_line(text, "[[yarns]]", entry) {
                    Some(l) => format!(" at line {l}"),
                    None => String::new(),
                };
                let copy = if count > 1 {
                    format!(", copy {copy} of {count}")
                } else {
                    String::new()
                };
                return Err(SceneError::Invalid {
                    field: format!("obstacles[{j}]"),
                    line: table_line(text, "[[obstacles]]", j),
                    message: format!(
                        "obstacle {j} (center [{}, {}], radius {}) overlaps yarn {yarn} \
                             (`yarns[{entry}]`{line}{copy}) at the start: its point [{}, {}] \
                             (near vertex {vertex}) lies {} m from the center, {} m inside the \
                             circle (more than half a grid cell); move the obstacle \
                             or the yarn apart",
                        o.center[0],
                        o.center[1],
                        o.radius,
                        short(p.x),
                        short(p.y),
                        short(d),
                        short(o.radius - d)
                    ),
                });
            }
        }
    }
    Ok(())
}

/// A warning when a yarn starts closer to an obstacle's surface than
/// `material.diameter / 2` (`d`: the diameter in m): contact keeps a yarn's
/// centre line `d / 2` off every obstacle (`docs/obstacle-contact.md`, "Yarn
/// diameter"), so the first substep pushes such a vertex out, which
/// stretches a yarn laid on the bare surface by about `d / (2 R)` (at a
/// real yarn's EA a tension far above its weight: the capstan of
/// `tests/capstan_real_ea.rs` sprang off its drum laid so). Vertices
/// only: a chord between two vertices on the grown circle cuts it by its
/// sagitta, as every polyline on a circle does, and the vertices of a
/// yarn given by `points` lie on the chords between those points, so only
/// a vertex closer than `d / 4` warns (the capstan of
/// `tests/capstan_real_ea.rs`, laid at `R + d / 2` by points about 5 mm
/// apart, comes within 0.05 mm of a 0.16 mm yarn's surface, 0.6 d / 2,
/// and holds). Names the deepest such vertex, its yarn and obstacle, and
/// the radius to lay it at.
pub fn start_gap_warning(scene: &YarnScene, d: f64) -> Option<String> {
    // (depth inside the grown circle, yarn, entry, vertex, obstacle, gap)
    let mut deepest: Option<(f64, usize, usize, usize, usize, f64)> = None;
    for (yarn, entry, _, curve) in yarn_copies(scene) {
        for (j, o) in scene.obstacles.iter().enumerate() {
            let c = Vec2::from(o.center);
            for (vertex, &x) in curve.iter().enumerate() {
                let gap = (x - c).norm() - o.radius;
                let depth = 0.5 * d - gap;
                if gap < 0.25 * d && deepest.is_none_or(|b| depth > b.0) {
                    deepest = Some((depth, yarn, entry, vertex, j, gap));
                }
            }
        }
    }
    let (_, yarn, entry, vertex, j, gap) = deepest?;
    let r = scene.obstacles[j].radius;
    Some(format!(
        "yarn {yarn} (`yarns[{entry}]`) starts with vertex {vertex} {} m from the surface of \
         obstacle {j}, less than half of material.diameter / 2 = {} m, where contact holds the \
         centre line: the first substep pushes the yarn out and stretches it; lay it at radius \
         {} m from the obstacle's center (radius + d / 2)",
        short_to(gap, 6),
        short_to(0.5 * d, 6),
        short_to(r + 0.5 * d, 6)
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

    #[test]
    fn a_yarn_through_an_obstacle_is_refused_naming_both() {
        let Scene::Yarn(mut s) = Scene::resolve("yarn-reference").unwrap() else {
            unreachable!()
        };
        let first = s.curves()[3][100];
        s.obstacles[1].center = [first.x + 0.01, first.y];
        s.obstacles[1].radius = 0.05;
        let err = check_yarns_clear_of_obstacles(&s, None).unwrap_err();
        let text = err.to_string();
        assert!(text.contains("obstacles[1]"), "{text}");
        assert!(text.contains("overlaps yarn"), "{text}");
        assert!(text.contains("inside the circle"), "{text}");
        assert!(s.validate().is_err());
    }

    #[test]
    fn a_yarn_laid_on_an_obstacle_is_accepted() {
        // A polyline on the circle: its chords cut the circle by their sagitta.
        let Scene::Yarn(mut s) = Scene::resolve("yarn-drape").unwrap() else {
            unreachable!()
        };
        let o = s.obstacles[0].clone();
        let points: Vec<[f64; 2]> = (0..=20)
            .map(|k| {
                let a = std::f64::consts::PI * k as f64 / 20.0;
                [
                    o.center[0] + o.radius * a.cos(),
                    o.center[1] + o.radius * a.sin(),
                ]
            })
            .collect();
        s.yarns[0].start = None;
        s.yarns[0].end = None;
        s.yarns[0].direction = None;
        s.yarns[0].length = None;
        s.yarns[0].points = Some(points);
        s.yarns[0].vertices = 21;
        check_yarns_clear_of_obstacles(&s, None).unwrap();
    }
}
