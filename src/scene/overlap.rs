//! Start-up overlap checks: a scene whose bodies start inside each other is
//! refused, because the contact handling would push them apart violently in
//! the first step (a yarn through an obstacle gained 40x its energy in
//! 0.01 s; a cloth inside its sphere reached a strain of 28). The errors name
//! both objects and the distances that triggered them.

use super::error::{table_line, SceneError};
use crate::math::Vec2;

/// A circular obstacle: centre in m, radius in m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Circle {
    pub center: [f64; 2],
    pub radius: f64,
}

/// Distance from `c` to the segment `a`-`b`.
fn segment_distance(c: Vec2, a: Vec2, b: Vec2) -> f64 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        ((c - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * t - c).norm()
}

/// Refuses a yarn scene in which a yarn passes through an obstacle at the
/// start: closer to its centre than its radius less half a grid cell (the
/// contact's resolution; a yarn laid on the surface, whose chords cut the
/// circle by their sagitta, is fine). Yarns are numbered as in the
/// simulation, the CSV and the recording: copies of a `[[yarns]]` entry one
/// after another: `entries` holds each `[[yarns]]` entry's curves (`None`:
/// an entry whose geometry is invalid, reported by the geometry checks),
/// `obstacles` the obstacles as circles, `dx` the grid cell size. `text`
/// (the scene file) gives the obstacle's line.
pub fn check_yarns_clear_of_obstacles(
    dx: f64,
    entries: &[Option<Vec<Vec<Vec2>>>],
    obstacles: &[Circle],
    text: Option<&str>,
) -> Result<(), SceneError> {
    let tolerance = 0.5 * dx;
    let mut yarn = 0;
    for (entry, curves) in entries.iter().enumerate() {
        let Some(curves) = curves else {
            continue; // reported by the geometry checks
        };
        for (copy, curve) in curves.iter().enumerate() {
            for (j, o) in obstacles.iter().enumerate() {
                let c = Vec2::from(o.center);
                let d = match curve.len() {
                    0 => f64::INFINITY,
                    1 => (curve[0] - c).norm(),
                    _ => curve
                        .windows(2)
                        .map(|s| segment_distance(c, s[0], s[1]))
                        .fold(f64::INFINITY, f64::min),
                };
                if d < o.radius - tolerance {
                    return Err(SceneError::Invalid {
                        field: format!("obstacles[{j}]"),
                        line: table_line(text, "[[obstacles]]", j),
                        message: format!(
                            "obstacle {j} (centre ({}, {}), radius {}) overlaps yarn {yarn} \
                             ([[yarns]] entry {entry}, copy {copy}) at the start: the yarn passes \
                             {d:.4} m from the centre, {:.4} m inside the circle (more than half \
                             a grid cell); move the obstacle or the yarn apart",
                            o.center[0],
                            o.center[1],
                            o.radius,
                            o.radius - d
                        ),
                    });
                }
            }
            yarn += 1;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::massspring::overlap::check_particles_outside_spheres;
    use crate::scene::massspring::{SphereSpec, V3};
    use crate::scene::{builtin_names, Scene, YarnScene};

    fn yarn_check(s: &YarnScene) -> Result<(), SceneError> {
        let entries: Vec<_> = s.yarns.iter().map(|y| y.curves().ok()).collect();
        check_yarns_clear_of_obstacles(s.dx(), &entries, &s.obstacle_circles(), None)
    }

    #[test]
    fn builtin_scenes_start_apart() {
        for (name, _) in builtin_names() {
            match Scene::resolve(name).unwrap() {
                Scene::Yarn(y) => y.validate().unwrap(),
                Scene::MassSpring(l) => l.validate().unwrap(),
            }
        }
    }

    #[test]
    fn a_yarn_through_an_obstacle_is_refused_naming_both() {
        let Scene::Yarn(mut s) = Scene::resolve("yarn-reference").unwrap() else {
            unreachable!()
        };
        let first = s.curves()[3][100];
        s.obstacles[1].center = [first.x + 0.01, first.y];
        s.obstacles[1].radius = 0.05;
        let err = yarn_check(&s).unwrap_err();
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
        yarn_check(&s).unwrap();
    }

    #[test]
    fn a_particle_inside_a_sphere_is_refused() {
        let sphere = SphereSpec {
            center: [0.0, 0.0, 0.0],
            radius: 1.0,
        };
        let xs = [
            V3::new(2.0, 0.0, 0.0),
            V3::new(0.5, 0.0, 0.0),
            V3::new(0.9, 0.0, 0.0),
        ];
        let text = check_particles_outside_spheres(&xs, std::slice::from_ref(&sphere), None)
            .unwrap_err()
            .to_string();
        assert!(text.contains("2 particles start inside sphere 0"), "{text}");
        assert!(
            text.contains("particle 1, is 0.5000 m from the centre"),
            "{text}"
        );
        assert!(check_particles_outside_spheres(&xs[..1], &[sphere], None).is_ok());
    }
}
