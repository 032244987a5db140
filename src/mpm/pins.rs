//! Pinned and driven yarn vertices: each pin holds some vertices on a
//! prescribed path (fixed, a line, a circle). After every grid-to-particle
//! pass the pinned vertices get exactly their prescribed position and
//! velocity; the momentum this takes, per substep, is the pin's reaction
//! force on the yarn.

use super::particles::{Particles, Vertices};
use crate::math::{perp, Mat2, Vec2};
use crate::scene::{PinMotionKind, SceneError, YarnScene};

/// How a pin moves its vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PinMotion {
    /// Held where they start.
    Fixed,
    /// `x(t) = x(0) + velocity t`.
    Line { velocity: Vec2 },
    /// Turned rigidly about `center`: `x(t) = center + Rot(omega t) (x(0) - center)`.
    Circle { center: Vec2, omega: f64 },
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
        }
    }

    /// Prescribed affine velocity matrix `C` (the velocity gradient of the
    /// motion) of the pin's vertices: zero for fixed and line motions, the
    /// rotation rate `omega [[0, -1], [1, 0]]` for a circle.
    pub fn affine(&self) -> Mat2 {
        match self.motion {
            PinMotion::Fixed | PinMotion::Line { .. } => Mat2::zeros(),
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
            let origin = vertices.iter().map(|&i| p.vert.x[i]).collect();
            let motion = match spec.motion {
                PinMotionKind::Fixed => PinMotion::Fixed,
                PinMotionKind::Line => PinMotion::Line {
                    velocity: Vec2::from(spec.velocity.expect("validated")),
                },
                PinMotionKind::Circle => PinMotion::Circle {
                    center: Vec2::from(spec.center.expect("validated")),
                    omega: spec.angular_velocity.expect("validated"),
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

/// Puts every pinned vertex at its target at time `t` and returns, per pin,
/// the force the pin exerted on the yarn over the last substep of length
/// `dt`: `sum (m (v_target - v) / dt - f)` over its vertices, with `v` the
/// velocity the vertex had from the grid and `f` the yarn's internal force
/// on it (not scattered to the grid: the pin takes it up, see
/// [`super::particle_to_grid::scatter_pinned`]).
pub fn apply(pins: &[Pin], vert: &mut Vertices, t: f64, dt: f64, reactions: &mut Vec<Vec2>) {
    reactions.clear();
    for pin in pins {
        let mut force = Vec2::zeros();
        for (k, &i) in pin.vertices.iter().enumerate() {
            let (x, v) = pin.target(k, t);
            force += (v - vert.v[i]) * (vert.m[i] / dt) - vert.f[i];
            vert.x[i] = x;
            vert.v[i] = v;
            // Without this a FLIP transfer keeps adding the grid's change of
            // `C` to a vertex whose velocity is reset, and `C` grows without
            // bound (a pinned hanging yarn diverged within 0.02 s).
            vert.c[i] = pin.affine();
        }
        reactions.push(force);
    }
}

/// Sets the pinned vertices to their targets at time `t` without measuring
/// a reaction (at the start, or after the state was set from outside).
pub fn place(pins: &[Pin], vert: &mut Vertices, t: f64) {
    for pin in pins {
        for (k, &i) in pin.vertices.iter().enumerate() {
            let (x, v) = pin.target(k, t);
            vert.x[i] = x;
            vert.v[i] = v;
            vert.c[i] = pin.affine();
        }
    }
}
