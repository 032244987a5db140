//! Contact and boundary laws: circular obstacles with Coulomb friction on
//! the grid and on the vertices, the domain walls, and the clamp that keeps
//! particles on the grid.
//!
//! Obstacle contact acts on every grid node that carries the weight of a
//! particle touching the obstacle (within [`super::particle_to_grid::CONTACT_CELLS`]
//! cells of its surface), not only on nodes inside the circle, so a yarn
//! resting on an obstacle gets friction on all of its grid weight. At such a
//! node with outward normal `n` (from the centre) an inward velocity
//! `v . n < 0` is removed, and the tangential velocity is reduced by `mu`
//! times the removed normal velocity, or stopped if that is more: Coulomb's
//! law in impulse terms (`|dp_t| <= mu dp_n`). A node carrying both touching
//! and free particles gets the law in proportion to the touching mass.

use crate::math::Vec2;
use crate::scene::{Obstacle, WallMode};

/// Coulomb response of velocity `v` at outward normal `n`: no inward normal
/// velocity, tangential velocity reduced by `mu` times the removed part.
#[inline(always)]
pub fn coulomb(v: Vec2, n: Vec2, mu: f64) -> Vec2 {
    let vn = v.dot(&n);
    if vn >= 0.0 {
        return v;
    }
    let vt = v - n * vn;
    let vt_norm = vt.norm();
    if vt_norm <= -mu * vn {
        Vec2::zeros()
    } else {
        vt * (1.0 + mu * vn / vt_norm)
    }
}

/// Velocity of a grid node at `xi` after contact with obstacle `o`:
/// `touching` is the fraction of the node's mass that belongs to particles
/// touching an obstacle. Inside the circle the law acts in full.
#[inline]
pub fn obstacle_velocity(o: &Obstacle, xi: Vec2, v: Vec2, touching: f64) -> Vec2 {
    let c = Vec2::from(o.center);
    let r = xi - c;
    let dist = r.norm();
    let share = if dist < o.radius { 1.0 } else { touching };
    if share <= 0.0 {
        return v;
    }
    let n = if dist > 0.0 {
        r / dist
    } else {
        Vec2::new(0.0, 1.0)
    };
    let vc = coulomb(v, n, o.friction);
    if share >= 1.0 {
        vc
    } else {
        v + (vc - v) * share
    }
}

/// Velocity of grid node `(i, j)` after the walls (`cells` thick) of an `n`-node grid.
#[inline(always)]
pub fn wall_velocity(
    mode: WallMode,
    cells: usize,
    n: usize,
    i: usize,
    j: usize,
    mut v: Vec2,
) -> Vec2 {
    let (lo_x, hi_x) = (i < cells, i + cells >= n);
    let (lo_y, hi_y) = (j < cells, j + cells >= n);
    match mode {
        WallMode::None => v,
        WallMode::Sticky => {
            if lo_x || hi_x || lo_y || hi_y {
                Vec2::zeros()
            } else {
                v
            }
        }
        WallMode::Slip => {
            if lo_x {
                v.x = v.x.max(0.0);
            }
            if hi_x {
                v.x = v.x.min(0.0);
            }
            if lo_y {
                v.y = v.y.max(0.0);
            }
            if hi_y {
                v.y = v.y.min(0.0);
            }
            v
        }
    }
}

/// Keeps a particle where its stencil stays on the grid; removes outward velocity there.
#[inline(always)]
pub fn clamp_to_grid(x: &mut Vec2, v: &mut Vec2, lo: f64, hi: f64) {
    for a in 0..2 {
        if x[a] < lo {
            x[a] = lo;
            v[a] = v[a].max(0.0);
        } else if x[a] > hi {
            x[a] = hi;
            v[a] = v[a].min(0.0);
        }
    }
}

/// Pushes a vertex that ended inside an obstacle back to its surface; its
/// velocity gets the obstacle's Coulomb law at the surface normal.
#[inline]
pub fn project_out(o: &Obstacle, x: &mut Vec2, v: &mut Vec2) {
    let c = Vec2::from(o.center);
    let r = *x - c;
    let dist2 = r.norm_squared();
    if dist2 < o.radius * o.radius {
        let dist = dist2.sqrt();
        let n = if dist > 0.0 {
            r / dist
        } else {
            Vec2::new(0.0, 1.0)
        };
        *x = c + n * o.radius;
        *v = coulomb(*v, n, o.friction);
    }
}
