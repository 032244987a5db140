//! # yarnsim-oracles
//!
//! Closed-form and semi-analytic oracles that both the evidence studies
//! (`yarnsim-evidence`, which the `yarnsim` CLI runs) and the library's tests
//! (`yarnsim::testing`, which re-exports them) measure the hanging chain
//! against: the Bessel function `J0` and its first zero (the mode shapes of
//! Daniel Bernoulli's uniform hanging chain), and the first frequency of the
//! discrete extensible chain. Plain `f64` math without dependencies, so the
//! CLI's release build carries these and not the test helpers of
//! `yarnsim::testing`.

/// `J0(x)`, the Bessel function of the first kind of order 0, by its power
/// series `sum_k (-1)^k (x/2)^(2k) / (k!)^2` (to round-off for `|x| <= 10`):
/// the mode shapes of the hanging chain, the oracle of the yarn tests and of
/// the work-precision study.
pub fn bessel_j0(x: f64) -> f64 {
    let q = -(x * x) / 4.0;
    let mut term = 1.0;
    let mut sum = 1.0;
    for k in 1..60 {
        term *= q / (k * k) as f64;
        sum += term;
        if term.abs() < 1e-17 * sum.abs().max(1e-300) {
            break;
        }
    }
    sum
}

/// The first zero of `J0`, `j_{0,1}`.
pub const J0_FIRST_ZERO: f64 = 2.404_825_557_695_773;

/// First angular frequency of a discrete *extensible* hanging chain: `n`
/// equal segments of rest length `l / n`, line density `rho`, fiber
/// stiffness `k` (tension `k` times strain), in gravity `g`, top node fixed,
/// each segment stretched by its static tension (the weight below it).
/// Small transverse oscillations `M u'' = -K u` with `K` from the tensions
/// over the stretched lengths; the smallest eigenvalue of the symmetric
/// tridiagonal `M^-1/2 K M^-1/2` by bisection on its Sturm count. With
/// `k -> infinity` and large `n` it tends to the inextensible continuum's `(j01 / 2) sqrt(g / l)`; the
/// difference at finite `k` is the model error that stretching adds.
pub fn extensible_chain_omega(n: usize, l: f64, rho: f64, k: f64, g: f64) -> f64 {
    let l0 = l / n as f64;
    // node i = 1..=n (index i - 1); node 0 is the pin
    let m: Vec<f64> = (1..=n)
        .map(|i| if i < n { rho * l0 } else { 0.5 * rho * l0 })
        .collect();
    // tension and stretched length of segment j = 1..=n (index j - 1)
    let mut below = 0.0;
    let mut t = vec![0.0; n];
    for j in (0..n).rev() {
        below += m[j];
        t[j] = g * below;
    }
    let s: Vec<f64> = t.iter().map(|tj| tj / (l0 * (1.0 + tj / k))).collect();
    let a: Vec<f64> = (0..n)
        .map(|i| (s[i] + if i + 1 < n { s[i + 1] } else { 0.0 }) / m[i])
        .collect();
    let b: Vec<f64> = (0..n - 1)
        .map(|i| -s[i + 1] / (m[i] * m[i + 1]).sqrt())
        .collect();
    // eigenvalues below x
    let count = |x: f64| {
        let mut c = 0;
        let mut q = 1.0;
        for i in 0..n {
            let off = if i > 0 { b[i - 1] * b[i - 1] / q } else { 0.0 };
            q = a[i] - x - off;
            if q == 0.0 {
                q = -1e-300;
            }
            if q < 0.0 {
                c += 1;
            }
        }
        c
    };
    // the inextensible continuum's omega_1^2 = (j01 / 2)^2 g / l, times 4
    let (mut lo, mut hi) = (0.0, (J0_FIRST_ZERO * J0_FIRST_ZERO) * g / l);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if count(mid) >= 1 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    (0.5 * (lo + hi)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_zero_of_j0() {
        assert!(bessel_j0(J0_FIRST_ZERO).abs() < 1e-12);
    }
}
