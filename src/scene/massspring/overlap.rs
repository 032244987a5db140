//! Start-up overlap check of a mass-spring scene: a particle that starts
//! inside a sphere collider is refused, because the collision projection
//! would push it out violently in the first step (a cloth inside its sphere
//! reached a strain of 28). The error names the sphere, the particle and the
//! distance.

use super::{SphereSpec, V3};
use crate::scene::error::{table_line, SceneError};

/// Refuses a mass-spring scene in which a particle starts inside a sphere
/// collider. `positions` are the expanded initial positions (particles,
/// then chains, then sheets, as in the built system); `text` (the scene
/// file) gives the sphere's line.
pub fn check_particles_outside_spheres(
    positions: &[V3],
    spheres: &[SphereSpec],
    text: Option<&str>,
) -> Result<(), SceneError> {
    for (j, s) in spheres.iter().enumerate() {
        let c = V3::from(s.center);
        let inside = positions
            .iter()
            .enumerate()
            .map(|(i, x)| (i, (x - c).norm()))
            .filter(|&(_, d)| d < s.radius * (1.0 - 1e-9));
        let (count, deepest) = inside.fold((0usize, None::<(usize, f64)>), |(n, best), (i, d)| {
            let best = match best {
                Some((_, bd)) if bd <= d => best,
                _ => Some((i, d)),
            };
            (n + 1, best)
        });
        if let Some((i, d)) = deepest {
            return Err(SceneError::Invalid {
                field: format!("spheres[{j}]"),
                line: table_line(text, "[[spheres]]", j),
                message: format!(
                    "{count} particle{} start{} inside sphere {j} (center [{}, {}, {}], radius {}); \
                     the deepest, particle {i}, is {d:.4} m from the center, {:.4} m inside; move \
                     the sphere or the particles apart",
                    if count == 1 { "" } else { "s" },
                    if count == 1 { "s" } else { "" },
                    s.center[0],
                    s.center[1],
                    s.center[2],
                    s.radius,
                    s.radius - d
                ),
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

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
            text.contains("particle 1, is 0.5000 m from the center"),
            "{text}"
        );
        assert!(check_particles_outside_spheres(&xs[..1], &[sphere], None).is_ok());
    }
}
