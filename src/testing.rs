//! Helpers for tests and evidence studies, not part of the simulator: a
//! small yarn scene for quick runs, the reference material, and the Bessel
//! function `J0` that the hanging-chain oracles are written in. Built only
//! with the cargo feature `testing` (the crate's own tests switch it on
//! through a dev-dependency on the crate itself; `yarnsim-evidence` names it
//! in its manifest).

use crate::scene::builtin::yarn_reference;
use crate::scene::{Material, Obstacle, StepSize, YarnScene, YarnSpec};

/// The material of the reference scene (`yarn-reference`).
pub fn reference_material() -> Material {
    yarn_reference().material
}

/// A small yarn scene for quick measurements: `yarns` yarns of `vertices`
/// vertices (0.8 m long, 0.02 m apart) on a `resolution`^2 grid over 1 m,
/// falling from y = 0.75 onto one circle (centre (0.5, 0.55), radius 0.1),
/// reference material, gravity -9.8, sticky walls, dt 1e-4. Used by the
/// evidence studies (`yarnsim-evidence`) and by the library's own tests.
pub fn small_yarn_scene(yarns: u32, vertices: u32, resolution: u32) -> YarnScene {
    let mut s = yarn_reference();
    s.name = "yarn-small".into();
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

/// `J0(x)`, the Bessel function of the first kind of order 0, by its power
/// series `sum_k (-1)^k (x/2)^(2k) / (k!)^2` (to round-off for `|x| <= 10`):
/// the mode shapes of the hanging chain, the oracle of the yarn tests and of
/// the work-precision study.
pub fn bessel_j0(x: f64) -> f64 {
    let q = -(x * x) / 4.0;
    let mut term = 1.0;
    let mut sum = 1.0;
    for k in 1..60 {
        term *= q / (k * k) as f64;
        sum += term;
        if term.abs() < 1e-17 * sum.abs().max(1e-300) {
            break;
        }
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_scene_is_valid() {
        small_yarn_scene(2, 40, 64).validate().unwrap();
    }
}
