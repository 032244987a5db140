//! The quadrature particles' frame update, over a batch of particles: the
//! QR of `d / l0`, the Mohr-Coulomb return mapping and the stress for the
//! next scatter (the particle's own part of pass 4, after the grid has given
//! it `d`).
//!
//! Per particle this is a chain of `sqrt`, divisions and `ln` that leaves
//! the core waiting when particles go one at a time. Here every step runs as
//! a loop over the batch, on structure-of-arrays scratch, so that the
//! compiler vectorizes it across particles; only the rare cases that need
//! `ln` in the return mapping (sheared beyond the cone while compressed) and
//! the `ln` of the stress run one particle at a time. Each particle goes
//! through exactly the operations of [`YarnEnergy::return_map`], [`qr`] and
//! [`YarnEnergy::stress_qr`], in the same order (`sqrt` and division are
//! correctly rounded in every SIMD width), so the results are bitwise those
//! of the one-at-a-time functions (tested).
//!
//! [`qr`]: crate::math::qr::qr

use crate::math::qr::Qr2;
use crate::math::{Mat2, Vec2};
use crate::mpm::laws::constitutive::{YarnEnergy, R11_MIN, R22_MIN};

/// Particles per batch (the scratch lives on the stack).
const BATCH: usize = 64;

/// The per-particle arrays of a frame update (all of one length): rest
/// length and volume (read), `d` (read and replaced), frame and stress
/// columns (written).
pub struct Frames<'a> {
    pub l0: &'a [f64],
    pub vol: &'a [f64],
    pub d: &'a mut [Mat2],
    pub frame: &'a mut [Qr2],
    pub t1: &'a mut [Vec2],
    pub t2: &'a mut [Vec2],
}

/// Frame update of every particle `k`: `d[k]` holds `[d1, d2]` (the fiber
/// direction from the vertices, the cross-section direction advected by the
/// grid) and is replaced by the return-mapped one (when `plastic`);
/// `frame[k]` gets `qr(d[k] / l0[k])` and `(t1[k], t2[k])` the stress
/// columns `dE/dd1`, `dE/dd2` times `vol[k] / l0[k]`, as
/// [`crate::mpm::laws::constitutive::frame_gradient_qr`] gives them.
#[inline(always)]
pub fn update_frames(energy: &YarnEnergy, plastic: bool, f: Frames) {
    let n = f.d.len();
    debug_assert!(f.l0.len() == n && f.vol.len() == n && f.frame.len() == n);
    debug_assert!(f.t1.len() == n && f.t2.len() == n);
    let mut start = 0;
    while start < n {
        let r = start..(start + BATCH).min(n);
        let part = Frames {
            l0: &f.l0[r.clone()],
            vol: &f.vol[r.clone()],
            d: &mut f.d[r.clone()],
            frame: &mut f.frame[r.clone()],
            t1: &mut f.t1[r.clone()],
            t2: &mut f.t2[r.clone()],
        };
        batch(energy, plastic, part);
        start = r.end;
    }
}

/// Structure-of-arrays scratch of one batch.
struct Scratch {
    /// `d1` and `d2` (x and y components).
    d1x: [f64; BATCH],
    d1y: [f64; BATCH],
    d2x: [f64; BATCH],
    d2y: [f64; BATCH],
    l0: [f64; BATCH],
    inv_l0: [f64; BATCH],
    /// The QR factors.
    c: [f64; BATCH],
    s: [f64; BATCH],
    r11: [f64; BATCH],
    r12: [f64; BATCH],
    r22: [f64; BATCH],
    /// Return-mapped `(r12, r22)`, and particles needing the `ln` case.
    m12: [f64; BATCH],
    m22: [f64; BATCH],
    slow: [bool; BATCH],
    /// `ln(max(r22, R22_MIN))` where that is below 1 (else unused).
    ln22: [f64; BATCH],
}

#[inline(always)]
fn batch(energy: &YarnEnergy, plastic: bool, f: Frames) {
    let Frames {
        l0,
        vol,
        d,
        frame,
        t1,
        t2,
    } = f;
    let n = d.len();
    let mut w = Scratch {
        d1x: [0.0; BATCH],
        d1y: [0.0; BATCH],
        d2x: [0.0; BATCH],
        d2y: [0.0; BATCH],
        l0: [1.0; BATCH],
        inv_l0: [1.0; BATCH],
        c: [0.0; BATCH],
        s: [0.0; BATCH],
        r11: [0.0; BATCH],
        r12: [0.0; BATCH],
        r22: [0.0; BATCH],
        m12: [0.0; BATCH],
        m22: [0.0; BATCH],
        slow: [false; BATCH],
        ln22: [0.0; BATCH],
    };
    for k in 0..n {
        let m = &d[k];
        w.d1x[k] = m[(0, 0)];
        w.d1y[k] = m[(1, 0)];
        w.d2x[k] = m[(0, 1)];
        w.d2y[k] = m[(1, 1)];
        w.l0[k] = l0[k];
    }
    // QR of d / l0 (as `qr`)
    for k in 0..BATCH {
        let inv = 1.0 / w.l0[k];
        w.inv_l0[k] = inv;
        let (a, cc) = (w.d1x[k] * inv, w.d1y[k] * inv);
        let (b, dd) = (w.d2x[k] * inv, w.d2y[k] * inv);
        let r11 = (a * a + cc * cc).sqrt();
        let pos = r11 > 0.0;
        let c = if pos { a / r11 } else { 1.0 };
        let s = if pos { cc / r11 } else { 0.0 };
        w.c[k] = c;
        w.s[k] = s;
        w.r11[k] = r11;
        w.r12[k] = c * b + s * dd;
        w.r22[k] = -s * b + c * dd;
    }
    if plastic {
        let e = energy;
        // the return mapping's two cases without `ln` (as `return_map`)
        for k in 0..BATCH {
            let (r12, r22) = (w.r12[k], w.r22[k]);
            let big = r22 > 1.0;
            let r22c = r22.max(R22_MIN);
            let inside = e.gamma * r12.abs() * r22c <= e.friction * e.normal * (1.0 - r22c);
            w.m12[k] = if big { 0.0 } else { r12 };
            w.m22[k] = if big { 1.0 } else { r22c };
            w.slow[k] = !big && !inside;
        }
        for k in 0..n {
            if w.slow[k] {
                (w.m12[k], w.m22[k]) = e.return_map(w.r12[k], w.r22[k]);
            }
        }
        // where it changed R: d2 = Q R(:, 2) l0 and the QR again (d1, and so
        // c, s and r11, are unchanged)
        for k in 0..BATCH {
            let (c, s) = (w.c[k], w.s[k]);
            let (m12, m22) = (w.m12[k], w.m22[k]);
            let changed = m12 != w.r12[k] || m22 != w.r22[k];
            let d2x = (c * m12 - s * m22) * w.l0[k];
            let d2y = (s * m12 + c * m22) * w.l0[k];
            let (b, dd) = (d2x * w.inv_l0[k], d2y * w.inv_l0[k]);
            let r12 = c * b + s * dd;
            let r22 = -s * b + c * dd;
            if changed {
                w.d2x[k] = d2x;
                w.d2y[k] = d2y;
                w.r12[k] = r12;
                w.r22[k] = r22;
            }
        }
    }
    // the stress's `ln` (as `stress_qr`)
    for k in 0..n {
        let r22 = w.r22[k].max(R22_MIN);
        if r22 < 1.0 {
            w.ln22[k] = r22.ln();
        }
    }
    for k in 0..n {
        let (c, s) = (w.c[k], w.s[k]);
        let r12 = w.r12[k];
        let r11 = w.r11[k].max(R11_MIN);
        let r22 = w.r22[k].max(R22_MIN);
        let p = energy.stress_clamped(c, s, r11, r12, r22, w.ln22[k]);
        let sc = vol[k] / w.l0[k];
        t1[k] = p.column(0) * sc;
        t2[k] = p.column(1) * sc;
        d[k] = Mat2::new(w.d1x[k], w.d2x[k], w.d1y[k], w.d2y[k]);
        frame[k] = Qr2 {
            c,
            s,
            r11: w.r11[k],
            r12,
            r22: w.r22[k],
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::qr::qr;
    use crate::mpm::laws::constitutive::frame_gradient_qr;

    /// The one-at-a-time update that [`update_frames`] must reproduce.
    fn one_by_one(
        e: &YarnEnergy,
        plastic: bool,
        l0: f64,
        vol: f64,
        d: Mat2,
    ) -> (Mat2, Qr2, Vec2, Vec2) {
        let (d1, mut d2) = (d.column(0).into_owned(), d.column(1).into_owned());
        let inv_l0 = 1.0 / l0;
        let mut r = qr(&(Mat2::from_columns(&[d1, d2]) * inv_l0));
        if plastic {
            let (r12, r22) = e.return_map(r.r12, r.r22);
            if r12 != r.r12 || r22 != r.r22 {
                d2 = r.rotate(Vec2::new(r12, r22)) * l0;
                r = qr(&(Mat2::from_columns(&[d1, d2]) * inv_l0));
            }
        }
        let (t1, t2) = frame_gradient_qr(e, &r, l0, vol);
        (Mat2::from_columns(&[d1, d2]), r, t1, t2)
    }

    #[test]
    fn batches_give_the_bits_of_one_at_a_time() {
        let e = YarnEnergy {
            k: 2000.0,
            gamma: 600.0,
            normal: 900.0,
            friction: 0.3,
        };
        // stretched, compressed, sheared beyond and within the cone,
        // inverted, degenerate and non-finite frames, 150 of them (three
        // batches, the last one partial)
        let n = 150;
        let mut d: Vec<Mat2> = (0..n)
            .map(|i| {
                let t = i as f64;
                let l = 0.01 * (1.0 + 0.3 * (0.7 * t).sin());
                let stretch = 1.0 + 0.05 * (1.3 * t).cos();
                let squeeze = 1.0 + 0.4 * (0.37 * t).sin();
                let shear = 2.0 * (0.91 * t).cos();
                let a = 0.4 * t;
                let (c, s) = (a.cos(), a.sin());
                let d1 = Vec2::new(c, s) * (l * stretch);
                let d2 = Vec2::new(-s, c) * (l * squeeze) + d1 * shear;
                Mat2::from_columns(&[d1, d2])
            })
            .collect();
        d[7] = Mat2::zeros();
        d[8] = Mat2::new(0.01, 0.0, 0.0, -0.01);
        d[9][(1, 1)] = f64::NAN;
        d[10][(0, 0)] = f64::INFINITY;
        let l0: Vec<f64> = (0..n)
            .map(|i| 0.01 * (1.0 + 0.2 * (i as f64).sin()))
            .collect();
        let vol: Vec<f64> = (0..n).map(|i| 1e-5 * (1.0 + 0.1 * i as f64)).collect();
        for plastic in [true, false] {
            let mut dd = d.clone();
            let mut frame = vec![qr(&Mat2::identity()); n];
            let (mut t1, mut t2) = (vec![Vec2::zeros(); n], vec![Vec2::zeros(); n]);
            let frames = Frames {
                l0: &l0,
                vol: &vol,
                d: &mut dd,
                frame: &mut frame,
                t1: &mut t1,
                t2: &mut t2,
            };
            update_frames(&e, plastic, frames);
            let mut slow_cases = 0;
            for k in 0..n {
                let (d_ref, f_ref, t1_ref, t2_ref) = one_by_one(&e, plastic, l0[k], vol[k], d[k]);
                // bits, except that any NaN equals any NaN (SIMD and scalar code may
                // give NaNs of different sign or payload)
                let bits = |m: &[f64]| {
                    m.iter()
                        .map(|x| if x.is_nan() { u64::MAX } else { x.to_bits() })
                        .collect::<Vec<_>>()
                };
                assert_eq!(
                    bits(dd[k].as_slice()),
                    bits(d_ref.as_slice()),
                    "d {k} plastic {plastic}"
                );
                let fb = |f: &Qr2| bits(&[f.c, f.s, f.r11, f.r12, f.r22]);
                assert_eq!(fb(&frame[k]), fb(&f_ref), "frame {k} plastic {plastic}");
                assert_eq!(bits(t1[k].as_slice()), bits(t1_ref.as_slice()), "t1 {k}");
                assert_eq!(bits(t2[k].as_slice()), bits(t2_ref.as_slice()), "t2 {k}");
                let r = qr(&(d[k] * (1.0 / l0[k])));
                let ok = r.r22 <= 1.0
                    && e.gamma * r.r12.abs() * r.r22.max(R22_MIN)
                        > e.friction * e.normal * (1.0 - r.r22.max(R22_MIN));
                slow_cases += ok as usize;
            }
            // the cases exercise the return mapping's `ln` branch too
            assert!(slow_cases > 10, "{slow_cases}");
        }
    }
}
