//! # yarnsim
//!
//! Simulation of thin elastic objects: 2D yarn bundles by the Material Point
//! Method (Jiang, Gast, Teran 2017), and mass-spring wires and cloth.
//!
//! * [`math`]: 2x2 QR, B-spline weights.
//! * [`scene`]: scene descriptions and their TOML files (the bottom layer:
//!   the models import it).
//! * [`mpm`]: the yarn-bundle MPM solver.
//! * [`massspring`]: mass-spring wires and cloth (course lecture notes; Baraff and Witkin 1998; Wang 2015, Müller et al. 2007).
//! * [`pool`]: running a call's parallel passes on a rayon worker.
//! * `testing` (cargo feature `testing`): scenes and oracles for tests and
//!   evidence studies.

#![warn(missing_docs)]

pub mod massspring;
pub mod math;
pub mod mpm;
pub mod pool;
pub mod scene;
#[cfg(feature = "testing")]
pub mod testing;

pub use mpm::{SimError, YarnSim};
pub use scene::{MassSpringScene, Scene, SceneError, YarnScene};
