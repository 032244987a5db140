//! `[time] axial`: how the explicit integrator treats the fibre-stretch
//! term (`material.k`) of the yarn energy.

use serde::{Deserialize, Serialize};

/// The fibre-stretch term under `integrator = "explicit"` (`[time] axial`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Axial {
    /// The `k` term is one of the explicit grid forces (the default; the
    /// fibre wave `sqrt(k / rho)` bounds the substep).
    #[default]
    Explicit,
    /// The `k` term leaves the explicit scatter: after the grid-to-particle
    /// pass each yarn's axial springs take a backward Euler step on their
    /// vertices (`crate::mpm::driver::axial`), so the fibre wave no longer
    /// bounds the substep; shear, the cross-section, bending and contact
    /// stay explicit on the grid.
    Implicit,
}

impl Axial {
    /// Every value of `[time] axial`, as a scene file writes it.
    pub const NAMES: [&'static str; 2] = ["explicit", "implicit"];

    /// The value as a scene file writes it (one of [`Axial::NAMES`], in
    /// the order of the variants).
    pub fn name(&self) -> &'static str {
        Self::NAMES[*self as usize]
    }

    /// Whether the `k` term is an explicit grid force (the default).
    pub fn is_explicit(&self) -> bool {
        *self == Axial::Explicit
    }

    /// Whether the `k` term takes the implicit vertex step.
    pub fn is_implicit(&self) -> bool {
        *self == Axial::Implicit
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Serialize, Deserialize)]
    struct Value {
        v: Axial,
    }

    #[test]
    fn names_are_the_scene_files_spelling() {
        for (v, n) in [Axial::Explicit, Axial::Implicit].iter().zip(Axial::NAMES) {
            assert_eq!(v.name(), n);
            let text = toml::to_string(&Value { v: *v }).unwrap();
            assert_eq!(text.trim(), format!("v = {n:?}"));
            let back: Value = toml::from_str(&text).unwrap();
            assert_eq!(back.v, *v);
        }
    }
}
