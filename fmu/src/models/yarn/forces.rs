//! The pins' forces on the yarn over a communication step.

use yarnsim::math::Vec2;

/// The pins' forces on the yarn summed over the substeps of a
/// communication step: with a fixed `dt` plainly (weight 1 per substep),
/// under `dt = "auto"` weighted by each substep's length, so the mean is
/// the time average over the step either way.
#[derive(Clone, Debug, PartialEq)]
pub struct PinForces {
    /// Per pin, the weighted sum of the yarn's force on it.
    pub sum: Vec<Vec2>,
    pub substeps: u64,
    /// Sum of the weights (the substep count, or the time under "auto").
    pub weight: f64,
}

impl PinForces {
    pub(super) fn new(pins: usize) -> Self {
        PinForces {
            sum: vec![Vec2::zeros(); pins],
            substeps: 0,
            weight: 0.0,
        }
    }

    /// The mean force on pin `i` (0 before any substep).
    pub fn mean(&self, i: usize) -> Vec2 {
        if self.substeps == 0 {
            Vec2::zeros()
        } else {
            self.sum[i] / self.weight
        }
    }
}
