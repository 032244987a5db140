//! The expanded mass-spring scene: flat arrays of particles, springs,
//! kinematic constraints and colliders that the integrators in
//! [`crate::massspring`] advance.

use nalgebra::Vector3;

/// 3-vector of f64 used throughout the mass-spring model.
pub type V3 = Vector3<f64>;

/// One spring of the expanded system.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spring {
    /// Index of the first particle.
    pub a: usize,
    /// Index of the second particle.
    pub b: usize,
    /// Stiffness in N/m.
    pub k: f64,
    /// Damping in N s/m.
    pub damping: f64,
    /// Rest length in m.
    pub rest_length: f64,
}

/// How a particle moves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kinematic {
    /// Moved by the integrator.
    Free,
    /// Held at this position (bitwise).
    Pinned(V3),
    /// Driven on a circle.
    Circle {
        /// Centre of the circle in m.
        center: V3,
        /// Position relative to the centre at phase pi/2 (the `sin` axis) in m.
        u: V3,
        /// Position relative to the centre at phase 0 (the `cos` axis) in m.
        v: V3,
        /// Angular velocity in rad/s.
        omega: f64,
        /// Phase at t = 0 in rad.
        phase: f64,
    },
}

impl Kinematic {
    /// Prescribed position and velocity at time `t`, or `None` for a free particle.
    pub fn at(&self, t: f64) -> Option<(V3, V3)> {
        match *self {
            Kinematic::Free => None,
            Kinematic::Pinned(x) => Some((x, V3::zeros())),
            Kinematic::Circle {
                center,
                u,
                v,
                omega,
                phase,
            } => {
                let a = omega * t + phase;
                let (s, c) = a.sin_cos();
                Some((center + u * s + v * c, (u * c - v * s) * omega))
            }
        }
    }

    /// Whether the integrator moves this particle.
    pub fn is_free(&self) -> bool {
        matches!(self, Kinematic::Free)
    }
}

/// A sphere collider of the expanded system.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre in m.
    pub center: V3,
    /// Radius in m.
    pub radius: f64,
}

/// The expanded scene: flat arrays the integrators work on.
#[derive(Clone, Debug, PartialEq)]
pub struct System {
    /// Initial positions in m.
    pub positions: Vec<V3>,
    /// Initial velocities in m/s.
    pub velocities: Vec<V3>,
    /// Masses in kg.
    pub masses: Vec<f64>,
    /// Springs between particles.
    pub springs: Vec<Spring>,
    /// One entry per particle.
    pub kinematics: Vec<Kinematic>,
    /// Sphere colliders.
    pub spheres: Vec<Sphere>,
    /// Gravity in m/s^2.
    pub gravity: V3,
    /// Time between output frames in s.
    pub frame_time: f64,
    /// Number of frames of a whole run.
    pub frames: u32,
    /// Step of the implicit integrators in s.
    pub time_step: f64,
    /// Fraction of the explicit integrators' stability bound they step with.
    pub cfl_number: f64,
    /// Fraction of the free particles' velocity kept per `frame_time`.
    pub velocity_damping: f64,
    /// Largest spring strain `|l/l0 - 1|` the strain limiting allows, if any.
    pub strain_limit: Option<f64>,
}

impl System {
    /// Number of particles.
    pub fn len(&self) -> usize {
        self.positions.len()
    }
    /// Whether there are no particles.
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }
    /// Whether particle `i` is moved by the integrator.
    pub fn is_free(&self, i: usize) -> bool {
        self.kinematics[i].is_free()
    }
    /// Number of free particles.
    pub fn free_count(&self) -> usize {
        self.kinematics.iter().filter(|k| k.is_free()).count()
    }
}
