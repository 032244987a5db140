//! The hanging chain's analytic oracle: the first mode of the uniform
//! inextensible chain (`omega_1 = (j01 / 2) sqrt(g / L)`), the discrete
//! extensible chain that measures the model error of stretching, and the
//! frequency of a run from its zero crossings.

/// First zero of `J0`.
pub const J01: f64 = yarnsim_oracles::J0_FIRST_ZERO;

/// The oracle: first angular frequency (rad/s) of the uniform inextensible
/// chain of length `l` hanging in gravity `g`.
pub fn oracle_omega(g: f64, l: f64) -> f64 {
    0.5 * J01 * (g / l).sqrt()
}

/// The linearised discrete extensible chain (in `yarnsim-oracles`,
/// shared with the library's tests).
pub use yarnsim_oracles::extensible_chain_omega;

/// Angular frequency from the zero crossings of `(t, x)` samples: the
/// crossing times by linear interpolation, `omega = pi (n - 1) / (t_n - t_1)`
/// over the `n >= 3` crossings; `None` with fewer.
pub fn frequency_from_crossings(samples: &[(f64, f64)]) -> Option<f64> {
    let mut tc = Vec::new();
    for w in samples.windows(2) {
        let ((t0, x0), (t1, x1)) = (w[0], w[1]);
        if (x0 > 0.0 && x1 <= 0.0) || (x0 < 0.0 && x1 >= 0.0) {
            tc.push(t0 + (t1 - t0) * x0 / (x0 - x1));
        }
    }
    // A sample exactly at zero would count twice; drop near-duplicates.
    tc.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    (tc.len() >= 3)
        .then(|| std::f64::consts::PI * (tc.len() - 1) as f64 / (tc[tc.len() - 1] - tc[0]))
}
