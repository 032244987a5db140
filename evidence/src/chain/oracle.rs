//! The hanging chain's analytic oracle: the first mode of the uniform
//! inextensible chain (`omega_1 = (j01 / 2) sqrt(g / L)`), the discrete
//! extensible chain that measures the model error of stretching, and the
//! frequency of a run from its zero crossings.

/// First zero of `J0`.
pub const J01: f64 = 2.404_825_557_695_773;

/// The oracle: first angular frequency (rad/s) of the uniform inextensible
/// chain of length `l` hanging in gravity `g`.
pub fn oracle_omega(g: f64, l: f64) -> f64 {
    0.5 * J01 * (g / l).sqrt()
}

/// First angular frequency of a discrete *extensible* hanging chain: `n`
/// equal segments of rest length `l / n`, line density `rho`, fiber
/// stiffness `k` (tension `k` times strain), in gravity `g`, top node fixed,
/// each segment stretched by its static tension (the weight below it).
/// Small transverse oscillations `M u'' = -K u` with `K` from the tensions
/// over the stretched lengths; the smallest eigenvalue of the symmetric
/// tridiagonal `M^-1/2 K M^-1/2` by bisection on its Sturm count. With
/// `k -> infinity` and large `n` it tends to [`oracle_omega`]; the
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
    let (mut lo, mut hi) = (0.0, 4.0 * oracle_omega(g, l).powi(2));
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
