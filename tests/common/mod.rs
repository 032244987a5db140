//! Shared helpers of the integration tests.
#![allow(dead_code)]

use yarnsim::scene::YarnScene;

/// A small deterministic generator (xorshift64*), so tests need no `rand`.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed.wrapping_mul(0x9E3779B97F4A7C15) | 1)
    }
    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545F4914F6CDD1D)
    }
    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// A yarn scene from TOML text; panics with the loader's message on error.
pub fn scene(text: &str) -> YarnScene {
    YarnScene::from_toml_str(text).unwrap_or_else(|e| panic!("{e}"))
}

/// A 64^2 scene without gravity, walls, obstacles or plasticity; `yarns` is
/// the `[[yarns]]` part.
pub fn bare_scene(yarns: &str) -> YarnScene {
    scene(&format!(
        r#"
gravity = [0.0, 0.0]
[grid]
resolution = 64
[time]
dt = 1e-4
[material]
k = 1000.0
gamma = 500.0
youngs_modulus = 1000.0
friction = 0.05
bending = 1e-4
plasticity = false
[walls]
mode = "none"
{yarns}
"#
    ))
}
