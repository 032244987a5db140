//! The energy's derivatives against central finite differences, the pin
//! projection, and the solve, on a bent, stretched (and partly compressed)
//! yarn with hand-made stencils.

use super::*;

/// A small deterministic generator (LCG) of numbers in [0, 1).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn vec(&mut self, n: usize, s: f64) -> Vec<Vec2> {
        (0..n)
            .map(|_| Vec2::new(s * (self.next() - 0.5), s * (self.next() - 0.5)))
            .collect()
    }
}

/// 8 vertices on a bent curve, segments stretched 10 % or compressed 5 %
/// (an indefinite transverse term), 30 nodes, overlapping stencils.
fn problem(pinned: bool) -> Problem {
    let mut r = Lcg(7);
    let (nv, nn) = (8, 30);
    let x0: Vec<Vec2> = (0..nv)
        .map(|k| Vec2::new(0.1 * k as f64, 0.02 * (k * k) as f64))
        .collect();
    let weights = (0..nv)
        .map(|k| {
            let mut w = Weights {
                node: [NONE; 9],
                w: [0.0; 9],
            };
            let raw: Vec<f64> = (0..9).map(|_| 0.1 + r.next()).collect();
            let sum: f64 = raw.iter().sum();
            for (n, r) in raw.iter().enumerate() {
                w.node[n] = ((3 * k + n) % nn) as u32;
                w.w[n] = r / sum;
            }
            w
        })
        .collect::<Vec<_>>();
    let springs = (0..nv - 1)
        .map(|k| {
            let l = (x0[k + 1] - x0[k]).norm();
            let f = if k % 3 == 1 { 1.05 } else { 1.0 / 1.1 };
            Spring {
                left: k,
                l0: l * f,
                c: 1e5,
            }
        })
        .collect();
    let rows = if pinned {
        vec![(weights[0], Vec2::new(0.1, -0.2), 0)]
    } else {
        Vec::new()
    };
    let mut p = Problem {
        nodes: (0..nn).collect(),
        mass: (0..nn).map(|_| 0.5 + r.next()).collect(),
        vstar: r.vec(nn, 1.0),
        dt: 1e-2,
        x0,
        weights,
        springs,
        rows,
        chol: Vec::new(),
    };
    p.factor();
    p
}

fn rel(a: &[Vec2], b: &[Vec2]) -> f64 {
    let d: Vec<Vec2> = a.iter().zip(b).map(|(a, b)| a - b).collect();
    dot(&d, &d).sqrt() / dot(b, b).sqrt()
}

#[test]
fn gradient_matches_central_differences_of_the_energy() {
    let p = problem(false);
    let v = Lcg(3).vec(p.len(), 2.0);
    let g = p.gradient(&v);
    let h = 1e-6;
    let mut fd = vec![Vec2::zeros(); v.len()];
    for i in 0..v.len() {
        for c in 0..2 {
            let (mut a, mut b) = (v.clone(), v.clone());
            a[i][c] += h;
            b[i][c] -= h;
            fd[i][c] = (p.energy(&a) - p.energy(&b)) / (2.0 * h);
        }
    }
    // tolerance 1e-6 relative (central differences: O(h^2) plus round-off)
    let e = rel(&g, &fd);
    assert!(e < 1e-6, "gradient relative error {e:.3e}");
}

#[test]
fn hessian_vector_product_matches_central_differences_of_the_gradient() {
    let p = problem(false);
    let mut r = Lcg(5);
    let v = r.vec(p.len(), 2.0);
    let d = r.vec(p.len(), 1.0);
    let h = 1e-6;
    let a: Vec<Vec2> = v.iter().zip(&d).map(|(v, d)| v + d * h).collect();
    let b: Vec<Vec2> = v.iter().zip(&d).map(|(v, d)| v - d * h).collect();
    let (ga, gb) = (p.gradient(&a), p.gradient(&b));
    let fd: Vec<Vec2> = ga
        .iter()
        .zip(&gb)
        .map(|(a, b)| (a - b) / (2.0 * h))
        .collect();
    let hd = p.hess_vec(&v, &d);
    // tolerance 1e-6 relative
    let e = rel(&hd, &fd);
    assert!(e < 1e-6, "Hessian-vector product relative error {e:.3e}");
    // the elastic part is not negligible in this test
    let md: Vec<Vec2> = d.iter().zip(&p.mass).map(|(d, m)| d * *m).collect();
    assert!(rel(&hd, &md) > 1e-2);
}

#[test]
fn pin_projection_keeps_the_pins_and_solve_reaches_the_constrained_minimum() {
    let p = problem(true);
    let mut r = Lcg(11);
    let mut x = r.vec(p.len(), 1.0);
    p.project(&mut x);
    // A Pi x = 0 to round-off
    assert!(p.apply_a(&x)[0].norm() < 1e-14, "{:?}", p.apply_a(&x));
    let mut v = r.vec(p.len(), 1.0);
    p.make_feasible(&mut v);
    assert!((p.apply_a(&v)[0] - Vec2::new(0.1, -0.2)).norm() < 1e-14);
    for precond in [Precond::Jacobi, Precond::Stiff] {
        let settings = Settings {
            precond,
            ..Settings::default()
        };
        reaches_the_constrained_minimum(&p, &settings);
    }
}

/// The solve with `s` meets the pins, the tolerance, and no feasible
/// neighbour of its solution is lower.
fn reaches_the_constrained_minimum(p: &Problem, s: &Settings) {
    let sol = solve(p, s).unwrap();
    assert!((p.apply_a(&sol.v)[0] - Vec2::new(0.1, -0.2)).norm() < 1e-12);
    let mut g = p.gradient(&sol.v);
    let mut g0 = p.gradient(&{
        let mut v = p.vstar.clone();
        p.make_feasible(&mut v);
        v
    });
    p.project_dual(&mut g);
    p.project_dual(&mut g0);
    // converged to the stated tolerance (1e-8 of the start)
    assert!(dot(&g, &g).sqrt() <= 1e-8 * dot(&g0, &g0).sqrt());
    // no feasible neighbour is lower
    let e = p.energy(&sol.v);
    for k in 0..20 {
        let mut d = Lcg(100 + k).vec(p.len(), 1e-3);
        p.project(&mut d);
        let t: Vec<Vec2> = sol.v.iter().zip(&d).map(|(v, d)| v + d).collect();
        assert!(p.energy(&t) >= e, "a feasible neighbour is lower");
    }
    eprintln!(
        "small problem, {:?}: {} Newton, {} CG iterations",
        s.precond, sol.stats.newton, sol.stats.cg
    );
}
