//! Projected Newton on one yarn's step energy ([`super::energy`]) with
//! linear equality constraints per vertex, held by the filter of Baraff and
//! Witkin 1998 ("Large steps in cloth simulation"): a pinned vertex has
//! its velocity, a vertex in contact its normal velocity; every Newton
//! direction lies in the free subspace, so an iterate that starts feasible
//! stays feasible. The friction of the contacts enters as a smoothed
//! Coulomb term with a fixed normal impulse (the lagged friction of Li et
//! al. 2020, "Incremental Potential Contact", section 5), so the Newton
//! system stays symmetric positive definite and is solved exactly by a
//! banded Cholesky factorisation ([`super::banded`]): the Hessian of a
//! yarn couples each vertex to its two neighbours on either side
//! (bending), half-bandwidth 5 in the 2n unknowns; without bending, to its
//! neighbours only, by a block tridiagonal `LDL^T`
//! ([`super::block_tridiagonal`]).

use super::banded::Banded;
use super::block_tridiagonal::BlockTridiagonal;
use super::energy::{Block, Rod};
use crate::math::Vec2;

/// The per-vertex constraint of a solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Constraint {
    Free,
    /// The velocity is prescribed (a pin).
    Fixed(Vec2),
    /// `n . v = b` (a contact: `n` the outward unit normal).
    Normal {
        n: Vec2,
        b: f64,
    },
}

/// Smoothed Coulomb friction of a vertex in contact: tangent `t` (unit)
/// and the bound `mu lambda` of its tangential impulse.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Friction {
    pub t: Vec2,
    pub bound: f64,
}

/// Stated tolerances and caps of the solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// Converged when the free part of the gradient has fallen by this
    /// factor in the norm `|g|_{M^-1}` from the first iterate, or the
    /// Newton step is below [`Settings::step_tol`] of the largest velocity,
    /// or the line search can no longer lower the energy (round-off) with
    /// the gradient down by [`Settings::floor_tol`].
    pub rel_tol: f64,
    /// Converged, too, when `|g|_{M^-1}` is at most this (absolute, in
    /// sqrt(J): the square root of twice the kinetic energy of the
    /// velocity error it stands for); 0 by default.
    pub abs_tol: f64,
    pub step_tol: f64,
    pub floor_tol: f64,
    /// Converged, too, when the Newton step's predicted decrease `-g . d`
    /// is below this fraction of the energy (its round-off).
    pub decrease_tol: f64,
    pub max_newton: usize,
    /// Armijo backtracking halvings per Newton iteration.
    pub max_halvings: usize,
    /// Speed below which friction is viscous (the smoothing `eps_v` of
    /// the friction term): a yarn held by friction creeps at most this
    /// fast.
    pub eps_v: f64,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            rel_tol: 1e-10,
            abs_tol: 0.0,
            step_tol: 1e-13,
            floor_tol: 1e-6,
            decrease_tol: 1e-13,
            max_newton: 50,
            max_halvings: 40,
            eps_v: 1e-5,
        }
    }
}

/// `f0(u)` of the smoothed friction (Li et al. 2020, eq. 16: `u^2 / eps -
/// u^3 / (3 eps^2)` below `eps`, `u - eps / 3` above) and its first two
/// derivatives; `C^1`, convex, `f0' = 1` above `eps`.
fn f0(u: f64, eps: f64) -> (f64, f64, f64) {
    if u >= eps {
        (u - eps / 3.0, 1.0, 0.0)
    } else {
        (
            u * u / eps - u * u * u / (3.0 * eps * eps),
            2.0 * u / eps - u * u / (eps * eps),
            2.0 / eps - 2.0 * u / (eps * eps),
        )
    }
}

/// The Newton system of a yarn: the band of half-bandwidth 5 in the `2n`
/// unknowns with bending (a vertex coupled to the second one on), the
/// 2x2 blocks of a block tridiagonal matrix without it (the stretch
/// springs couple neighbours only; its factorisation chains one division
/// per vertex where the band's chains two rows' square roots and
/// divisions).
enum System {
    Band(Banded),
    Blocks(BlockTridiagonal),
}

impl System {
    fn new(n: usize, bends: bool) -> Self {
        if bends {
            System::Band(Banded::zeros(2 * n, 5))
        } else {
            System::Blocks(BlockTridiagonal::zeros(n))
        }
    }

    fn clear(&mut self) {
        match self {
            System::Band(a) => a.clear(),
            System::Blocks(t) => t.clear(),
        }
    }

    /// Adds the block `b` to `A(i, i + off)`, `off` 0 (the lower triangle
    /// of a diagonal block is read), 1 or 2 (with bending only).
    // the 2x2 blocks' entries read best as index loops
    #[allow(clippy::needless_range_loop)]
    fn add(&mut self, i: usize, off: usize, b: &Block) {
        match self {
            System::Band(a) => {
                for r in 0..2 {
                    let cols = if off == 0 { r + 1 } else { 2 };
                    for c in 0..cols {
                        a.add(2 * i + r, 2 * (i + off) + c, b[r][c]);
                    }
                }
            }
            System::Blocks(t) if off == 0 => t.add_diag(i, b),
            System::Blocks(t) => {
                debug_assert_eq!(off, 1, "no block beyond the next without bending");
                t.add_off(i, b);
            }
        }
    }

    /// Factors the system; `Err(vertex)` where it is not positive definite.
    fn factor(&mut self) -> Result<(), usize> {
        match self {
            System::Band(a) => a.factor().map_err(|row| row / 2),
            System::Blocks(t) => t.factor(),
        }
    }

    fn solve(&self, b: &mut [f64]) {
        match self {
            System::Band(a) => a.solve(b),
            System::Blocks(t) => t.solve(b),
        }
    }
}

/// The result of one solve.
#[derive(Clone, Debug)]
pub struct Solved {
    pub v: Vec<Vec2>,
    /// `dE/dv` at `v`, friction included: at a constrained vertex the
    /// impulse its constraint delivers.
    pub gradient: Vec<Vec2>,
    pub newton: usize,
}

fn project(c: &Constraint, g: Vec2) -> Vec2 {
    match *c {
        Constraint::Free => g,
        Constraint::Fixed(_) => Vec2::zeros(),
        Constraint::Normal { n, .. } => g - n * n.dot(&g),
    }
}

/// `P B P` for the 2x2 block `B` between vertices with filters `pa`, `pb`
/// (`P = I`, `0` or `t t^T`).
fn filter(b: &Block, pa: &Constraint, pb: &Constraint) -> Block {
    if let (Constraint::Free, Constraint::Free) = (pa, pb) {
        // `I B I`, the same bits for finite entries
        return *b;
    }
    let p = |c: &Constraint| -> Block {
        match *c {
            Constraint::Free => [[1.0, 0.0], [0.0, 1.0]],
            Constraint::Fixed(_) => [[0.0; 2]; 2],
            Constraint::Normal { n, .. } => {
                let t = Vec2::new(-n.y, n.x);
                [[t.x * t.x, t.x * t.y], [t.y * t.x, t.y * t.y]]
            }
        }
    };
    let (l, r) = (p(pa), p(pb));
    let mut lb = [[0.0; 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            lb[i][j] = l[i][0] * b[0][j] + l[i][1] * b[1][j];
        }
    }
    let mut out = [[0.0; 2]; 2];
    for i in 0..2 {
        for j in 0..2 {
            out[i][j] = lb[i][0] * r[0][j] + lb[i][1] * r[1][j];
        }
    }
    out
}

/// The feasible point nearest `v` (per vertex, in its own constraint).
pub fn feasible(cons: &[Constraint], v: &mut [Vec2]) {
    for (c, v) in cons.iter().zip(v.iter_mut()) {
        match *c {
            Constraint::Free => {}
            Constraint::Fixed(u) => *v = u,
            Constraint::Normal { n, b } => *v += n * (b - n.dot(v)),
        }
    }
}

/// `E(v)` with the friction term.
fn total_energy(rod: &Rod, fric: &[Option<Friction>], eps: f64, v: &[Vec2]) -> f64 {
    let mut e = rod.energy(v);
    for (f, v) in fric.iter().zip(v) {
        if let Some(f) = f {
            e += f.bound * f0(f.t.dot(v).abs(), eps).0;
        }
    }
    e
}

fn total_gradient(rod: &Rod, fric: &[Option<Friction>], eps: f64, v: &[Vec2]) -> Vec<Vec2> {
    let mut g = rod.gradient(v);
    for ((f, v), g) in fric.iter().zip(v).zip(g.iter_mut()) {
        if let Some(f) = f {
            let u = f.t.dot(v);
            *g += f.t * (f.bound * f0(u.abs(), eps).1 * u.signum());
        }
    }
    g
}

fn m_norm(rod: &Rod, g: &[Vec2]) -> f64 {
    g.iter()
        .zip(&rod.m)
        .map(|(g, m)| g.norm_squared() / m)
        .sum::<f64>()
        .sqrt()
}

/// Minimises `E` over the velocities that satisfy `cons`, from `v`
/// (made feasible first). `Err`: why it did not converge.
// the 2x2 blocks' entries read best as index loops
#[allow(clippy::needless_range_loop)]
pub fn solve(
    rod: &Rod,
    cons: &[Constraint],
    fric: &[Option<Friction>],
    mut v: Vec<Vec2>,
    s: &Settings,
) -> Result<Solved, String> {
    let n = rod.len();
    feasible(cons, &mut v);
    let eps = s.eps_v;
    // the energy is needed from the first line search on: a solve that
    // starts converged (a yarn at rest, in free fall) never computes it
    let mut energy = f64::NAN;
    let mut g = total_gradient(rod, fric, eps, &v);
    let pg =
        |g: &[Vec2]| -> Vec<Vec2> { cons.iter().zip(g).map(|(c, g)| project(c, *g)).collect() };
    let mut pgv = pg(&g);
    let g0 = m_norm(rod, &pgv);
    // half-bandwidth: bending couples a vertex to the second one on, stretch
    // to the next only
    let bends = rod.bending > 0.0;
    let mut a = System::new(n, bends);
    // iteration `max_newton` only tests the last iterate
    for it in 0..=s.max_newton {
        if it > 0 {
            pgv = pg(&g);
        }
        let gn = if it == 0 { g0 } else { m_norm(rod, &pgv) };
        let not_finite = || format!("the step energy is not finite at Newton iteration {it}");
        if !gn.is_finite() {
            return Err(not_finite());
        }
        if gn <= s.rel_tol * g0 || gn <= s.abs_tol || gn == 0.0 {
            return Ok(Solved {
                v,
                gradient: g,
                newton: it,
            });
        }
        if it == 0 {
            energy = total_energy(rod, fric, eps, &v);
        }
        if !energy.is_finite() {
            return Err(not_finite());
        }
        if it == s.max_newton {
            break;
        }
        // the filtered Hessian, with the mass on the constrained directions
        let mut h = rod.hessian(&v);
        for (i, f) in fric.iter().enumerate() {
            if let Some(f) = f {
                let k = f.bound * f0(f.t.dot(&v[i]).abs(), eps).2;
                for r in 0..2 {
                    for c in 0..2 {
                        h.diag[i][r][c] += k * f.t[r] * f.t[c];
                    }
                }
            }
        }
        a.clear();
        for i in 0..n {
            let mut d = filter(&h.diag[i], &cons[i], &cons[i]);
            let m = rod.m[i];
            match cons[i] {
                Constraint::Free => {}
                Constraint::Fixed(_) => {
                    d[0][0] += m;
                    d[1][1] += m;
                }
                Constraint::Normal { n: nn, .. } => {
                    for r in 0..2 {
                        for c in 0..2 {
                            d[r][c] += m * nn[r] * nn[c];
                        }
                    }
                }
            }
            a.add(i, 0, &d);
            for (off, blocks) in [(1, &h.off1), (2, &h.off2)] {
                if i + off < n && (off == 1 || bends) {
                    a.add(i, off, &filter(&blocks[i], &cons[i], &cons[i + off]));
                }
            }
        }
        if let Err(vertex) = a.factor() {
            return Err(format!(
                "the Newton system is not positive definite at vertex {vertex} (iteration {it})"
            ));
        }
        let mut d: Vec<f64> = pgv.iter().flat_map(|g| [-g.x, -g.y]).collect();
        a.solve(&mut d);
        let dir: Vec<Vec2> = (0..n)
            .map(|i| project(&cons[i], Vec2::new(d[2 * i], d[2 * i + 1])))
            .collect();
        let vmax = v.iter().map(|v| v.norm()).fold(0.0, f64::max);
        let dmax = dir.iter().map(|d| d.norm()).fold(0.0, f64::max);
        if dmax <= s.step_tol * vmax {
            return Ok(Solved {
                v,
                gradient: g,
                newton: it,
            });
        }
        let slope: f64 = dir.iter().zip(&g).map(|(d, g)| d.dot(g)).sum();
        if slope.is_nan() || slope >= 0.0 {
            return Err(format!("no descent direction at Newton iteration {it}"));
        }
        if -slope <= s.decrease_tol * energy.abs() {
            // the step's predicted decrease is below the energy's round-off
            return Ok(Solved {
                v,
                gradient: g,
                newton: it,
            });
        }
        let mut alpha = 1.0;
        let mut accepted = false;
        for _ in 0..=s.max_halvings {
            let trial: Vec<Vec2> = v.iter().zip(&dir).map(|(v, d)| v + d * alpha).collect();
            let e = total_energy(rod, fric, eps, &trial);
            if e <= energy + 1e-4 * alpha * slope && e < energy {
                v = trial;
                energy = e;
                accepted = true;
                break;
            }
            alpha *= 0.5;
        }
        if !accepted {
            if gn <= s.floor_tol * g0 {
                // no decrease left to find: the energy is at round-off
                return Ok(Solved {
                    v,
                    gradient: g,
                    newton: it,
                });
            }
            return Err(format!(
                "the line search found no decrease in {} halvings at Newton iteration {it} (gradient {gn:.3e} of {g0:.3e}, slope {slope:.3e}, energy {energy:.6e})",
                s.max_halvings
            ));
        }
        g = total_gradient(rod, fric, eps, &v);
    }
    Err(format!(
        "Newton did not converge in {} iterations",
        s.max_newton
    ))
}
