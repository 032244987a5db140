//! Pinned and driven yarn vertices: each pin holds some vertices on a
//! prescribed path (fixed, a line, a circle) or on a target set at run time
//! ([`PinMotion::Input`], [`YarnSim::set_pin_target`](crate::mpm::YarnSim::set_pin_target)).
//!
//! A pin acts on the grid, as a constraint: after the grid update,
//! [`constrain_grid`] adds to the nodes of each pinned vertex's stencil the
//! impulse (spread with the vertex's weights, like any force on it) that
//! makes the grid velocity interpolated at the vertex equal its prescribed
//! velocity, so the yarn around the pin feels the pin's force in the same
//! substep. (Resetting only the pinned particles lets the grid near the pin
//! fall freely: the pull of the pinned vertex on its neighbour and theirs
//! on it cancel on the shared nodes, the first segment stretches without
//! bound, and a hanging yarn diverges within 0.02 s.) After every
//! grid-to-particle pass the pinned vertices get exactly their prescribed
//! position and velocity ([`apply`]); the constraint impulse plus what this
//! takes, per substep, is the pin's reaction force on the yarn.

use crate::math::{perp, Mat2, Vec2};
use crate::mpm::machinery::grid::{Grid, DVX, DVY, VX, VY};
use crate::mpm::machinery::particles::{Particles, Vertices};
use crate::scene::{PinMotionKind, SceneError, YarnScene};

/// How a pin moves its vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PinMotion {
    /// Held where they start.
    Fixed,
    /// `x(t) = x(0) + velocity t`.
    Line {
        /// m/s.
        velocity: Vec2,
    },
    /// Turned rigidly about `center`: `x(t) = center + Rot(omega t) (x(0) - center)`.
    Circle {
        /// Centre of the turn, m.
        center: Vec2,
        /// Angular velocity, rad/s (counter-clockwise).
        omega: f64,
    },
    /// Driven from outside: the first vertex at
    /// `x(t) = position + velocity (t - since)` with velocity `velocity`, the
    /// others translated rigidly with it (their offsets from the first
    /// vertex stay those of t = 0). Until a target is set: `position` is the
    /// first vertex's start, `velocity` zero (a fixed pin).
    Input {
        /// The first vertex's target position at `since`, m.
        position: Vec2,
        /// Its target velocity, m/s.
        velocity: Vec2,
        /// Time the target was set, s.
        since: f64,
    },
}

/// One pin: its vertices (global indices), where they start, how they move.
#[derive(Clone, Debug, PartialEq)]
pub struct Pin {
    /// Yarn index.
    pub yarn: usize,
    /// Global vertex indices.
    pub vertices: Vec<usize>,
    /// Their positions at t = 0.
    pub origin: Vec<Vec2>,
    /// How the pinned vertices move.
    pub motion: PinMotion,
}

impl Pin {
    /// Prescribed position and velocity of the pin's `k`-th vertex at time `t`.
    pub fn target(&self, k: usize, t: f64) -> (Vec2, Vec2) {
        let x0 = self.origin[k];
        match self.motion {
            PinMotion::Fixed => (x0, Vec2::zeros()),
            PinMotion::Line { velocity } => (x0 + velocity * t, velocity),
            PinMotion::Circle { center, omega } => {
                let (s, c) = (omega * t).sin_cos();
                let r0 = x0 - center;
                let r = Vec2::new(c * r0.x - s * r0.y, s * r0.x + c * r0.y);
                (center + r, perp(r) * omega)
            }
            PinMotion::Input {
                position,
                velocity,
                since,
            } => {
                // The first vertex exactly at the input; the others keep
                // their offset (written so that an input pin set once to a
                // line's start and velocity gives the `Line` bits).
                let base = if k == 0 {
                    position
                } else {
                    x0 + (position - self.origin[0])
                };
                (base + velocity * (t - since), velocity)
            }
        }
    }
}

impl Pin {
    /// Prescribed velocity gradient (the affine matrix `C`) of the pin's
    /// vertices: zero for a fixed, translating or input pin, the rigid rotation
    /// `[[0, -omega], [omega, 0]]` for a circle.
    pub fn velocity_gradient(&self) -> Mat2 {
        match self.motion {
            PinMotion::Fixed | PinMotion::Line { .. } | PinMotion::Input { .. } => Mat2::zeros(),
            PinMotion::Circle { omega, .. } => Mat2::new(0.0, -omega, omega, 0.0),
        }
    }
}

/// The pins of a scene over its particles (validated).
pub fn pins_of_scene(scene: &YarnScene, p: &Particles) -> Result<Vec<Pin>, SceneError> {
    let ranges = scene.pin_ranges()?;
    Ok(scene
        .pins
        .iter()
        .zip(ranges)
        .map(|(spec, (yarn, r))| {
            let base = p.yarn_vertices[yarn];
            let vertices: Vec<usize> = r.map(|i| base + i).collect();
            let origin: Vec<Vec2> = vertices.iter().map(|&i| p.vert.x[i]).collect();
            let motion = match spec.motion {
                PinMotionKind::Fixed => PinMotion::Fixed,
                PinMotionKind::Line => PinMotion::Line {
                    velocity: Vec2::from(spec.velocity.expect("validated")),
                },
                PinMotionKind::Circle => PinMotion::Circle {
                    center: Vec2::from(spec.center.expect("validated")),
                    omega: spec.angular_velocity.expect("validated"),
                },
                PinMotionKind::Input => PinMotion::Input {
                    position: origin[0],
                    velocity: Vec2::zeros(),
                    since: 0.0,
                },
            };
            Pin {
                yarn,
                vertices,
                origin,
                motion,
            }
        })
        .collect())
}

/// Most Gauss-Seidel sweeps of [`constrain_grid`] (pins whose stencils
/// overlap couple; the sweeps stop once every pinned vertex's interpolated
/// velocity is its target to round-off).
const PIN_SWEEPS: usize = 200;

/// One pinned vertex's stencil on the grid: node indices, weights, the
/// weights over the node masses and the target velocity at the end of the
/// substep (see [`constrain_grid`]).
#[derive(Clone, Debug)]
pub struct PinEntry {
    pub(crate) pin: usize,
    pub(crate) idx: [usize; 9],
    pub(crate) w: [f64; 9],
    /// `w_i / m_i` (0 where the node has no mass).
    w_inv_m: [f64; 9],
    denom: f64,
    pub(crate) target: Vec2,
}

/// The stencils of every pinned vertex with the node masses of this
/// substep's scatter: read after the scatter and before the grid update
/// (which consumes the scatter buffers), for the substep ending at `t`.
pub fn stencil_masses(pins: &[Pin], vert: &Vertices, grid: &Grid, t: f64) -> Vec<PinEntry> {
    let geom = grid.geom;
    let mut entries = Vec::new();
    for (k, pin) in pins.iter().enumerate() {
        for (j, &i) in pin.vertices.iter().enumerate() {
            let st = &vert.stencil[i];
            let (bi, bj) = (st.base[0] as usize, st.base[1] as usize);
            let mut e = PinEntry {
                pin: k,
                idx: [0; 9],
                w: [0.0; 9],
                w_inv_m: [0.0; 9],
                denom: 0.0,
                target: pin.target(j, t).1,
            };
            for a in 0..3 {
                for b in 0..3 {
                    let n = 3 * a + b;
                    let (ni, nj) = (bi + a, bj + b);
                    let idx = geom.index(ni, nj);
                    let m = grid.scattered_mass(idx, ni, nj);
                    let w = st.weight(a, b);
                    e.idx[n] = idx;
                    e.w[n] = w;
                    if m > 0.0 {
                        e.w_inv_m[n] = w / m;
                        e.denom += w * w / m;
                    }
                }
            }
            if e.denom > 0.0 {
                entries.push(e);
            }
        }
    }
    entries
}

/// Pin constraint on the grid after the grid update of the substep: for
/// each pinned vertex (the `entries` of [`stencil_masses`]: weights `w_i`
/// of its start-of-step stencil, node masses `m_i`) the impulse
/// `J = (v_target - sum w_i v_i) / sum (w_i^2 / m_i)` is added to its nodes
/// as `w_i J / m_i` (to the velocity and, for FLIP, to its change), in
/// Gauss-Seidel sweeps over all pinned vertices. Sets `forces[k]` to
/// `sum J / dt` of pin `k` (`n_pins` pins).
pub fn constrain_grid(
    entries: &[PinEntry],
    n_pins: usize,
    grid: &mut Grid,
    dt: f64,
    forces: &mut Vec<Vec2>,
) {
    forces.clear();
    forces.resize(n_pins, Vec2::zeros());
    for _ in 0..PIN_SWEEPS {
        let mut worst: f64 = 0.0;
        let mut scale: f64 = 0.0;
        for e in entries {
            let mut v = Vec2::zeros();
            for n in 0..9 {
                let node = &grid.node[e.idx[n]];
                v += Vec2::new(node[VX], node[VY]) * e.w[n];
            }
            let r = e.target - v;
            worst = worst.max(r.norm());
            scale = scale.max(v.norm()).max(e.target.norm());
            let j = r / e.denom;
            for n in 0..9 {
                let dv = j * e.w_inv_m[n];
                let node = &mut grid.node[e.idx[n]];
                node[VX] += dv.x;
                node[VY] += dv.y;
                node[DVX] += dv.x;
                node[DVY] += dv.y;
            }
            forces[e.pin] += j / dt;
        }
        if worst <= 1e-13 * scale.max(1e-300) || worst == 0.0 {
            break;
        }
    }
}

/// Marks in `out` (one entry per node of the window) the nodes of every
/// pinned vertex's stencil that carry weight: `1 + pin` (the last pin in
/// `entries` order where stencils of two pins share a node).
pub fn mark_stencil_nodes(entries: &[PinEntry], out: &mut [u32]) {
    set_stencil_nodes(entries, out, true);
}

/// Undoes [`mark_stencil_nodes`] of the same `entries`: their nodes back
/// to 0.
pub fn unmark_stencil_nodes(entries: &[PinEntry], out: &mut [u32]) {
    set_stencil_nodes(entries, out, false);
}

/// The weighted stencil nodes of `entries` in `out` to `1 + pin` (`mark`)
/// or 0.
fn set_stencil_nodes(entries: &[PinEntry], out: &mut [u32], mark: bool) {
    for e in entries {
        for n in 0..9 {
            if e.w[n] > 0.0 {
                out[e.idx[n]] = if mark { e.pin as u32 + 1 } else { 0 };
            }
        }
    }
}

/// Puts `pin`'s vertices at their targets at time `t` (position, velocity
/// and the prescribed velocity gradient as their affine matrix: a FLIP
/// vertex would otherwise keep adding the grid's change of `C` to a `C`
/// that nothing resets, which diverges within 0.02 s at a pinned yarn end);
/// with `dt`, returns the force this exerted over a substep of that length,
/// `sum m (v_target - v) / dt`.
fn set_to_target(pin: &Pin, vert: &mut Vertices, t: f64, dt: Option<f64>) -> Vec2 {
    let c = pin.velocity_gradient();
    let mut force = Vec2::zeros();
    for (k, &i) in pin.vertices.iter().enumerate() {
        let (x, v) = pin.target(k, t);
        if let Some(dt) = dt {
            force += (v - vert.v[i]) * (vert.m[i] / dt);
        }
        vert.x[i] = x;
        vert.v[i] = v;
        vert.c[i] = c;
    }
    force
}

/// Puts every pinned vertex at its target at time `t` and adds to
/// `reactions[k]`, per pin, the force this exerted on the yarn over the last
/// substep of length `dt`: `sum m (v_target - v) / dt` over its vertices,
/// with `v` the velocity the vertex had from the grid.
pub fn apply(pins: &[Pin], vert: &mut Vertices, t: f64, dt: f64, reactions: &mut [Vec2]) {
    for (pin, reaction) in pins.iter().zip(reactions.iter_mut()) {
        *reaction += set_to_target(pin, vert, t, Some(dt));
    }
}

/// Sets the pinned vertices to their targets at time `t` without measuring
/// a reaction (at the start, or after the state was set from outside).
pub fn place(pins: &[Pin], vert: &mut Vertices, t: f64) {
    for pin in pins {
        set_to_target(pin, vert, t, None);
    }
}
