//! Start-up overlap check of a mass-spring scene: a particle that starts
//! inside a sphere collider is refused (a cloth inside its sphere reached a
//! strain of 28 when pushed out in the first step). The error names the
//! sphere, the particles and the distances that triggered it.

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
                    "{count} particle{} start{} inside sphere {j} (centre ({}, {}, {}), radius {}); \
                     the deepest, particle {i}, is {d:.4} m from the centre, {:.4} m inside; move \
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
