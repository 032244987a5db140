//! The yarn energy's stress against finite differences, and the
//! Mohr-Coulomb return mapping.

mod common;

use common::Rng;
use std::f64::consts::{FRAC_PI_2, PI};
use yarnsim::math::qr::qr;
use yarnsim::math::{Mat2, Vec2};
use yarnsim::mpm::laws::constitutive::{frame_gradient, YarnEnergy, R22_MIN};

fn energy() -> YarnEnergy {
    YarnEnergy {
        k: 1000.0,
        gamma: 500.0,
        normal: 1400.0,
        friction: 0.05,
    }
}

fn rotation(a: f64) -> Mat2 {
    Mat2::new(a.cos(), -a.sin(), a.sin(), a.cos())
}

/// Central finite difference of `f` with respect to each entry of `g`.
fn fd_gradient(f: impl Fn(&Mat2) -> f64, g: &Mat2, h: f64) -> Mat2 {
    let mut out = Mat2::zeros();
    for r in 0..2 {
        for c in 0..2 {
            let mut gp = *g;
            let mut gm = *g;
            gp[(r, c)] += h;
            gm[(r, c)] -= h;
            out[(r, c)] = (f(&gp) - f(&gm)) / (2.0 * h);
        }
    }
    out
}

/// Random `G = Q(a) R` with the factor entries drawn from the given ranges.
fn random_g(rng: &mut Rng, r11: (f64, f64), r12: (f64, f64), r22: (f64, f64)) -> Mat2 {
    let r = Mat2::new(
        rng.uniform(r11.0, r11.1),
        rng.uniform(r12.0, r12.1),
        0.0,
        rng.uniform(r22.0, r22.1),
    );
    rotation(rng.uniform(-PI, PI)) * r
}

fn check_stress(g: &Mat2, tol: f64) {
    let e = energy();
    let p = e.stress(g);
    let d = qr(g);
    // step relative to the smallest scale of the factorisation
    let h = 1e-6 * d.r11.min(d.r22.abs()).min(1.0);
    let fd = fd_gradient(|m| e.psi(m), g, h);
    let err = (p - fd).norm() / p.norm().max(1e-8);
    assert!(
        err < tol,
        "relative error {err:.3e} at G = {g}, R = ({}, {}, {}): P = {p}, FD = {fd}",
        d.r11,
        d.r12,
        d.r22
    );
}

/// Ranges of the factor entries `r11`, `r12`, `r22` of a random `G`
/// ([`random_g`]).
type FactorRanges = ((f64, f64), (f64, f64), (f64, f64));

/// `n` rounds of [`check_stress`] (relative tolerance 1e-6) on a random
/// `G` from each of `ranges`, drawn in that order.
fn check_random_stresses(rng: &mut Rng, n: usize, ranges: &[FactorRanges]) {
    for _ in 0..n {
        for &(r11, r12, r22) in ranges {
            let g = random_g(rng, r11, r12, r22);
            check_stress(&g, 1e-6);
        }
    }
}

#[test]
fn stress_matches_finite_differences_of_psi() {
    let mut rng = Rng::new(1);
    check_random_stresses(&mut rng, 2000, &[((0.3, 1.8), (-1.0, 1.0), (0.2, 0.99))]);
    // cross-section in tension (r22 > 1: no normal energy)
    check_random_stresses(&mut rng, 500, &[((0.3, 1.8), (-1.0, 1.0), (1.01, 2.0))]);
}

#[test]
fn stress_matches_finite_differences_near_degenerate() {
    let mut rng = Rng::new(2);
    // nearly crushed cross-section, nearly collapsed fiber, large shear
    check_random_stresses(
        &mut rng,
        500,
        &[
            ((0.5, 1.5), (-0.5, 0.5), (0.01, 0.05)),
            ((0.02, 0.1), (-0.05, 0.05), (0.3, 0.9)),
            ((0.8, 1.2), (-5.0, 5.0), (0.5, 0.95)),
        ],
    );
    // r22 just above the clamp
    let g = rotation(0.7) * Mat2::new(1.1, 0.3, 0.0, 3.0 * R22_MIN);
    check_stress(&g, 1e-6);
}

#[test]
fn stress_is_rotation_equivariant_and_zero_at_rest() {
    let e = energy();
    for a in [0.0, 0.3, 1.7, -2.5] {
        assert!(e.stress(&rotation(a)).norm() < 1e-12);
        let g = Mat2::new(1.1, 0.2, 0.0, 0.8);
        let p0 = e.stress(&g);
        let p1 = e.stress(&(rotation(a) * g));
        assert!((rotation(a) * p0 - p1).norm() < 1e-9 * p0.norm());
    }
}

#[test]
fn frame_gradient_is_energy_gradient_for_any_yarn_orientation() {
    // E(d) = V psi(d / l0) for a segment at angle `a`: the force vectors
    // used by the solver must be dE/dd1 and dE/dd2 whatever the orientation.
    let e = energy();
    let mut rng = Rng::new(3);
    for _ in 0..500 {
        let a = rng.uniform(-PI, PI);
        let l0 = rng.uniform(0.001, 0.02);
        let vol = l0;
        let rest = Mat2::from_columns(&[
            Vec2::new(a.cos(), a.sin()) * l0,
            Vec2::new(-a.sin(), a.cos()) * l0,
        ]);
        // deform: stretch, shear and compress in the fiber frame, then rotate
        let g = Mat2::new(
            rng.uniform(0.8, 1.2),
            rng.uniform(-0.3, 0.3),
            0.0,
            rng.uniform(0.5, 1.1),
        );
        let d = rotation(rng.uniform(-0.5, 0.5)) * rest * g * (1.0 / l0) * l0;
        let d = rotation(0.0) * d;
        let (t1, t2) = frame_gradient(&e, &d, l0, vol);
        let fd = fd_gradient(|m| vol * e.psi(&(m / l0)), &d, 1e-7 * l0);
        let ours = Mat2::from_columns(&[t1, t2]);
        let err = (ours - fd).norm() / ours.norm().max(1e-9);
        assert!(err < 1e-6, "orientation {a}: relative error {err:.3e}");
    }
}

#[test]
fn stretch_response_is_independent_of_orientation() {
    // A segment stretched 2 % along its own direction has the same tension
    // along the fiber whatever its angle (fails for QR of the world-frame F).
    let e = energy();
    let l0 = 0.01;
    let tension = |a: f64| {
        let t = Vec2::new(a.cos(), a.sin());
        let d = Mat2::from_columns(&[t * (1.02 * l0), yarnsim::math::perp(t) * l0]);
        let (t1, _) = frame_gradient(&e, &d, l0, l0);
        (t1.dot(&t), t1.dot(&yarnsim::math::perp(t)))
    };
    let (ref_t, _) = tension(0.0);
    assert!((ref_t - 1000.0 * 0.02).abs() < 1e-9, "{ref_t}");
    for a in [0.3, 0.785, 1.2, FRAC_PI_2, 2.5, -1.0] {
        let (t, n) = tension(a);
        assert!(
            (t - ref_t).abs() < 1e-9 * ref_t,
            "angle {a}: tension {t} vs {ref_t}"
        );
        assert!(n.abs() < 1e-9, "angle {a}: spurious normal force {n}");
    }
}

#[test]
fn return_mapping_free_expansion() {
    let e = energy();
    for (r12, r22) in [(0.3, 1.2), (-2.0, 1.0001), (0.0, 5.0)] {
        assert_eq!(e.return_map(r12, r22), (0.0, 1.0));
    }
}

#[test]
fn return_mapping_projects_onto_yield_surface_and_is_idempotent() {
    let e = energy();
    let mut rng = Rng::new(4);
    let mut projected = 0;
    for _ in 0..5000 {
        let r12 = rng.uniform(-2.0, 2.0);
        let r22 = rng.uniform(0.05, 1.3);
        let (a12, a22) = e.return_map(r12, r22);
        let f = e.yield_function(a12, a22);
        if r22 <= 1.0 {
            assert_eq!(a22, r22);
            if (a12 - r12).abs() > 0.0 {
                projected += 1;
                // on the surface, same sign, smaller magnitude
                assert!(f.abs() < 1e-9 * (1.0 + e.gamma * r12.abs()), "f = {f}");
                assert!(a12.abs() < r12.abs() && a12 * r12 >= 0.0);
            } else {
                assert!(f <= 1e-12, "inside states stay inside: f = {f}");
            }
        }
        // twice changes nothing
        assert_eq!(e.return_map(a12, a22), (a12, a22));
    }
    assert!(
        projected > 1000,
        "the sample must exercise the projection ({projected})"
    );
}

#[test]
fn return_mapping_is_in_stress_units() {
    // Doubling the shear stiffness halves the admissible r12 (the yield
    // surface bounds the shear stress gamma r12 r22, not r12 itself).
    let e1 = energy();
    let e2 = YarnEnergy {
        gamma: 2.0 * e1.gamma,
        ..e1
    };
    let (a, _) = e1.return_map(1.0, 0.9);
    let (b, _) = e2.return_map(1.0, 0.9);
    assert!((a - 2.0 * b).abs() < 1e-12, "{a} vs {b}");
    // and the bound scales with the normal stiffness
    let e3 = YarnEnergy {
        normal: 2.0 * e1.normal,
        ..e1
    };
    let (c, _) = e3.return_map(1.0, 0.9);
    assert!((c - 2.0 * a).abs() < 1e-12);
}
