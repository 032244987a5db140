//! The cloth's position-based pieces (Müller et al. 2007; Provot 1995): the PBD model (inertia and gravity, then
//! strain limiting), the strain-limiting projection itself (usable after any
//! integrator), and sphere collision by projection with a velocity fix-up.

use std::fmt;
use std::str::FromStr;

use super::{set_kinematics, State, StepStats};
use crate::massspring::forces::max_strain;
use crate::scene::massspring::{System, V3};

/// Weight of a vertex's own position in the Jacobi averaging (the Unity cloth scripts: 0.2).
pub const SELF_WEIGHT: f64 = 0.2;

/// How the strain-limiting passes visit the springs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum StrainSolver {
    /// The Unity cloth scripts: every spring proposes positions for its two ends, each free
    /// vertex moves to the average of its proposals and itself (weight
    /// `SELF_WEIGHT`). Order-independent, but it only approaches the limit
    /// asymptotically (slowly on large sheets).
    #[default]
    Jacobi,
    /// Provot-style: springs in order, each violating spring is moved exactly
    /// onto its limit (the displacement shared by inverse mass among its
    /// free ends). Converges in far fewer passes.
    GaussSeidel,
}

impl StrainSolver {
    /// Every solver.
    pub const ALL: [StrainSolver; 2] = [StrainSolver::Jacobi, StrainSolver::GaussSeidel];

    /// The canonical name.
    pub fn name(self) -> &'static str {
        match self {
            StrainSolver::Jacobi => "jacobi",
            StrainSolver::GaussSeidel => "gauss-seidel",
        }
    }
}

named_choice!(StrainSolver, "strain solver", {
    "jacobi" => Jacobi,
    "gauss-seidel" | "gs" => GaussSeidel,
});

/// Strain at or below `limit` up to rounding (a spring set exactly onto its
/// limit length can read back a few ulps above it).
fn within(strain: f64, limit: f64) -> bool {
    strain <= limit * (1.0 + 1e-12) + 1e-14
}

/// The PBD step (Müller et al. 2007): `v += h g; x += h v`, kinematics at `t + h`, then
/// strain limiting with `limit` (0 = pull every spring to its rest length).
pub fn step(
    sys: &System,
    s: &mut State,
    h: f64,
    limit: f64,
    passes: usize,
    solver: StrainSolver,
) -> StepStats {
    for i in 0..sys.len() {
        if sys.is_free(i) {
            s.v[i] += sys.gravity * h;
            s.x[i] += s.v[i] * h;
        }
    }
    set_kinematics(sys, s.t + h, &mut s.x, &mut s.v);
    let mut stats = StepStats::new(h);
    let (n, after) = strain_limit(sys, &mut s.x, &mut s.v, h, limit, passes, solver);
    stats.strain_passes = n;
    stats.strain_after_limiting = after;
    stats
}

/// Strain-limiting projection (Provot 1995; the Unity cloth scripts' `Strain_Limiting`, with each
/// spring's target length clamped into `[(1-limit) l0, (1+limit) l0]`), run
/// for up to `passes` passes, stopping early once every spring is within
/// the limit. Each moved free vertex gets the velocity fix-up `dx / h`.
/// Returns the passes run and the largest strain afterwards.
pub fn strain_limit(
    sys: &System,
    x: &mut [V3],
    v: &mut [V3],
    h: f64,
    limit: f64,
    passes: usize,
    solver: StrainSolver,
) -> (usize, f64) {
    let mut sweep = Sweep::new(sys, solver);
    let mut done = 0;
    for _ in 0..passes {
        if within(max_strain(&sys.springs, x), limit) {
            break;
        }
        done += 1;
        sweep.pass(sys, x, v, h, limit);
    }
    (done, max_strain(&sys.springs, x))
}

/// The length `l` of a spring clamped into `[(1-limit) l0, (1+limit) l0]`.
fn target_length(l: f64, rest_length: f64, limit: f64) -> f64 {
    l.clamp((1.0 - limit) * rest_length, (1.0 + limit) * rest_length)
}

/// One strain-limiting pass of either solver, with its scratch space.
enum Sweep {
    /// Spring by spring, in place: each free vertex moved by its inverse
    /// mass share (zero for pinned and driven ones).
    GaussSeidel { inv_mass: Vec<f64> },
    /// Every spring's projection of both ends summed per vertex, then each
    /// free vertex moved to the average, its own position weighted by
    /// `SELF_WEIGHT`.
    Jacobi { sum_x: Vec<V3>, sum_n: Vec<u32> },
}

impl Sweep {
    fn new(sys: &System, solver: StrainSolver) -> Self {
        let n = sys.len();
        match solver {
            StrainSolver::GaussSeidel => Sweep::GaussSeidel {
                inv_mass: (0..n)
                    .map(|i| {
                        if sys.is_free(i) {
                            1.0 / sys.masses[i]
                        } else {
                            0.0
                        }
                    })
                    .collect(),
            },
            StrainSolver::Jacobi => Sweep::Jacobi {
                sum_x: vec![V3::zeros(); n],
                sum_n: vec![0u32; n],
            },
        }
    }

    fn pass(&mut self, sys: &System, x: &mut [V3], v: &mut [V3], h: f64, limit: f64) {
        match self {
            Sweep::GaussSeidel { inv_mass } => {
                for sp in &sys.springs {
                    let (a, b) = (sp.a, sp.b);
                    let w = inv_mass[a] + inv_mass[b];
                    let dx = x[b] - x[a];
                    let l = dx.norm();
                    if w == 0.0 || l == 0.0 {
                        continue;
                    }
                    let target = target_length(l, sp.rest_length, limit);
                    if target == l {
                        continue;
                    }
                    // Move a and b so that |x_b - x_a| = target.
                    let corr = dx * ((l - target) / (l * w));
                    let da = corr * inv_mass[a];
                    let db = -corr * inv_mass[b];
                    x[a] += da;
                    v[a] += da / h;
                    x[b] += db;
                    v[b] += db / h;
                }
            }
            Sweep::Jacobi { sum_x, sum_n } => {
                sum_x.iter_mut().for_each(|s| *s = V3::zeros());
                sum_n.iter_mut().for_each(|c| *c = 0);
                for sp in &sys.springs {
                    let (a, b) = (sp.a, sp.b);
                    let dx = x[a] - x[b];
                    let l = dx.norm();
                    let mid = (x[a] + x[b]) * 0.5;
                    let half = if l > 0.0 {
                        dx * (0.5 * target_length(l, sp.rest_length, limit) / l)
                    } else {
                        V3::zeros()
                    };
                    sum_x[a] += mid + half;
                    sum_x[b] += mid - half;
                    sum_n[a] += 1;
                    sum_n[b] += 1;
                }
                for i in 0..sys.len() {
                    if !sys.is_free(i) || sum_n[i] == 0 {
                        continue;
                    }
                    let xt = (x[i] * SELF_WEIGHT + sum_x[i]) / (SELF_WEIGHT + sum_n[i] as f64);
                    v[i] += (xt - x[i]) / h;
                    x[i] = xt;
                }
            }
        }
    }
}

/// Projects free particles inside a sphere onto its surface, adding the
/// displacement over `h` to their velocity (the Unity cloth scripts' `Collision_Handling`).
/// Returns the number of projections.
pub fn collide_spheres(sys: &System, x: &mut [V3], v: &mut [V3], h: f64) -> usize {
    let mut count = 0;
    for sph in &sys.spheres {
        for i in 0..sys.len() {
            if !sys.is_free(i) {
                continue;
            }
            let d = x[i] - sph.center;
            let dist = d.norm();
            if dist < sph.radius {
                let dir = if dist > 0.0 {
                    d / dist
                } else {
                    V3::new(0.0, 1.0, 0.0)
                };
                let target = sph.center + dir * sph.radius;
                v[i] += (target - x[i]) / h;
                x[i] = target;
                count += 1;
            }
        }
    }
    count
}
