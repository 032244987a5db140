//! The small yarn scene of the stress study, which the library's tests
//! (`tests/adversarial.rs`, `tests/proptest_invariants.rs`,
//! `tests/yarn_oracles.rs`) share through a dev-dependency on this crate.

use yarnsim::scene::builtin::yarn_reference;
use yarnsim::scene::{Obstacle, StepSize, YarnScene, YarnSpec};

/// A small yarn scene for quick measurements: `yarns` yarns of `vertices`
/// vertices (0.8 m long, 0.02 m apart) on a `resolution`^2 grid over 1 m,
/// falling from y = 0.75 onto one circle (centre (0.5, 0.55), radius 0.1),
/// reference material, gravity -9.8, sticky walls, dt 1e-4. Used by the
/// evidence studies (`yarnsim-evidence`) and by the library's own tests.
/// Its name is `small-bundle` (`yarn-small` is `fmu/scenes/small.toml`).
pub fn small_yarn_scene(yarns: u32, vertices: u32, resolution: u32) -> YarnScene {
    let mut s = yarn_reference();
    s.name = "small-bundle".into();
    s.description =
        format!("{yarns} yarns x {vertices} vertices on {resolution}^2 falling onto one circle");
    s.grid.resolution = resolution;
    s.time.dt = StepSize::Fixed(1e-4);
    s.obstacles = vec![Obstacle {
        center: [0.5, 0.55],
        radius: 0.1,
        friction: 0.3,
    }];
    // The reference bundle's yarn: from (0.1, 0.75) along +x, 0.8 m long.
    s.yarns = vec![YarnSpec {
        vertices,
        count: yarns,
        spacing: [0.0, 0.02],
        ..s.yarns[0].clone()
    }];
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_scene_is_valid() {
        small_yarn_scene(2, 40, 64).validate().unwrap();
    }
}
