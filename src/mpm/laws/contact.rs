//! Contact and boundary laws: circular obstacles with Coulomb friction on
//! the grid and on the vertices, the domain walls, and the clamp that keeps
//! particles on the grid.
//!
//! Obstacle contact acts on every grid node that carries the weight of a
//! particle touching the obstacle (within [`CONTACT_CELLS`]
//! cells of its surface), not only on nodes inside the circle, so a yarn
//! resting on an obstacle gets friction on all of its grid weight. It has
//! two parts:
//!
//! * the normal part, per node ([`obstacle_normal`]): at a node with outward
//!   normal `n` (from the centre) an inward velocity `v . n < 0` is removed;
//!   the momentum removed is the normal impulse the obstacle delivers there;
//! * the friction part, per cross-section of whatever lies on the obstacle
//!   ([`obstacle_friction`]): the contact nodes are pooled in wedges of
//!   [`FRICTION_ARC_CELLS`] cells of arc, and each wedge's tangential
//!   momentum is reduced by `mu` times the wedge's normal impulse, or
//!   stopped if that is more (Coulomb's law in impulse terms,
//!   `|dp_t| <= mu dp_n`), by one tangential velocity change shared by the
//!   wedge's nodes.
//!
//! Pooling makes the friction follow the normal impulse the obstacle
//! actually delivers to the yarn's cross-section, wherever in the stencil it
//! lands: a yarn with cross-section stiffness presses its inner nodes onto
//! the obstacle and pushes its outer ones outward, and a node-by-node law
//! would give those outer nodes no friction at all.
//!
//! A node carrying both touching and free particles gets the normal part
//! in proportion to the touching mass, but joins the friction pool with
//! its whole mass, as does every node within [`POOL_CELLS`] of the
//! surface. A yarn that lands on an obstacle stops where its particles
//! enter the contact band, at its outer edge, so its particles are partly
//! inside the band and partly outside: pooled by the touching share alone,
//! a wedge's normal impulse fell on nodes whose tangential momentum
//! friction had already stopped (inside the circle) while the moving yarn
//! sat on nodes with a small share, and the wedge stuck with its Coulomb
//! limit `mu J` unused while the yarn slid on (measured in
//! `docs/obstacle-contact.md`, "Under impact"). Pooling whole nodes, the
//! wedge's tangential momentum is that of the whole cross-section on the
//! obstacle, as for a yarn laid on it.
//!
//! With a yarn diameter `d` (`material.diameter`) the laws act on the
//! obstacles grown by `d / 2` ([`with_yarn_radius`]), a particle touches
//! only on or inside the grown circle, and the normal part acts on the
//! touching mass only, inside too ([`normal_share`]): a yarn's centre line
//! rests `d / 2` from the surface whatever the cell.

use crate::math::bspline::Stencil;
use crate::math::Vec2;
pub use crate::mpm::machinery::grid::ContactNode;
use crate::scene::{Obstacle, WallMode};

/// The obstacles as contact sees them for yarns of diameter `diameter`
/// (`material.diameter`): each grown by `d / 2`, so that the laws below,
/// which keep a particle (a point of a yarn's centre line) outside a
/// circle, keep the centre line `d / 2` from the obstacle's surface; the
/// obstacles as they are without a diameter.
pub fn with_yarn_radius(obstacles: &[Obstacle], diameter: Option<f64>) -> Vec<Obstacle> {
    let grow = diameter.map_or(0.0, |d| 0.5 * d);
    obstacles
        .iter()
        .map(|o| {
            let mut o = o.clone();
            if grow > 0.0 {
                o.radius += grow;
            }
            o
        })
        .collect()
}

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

/// Arc length, in cells at the obstacle's radius, of the wedges over which
/// obstacle friction is pooled: a yarn cross-section's stencil (3 nodes)
/// with a margin, short against any arc over which the tension changes.
pub const FRICTION_ARC_CELLS: f64 = 2.0;

/// Normal part of the contact of a grid node at `xi` with velocity `v` and
/// mass `m` with obstacle `o`: `touching` is the fraction of the node's mass
/// that belongs to particles touching an obstacle (inside the circle the
/// law acts in full, without a yarn diameter: see [`normal_share`]). Removes the inward velocity of that share; returns
/// the outward normal and the normal impulse delivered, or `None` when the
/// node is not in contact: neither inside, nor carrying touching mass, nor
/// within the pool's reach (`wedges.reach`, m) of the surface; the
/// touching mass acts within `wedges.touch_reach` ([`normal_share`]). A node in contact joins its
/// wedge's friction pool with its whole mass ([`ContactNode`]).
#[inline]
pub fn obstacle_normal(
    o: &Obstacle,
    xi: Vec2,
    v: &mut Vec2,
    m: f64,
    touching: f64,
    wedges: &WedgeTable,
    yarn_radius: f64,
) -> Option<(Vec2, f64)> {
    let (share, n, dist) = normal_share(o, xi, touching, yarn_radius, wedges.touch_reach);
    if share <= 0.0 && dist >= o.radius + wedges.reach {
        return None;
    }
    let vn = v.dot(&n);
    let impulse = if vn < 0.0 {
        *v -= n * (vn * share);
        -vn * share * m
    } else {
        0.0
    };
    Some((n, impulse))
}

/// The share of the mass of a grid node at `xi` that the normal part of
/// the law acts on (1 inside the circle, else the touching fraction
/// `touching` of its mass, at most 1), the outward normal there and the
/// node's distance from the centre. Used by [`obstacle_normal`] and by the
/// implicit solve's contact term.
///
/// With a yarn diameter `d` (`yarn_radius = d / 2 > 0`) the circle `o` is
/// the obstacle grown by `d / 2` ([`with_yarn_radius`]) and the law acts
/// on the touching fraction everywhere, inside too: a node is in contact
/// through the particles on or inside the grown circle (which the
/// particle projection [`project_out`] keeps on its surface), never by
/// where it lies, so the nodes of a yarn's stencil that reach into the
/// circle do not stop it before its centre line reaches `d / 2` from the
/// surface (in full inside the obstacle itself, they held it up to 0.15
/// cells early at 256^2: `docs/obstacle-contact.md`, "Yarn diameter").
///
/// `touching` is one fraction for all obstacles (the scatter sums the
/// mass of particles touching any of them), so a node farther than
/// `touch_reach` (m, [`TOUCH_REACH_CELLS`] cells) from `o`'s surface,
/// where no particle touching `o` reaches, has share 0 for `o`: without
/// that bound a node carrying mass that touches one obstacle lost the
/// velocity pointing at every other obstacle's centre (and joined their
/// friction wedges), and the nodes inside a circle kept inward velocity
/// (`docs/obstacle-contact.md`, "A cross-section crushed on a circle").
#[inline]
pub fn normal_share(
    o: &Obstacle,
    xi: Vec2,
    touching: f64,
    yarn_radius: f64,
    touch_reach: f64,
) -> (f64, Vec2, f64) {
    let (n, dist) = outward(o, xi);
    let share = if yarn_radius == 0.0 && dist < o.radius {
        1.0
    } else if dist < o.radius + touch_reach {
        touching.min(1.0)
    } else {
        0.0
    };
    (share, n, dist)
}

/// A particle closer than this many cells to an obstacle's surface (or
/// inside it) counts as touching it: its grid weight gets Coulomb friction.
/// With a yarn diameter the surface is the obstacle grown by half of it
/// and a particle touches only on or inside it (margin 0), so the yarn's
/// rest distance does not follow the cell (`docs/obstacle-contact.md`,
/// "Yarn diameter").
pub const CONTACT_CELLS: f64 = 0.5;

/// The farthest a grid node lies from an obstacle's surface, in cells,
/// and still carries the mass of a particle touching it: the contact band
/// ([`CONTACT_CELLS`], 0.5 cells)
/// plus the reach of a particle's quadratic B-spline stencil (1.5 cells
/// per axis, `1.5 sqrt 2` along a diagonal).
pub const TOUCH_REACH_CELLS: f64 = CONTACT_CELLS + 1.5 * std::f64::consts::SQRT_2;

/// [`TOUCH_REACH_CELLS`] in m on a grid of spacing `dx`: the `touch_reach`
/// of [`normal_share`], for the explicit ([`WedgeTable`]) and the implicit
/// grid update alike.
#[inline]
pub fn touch_reach(dx: f64) -> f64 {
    TOUCH_REACH_CELLS * dx
}

/// The outward unit normal of obstacle `o` at `x` and the distance of `x`
/// from its centre (the normal is +y at the centre itself): the geometry
/// of the obstacle law, shared by the grid integrators' node projection
/// ([`normal_share`]) and the vertex integrator's contact constraints
/// (`crate::mpm::implicit_vertex::contacts`).
#[inline]
pub fn outward(o: &Obstacle, x: Vec2) -> (Vec2, f64) {
    let r = x - Vec2::from(o.center);
    let dist = r.norm();
    let n = if dist > 0.0 {
        r / dist
    } else {
        Vec2::new(0.0, 1.0)
    };
    (n, dist)
}

/// Number of friction wedges around obstacle `o` on a grid of spacing `dx`.
#[inline]
pub fn friction_wedges(o: &Obstacle, dx: f64) -> usize {
    let arc = 2.0 * std::f64::consts::PI * o.radius / (FRICTION_ARC_CELLS * dx);
    (arc.round() as usize).max(1)
}

/// Distance, in cells, from an obstacle's surface within which every grid
/// node joins its wedge's friction pool with its whole mass, whatever
/// particles it carries: the rows of the stencil of a yarn resting at the
/// outer edge of the contact band ([`CONTACT_CELLS`]),
/// whose particles sit partly inside the band and partly outside.
pub const POOL_CELLS: f64 = 1.0;

/// The friction wedges of all obstacles, numbered one obstacle after the
/// other: obstacle `k` has wedges `start[k] .. start[k + 1]`; and the
/// pools' reach outside the surface.
#[derive(Clone, Debug)]
pub struct WedgeTable {
    pub start: Vec<usize>,
    /// [`POOL_CELLS`] in m.
    pub reach: f64,
    /// [`TOUCH_REACH_CELLS`] in m.
    pub touch_reach: f64,
}

impl WedgeTable {
    pub fn new(obstacles: &[Obstacle], dx: f64) -> Self {
        let mut start = Vec::with_capacity(obstacles.len() + 1);
        let mut n = 0;
        start.push(0);
        for o in obstacles {
            n += friction_wedges(o, dx);
            start.push(n);
        }
        WedgeTable {
            start,
            reach: POOL_CELLS * dx,
            touch_reach: touch_reach(dx),
        }
    }

    /// Global wedge of a contact node of obstacle `k` with outward normal `n`.
    #[inline]
    pub fn wedge(&self, k: usize, n: Vec2) -> u32 {
        let wedges = self.start[k + 1] - self.start[k];
        let a = polar_angle(n); // [0, 2 pi]
        let w = ((a * (wedges as f64 / (2.0 * std::f64::consts::PI))) as usize).min(wedges - 1);
        (self.start[k] + w) as u32
    }
}

/// Polar angle of a unit vector in `[0, 2 pi]`, to 2e-5 rad (a
/// polynomial arctangent on the octant, cheaper than `atan2`; only the
/// wedge a node falls in depends on it).
#[inline(always)]
fn polar_angle(n: Vec2) -> f64 {
    use std::f64::consts::{FRAC_PI_2, PI};
    let (ax, ay) = (n.x.abs(), n.y.abs());
    let (lo, hi) = if ax < ay { (ax, ay) } else { (ay, ax) };
    let t = if hi > 0.0 { lo / hi } else { 0.0 };
    // atan(t) on [0, 1] (Abramowitz and Stegun 4.4.49)
    let t2 = t * t;
    let mut a =
        t * (0.9998660 + t2 * (-0.3302995 + t2 * (0.1801410 + t2 * (-0.0851330 + t2 * 0.0208351))));
    if ax < ay {
        a = FRAC_PI_2 - a;
    }
    if n.x < 0.0 {
        a = PI - a;
    }
    if n.y < 0.0 {
        a = 2.0 * PI - a;
    }
    a
}

/// Friction part of obstacle contact (see the module documentation) on
/// the contact nodes `bands` (per band, in a fixed order, so the sums are
/// the same for any thread count) of the node velocities `node` (`[vx, vy,
/// dvx, dvy]`; with `flip` the change is kept in step). `changed` sees
/// every node it changed, for the walls to act on again.
pub fn obstacle_friction(
    obstacles: &[Obstacle],
    table: &WedgeTable,
    bands: &[Vec<ContactNode>],
    node: &mut [[f64; 4]],
    flip: bool,
    changed: &mut dyn FnMut(&ContactNode, &mut [f64; 4]),
) {
    // per wedge: mass, tangential momentum (along perp(n)), normal impulse
    let mut sums = vec![[0.0f64; 3]; table.start[obstacles.len()]];
    for c in bands.iter().flatten() {
        let v = node[c.index];
        let s = &mut sums[c.wedge as usize];
        s[0] += c.mass;
        s[1] += c.mass * (v[0] * -c.normal.y + v[1] * c.normal.x);
        s[2] += c.impulse;
    }
    // the shared tangential velocity change of each wedge, in place of its sums
    for (k, o) in obstacles.iter().enumerate() {
        let mu = o.friction;
        for s in &mut sums[table.start[k]..table.start[k + 1]] {
            let [m, pt, jn] = *s;
            s[0] = if m <= 0.0 || pt == 0.0 || mu <= 0.0 {
                0.0
            } else if pt.abs() <= mu * jn {
                -pt / m
            } else {
                -pt.signum() * mu * jn / m
            };
        }
    }
    for c in bands.iter().flatten() {
        let d = sums[c.wedge as usize][0];
        if d == 0.0 {
            continue;
        }
        let t = Vec2::new(-c.normal.y, c.normal.x) * d;
        let out = &mut node[c.index];
        out[0] += t.x;
        out[1] += t.y;
        if flip {
            out[2] += t.x;
            out[3] += t.y;
        }
        changed(c, out);
    }
}

/// Whether node `k` of an `n`-node axis lies in the lower and in the upper
/// wall, `cells` thick: the nodes [`wall_velocity`] holds and
/// [`sticky_share`] weighs.
#[inline(always)]
fn in_walls(cells: usize, n: usize, k: usize) -> (bool, bool) {
    (k < cells, k + cells >= n)
}

/// Whether a sticky wall `cells` thick holds node `(i, j)` of an `n x n`
/// grid (sets its velocity to zero, [`wall_velocity`]).
#[inline(always)]
pub fn sticky_holds(cells: usize, n: usize, i: usize, j: usize) -> bool {
    let ((lo_x, hi_x), (lo_y, hi_y)) = (in_walls(cells, n, i), in_walls(cells, n, j));
    lo_x || hi_x || lo_y || hi_y
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
    let (lo_x, hi_x) = in_walls(cells, n, i);
    let (lo_y, hi_y) = in_walls(cells, n, j);
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

/// The share of the stencil weight of a particle at `x` (quadratic
/// B-spline, [`Stencil`]) on the nodes a sticky wall `cells` thick holds
/// on an `n`-node grid of spacing `1 / inv_dx` ([`wall_velocity`]): the
/// fraction of a force on the particle that the wall absorbs, 0 away
/// from the walls and 1 deep inside them.
#[inline]
pub fn sticky_share(cells: usize, n: usize, inv_dx: f64, x: Vec2) -> f64 {
    let s = Stencil::new(x, inv_dx);
    // a particle keeps `x >= dx` (`clamp_to_grid`): its stencil's nodes
    // are not negative
    let (bi, bj) = (s.base[0] as usize, s.base[1] as usize);
    let mut held = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            if sticky_holds(cells, n, bi + i, bj + j) {
                held += s.weight(i, j);
            }
        }
    }
    held
}

/// Where a particle ends its move of a substep: outside every obstacle of
/// `obstacles` ([`project_out_of`]), then where its stencil stays on the
/// grid ([`clamp_to_grid`] within [`grid_bounds`]).
#[inline(always)]
pub fn keep_in_domain(obstacles: &[Obstacle], bounds: (f64, f64), x: &mut Vec2, v: &mut Vec2) {
    project_out_of(obstacles, x, v);
    clamp_to_grid(x, v, bounds.0, bounds.1);
}

/// [`project_out`] of every obstacle of `obstacles`, in their order.
#[inline(always)]
pub fn project_out_of(obstacles: &[Obstacle], x: &mut Vec2, v: &mut Vec2) {
    for o in obstacles {
        project_out(o, x, v);
    }
}

/// The coordinates, m, a particle of the grid `n` cells of `dx` a side may
/// take on each axis (its 3x3 stencil stays on the grid): `[dx, (n - 2) dx]`.
#[inline]
pub fn grid_bounds(dx: f64, n: usize) -> (f64, f64) {
    (dx, (n as f64 - 2.0) * dx)
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

#[cfg(test)]
mod tests {
    use super::*;

    /// With a yarn diameter the grown circle's normal law acts on the
    /// touching mass only, inside too; without one, in full inside; the
    /// obstacles grow by d / 2 and stay as they are without a diameter.
    #[test]
    fn a_yarn_diameter_grows_the_circle_and_drops_the_full_law_inside() {
        let o = Obstacle {
            center: [0.5, 0.5],
            radius: 0.1,
            friction: 0.3,
        };
        let grown = with_yarn_radius(std::slice::from_ref(&o), Some(0.004));
        assert_eq!(grown[0].radius, 0.1 + 0.002);
        assert_eq!(with_yarn_radius(std::slice::from_ref(&o), None)[0], o);
        let inside = Vec2::new(0.5, 0.55);
        let reach = 0.01;
        assert_eq!(normal_share(&o, inside, 0.0, 0.0, reach).0, 1.0);
        assert_eq!(normal_share(&grown[0], inside, 0.0, 0.002, reach).0, 0.0);
        assert_eq!(normal_share(&grown[0], inside, 0.25, 0.002, reach).0, 0.25);
        // touching mass acts within the reach of o's surface, not beyond
        let near = Vec2::new(0.5, 0.609);
        let far = Vec2::new(0.5, 0.611);
        assert_eq!(normal_share(&o, near, 0.25, 0.0, reach).0, 0.25);
        assert_eq!(normal_share(&o, far, 0.25, 0.0, reach).0, 0.0);
    }

    /// The sticky share is the stencil weight on the nodes
    /// [`wall_velocity`] holds: 0 where no held node is in reach, 1 where
    /// all are, between at the edge of the wall; the same at each wall.
    #[test]
    fn sticky_share_is_the_weight_on_the_held_nodes() {
        let (cells, n) = (3, 64);
        let inv_dx = 64.0;
        let held = |i: i32, j: i32| {
            let v = wall_velocity(
                WallMode::Sticky,
                cells,
                n,
                i as usize,
                j as usize,
                Vec2::new(1.0, 1.0),
            );
            v == Vec2::zeros()
        };
        for x in [
            Vec2::new(0.5, 0.5),
            Vec2::new(0.03, 0.5),
            Vec2::new(0.07, 0.5),
            Vec2::new(0.5, 0.97),
            Vec2::new(0.02, 0.02),
        ] {
            let s = Stencil::new(x, inv_dx);
            let mut want = 0.0;
            for i in 0..3 {
                for j in 0..3 {
                    if held(s.base[0] + i as i32, s.base[1] + j as i32) {
                        want += s.weight(i, j);
                    }
                }
            }
            assert_eq!(sticky_share(cells, n, inv_dx, x), want, "at {x:?}");
        }
        assert_eq!(sticky_share(cells, n, inv_dx, Vec2::new(0.5, 0.5)), 0.0);
        assert!((sticky_share(cells, n, inv_dx, Vec2::new(0.02, 0.5)) - 1.0).abs() < 1e-12);
        let edge = sticky_share(cells, n, inv_dx, Vec2::new(0.03, 0.5));
        assert!(edge > 0.5 && edge < 1.0, "{edge}");
        let mirrored = sticky_share(cells, n, inv_dx, Vec2::new(1.0 - 0.03 - 1.0 / 64.0, 0.5));
        assert!((mirrored - edge).abs() < 1e-12, "{mirrored} {edge}");
        // sticky_holds names the same nodes, on every node of the grid
        for i in 0..n as i32 {
            for j in 0..n as i32 {
                let h = sticky_holds(cells, n, i as usize, j as usize);
                assert_eq!(h, held(i, j), "node ({i}, {j})");
            }
        }
    }

    #[test]
    fn polar_angle_matches_atan2_to_2e_5_rad() {
        for k in 0..100_000 {
            let a = k as f64 * (2.0 * std::f64::consts::PI / 100_000.0) + 1e-9;
            let n = Vec2::new(a.cos(), a.sin());
            let mut want = n.y.atan2(n.x);
            if want < 0.0 {
                want += 2.0 * std::f64::consts::PI;
            }
            let got = polar_angle(n);
            // tolerance 2e-5 rad: the polynomial's stated bound 1e-5 is exceeded slightly
            // (1.1e-5 measured near 0.1 rad); away from the 0 / 2 pi seam
            assert!(
                (got - want).abs() < 2e-5 || (got - want).abs() > 6.0,
                "{a}: {got} vs {want}"
            );
        }
    }
}
