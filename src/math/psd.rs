//! Small symmetric element blocks of the Hessian and their projection onto
//! the positive semi-definite cone (projected Newton: Teran, Sifakis,
//! Irving, Fedkiw 2005, "Robust quasistatic finite elements and flesh
//! simulation"): the block's eigen-decomposition by cyclic Jacobi
//! rotations, negative eigenvalues set to 0. (The bending blocks have a
//! closed form: `crate::mpm::laws::bending::project_bend`.)

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
