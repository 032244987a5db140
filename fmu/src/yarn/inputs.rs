//! The YarnBundle's inputs: attractor, gravity and the driven pins, with
//! the library's limits checked before they reach the simulation.

use yarnsim::math::Vec2;
use yarnsim::mpm::{Attractor, YarnSim};
use yarnsim::scene::YarnScene;

use super::variables::fmu_pins;
use crate::fmu_model::{refuse, ModelResult};

/// The inputs of one `motion = "input"` pin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PinInput {
    /// Index in `[[pins]]`.
    pub pin: usize,
    /// `pin[i].x`, `.y`: position of the pin's first vertex, m.
    pub position: [f64; 2],
    /// `pin[i].vx`, `.vy`: velocity of its vertices, m/s.
    pub velocity: [f64; 2],
}

/// Values of the inputs.
#[derive(Clone, Debug, PartialEq)]
pub struct Inputs {
    pub attractor: [f64; 2],
    pub strength: f64,
    pub active: bool,
    pub gravity: [f64; 2],
    /// The driven pins, in `[[pins]]` order.
    pub pins: Vec<PinInput>,
}

impl Inputs {
    pub(super) fn from_scene(s: &YarnScene) -> Self {
        Inputs {
            attractor: s.attractor.position,
            strength: s.attractor.strength,
            active: s.attractor.active,
            gravity: s.gravity,
            pins: fmu_pins(s)
                .iter()
                .enumerate()
                .filter(|(_, p)| p.input)
                .map(|(pin, p)| PinInput {
                    pin,
                    position: p.start,
                    velocity: [0.0; 2],
                })
                .collect(),
        }
    }

    /// The driven pin `pin`'s inputs.
    pub(super) fn pin_mut(&mut self, pin: usize) -> Option<&mut PinInput> {
        self.pins.iter_mut().find(|p| p.pin == pin)
    }

    /// Hands the pin targets to `sim`, for the communication step that
    /// starts at `since` on the simulation's clock.
    pub(super) fn latch_pins(&self, sim: &mut YarnSim, since: f64) -> ModelResult {
        for p in &self.pins {
            sim.set_pin_target_at(p.pin, Vec2::from(p.position), Vec2::from(p.velocity), since)
                .or_else(|e| refuse(e.to_string()))?;
        }
        Ok(())
    }

    /// The attractor inputs as the library's [`Attractor`].
    pub(super) fn attractor(&self) -> Attractor {
        Attractor {
            position: Vec2::from(self.attractor),
            strength: self.strength,
            active: self.active,
        }
    }

    /// Hands the inputs to `sim`, which checks them as [`Self::check`] does.
    pub(super) fn apply(&self, sim: &mut YarnSim) -> ModelResult {
        sim.set_gravity(Vec2::from(self.gravity))
            .and_then(|_| sim.set_attractor(self.attractor()))
            .or_else(|e| refuse(e.to_string()))
    }

    /// The library's input limits, without a simulation at hand.
    pub(super) fn check(&self) -> ModelResult {
        let g = Vec2::from(self.gravity);
        if g.norm() > 1e6 {
            return refuse(format!(
                "gravity ({}, {}) is absurd (|g| above 1e6 m/s2)",
                g.x, g.y
            ));
        }
        // The attractor's limits are the library's, checked in one place.
        self.attractor().check().or_else(refuse)?;
        for p in &self.pins {
            let x = Vec2::from(p.position);
            let v = Vec2::from(p.velocity);
            if x.norm() > 1e6 || v.norm() > 1e6 {
                return refuse(format!(
                    "pin[{}] position ({}, {}) m or velocity ({}, {}) m/s is absurd (beyond 1e6)",
                    p.pin, x.x, x.y, v.x, v.y
                ));
            }
        }
        Ok(())
    }
}
