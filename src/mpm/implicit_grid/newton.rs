//! Newton's method on `E(v)` ([`super::Problem`]) with a backtracking
//! (Armijo) line search, each Newton system `H d = -g` solved by conjugate
//! gradients with a Jacobi preconditioner on the Hessian-vector products
//! of the element blocks assembled once per Newton iteration (projected
//! onto PSD by default, [`crate::math::psd`]), in the subspace that keeps the pins (projected gradient and
//! preconditioner `Pi D^-1 Pi^T`). Serial, in a fixed order: the same bits
//! for any thread count.

use super::precond::StiffPrecond;
use super::{dot, Blocks, Problem};
use crate::math::Vec2;

/// Tolerances and caps of the solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// Converged when the projected gradient norm is at most this times
    /// its norm at the start (`v = v*` made feasible).
    pub rel_tol: f64,
    /// ... or at most this times `|M v*| + dt |F|`, `F` the elements'
    /// forces at unit strain ([`Problem::force_scale`]: stretch, shear and
    /// normal stiffness, bending, attractor): the round-off floor of the
    /// gradient, a strain of about this size.
    pub abs_tol: f64,
    /// Newton iterations before the step fails.
    pub max_newton: usize,
    /// CG iterations per Newton system.
    pub max_cg: usize,
    /// CG stops at this relative residual.
    pub cg_tol: f64,
    /// Line-search halvings before the step fails.
    pub max_halvings: usize,
    /// Project each element block onto the PSD cone (projected Newton);
    /// `false`: the exact Hessian (CG then stops at negative curvature).
    pub psd: bool,
    /// The CG preconditioner.
    pub precond: Precond,
}

/// The CG preconditioner of the Newton systems.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Precond {
    /// `diag H`.
    #[cfg_attr(not(test), allow(dead_code))]
    Jacobi,
    /// The fibre stretch exactly, the rest by its diagonal
    /// ([`super::precond`]), built at the solve's first Newton iterate and
    /// kept for the others (any fixed SPD preconditioner keeps CG exact;
    /// the Hessian changes little between Newton iterates).
    Stiff,
}

/// The preconditioner of one Newton system.
enum Pre<'a> {
    Jacobi(Vec<Vec2>),
    Stiff(&'a StiffPrecond),
}

impl Pre<'_> {
    /// `z = P^-1 r`.
    fn apply(&self, r: &[Vec2], z: &mut [Vec2]) {
        match self {
            Pre::Jacobi(d) => {
                for ((z, r), d) in z.iter_mut().zip(r).zip(d) {
                    *z = Vec2::new(r.x / d.x, r.y / d.y);
                }
            }
            Pre::Stiff(sp) => sp.apply(r, z),
        }
    }
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            rel_tol: 1e-8,
            abs_tol: 1e-11,
            max_newton: 50,
            max_cg: 2000,
            cg_tol: 1e-4,
            max_halvings: 40,
            psd: true,
            precond: Precond::Stiff,
        }
    }
}

/// What a solve took.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SolveStats {
    pub newton: usize,
    pub cg: usize,
}

/// The solution: grid velocities, the pin rows' impulses on the grid, and
/// the cost.
pub struct Solution {
    pub v: Vec<Vec2>,
    pub impulses: Vec<Vec2>,
    pub stats: SolveStats,
}

/// Minimises `E` from `v*` (made feasible). `Err` with a message when
/// Newton does not reach the tolerance within the caps.
pub fn solve(p: &Problem, s: &Settings) -> Result<Solution, String> {
    let mut v = p.vstar.clone();
    p.make_feasible(&mut v);
    let mv: f64 = p
        .vstar
        .iter()
        .zip(&p.mass)
        .map(|(v, m)| (v * *m).norm_squared())
        .sum::<f64>()
        .sqrt();
    let mut stats = SolveStats::default();
    let mut g = p.gradient(&v);
    let mut impulses = p.project_dual(&mut g);
    let g0 = dot(&g, &g).sqrt();
    let tol = (s.rel_tol * g0).max(s.abs_tol * (mv + p.dt() * p.force_scale()));
    let mut e = p.energy(&v);
    let mut stiff = None;
    let mut trial = vec![Vec2::zeros(); v.len()];
    loop {
        let gn = dot(&g, &g).sqrt();
        if gn <= tol || gn == 0.0 {
            return Ok(Solution { v, impulses, stats });
        }
        if stats.newton == s.max_newton {
            return Err(format!(
                "the implicit step's Newton solve did not converge in {} iterations \
                 (projected gradient {gn:.3e}, tolerance {tol:.3e}); try a smaller dt",
                s.max_newton
            ));
        }
        stats.newton += 1;
        let blocks = p.blocks(&v, s.psd);
        let pre = match s.precond {
            Precond::Jacobi => Pre::Jacobi(p.diagonal(&blocks)),
            Precond::Stiff => Pre::Stiff(stiff.get_or_insert_with(|| {
                let rows = p.stiff_rows(&v, &blocks);
                StiffPrecond::new(&p.diagonal_rest(&blocks, &rows), &rows)
            })),
        };
        let (mut d, its) = pcg(p, &blocks, &g, s, &pre);
        stats.cg += its;
        if !p.has_pins() && !p.has_external() {
            // The exact Newton step changes the momentum by -sum g (the
            // elastic blocks have no translation part); put CG's error in that mode right with
            // a uniform velocity, so the momentum is kept to round-off
            // (sum g = 0 at v* and stays so) at any CG tolerance.
            let mass: f64 = p.mass.iter().sum();
            let mut u = Vec2::zeros();
            for ((g, d), m) in g.iter().zip(&d).zip(&p.mass) {
                u -= g + d * *m;
            }
            let u = u / mass;
            d.iter_mut().for_each(|d| *d += u);
        }
        let slope = dot(&g, &d);
        let mut alpha = 1.0;
        let mut halvings = 0;
        loop {
            for ((t, v), d) in trial.iter_mut().zip(&v).zip(&d) {
                *t = v + d * alpha;
            }
            let et = p.energy(&trial);
            let armijo = et <= e + 1e-4 * alpha * slope;
            // near the solution E changes below its round-off (`L - l0`
            // of a segment 0.4 % stretched is known to about 1e-12 of
            // itself): then accept a step that shrinks the gradient
            let flat = (et - e).abs() <= 1e-9 * e.abs().max(1e-300);
            let (gt, lt) = if armijo || flat {
                let mut gt = p.gradient(&trial);
                let lt = p.project_dual(&mut gt);
                (Some(gt), lt)
            } else {
                (None, Vec::new())
            };
            if let Some(gt) = gt {
                if armijo || dot(&gt, &gt).sqrt() < gn {
                    std::mem::swap(&mut v, &mut trial);
                    e = et;
                    g = gt;
                    impulses = lt;
                    break;
                }
            }
            halvings += 1;
            alpha *= 0.5;
            if halvings > s.max_halvings {
                return Err(format!(
                    "the implicit step's line search found no decrease of the energy after \
                     {} halvings (Newton iteration {}, projected gradient {gn:.3e}); try a \
                     smaller dt",
                    s.max_halvings, stats.newton
                ));
            }
        }
    }
}

/// Preconditioned CG on `H d = -g` in the pin-keeping subspace; returns
/// `d` and the iterations. Stops at negative curvature (only with the
/// exact, unprojected blocks): with the iterate so far, or the
/// preconditioned steepest descent when that is the first. The work
/// vectors are allocated once per system.
fn pcg(p: &Problem, blocks: &Blocks, g: &[Vec2], s: &Settings, pre: &Pre) -> (Vec<Vec2>, usize) {
    let n = g.len();
    // z = Pi P^-1 Pi^T r, and |Pi^T r| (the residual that can vanish)
    let mut rp = vec![Vec2::zeros(); n];
    let mut precond = |r: &[Vec2], z: &mut [Vec2]| -> f64 {
        rp.copy_from_slice(r);
        p.project_dual(&mut rp);
        let norm = dot(&rp, &rp).sqrt();
        pre.apply(&rp, z);
        p.project(z);
        norm
    };
    let mut x = vec![Vec2::zeros(); n];
    let mut r: Vec<Vec2> = g.iter().map(|g| -g).collect();
    let mut z = vec![Vec2::zeros(); n];
    let r0 = precond(&r, &mut z);
    let mut pd = z.clone();
    let mut hp = vec![Vec2::zeros(); n];
    let mut rz = dot(&r, &z);
    for it in 0..s.max_cg {
        p.hess_vec_into(blocks, &pd, &mut hp);
        let curv = dot(&pd, &hp);
        if curv <= 0.0 {
            if it == 0 {
                return (z, 1);
            }
            return (x, it);
        }
        let a = rz / curv;
        for i in 0..n {
            x[i] += pd[i] * a;
            r[i] -= hp[i] * a;
        }
        let rn = precond(&r, &mut z);
        if rn <= s.cg_tol * r0 {
            return (x, it + 1);
        }
        let rz_new = dot(&r, &z);
        let beta = rz_new / rz;
        rz = rz_new;
        for i in 0..n {
            pd[i] = z[i] + pd[i] * beta;
        }
    }
    (x, s.max_cg)
}
