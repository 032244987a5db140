//! The attractor: a point that pulls the yarn with a settable strength
//! (the FMU's and the CLI's run-time input), and its one input check.

use crate::math::Vec2;
use crate::mpm::error::SimError;

/// The attractor as the simulation sees it (settable at run time).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Attractor {
    pub position: Vec2,
    pub strength: f64,
    pub active: bool,
}

impl Attractor {
    /// Largest accepted |coordinate| of the position in m: far outside any
    /// domain, yet small enough that `strength * distance` stays finite.
    pub const MAX_POSITION: f64 = 1e6;
    /// Largest accepted strength in m/s^2.
    pub const MAX_STRENGTH: f64 = 1e6;

    /// The attractor inputs' limits, the one check every caller (the
    /// simulation, the FMU) applies: a finite position within
    /// [`Self::MAX_POSITION`] m of the origin in each coordinate, a strength
    /// in `[0, MAX_STRENGTH]` m/s^2. The error names the input.
    pub fn check(&self) -> Result<(), SimError> {
        let p = self.position;
        if !(p.x.is_finite() && p.y.is_finite()) {
            return Err(SimError::BadInput(format!(
                "attractor position ({}, {}) must be finite",
                p.x, p.y
            )));
        }
        if p.x.abs() > Self::MAX_POSITION || p.y.abs() > Self::MAX_POSITION {
            return Err(SimError::BadInput(format!(
                "attractor position ({}, {}) is absurd (beyond 1e6 m)",
                p.x, p.y
            )));
        }
        if !(self.strength.is_finite() && (0.0..=Self::MAX_STRENGTH).contains(&self.strength)) {
            return Err(SimError::BadInput(format!(
                "attractor strength {} must be in [0, 1e6] m/s2",
                self.strength
            )));
        }
        Ok(())
    }
}
