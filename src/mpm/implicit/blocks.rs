//! Small symmetric element blocks of the Hessian and their projection onto
//! the positive semi-definite cone (projected Newton: Teran, Sifakis,
//! Irving, Fedkiw 2005, "Robust quasistatic finite elements and flesh
//! simulation"): the block's eigen-decomposition by cyclic Jacobi
//! rotations, negative eigenvalues set to 0; the bending blocks by their
//! closed-form eigen-structure ([`project_bend`]).

// small dense blocks and stencils: index loops read as the formulas
#![allow(clippy::needless_range_loop)]

/// Jacobi sweeps: a symmetric block of size <= 6 converges to round-off in
/// far fewer (quadratic convergence after the first sweeps).
const SWEEPS: usize = 8;

/// Eigenvalues and eigenvectors (columns of `v`) of the symmetric `a`.
pub fn eigen_sym<const N: usize>(a: &[[f64; N]; N]) -> ([f64; N], [[f64; N]; N]) {
    let mut a = *a;
    let mut v = [[0.0; N]; N];
    for (i, row) in v.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for _ in 0..SWEEPS {
        let (mut off, mut diag) = (0.0, 0.0);
        for i in 0..N {
            diag += a[i][i] * a[i][i];
            for j in i + 1..N {
                off += 2.0 * a[i][j] * a[i][j];
            }
        }
        // off-diagonal at 1e-13 of the diagonal (in norm): the eigenvalues
        // to about that of the block's size
        if off <= 1e-26 * diag || off == 0.0 {
            break;
        }
        for p in 0..N {
            for q in p + 1..N {
                // an entry below round-off of the block needs no rotation
                if a[p][q] * a[p][q] <= 1e-34 * diag {
                    continue;
                }
                // the rotation that zeroes a[p][q] (Golub, Van Loan 8.5)
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..N {
                    let (akp, akq) = (a[k][p], a[k][q]);
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for k in 0..N {
                    let (apk, aqk) = (a[p][k], a[q][k]);
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for row in v.iter_mut() {
                    let (vp, vq) = (row[p], row[q]);
                    row[p] = c * vp - s * vq;
                    row[q] = s * vp + c * vq;
                }
            }
        }
    }
    (std::array::from_fn(|i| a[i][i]), v)
}

/// `(a + a^T) / 2`.
pub fn symmetrize<const N: usize>(a: &mut [[f64; N]; N]) {
    for i in 0..N {
        for j in i + 1..N {
            let m = 0.5 * (a[i][j] + a[j][i]);
            a[i][j] = m;
            a[j][i] = m;
        }
    }
}

/// The nearest positive semi-definite matrix to the symmetric `a` (in the
/// Frobenius norm): `a` itself when it is positive definite (Cholesky
/// succeeds) or no computed eigenvalue is negative, else
/// `V max(Lambda, 0) V^T`.
pub fn project_psd<const N: usize>(a: &[[f64; N]; N]) -> [[f64; N]; N] {
    if positive_definite(a) {
        return *a;
    }
    let (l, v) = eigen_sym(a);
    if l.iter().all(|&l| l >= 0.0) {
        return *a;
    }
    let mut out = [[0.0; N]; N];
    for (k, &lk) in l.iter().enumerate() {
        if lk <= 0.0 {
            continue;
        }
        for i in 0..N {
            for j in 0..N {
                out[i][j] += lk * v[i][k] * v[j][k];
            }
        }
    }
    symmetrize(&mut out);
    out
}

/// Whether the symmetric `a` is positive definite: its Cholesky
/// factorisation runs with positive pivots (the cheap test before the
/// eigen-decomposition).
fn positive_definite<const N: usize>(a: &[[f64; N]; N]) -> bool {
    let mut l = [[0.0; N]; N];
    for j in 0..N {
        let mut d = a[j][j];
        for k in 0..j {
            d -= l[j][k] * l[j][k];
        }
        if d <= 0.0 || d.is_nan() {
            return false;
        }
        let d = d.sqrt();
        l[j][j] = d;
        for i in j + 1..N {
            let mut s = a[i][j];
            for k in 0..j {
                s -= l[i][k] * l[j][k];
            }
            l[i][j] = s / d;
        }
    }
    true
}

/// `a x`.
#[inline(always)]
pub fn mul<const N: usize>(a: &[[f64; N]; N], x: &[f64; N]) -> [f64; N] {
    std::array::from_fn(|i| (0..N).map(|j| a[i][j] * x[j]).sum())
}

/// The PSD projection of a bending block in edge coordinates `e = (e1,
/// e2)` in closed form. The exact block is `H = B inv_len [g g^T + (kappa -
/// kappa0) K]`, `g = dkappa/de`, `K` its Hessian. `kappa` is invariant
/// under a rotation and a scaling of both edges, so with `s = e`, `r = J e`
/// (`J` the quarter turn of each edge), `g . s = g . r = 0` and `K s = -g`,
/// `K r = J g`: in the orthonormal basis `(s, g, J g, r)` normalised, `H s`
/// lies along `g`, `H r` along `J g`, with the same coefficient `-beta`,
/// `beta`. The `2x2` part in `(g, J g)` has eigenvectors `(c, s)` and
/// values `nu`; each `y = c g + s J g` pairs with `z = -c s + s r` into an
/// invariant plane where `H = [[nu, beta], [beta, 0]]` (one eigenvalue of
/// each sign unless `beta = 0`). The projection keeps the positive one of
/// each plane. `f` is the energy's gradient `B inv_len (kappa - kappa0)
/// g`, the direction of `g`; where it is zero `H` is the rank-one `B
/// inv_len g g^T` (PSD) and is returned as it is.
pub fn project_bend(h: &[[f64; 4]; 4], e: [f64; 4], f: [f64; 4]) -> [[f64; 4]; 4] {
    let norm = |x: &[f64; 4]| x.iter().map(|x| x * x).sum::<f64>().sqrt();
    let turn = |x: &[f64; 4]| [-x[1], x[0], -x[3], x[2]];
    let (se, sf) = (norm(&e), norm(&f));
    if !(se > 0.0 && sf > 0.0 && se.is_finite() && sf.is_finite()) {
        return *h;
    }
    let qs: [f64; 4] = std::array::from_fn(|i| e[i] / se);
    let qg: [f64; 4] = std::array::from_fn(|i| f[i] / sf);
    let (qj, qr) = (turn(&qg), turn(&qs));
    let quad = |a: &[f64; 4], b: &[f64; 4]| -> f64 {
        let hb = mul(h, b);
        (0..4).map(|i| a[i] * hb[i]).sum()
    };
    let (alpha, delta, gamma) = (quad(&qg, &qg), quad(&qg, &qj), quad(&qj, &qj));
    let beta = 0.5 * (quad(&qj, &qr) - quad(&qs, &qg));
    // the 2x2 [[alpha, delta], [delta, gamma]]: angle of its first
    // eigenvector
    let theta = 0.5 * (2.0 * delta).atan2(alpha - gamma);
    let (c, s) = (theta.cos(), theta.sin());
    let mut out = [[0.0; 4]; 4];
    for (c, s) in [(c, s), (-s, c)] {
        let nu = alpha * c * c + 2.0 * delta * c * s + gamma * s * s;
        // the positive root of l^2 - nu l - beta^2, without cancellation
        let root = (0.25 * nu * nu + beta * beta).sqrt();
        let l = if nu >= 0.0 {
            0.5 * nu + root
        } else {
            beta * beta / (root - 0.5 * nu)
        };
        if l.is_nan() || l <= 0.0 {
            continue;
        }
        let w = 1.0 / (l * l + beta * beta).sqrt();
        let (a, b) = (l * w, beta * w);
        let v: [f64; 4] =
            std::array::from_fn(|i| a * (c * qg[i] + s * qj[i]) + b * (-c * qs[i] + s * qr[i]));
        for i in 0..4 {
            for j in 0..4 {
                out[i][j] += l * v[i] * v[j];
            }
        }
    }
    symmetrize(&mut out);
    out
}
