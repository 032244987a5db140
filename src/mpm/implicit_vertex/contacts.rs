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
//! joins it. A box of walls (the grid's bounds under the axial step of the
//! explicit substep) is held the same way, without friction: a vertex that
//! would end beyond a wall takes `n . v_i = (wall - x_i) / dt` along the
//! wall's inward normal, and one that would end beyond two (or that one
//! wall's constraint leaves beyond the other) ends in their corner, which
//! lets go of a wall whose impulse pulls. Friction bounds the tangential
//! impulse by `mu lambda_i` (smoothed below `eps_v`,
//! [`super::newton::Settings`]), with `lambda` from the previous round of
//! the same step (round 0 frictionless): the
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

/// What a vertex touches: an obstacle (by index) or a wall of the box,
/// along `axis` (0: x, 1: y), the lower or the upper one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Touch {
    Circle(usize),
    Wall {
        axis: usize,
        upper: bool,
    },
    /// Two walls: the vertex ends in the corner, `upper` per axis.
    Corner([bool; 2]),
}

/// What a vertex touches when, touching `now`, its end is found in
/// `next`: a wall and then the other axis's wall make a corner, which
/// holds the vertex on both (one wall at a time would swap for ever).
fn then(now: Touch, next: Touch) -> Touch {
    match (now, next) {
        (Touch::Wall { axis: a, upper: ua }, Touch::Wall { axis: b, upper: ub }) if a != b => {
            let mut c = [false; 2];
            c[a] = ua;
            c[b] = ub;
            Touch::Corner(c)
        }
        _ => next,
    }
}

/// A vertex in contact with an obstacle at the end of a step (a wall's
/// contact is not listed).
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

/// The constraints of vertices held at `fixed` velocities (`None`: free).
pub(crate) fn held(fixed: &[Option<Vec2>]) -> Vec<Constraint> {
    (fixed.iter())
        .map(|f| f.map_or(Constraint::Free, Constraint::Fixed))
        .collect()
}

/// What a position `y` is inside: the deepest obstacle, else the wall of
/// `walls` (`[lo, hi]` on both axes) it is beyond, or the corner.
pub(crate) fn inside(obstacles: &[Obstacle], walls: Option<(f64, f64)>, y: Vec2) -> Option<Touch> {
    let mut best: Option<(usize, f64)> = None;
    for (k, o) in obstacles.iter().enumerate() {
        let depth = o.radius - outward(o, y).1;
        if depth > 0.0 && best.is_none_or(|(_, d)| depth > d) {
            best = Some((k, depth));
        }
    }
    if let Some((k, _)) = best {
        return Some(Touch::Circle(k));
    }
    let (lo, hi) = walls?;
    // per axis, the wall it is beyond, if any
    let beyond = |axis: usize| {
        if y[axis] < lo {
            Some(false)
        } else if y[axis] > hi {
            Some(true)
        } else {
            None
        }
    };
    match (beyond(0), beyond(1)) {
        (Some(ux), Some(uy)) => Some(Touch::Corner([ux, uy])),
        (Some(upper), None) => Some(Touch::Wall { axis: 0, upper }),
        (None, Some(upper)) => Some(Touch::Wall { axis: 1, upper }),
        (None, None) => None,
    }
}

/// The constraint of vertex `x` touching `touch` when its velocity moves
/// it over `dt`.
fn contact(
    obstacles: &[Obstacle],
    walls: Option<(f64, f64)>,
    touch: Touch,
    x: Vec2,
    dt: f64,
) -> Constraint {
    match touch {
        Touch::Circle(k) => {
            let o = &obstacles[k];
            let (n, d) = outward(o, x);
            Constraint::Normal {
                n,
                b: (o.radius - d) / dt,
            }
        }
        Touch::Wall { axis, upper } => {
            let (lo, hi) = walls.expect("a wall contact has walls");
            let mut n = Vec2::zeros();
            if upper {
                n[axis] = -1.0;
                Constraint::Normal {
                    n,
                    b: (x[axis] - hi) / dt,
                }
            } else {
                n[axis] = 1.0;
                Constraint::Normal {
                    n,
                    b: (lo - x[axis]) / dt,
                }
            }
        }
        Touch::Corner(upper) => {
            let (lo, hi) = walls.expect("a corner has walls");
            let at = |u: bool| if u { hi } else { lo };
            Constraint::Fixed((Vec2::new(at(upper[0]), at(upper[1])) - x) / dt)
        }
    }
}

/// The step of `rod` with the velocities `fixed` (pins) and the obstacles;
/// the solved velocity moves a vertex over `reach` (s): the substep `dt`
/// (the solve's own step is `dt` under backward Euler, `theta dt` under
/// the generalized midpoint rule); `walls`, where given, the box `[lo,
/// hi]` on both axes the vertices stay in. `Err` when a solve fails or
/// the contacts do not settle in [`MAX_ROUNDS`] (the cutback then halves
/// the substep).
pub fn step(
    rod: &Rod,
    fixed: &[Option<Vec2>],
    obstacles: &[Obstacle],
    walls: Option<(f64, f64)>,
    reach: f64,
    s: &Settings,
) -> Result<Stepped, String> {
    let n = rod.len();
    let base = held(fixed);
    // what each vertex touches
    let mut touch: Vec<Option<Touch>> = vec![None; n];
    let start = rod.vstar.clone();
    let first = ahead(rod, &start, reach);
    for i in 0..n {
        if base[i] == Constraint::Free {
            touch[i] = inside(obstacles, walls, first[i]);
        }
    }
    let mut lambda = vec![0.0; n];
    let mut v = start;
    let mut newton = 0;
    for round in 1..=MAX_ROUNDS {
        let cons: Vec<Constraint> = (0..n)
            .map(|i| match touch[i] {
                Some(t) => contact(obstacles, walls, t, rod.x[i], reach),
                None => base[i],
            })
            .collect();
        let fric: Vec<Option<Friction>> = (0..n)
            .map(|i| match (touch[i], cons[i]) {
                (Some(Touch::Circle(k)), Constraint::Normal { n, .. }) if lambda[i] > 0.0 => {
                    Some(Friction {
                        t: Vec2::new(-n.y, n.x),
                        bound: obstacles[k].friction * lambda[i],
                    })
                }
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
                        // ending inside another circle or beyond a wall:
                        // that one instead
                        if let Some(j) = inside(obstacles, walls, y[i]).filter(|&j| j != k) {
                            touch[i] = Some(then(k, j));
                            changed = true;
                        }
                    }
                }
                (Some(Touch::Corner(upper)), _) => {
                    // the corner's impulse along each wall's inward
                    // normal: a wall that pulls lets go, and the vertex
                    // keeps the other if that one pushes
                    let g = sol.gradient[i];
                    let pushes = |a: usize| if upper[a] { -g[a] } else { g[a] } >= 0.0;
                    let keep = match (pushes(0), pushes(1)) {
                        (true, true) => touch[i],
                        (true, false) => Some(Touch::Wall {
                            axis: 0,
                            upper: upper[0],
                        }),
                        (false, true) => Some(Touch::Wall {
                            axis: 1,
                            upper: upper[1],
                        }),
                        (false, false) => None,
                    };
                    if keep != touch[i] {
                        touch[i] = keep;
                        changed = true;
                    }
                }
                _ if base[i] == Constraint::Free => {
                    if let Some(k) = inside(obstacles, walls, y[i]) {
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
        let rubbing = (0..n).any(|i| match touch[i] {
            Some(Touch::Circle(k)) => obstacles[k].friction > 0.0,
            _ => false,
        });
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
                    (Some(Touch::Circle(k)), Constraint::Normal { n, .. }) => Some(Contact {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// One free vertex of mass 1 at `x` with the velocity `v*` it would
    /// keep without contact (no springs).
    fn lone(x: Vec2, vstar: Vec2) -> Rod {
        Rod {
            x: vec![x],
            m: vec![1.0],
            vstar: vec![vstar],
            dt: 0.1,
            segments: Vec::new(),
            bending: 0.0,
            bend: Vec::new(),
            attractor: None,
        }
    }

    fn settings() -> Settings {
        Settings::default()
    }

    /// The walls `[0, 1]` stop a vertex on the one it would cross, keep
    /// its velocity along the wall, take the impulse that stops it, list
    /// no obstacle contact; and do nothing without walls or when the
    /// vertex moves away from the wall.
    #[test]
    fn a_wall_stops_a_vertex_on_it_and_lets_one_leave() {
        let walls = Some((0.0, 1.0));
        let rod = lone(Vec2::new(0.99, 0.5), Vec2::new(1.0, 0.3));
        let out = step(&rod, &[None], &[], walls, 0.1, &settings()).unwrap();
        let end = rod.x[0] + out.v[0] * 0.1;
        assert!((end.x - 1.0).abs() < 1e-12, "ends at {end:?}");
        assert_eq!(out.v[0].y, 0.3);
        // dE/dv = m (v - v*) = 0.1 - 1: the wall's impulse, inward
        assert!((out.gradient[0].x - (0.1 - 1.0)).abs() < 1e-12);
        assert!(out.contacts.is_empty());
        let free = step(&rod, &[None], &[], None, 0.1, &settings()).unwrap();
        assert_eq!(free.v[0], Vec2::new(1.0, 0.3));
        let away = lone(Vec2::new(1.0, 0.5), Vec2::new(-1.0, 0.0));
        let out = step(&away, &[None], &[], walls, 0.1, &settings()).unwrap();
        assert_eq!(out.v[0], Vec2::new(-1.0, 0.0));
    }

    /// A vertex driven beyond two walls ends in their corner, whether it
    /// moves more along one axis or the other.
    #[test]
    fn a_vertex_driven_into_a_corner_ends_in_it() {
        let walls = Some((0.0, 1.0));
        for vstar in [Vec2::new(-1.0, 3.0), Vec2::new(-3.0, 1.0)] {
            let rod = lone(Vec2::new(0.02, 0.98), vstar);
            let out = step(&rod, &[None], &[], walls, 0.1, &settings()).unwrap();
            let end = rod.x[0] + out.v[0] * 0.1;
            assert!(
                (end - Vec2::new(0.0, 1.0)).norm() < 1e-12,
                "ends at {end:?}"
            );
        }
    }

    /// A corner lets go of a wall that pulls: a vertex driven into the
    /// corner (0, 1) on a stiff spring to a held vertex 0.09 below it ends
    /// on the wall x = 0 the spring presses it against, below y = 1, which
    /// it would only reach with the upper wall pulling it up.
    #[test]
    fn a_corner_lets_go_of_a_wall_that_pulls() {
        let walls = Some((0.0, 1.0));
        let rod = Rod {
            x: vec![Vec2::new(0.02, 0.99), Vec2::new(0.02, 0.9)],
            m: vec![1.0, 1.0],
            vstar: vec![Vec2::new(-1.0, 0.5), Vec2::zeros()],
            dt: 0.1,
            segments: vec![(1e4, 0.09)],
            bending: 0.0,
            bend: Vec::new(),
            attractor: None,
        };
        let fixed = [None, Some(Vec2::zeros())];
        let out = step(&rod, &fixed, &[], walls, 0.1, &settings()).unwrap();
        let end = rod.x[0] + out.v[0] * 0.1;
        assert!(end.x.abs() < 1e-12, "ends at {end:?}");
        assert!(end.y < 1.0, "ends at {end:?}");
    }

    /// A wall and then the other axis's wall make a corner; the same wall,
    /// or a wall after a circle, stay what they are.
    #[test]
    fn a_wall_and_then_the_other_make_a_corner() {
        let a = Touch::Wall {
            axis: 0,
            upper: true,
        };
        let b = Touch::Wall {
            axis: 1,
            upper: false,
        };
        assert_eq!(then(a, b), Touch::Corner([true, false]));
        assert_eq!(then(b, a), Touch::Corner([true, false]));
        assert_eq!(then(a, a), a);
        assert_eq!(then(Touch::Circle(0), a), a);
    }
}
