//! The energy's derivatives against central finite differences and the
//! explicit force laws, the PSD projection of the blocks, the pin
//! projection and the solve, on hand-made element lists: stretched,
//! sheared and compressed (`r22 < 1`) quadrature particles, bent vertices
//! and the attractor.

use super::problem::Elements;
use super::*;
use crate::math::dual::jacobian;
use crate::math::psd::{eigen_sym, project_psd, symmetrize};
use crate::math::qr::qr;
use crate::math::Mat2;
use crate::mpm::laws::bending::{bend_gradient, bend_gradient_edges, project_bend};
use crate::mpm::laws::constitutive::frame_gradient;
use crate::mpm::laws::constitutive::{quad_gradient, stress};
use crate::mpm::machinery::particles::NONE;
use crate::testing::Rng;

/// The built-in material's constants.
fn material() -> YarnEnergy {
    YarnEnergy {
        k: 1000.0,
        gamma: 500.0,
        normal: 1400.0,
        friction: 0.3,
    }
}

/// A frame `G = Q R` with the given factor entries at angle `a`.
fn frame(a: f64, r11: f64, r12: f64, r22: f64) -> Mat2 {
    let q = Mat2::new(a.cos(), -a.sin(), a.sin(), a.cos());
    q * Mat2::new(r11, r12, 0.0, r22)
}

/// 30 nodes; 6 quadrature particles stretched, sheared and compressed
/// (r22 0.9 .. 1.05), 5 bent vertices, the attractor when `attractor`, a
/// pin on the first quadrature particle's terms when `pinned`; every
/// element's terms on random nodes.
fn problem(pinned: bool, attractor: bool) -> Problem {
    let mut r = Rng::new(7);
    let nn = 30;
    let (l0, dt) = (0.05, 1e-2);
    let states = [
        (1.1, 0.1, 0.9),
        (0.95, -0.2, 0.95),
        (1.02, 0.05, 1.05),
        (1.0, 0.3, 0.97),
        (0.9, 0.0, 0.8),
        (1.05, -0.1, 0.99),
    ];
    let mut quads = Vec::new();
    let mut quad_terms = Vec::new();
    for (k, &(r11, r12, r22)) in states.iter().enumerate() {
        let g = frame(0.7 * k as f64, r11, r12, r22) * l0;
        let start = quad_terms.len() as u32;
        for n in 0..12 {
            quad_terms.push(QuadTerm {
                node: ((5 * k + 2 * n) % nn) as u32,
                c1: r.sym(2e-3),
                c2: r.sym(2e-3),
            });
        }
        quads.push(QuadElem {
            left: k as u32,
            l0,
            vol: 0.01 * l0,
            d1: g.column(0).into_owned(),
            d2: g.column(1).into_owned(),
            start,
            end: quad_terms.len() as u32,
        });
    }
    let mut bends = Vec::new();
    let mut bend_terms = Vec::new();
    for k in 0..5 {
        let x0 = Vec2::new(0.1 * k as f64, 0.0);
        let a = 0.3 + 0.2 * k as f64;
        let x = [
            x0,
            x0 + Vec2::new(l0, 0.0),
            x0 + Vec2::new(l0 * (1.0 + a.cos()), l0 * a.sin()),
        ];
        let start = bend_terms.len() as u32;
        for n in 0..14 {
            // vertex coefficients c_k, as edge coefficients a = differences
            let c = [r.sym(2e-3), r.sym(2e-3), r.sym(2e-3)];
            bend_terms.push(BendTerm {
                node: ((3 * k + 2 * n + 1) % nn) as u32,
                a: [c[1] - c[0], c[2] - c[1]],
            });
        }
        bends.push(BendElem {
            kappa0: 0.1 * k as f64 - 0.2,
            inv_len: 1.0 / l0,
            e: [x[1] - x[0], x[2] - x[1]],
            start,
            end: bend_terms.len() as u32,
        });
    }
    let model = Model {
        energy: material(),
        bending: 1e-3,
        attractor: attractor.then_some((Vec2::new(0.5, 0.5), 30.0)),
    };
    let node_x = if attractor {
        (0..nn).map(|_| Vec2::new(r.unit(), r.unit())).collect()
    } else {
        Vec::new()
    };
    let rows = if pinned {
        let mut w = Weights {
            node: [NONE; 9],
            w: [0.0; 9],
        };
        for n in 0..9 {
            w.node[n] = (2 * n) as u32;
            w.w[n] = 0.05 + 0.1 * n as f64;
        }
        vec![(w, Vec2::new(0.1, -0.2), 0)]
    } else {
        Vec::new()
    };
    let mass = (0..nn).map(|_| 1e-3 * (0.5 + r.unit())).collect();
    let elements = Elements {
        quads,
        quad_terms,
        bends,
        bend_terms,
    };
    let mut p = Problem::assemble((0..nn).collect(), mass, dt, &model, node_x, elements, rows);
    p.vstar = r.vec(nn, 1.0);
    p
}

fn rel(a: &[Vec2], b: &[Vec2]) -> f64 {
    let d: Vec<Vec2> = a.iter().zip(b).map(|(a, b)| a - b).collect();
    dot(&d, &d).sqrt() / dot(b, b).sqrt()
}

/// The gradient of `p`'s energy at `v` by central differences, step `h`
/// per component.
fn fd_gradient(p: &Problem, v: &[Vec2], h: f64) -> Vec<Vec2> {
    let mut fd = vec![Vec2::zeros(); v.len()];
    for i in 0..v.len() {
        for c in 0..2 {
            let (mut a, mut b) = (v.to_vec(), v.to_vec());
            a[i][c] += h;
            b[i][c] -= h;
            fd[i][c] = (p.energy(&a) - p.energy(&b)) / (2.0 * h);
        }
    }
    fd
}

/// The Hessian-vector product `H d` of `p` at `v` by central differences
/// of the gradient, step `h` along `d`.
fn fd_hess_vec(p: &Problem, v: &[Vec2], d: &[Vec2], h: f64) -> Vec<Vec2> {
    let a: Vec<Vec2> = v.iter().zip(d).map(|(v, d)| v + d * h).collect();
    let b: Vec<Vec2> = v.iter().zip(d).map(|(v, d)| v - d * h).collect();
    let (ga, gb) = (p.gradient(&a), p.gradient(&b));
    ga.iter()
        .zip(&gb)
        .map(|(a, b)| (a - b) / (2.0 * h))
        .collect()
}

/// Asserts that every entry of the 4x4 block `got` is within `tol` of
/// `want`'s; `what` names the case in the message.
fn assert_blocks_close(got: &[[f64; 4]; 4], want: &[[f64; 4]; 4], tol: f64, what: &str) {
    for i in 0..4 {
        for j in 0..4 {
            assert!(
                (got[i][j] - want[i][j]).abs() <= tol,
                "{what} ({i}, {j}): {} vs {}",
                got[i][j],
                want[i][j]
            );
        }
    }
}

#[test]
fn stress_and_bending_gradient_are_the_explicit_force_laws() {
    let e = material();
    let mut r = Rng::new(1);
    let mut worst: f64 = 0.0;
    let mut compressed = 0;
    for k in 0..2000 {
        // stretched, sheared, compressed (r22 < 1, some below R22_MIN) and
        // inverted frames, and fully random ones
        let g = if k % 2 == 0 {
            frame(
                r.sym(7.0),
                0.5 + r.unit(),
                r.sym(1.0),
                1.2 * r.unit() - 0.05,
            )
        } else {
            Mat2::new(r.sym(3.0), r.sym(3.0), r.sym(3.0), r.sym(3.0))
        };
        compressed += (qr(&g).r22 < 1.0) as usize;
        let (l0, vol) = (0.01 + r.unit(), 0.1 + r.unit());
        let d = g * l0;
        let (t1, t2) = frame_gradient(&e, &d, l0, vol);
        let t = quad_gradient(&e, [d[(0, 0)], d[(1, 0)], d[(0, 1)], d[(1, 1)]], l0, vol);
        let scale = t1.norm().max(t2.norm()).max(1e-300);
        for (a, b) in [t1.x, t1.y, t2.x, t2.y].iter().zip(t) {
            worst = worst.max((a - b).abs() / scale);
        }
        let p = e.stress(&g);
        let pg = stress(&e, [g[(0, 0)], g[(0, 1)], g[(1, 0)], g[(1, 1)]]);
        assert_eq!([p[(0, 0)], p[(0, 1)], p[(1, 0)], p[(1, 1)]], pg);
    }
    assert!(compressed > 500, "{compressed}");
    // same operations: 1e-13 relative at most (bitwise in practice)
    eprintln!("quad gradient vs frame_gradient: {worst:.2e} ({compressed} of 2000 with r22 < 1)");
    assert!(
        worst <= 1e-13,
        "quad gradient vs frame_gradient: {worst:.3e}"
    );

    // bending: the summed vertex gradients are minus vertex_forces
    let n = 12;
    let rest: Vec<Vec2> = (0..n)
        .map(|i| Vec2::new(0.03 * i as f64, 0.01 * (0.5 * i as f64).sin()))
        .collect();
    let mut vert = crate::mpm::machinery::particles::Vertices {
        bend: crate::mpm::laws::bending::rest_of_curve(&rest),
        q_left: vec![NONE; n],
        q_right: vec![NONE; n],
        ..Default::default()
    };
    vert.x = rest
        .iter()
        .enumerate()
        .map(|(i, x)| x + Vec2::new(0.0, 0.004 * (i as f64 * 1.3).cos()))
        .collect();
    let b = 2e-3;
    let mut f = vec![Vec2::zeros(); n];
    crate::mpm::laws::vertex_forces::vertex_forces(&vert, &[], b, 0..n, &mut f);
    let mut g = vec![Vec2::zeros(); n];
    for j in 1..n - 1 {
        let x = &vert.x;
        let gj = bend_gradient(
            [
                x[j - 1].x,
                x[j - 1].y,
                x[j].x,
                x[j].y,
                x[j + 1].x,
                x[j + 1].y,
            ],
            b,
            vert.bend[j].kappa0,
            vert.bend[j].inv_len,
        );
        for k in 0..3 {
            g[j + k - 1] += Vec2::new(gj[2 * k], gj[2 * k + 1]);
        }
    }
    let minus: Vec<Vec2> = g.iter().map(|g| -g).collect();
    let fmax = f.iter().map(|f| f.norm()).fold(0.0, f64::max);
    assert!(fmax > 1e-3, "{fmax}");
    // same formula, other summation order: 1e-13 relative
    eprintln!("bending gradient vs vertex_forces: {:.2e}", rel(&minus, &f));
    assert!(rel(&minus, &f) < 1e-13, "{:.3e}", rel(&minus, &f));
}

#[test]
fn gradient_matches_central_differences_of_the_energy() {
    for attractor in [false, true] {
        let p = problem(false, attractor);
        let v = Rng::new(3).vec(p.len(), 2.0);
        let g = p.gradient(&v);
        let h = 1e-6;
        let fd = fd_gradient(&p, &v, h);
        // tolerance 1e-6 relative (central differences: O(h^2) plus round-off)
        let e = rel(&g, &fd);
        eprintln!("gradient vs central differences (attractor {attractor}): {e:.2e}");
        assert!(e < 1e-6, "gradient relative error {e:.3e}");
        // the elastic part is not negligible
        let m: Vec<Vec2> = (0..v.len())
            .map(|i| (v[i] - p.vstar[i]) * p.mass[i])
            .collect();
        assert!(rel(&g, &m) > 1e-2, "{:.3e}", rel(&g, &m));
    }
}

#[test]
fn hessian_vector_product_matches_central_differences_of_the_gradient() {
    let p = problem(false, true);
    let mut r = Rng::new(5);
    let v = r.vec(p.len(), 2.0);
    // every kind of state is present at v
    let fr = p.frames(&v);
    let r22: Vec<f64> = fr
        .iter()
        .map(|d| qr(&Mat2::new(d[0], d[2], d[1], d[3])).r22 / 0.05)
        .collect();
    assert!(
        r22.iter().any(|&r| r < 0.95) && r22.iter().any(|&r| r > 1.0),
        "{r22:?}"
    );
    let d = r.vec(p.len(), 1.0);
    let fd = fd_hess_vec(&p, &v, &d, 1e-6);
    let hd = p.hess_vec(&v, &d);
    // tolerance 1e-6 relative
    let e = rel(&hd, &fd);
    eprintln!("exact Hessian-vector product vs central differences: {e:.2e}");
    assert!(e < 1e-6, "Hessian-vector product relative error {e:.3e}");
    // the elastic part is not negligible in this test
    let md: Vec<Vec2> = d.iter().zip(&p.mass).map(|(d, m)| d * *m).collect();
    assert!(rel(&hd, &md) > 1e-2);
    // each part alone: the same product with one kind of element
    for part in 0..3 {
        let mut k = p.blocks(&v, false);
        if part != 0 {
            k.quad.iter_mut().for_each(|b| *b = [[0.0; 4]; 4]);
        }
        if part != 1 {
            k.bend.iter_mut().for_each(|b| *b = [[0.0; 4]; 4]);
        }
        if part != 2 {
            k.attr.iter_mut().for_each(|b| *b = [[0.0; 2]; 2]);
        }
        let y = p.hess_vec_blocks(&k, &d);
        assert!(rel(&y, &md) > 1e-3, "part {part}: {:.3e}", rel(&y, &md));
    }
    // the diagonal from the blocks is the diagonal of H
    let k = p.blocks(&v, false);
    let mut diag = vec![Vec2::zeros(); p.len()];
    for i in 0..p.len() {
        for c in 0..2 {
            let mut e = vec![Vec2::zeros(); p.len()];
            e[i][c] = 1.0;
            diag[i][c] = p.hess_vec_blocks(&k, &e)[i][c].max(p.mass[i]);
        }
    }
    assert!(rel(&p.diagonal(&k), &diag) < 1e-13);
}

#[test]
fn psd_projection_keeps_pd_blocks_and_removes_negative_curvature() {
    let e = material();
    let mut r = Rng::new(9);
    let (mut pd, mut indefinite) = (0, 0);
    for k in 0..400 {
        let g = frame(
            r.sym(7.0),
            0.8 + 0.4 * r.unit(),
            r.sym(0.6),
            0.8 + 0.3 * r.unit(),
        );
        let l0 = 0.05;
        let d = g * l0;
        let mut h = jacobian([d[(0, 0)], d[(1, 0)], d[(0, 1)], d[(1, 1)]], |x| {
            quad_gradient(&e, x, l0, 1e-3)
        });
        symmetrize(&mut h);
        let (l, vecs) = eigen_sym(&h);
        let scale = l.iter().fold(0.0f64, |m, l| m.max(l.abs()));
        // the decomposition reconstructs the block to 1e-12 of its size
        for i in 0..4 {
            for j in 0..4 {
                let s: f64 = (0..4).map(|m| l[m] * vecs[i][m] * vecs[j][m]).sum();
                assert!((s - h[i][j]).abs() <= 1e-12 * scale);
            }
        }
        let p = project_psd(&h);
        if l.iter().all(|&l| l > 0.0) {
            pd += 1;
            assert_eq!(p, h);
        } else {
            indefinite += 1;
            let (lp, _) = eigen_sym(&p);
            // no negative eigenvalue beyond round-off (1e-12 of the block)
            assert!(lp.iter().all(|&l| l >= -1e-12 * scale), "{lp:?}");
            // the positive part is kept
            let pos: f64 = l.iter().filter(|&&l| l > 0.0).sum();
            let tr: f64 = (0..4).map(|i| p[i][i]).sum();
            assert!((tr - pos).abs() <= 1e-12 * scale, "{tr} vs {pos}");
        }
        if k % 4 == 0 {
            // a bending block (6x6) too
            let a = r.sym(2.0);
            let x = [0.0, 0.0, l0, 0.0, l0 * (1.0 + a.cos()), l0 * a.sin()];
            let k0 = 0.3 + r.sym(0.4);
            let mut hb = jacobian(x, |x| bend_gradient(x, 1e-3, k0, 1.0 / l0));
            symmetrize(&mut hb);
            let (lp, _) = eigen_sym(&project_psd(&hb));
            let (lb, vb) = eigen_sym(&hb);
            let sb = lb.iter().fold(0.0f64, |m, l| m.max(l.abs()));
            // converged within the fixed sweeps: reconstructs to 1e-12
            for i in 0..6 {
                for j in 0..6 {
                    let s: f64 = (0..6).map(|m| lb[m] * vb[i][m] * vb[j][m]).sum();
                    assert!((s - hb[i][j]).abs() <= 1e-12 * sb, "bending block");
                }
            }
            assert!(lp.iter().all(|&l| l >= -1e-12 * sb), "{lp:?}");
        }
    }
    eprintln!("quadrature blocks: {pd} PD, {indefinite} indefinite of 400");
    assert!(
        pd > 20 && indefinite > 20,
        "{pd} PD, {indefinite} indefinite"
    );
}

#[test]
fn pin_projection_keeps_the_pins_and_solve_reaches_the_constrained_minimum() {
    let cases = [
        (true, Precond::Stiff),
        (true, Precond::Jacobi),
        (false, Precond::Stiff),
    ];
    for (psd, precond) in cases {
        let p = problem(true, true);
        let mut r = Rng::new(11);
        let mut x = r.vec(p.len(), 1.0);
        p.project(&mut x);
        // A Pi x = 0 to round-off
        assert!(p.apply_a(&x)[0].norm() < 1e-14, "{:?}", p.apply_a(&x));
        let mut v = r.vec(p.len(), 1.0);
        p.make_feasible(&mut v);
        assert!((p.apply_a(&v)[0] - Vec2::new(0.1, -0.2)).norm() < 1e-14);
        let s = Settings {
            psd,
            precond,
            ..Settings::default()
        };
        let sol = solve(&p, &s).unwrap();
        assert!((p.apply_a(&sol.v)[0] - Vec2::new(0.1, -0.2)).norm() < 1e-12);
        let mut g = p.gradient(&sol.v);
        let mut g0 = p.gradient(&{
            let mut v = p.vstar.clone();
            p.make_feasible(&mut v);
            v
        });
        p.project_dual(&mut g);
        p.project_dual(&mut g0);
        // converged to the stated tolerance (`rel_tol` of the start)
        assert!(dot(&g, &g).sqrt() <= s.rel_tol * dot(&g0, &g0).sqrt());
        // no feasible neighbour is lower
        let e = p.energy(&sol.v);
        for k in 0..20 {
            let mut d = Rng::new(100 + k).vec(p.len(), 1e-3);
            p.project(&mut d);
            let t: Vec<Vec2> = sol.v.iter().zip(&d).map(|(v, d)| v + d).collect();
            assert!(p.energy(&t) >= e, "a feasible neighbour is lower");
        }
        eprintln!(
            "small problem (psd {psd}, {precond:?}): {} Newton, {} CG iterations",
            sol.stats.newton, sol.stats.cg
        );
    }
}

/// The closed-form block of a pure fibre stretch is the dual-number
/// Jacobian of the stress (to 1e-12 of the block) on stretched and
/// compressed random frames, and its projection is the PSD projection of
/// that Jacobian (to 1e-12).
#[test]
fn spring_block_is_the_exact_and_the_projected_block() {
    let e = YarnEnergy {
        k: 2e5,
        gamma: 0.0,
        normal: 0.0,
        friction: 0.0,
    };
    let mut r = Rng::new(5);
    let (l0, vol) = (0.01, 1e-4);
    let mut compressed = 0;
    for _ in 0..200 {
        let a = r.sym(7.0);
        let len = l0 * (0.5 + r.unit());
        compressed += (len < l0) as usize;
        let d = [len * a.cos(), len * a.sin(), r.sym(0.02), r.sym(0.02)];
        let mut h = jacobian(d, |d| quad_gradient(&e, d, l0, vol));
        symmetrize(&mut h);
        let scale = vol * e.k / (l0 * l0);
        for psd in [false, true] {
            let want = if psd { project_psd(&h) } else { h };
            let got = energy::spring_block(e.k, d, l0, vol, psd).unwrap();
            assert_blocks_close(&got, &want, 1e-12 * scale, &format!("psd {psd}"));
        }
    }
    assert!(compressed > 50 && compressed < 150, "{compressed}");
}

/// The closed-form projection of the bending blocks (edge coordinates) is
/// the Jacobi one: on 300 random joints (bent up to 2 rad either way, edge
/// lengths 0.5 to 1.5 of each other, any orientation, the rest curvature
/// near, at and far from the curvature) the blocks agree to 1e-11 of the
/// block, and each exact block far from rest has two negative
/// eigenvalues (one per invariant plane).
#[test]
fn closed_form_bending_projection_is_the_jacobi_projection() {
    let mut r = Rng::new(13);
    let (b, l0) = (1e-3, 0.02);
    let mut indefinite = 0;
    for k in 0..300 {
        let (a, turn) = (r.sym(7.0), r.sym(4.0));
        let (n1, n2) = (l0 * (0.5 + r.unit()), l0 * (0.5 + r.unit()));
        let e = [
            n1 * a.cos(),
            n1 * a.sin(),
            n2 * (a + turn).cos(),
            n2 * (a + turn).sin(),
        ];
        let kappa =
            crate::mpm::laws::bending::curvature(Vec2::new(e[0], e[1]), Vec2::new(e[2], e[3]));
        let k0 = match k % 3 {
            0 => kappa,
            1 => kappa + 1e-9 * r.sym(1.0),
            _ => kappa + r.sym(2.0),
        };
        let mut h = jacobian(e, |e| bend_gradient_edges(e, b, k0, 1.0 / l0));
        symmetrize(&mut h);
        let (l, _) = eigen_sym(&h);
        let scale = l.iter().fold(0.0f64, |m, l| m.max(l.abs()));
        if k % 3 == 2 && l.iter().filter(|&&l| l < -1e-9 * scale).count() == 2 {
            indefinite += 1;
        }
        let (want, got) = (
            project_psd(&h),
            project_bend(&h, e, bend_gradient_edges(e, b, k0, 1.0 / l0)),
        );
        let what = format!("joint {k} (scale {scale:.3e})");
        assert_blocks_close(&got, &want, 1e-11 * scale, &what);
    }
    eprintln!("{indefinite} of 100 joints far from rest with two negative eigenvalues");
    assert!(indefinite == 100, "{indefinite} of 100");
}

/// The obstacles' contact terms: gradient and Hessian-vector product
/// against central differences (away from the kink at `v . n = 0`), and
/// on nodes with no element the solve's velocity is the explicit normal
/// law's (`contact::obstacle_normal`: `share` of the inward normal
/// velocity removed) for `c = share / (1 - share)`.
#[test]
fn contact_terms_are_the_explicit_normal_law() {
    let mut p = problem(false, false);
    let mut r = Rng::new(11);
    let contacts: Vec<ContactTerm> = (0..p.len())
        .step_by(3)
        .map(|i| {
            let a = 6.0 * r.unit();
            ContactTerm {
                node: i as u32,
                n: Vec2::new(a.cos(), a.sin()),
                w: 5.0 * r.unit() * p.mass[i],
            }
        })
        .collect();
    p.set_contacts(contacts.clone());
    let v = r.vec(p.len(), 2.0);
    let active = contacts
        .iter()
        .filter(|c| v[c.node as usize].dot(&c.n) < 0.0)
        .count();
    assert!(active > 1 && active < contacts.len(), "{active}");
    let g = p.gradient(&v);
    let h = 1e-6;
    let fd = fd_gradient(&p, &v, h);
    // tolerance 1e-6 relative, as for the elements
    assert!(rel(&g, &fd) < 1e-6, "{:.3e}", rel(&g, &fd));
    let d = r.vec(p.len(), 1.0);
    let fd = fd_hess_vec(&p, &v, &d, h);
    let hd = p.hess_vec(&v, &d);
    assert!(rel(&hd, &fd) < 1e-6, "{:.3e}", rel(&hd, &fd));
    // nodes without elements: the minimiser is the law, node by node
    let n = 8;
    let mut q = problem(false, false);
    q.quads.clear();
    q.quad_terms.clear();
    q.bends.clear();
    q.bend_terms.clear();
    q.nodes.truncate(n);
    q.mass.truncate(n);
    q.vstar.truncate(n);
    let shares = [0.0, 0.1, 0.3, 0.5, 0.7, 0.9, 0.99, 0.999];
    let terms = (0..n)
        .map(|i| {
            let a = 0.8 * i as f64;
            ContactTerm {
                node: i as u32,
                n: Vec2::new(a.cos(), a.sin()),
                w: shares[i] / (1.0 - shares[i]) * q.mass[i],
            }
        })
        .collect::<Vec<_>>();
    q.set_contacts(terms.clone());
    let sol = solve(&q, &Settings::default()).unwrap();
    for (i, t) in terms.iter().enumerate() {
        let vs = q.vstar[i];
        let vn = vs.dot(&t.n);
        let law = if vn < 0.0 {
            vs - t.n * (vn * shares[i])
        } else {
            vs
        };
        let e = (sol.v[i] - law).norm() / vs.norm();
        assert!(
            e < 1e-9,
            "node {i}, share {}: {:?} vs {law:?}",
            shares[i],
            sol.v[i]
        );
    }
}
