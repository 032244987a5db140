//! The YarnBundle's driven-pin inputs, held until a communication step
//! begins (they become the pins' targets then). The attractor and gravity
//! inputs are not held here: the simulation holds them, sets them at once
//! through its checked setters, and saves them in its state.

use yarnsim::math::Vec2;
use yarnsim::mpm::YarnSim;
use yarnsim::scene::YarnScene;

use super::variables::fmu_pins;
use crate::models::model::{refuse, ModelResult};

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

/// Values of the driven-pin inputs.
#[derive(Clone, Debug, PartialEq)]
pub struct Inputs {
    /// The driven pins, in `[[pins]]` order.
    pub pins: Vec<PinInput>,
}

impl Inputs {
    pub(super) fn from_scene(s: &YarnScene) -> Self {
        Inputs {
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

    /// The pin inputs' limits: the library's ([`YarnSim::check_pin_target`]).
    pub(super) fn check(&self) -> ModelResult {
        for p in &self.pins {
            YarnSim::check_pin_target(p.pin, Vec2::from(p.position), Vec2::from(p.velocity))
                .or_else(|e| refuse(e.to_string()))?;
        }
        Ok(())
    }
}
