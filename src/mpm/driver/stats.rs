//! What a running simulation reports about its own stepping: the passes a
//! scene needs, the time spent in each, and the substeps taken.

/// Which optional passes a scene needs; the stepper skips the others.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Passes {
    /// Bending forces (bending stiffness > 0).
    pub bending: bool,
    /// The plastic return mapping.
    pub plasticity: bool,
    /// Obstacle contact.
    pub obstacles: bool,
    /// The attractor (active, nonzero strength).
    pub attractor: bool,
    /// Domain walls.
    pub walls: bool,
}

/// Wall-clock seconds spent in each pass since the last reset.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PassTimes {
    /// Stencils and stress recomputed from the frames after the state was
    /// set from outside (new simulation, restore, edited particles); zero
    /// in steady stepping, where [`PassTimes::gather_quads`] does this work.
    pub forces: f64,
    /// Particle-to-grid, with the vertex forces (fiber and bending).
    pub scatter: f64,
    /// Grid velocities, gravity, attractor, obstacles, walls.
    pub grid: f64,
    /// Grid-to-particle of the vertices, advection, obstacle projection.
    pub gather_vertices: f64,
    /// Grid-to-particle of the quadrature particles, return mapping, stress.
    pub gather_quads: f64,
    /// Substeps counted.
    pub substeps: u64,
}

impl PassTimes {
    /// All passes together, s.
    pub fn total(&self) -> f64 {
        self.forces + self.scatter + self.grid + self.gather_vertices + self.gather_quads
    }

    /// `(name, seconds)` of every pass, in execution order.
    pub fn entries(&self) -> [(&'static str, f64); 5] {
        [
            (
                "stress refresh (only after outside state changes)",
                self.forces,
            ),
            ("P2G scatter + vertex forces (fiber, bending)", self.scatter),
            (
                "grid update (gravity, attractor, obstacles, walls)",
                self.grid,
            ),
            (
                "G2P vertices + advection + obstacle projection",
                self.gather_vertices,
            ),
            (
                "G2P quadrature + return mapping + stress",
                self.gather_quads,
            ),
        ]
    }
}

/// The substeps taken since the last reset: count and sizes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DtStats {
    /// Substeps counted.
    pub substeps: u64,
    /// Smallest substep, s.
    pub min: f64,
    /// Largest substep, s.
    pub max: f64,
    /// Sum of the substeps (simulated time), s.
    pub sum: f64,
}

impl Default for DtStats {
    fn default() -> Self {
        DtStats {
            substeps: 0,
            min: f64::INFINITY,
            max: 0.0,
            sum: 0.0,
        }
    }
}

impl DtStats {
    pub(super) fn record(&mut self, dt: f64) {
        self.substeps += 1;
        self.min = self.min.min(dt);
        self.max = self.max.max(dt);
        self.sum += dt;
    }

    /// Mean substep, s (0 before any).
    pub fn mean(&self) -> f64 {
        if self.substeps == 0 {
            0.0
        } else {
            self.sum / self.substeps as f64
        }
    }
}
