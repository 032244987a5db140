//! `[transfer]`: how particles take their velocity back from the grid
//! (`crate::mpm::machinery::transfer`).

use serde::{Deserialize, Serialize};

use crate::scene::readers::{one, opt_positive, unit_interval_closed};

/// The grid-to-particle velocity update (`[transfer]`); see
/// `crate::mpm::machinery::transfer`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransferSpec {
    /// `"flip"` (default) or `"apic"`.
    #[serde(default)]
    pub scheme: TransferScheme,
    /// FLIP ratio in `[0, 1]` for `"flip"` (default 1: pure FLIP, no
    /// per-transfer dissipation); `r < 1` blends in APIC's damping.
    #[serde(default = "one", deserialize_with = "unit_interval_closed")]
    pub flip_ratio: f64,
    /// Instead of `flip_ratio`: the time, s, over which a FLIP particle's
    /// own velocity relaxes to the grid's; each substep's ratio is
    /// `exp(-dt / flip_time)`, a damping per simulated second that does
    /// not depend on the step.
    #[serde(
        default,
        deserialize_with = "opt_positive",
        skip_serializing_if = "Option::is_none"
    )]
    pub flip_time: Option<f64>,
}

impl Default for TransferSpec {
    fn default() -> Self {
        TransferSpec {
            scheme: TransferScheme::default(),
            flip_ratio: 1.0,
            flip_time: None,
        }
    }
}

/// Name of a transfer scheme.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum TransferScheme {
    /// The particle keeps its velocity and adds the grid's change (blended
    /// with APIC by `flip_ratio`).
    #[default]
    Flip,
    /// APIC (the reference Taichi implementation's): velocity and affine matrix replaced by the grid's.
    Apic,
}

impl TransferScheme {
    /// Every value of `[transfer] scheme`, as a scene file writes it.
    pub const NAMES: [&'static str; 2] = ["flip", "apic"];

    /// The value as a scene file writes it (one of [`TransferScheme::NAMES`]).
    pub fn name(&self) -> &'static str {
        match self {
            TransferScheme::Flip => Self::NAMES[0],
            TransferScheme::Apic => Self::NAMES[1],
        }
    }
}
