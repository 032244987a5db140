//! The `yarnsim` command-line program as a library: each command is a
//! function over the `yarnsim` library, so tests can call them directly;
//! `main.rs` only parses arguments and prints.
//!
//! * [`scenes`]: `yarnsim scenes`, `yarnsim scene show`.
//! * [`materials`]: `yarnsim materials`, the yarn presets.
//! * [`run`]: `yarnsim run` (+ [`table`] for its summary).
//! * [`record`]: `yarnsim record`, the only module that talks to Rerun.
//! * [`bench`](mod@bench): `yarnsim bench`.
//! * [`driver`], [`schedule`]: the frame loop, progress bar and Ctrl-C.
//! * [`estimate`]: memory and recording-size estimates of large scenes.
//! * [`yarn`]: how the commands start a yarn scene (the stable-step check)
//!   and report its divergence.

pub mod bench;
pub mod driver;
pub mod duration;
pub mod error;
pub mod estimate;
pub mod evidence;
pub mod massspring;
pub mod materials;
pub mod record;
pub mod run;
pub mod scenes;
pub mod schedule;
pub mod table;
pub mod yarn;

pub use error::CliError;
