//! One yarn's step with its obstacle contacts: the active set of vertices
//! in contact with a circle (held by a normal-velocity constraint in the
//! solve, [`super::newton`]) and the Coulomb friction on them, iterated
//! until both settle.
//!
//! A vertex `i` in contact with obstacle `o` (centre `c`, radius `r`) at
//! the start of the step has the outward normal `n = (x_i - c) / |x_i - c|`
//! and the constraint `n . v_i = (r - |x_i - c|) / dt` (its end position
//! on the tangent line of the surface; a vertex inside is pushed out).
//! The constraint's multiplier `lambda_i = n . dE/dv_i` is the normal
//! impulse the obstacle delivers; a vertex with `lambda_i < 0` is pulled
//! off and leaves the set, a free vertex that would end inside a circle
//! joins it. Friction bounds the tangential impulse by `mu lambda_i`
//! (smoothed below `eps_v`, [`super::newton::Settings`]), with `lambda`
//! from the previous round of the same step (round 0 frictionless): the
//! rounds stop when the set is unchanged and no `lambda` moved by more than
//! [`LAMBDA_RTOL`] of the largest, at most [`MAX_ROUNDS`] (else an error,
//! which the cutback answers by halving the substep). Nothing carries
//! over from one step to the next, so a saved state needs nothing more.

use super::energy::Rod;
use super::newton::{self, Constraint, Friction, Settings};
use crate::math::Vec2;
use crate::mpm::laws::contact::outward;
use crate::scene::Obstacle;

/// Most solves of one step (active-set and friction rounds).
pub const MAX_ROUNDS: usize = 16;
/// The friction rounds have converged when no normal impulse moved by more
/// than this fraction of the largest one.
pub const LAMBDA_RTOL: f64 = 1e-4;

/// A vertex in contact at the end of a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    pub vertex: usize,
    pub obstacle: usize,
    /// Outward unit normal of the constraint (at the start of the step).
    pub normal: Vec2,
    /// Normal impulse the obstacle delivered (`lambda`).
    pub impulse: f64,
}

/// A step's result.
#[derive(Clone, Debug)]
pub struct Stepped {
    pub v: Vec<Vec2>,
    /// `dE/dv` at the solution (a pinned vertex: its pin's impulse).
    pub gradient: Vec<Vec2>,
    /// The vertices in contact.
    pub contacts: Vec<Contact>,
    pub newton: usize,
}

/// The positions `x + reach v`.
fn ahead(rod: &Rod, v: &[Vec2], reach: f64) -> Vec<Vec2> {
    rod.x.iter().zip(v).map(|(x, v)| x + v * reach).collect()
}

/// The obstacle a position `y` is inside, the deepest if several.
fn inside(obstacles: &[Obstacle], y: Vec2) -> Option<usize> {
    let mut best: Option<(usize, f64)> = None;
    for (k, o) in obstacles.iter().enumerate() {
        let depth = o.radius - outward(o, y).1;
        if depth > 0.0 && best.is_none_or(|(_, d)| depth > d) {
            best = Some((k, depth));
        }
    }
    best.map(|(k, _)| k)
}

/// The constraint of vertex `x` in contact with `o` when its velocity
/// moves it over `dt`.
fn contact(o: &Obstacle, x: Vec2, dt: f64) -> Constraint {
    let (n, d) = outward(o, x);
    Constraint::Normal {
        n,
        b: (o.radius - d) / dt,
    }
}

/// The step of `rod` with the velocities `fixed` (pins) and the obstacles;
/// the solved velocity moves a vertex over `reach` (s): the substep `dt`
/// (the solve's own step is `dt` under backward Euler, `theta dt` under
/// the generalized midpoint rule). `Err` when a solve fails or the
/// contacts do not settle in [`MAX_ROUNDS`] (the cutback then halves the
/// substep).
pub fn step(
    rod: &Rod,
    fixed: &[Option<Vec2>],
    obstacles: &[Obstacle],
    reach: f64,
    s: &Settings,
) -> Result<Stepped, String> {
    let n = rod.len();
    let base: Vec<Constraint> = fixed
        .iter()
        .map(|f| f.map_or(Constraint::Free, Constraint::Fixed))
        .collect();
    // which obstacle each vertex touches
    let mut touch: Vec<Option<usize>> = vec![None; n];
    let start = rod.vstar.clone();
    let first = ahead(rod, &start, reach);
    for i in 0..n {
        if base[i] == Constraint::Free {
            touch[i] = inside(obstacles, first[i]);
        }
    }
    let mut lambda = vec![0.0; n];
    let mut v = start;
    let mut newton = 0;
    for round in 1..=MAX_ROUNDS {
        let cons: Vec<Constraint> = (0..n)
            .map(|i| match touch[i] {
                Some(k) => contact(&obstacles[k], rod.x[i], reach),
                None => base[i],
            })
            .collect();
        let fric: Vec<Option<Friction>> = (0..n)
            .map(|i| match (touch[i], cons[i]) {
                (Some(k), Constraint::Normal { n, .. }) if lambda[i] > 0.0 => Some(Friction {
                    t: Vec2::new(-n.y, n.x),
                    bound: obstacles[k].friction * lambda[i],
                }),
                _ => None,
            })
            .collect();
        let sol = newton::solve(rod, &cons, &fric, v, s)?;
        newton += sol.newton;
        v = sol.v;
        let y = ahead(rod, &v, reach);
        let mut changed = false;
        let mut new_lambda = vec![0.0; n];
        for i in 0..n {
            match (touch[i], cons[i]) {
                (Some(k), Constraint::Normal { n, .. }) => {
                    let l = n.dot(&sol.gradient[i]);
                    if l < 0.0 {
                        touch[i] = None;
                        changed = true;
                    } else {
                        new_lambda[i] = l;
                        // ending inside another circle: that one instead
                        if let Some(j) = inside(obstacles, y[i]).filter(|&j| j != k) {
                            touch[i] = Some(j);
                            changed = true;
                        }
                    }
                }
                _ if base[i] == Constraint::Free => {
                    if let Some(k) = inside(obstacles, y[i]) {
                        touch[i] = Some(k);
                        changed = true;
                    }
                }
                _ => {}
            }
        }
        let top = new_lambda.iter().fold(0.0f64, |a, &b| a.max(b));
        let moved = new_lambda
            .iter()
            .zip(&lambda)
            .any(|(a, b)| (a - b).abs() > LAMBDA_RTOL * top);
        let rubbing = (0..n).any(|i| touch[i].is_some_and(|k| obstacles[k].friction > 0.0));
        lambda = new_lambda;
        let settled = !changed && (!moved || !rubbing);
        if !settled && round == MAX_ROUNDS {
            return Err(format!(
                "the contacts did not settle in {MAX_ROUNDS} rounds (the contact set {}, the normal impulses {})",
                if changed { "still changing" } else { "settled" },
                if moved && rubbing { "still moving" } else { "settled" }
            ));
        }
        if settled {
            // settled: each contact's constraint is this round's
            let contacts = (0..n)
                .filter_map(|i| match (touch[i], cons[i]) {
                    (Some(k), Constraint::Normal { n, .. }) => Some(Contact {
                        vertex: i,
                        obstacle: k,
                        normal: n,
                        impulse: lambda[i],
                    }),
                    _ => None,
                })
                .collect();
            return Ok(Stepped {
                v,
                gradient: sol.gradient,
                contacts,
                newton,
            });
        }
    }
    unreachable!("the last round returns")
}
