//! The driver: [`YarnSim`], a yarn-bundle scene turned into a running MPM
//! simulation, and everything it does itself: stepping and the substep
//! (`substep.rs`, where the integrator is chosen), the grid integrators'
//! grid velocities as the substep calls them (`substep.rs`,
//! `implicit_grid.rs`), the axial springs' vertex step of the explicit
//! substep (`axial.rs`), the grid-free substep (`implicit_vertex.rs`),
//! cutback (`cutback.rs`), the stable time step ([`timestep`]), the dynamic
//! state ([`state`]), diagnostics (`diagnostics.rs`) and statistics
//! (`stats.rs`).

use crate::math::Vec2;
pub use crate::mpm::error::SimError;
use crate::mpm::laws::bending;
use crate::mpm::laws::constitutive::YarnEnergy;
use crate::mpm::laws::contact::with_yarn_radius;
use crate::mpm::laws::fields::{Fields, Partition};
use crate::mpm::laws::pins::{self, Pin};
use crate::mpm::machinery::grid::{Grid, GridGeom};
use crate::mpm::machinery::particles::Particles;
use crate::mpm::machinery::transfer::Transfer;

mod axial;
mod cutback;
mod diagnostics;
mod implicit_grid;
mod implicit_vertex;
pub mod state;
mod stats;
mod substep;
pub mod timestep;

use crate::scene::{
    FieldPartition, Obstacle, SceneError, StepSize, TransferScheme, TransferSpec, WallMode,
    YarnScene, DEFAULT_SAFETY,
};
pub use cutback::{ENERGY_TOL, MAX_CUTBACKS};
pub use diagnostics::Diagnostics;
pub use implicit_grid::ImplicitStats;
pub use implicit_vertex::THETA;
pub use stats::{DtStats, PassTimes, Passes};

pub use crate::mpm::laws::attractor::Attractor;

/// How the substep is chosen (`[time] dt`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stepping {
    /// Every substep has the same size.
    Fixed(f64),
    /// `dt = "auto"`: each substep is `min(safety * stable_dt, dt_max)` of
    /// the state it starts from ([`timestep::stable_dt`]).
    Auto {
        /// Factor on the stability bound, in (0, 2].
        safety: f64,
        /// Largest substep, s.
        dt_max: f64,
    },
}

/// A running yarn-bundle simulation.
#[derive(Clone, Debug)]
pub struct YarnSim {
    scene: YarnScene,
    pub(crate) particles: Particles,
    grid: Grid,
    energy: YarnEnergy,
    pub(crate) dt: f64,
    stepping: Stepping,
    dt_stats: DtStats,
    pub(crate) gravity: Vec2,
    pub(crate) attractor: Attractor,
    pub(crate) time: f64,
    pub(crate) steps: u64,
    pub(crate) failed: Option<SimError>,
    /// `particles.quad.frame` must be recomputed from `d` before the next step.
    pub(crate) frames_stale: bool,
    timings: PassTimes,
    transfer: Transfer,
    pins: Vec<Pin>,
    /// Force of each pin on the yarn over the last substep.
    pin_reactions: Vec<Vec2>,
    /// Whether each vertex is held by a pin.
    pinned: Vec<bool>,
    /// The velocity fields beyond the grid's own, when the scene's yarns
    /// fall into more than one ([`crate::mpm::laws::fields`]); `None`: one
    /// field for all.
    fields: Option<Fields>,
    /// The obstacles as contact sees them: the scene's, each grown by half
    /// the yarn diameter where `material.diameter` is given (a yarn's
    /// centre line rests `d / 2` from the surface), else the scene's as
    /// they are ([`crate::mpm::laws::contact::with_yarn_radius`]).
    obstacles: Vec<Obstacle>,
    /// Newton and CG iterations of the implicit substeps.
    implicit_stats: ImplicitStats,
    /// The axial solve's buffers (`[time] axial = "implicit"`).
    axial_scratch: axial::AxialScratch,
}

/// The transfer scheme a scene asks for.
pub fn transfer_of(spec: &TransferSpec) -> Transfer {
    match spec.scheme {
        TransferScheme::Apic => Transfer::Apic,
        TransferScheme::Flip => Transfer::Flip {
            ratio: spec.flip_ratio,
        },
    }
}

/// How a scene's substeps are chosen.
pub fn stepping_of(scene: &YarnScene) -> Stepping {
    match scene.time.dt {
        StepSize::Fixed(dt) => Stepping::Fixed(dt),
        StepSize::Auto => Stepping::Auto {
            safety: scene.time.safety.unwrap_or(DEFAULT_SAFETY),
            // implicit: no stability cap, so the frame time by default
            dt_max: scene
                .time
                .dt_max
                .unwrap_or(if scene.time.integrator.is_implicit() {
                    scene.time.frame_dt
                } else {
                    f64::INFINITY
                }),
        },
    }
}

impl YarnSim {
    /// Builds the simulation of a scene, at rest at t = 0.
    pub fn new(scene: &YarnScene) -> Result<Self, SceneError> {
        scene.validate()?;
        let geom = GridGeom::new(scene.grid.resolution as usize, scene.grid.size);
        let mut particles = Particles::from_scene(scene, bending::rest_of_curve);
        let pins = pins::pins_of_scene(scene, &particles)?;
        pins::place(&pins, &mut particles.vert, 0.0);
        let mut pinned = vec![false; particles.vert.x.len()];
        for pin in &pins {
            for &i in &pin.vertices {
                pinned[i] = true;
            }
        }
        let mut held_yarn = vec![false; particles.num_yarns()];
        for pin in &pins {
            held_yarn[pin.yarn] = true;
        }
        let mut grid = Grid::new(geom);
        let fields = Fields::of_yarns(
            match scene.contact.fields {
                FieldPartition::PerYarn => Partition::PerYarn,
                FieldPartition::HeldFree => Partition::HeldFree,
            },
            &held_yarn,
            &particles.yarn_vertices,
            &particles.quad.left,
            &mut grid,
            scene.material.diameter(),
        );
        let mut sim = YarnSim {
            obstacles: with_yarn_radius(&scene.obstacles, scene.material.diameter()),
            pinned,
            fields,
            transfer: transfer_of(&scene.transfer),
            pin_reactions: vec![Vec2::zeros(); pins.len()],
            pins,
            particles,
            grid,
            energy: YarnEnergy::from_material(&scene.material),
            dt: scene.time.dt.fixed().unwrap_or(0.0),
            stepping: stepping_of(scene),
            dt_stats: DtStats::default(),
            gravity: Vec2::from(scene.gravity),
            attractor: Attractor {
                position: Vec2::from(scene.attractor.position),
                strength: scene.attractor.strength,
                active: scene.attractor.active,
            },
            time: 0.0,
            steps: 0,
            failed: None,
            frames_stale: true,
            timings: PassTimes::default(),
            scene: scene.clone(),
            implicit_stats: ImplicitStats::default(),
            axial_scratch: Default::default(),
        };
        if sim.is_auto() {
            // Not used under "auto"; kept positive for the saved state.
            sim.dt = sim.auto_dt();
        }
        Ok(sim)
    }

    /// The scene it was built from.
    pub fn scene(&self) -> &YarnScene {
        &self.scene
    }
    /// The particles (vertices and quadrature particles) as they are now.
    pub fn particles(&self) -> &Particles {
        &self.particles
    }
    /// Mutable particles, to set up initial conditions in tests and tools
    /// (`crate::testing::particles_mut`). The cached frame factorisations
    /// are recomputed at the next step.
    #[cfg(feature = "testing")]
    pub(crate) fn particles_mut(&mut self) -> &mut Particles {
        self.frames_stale = true;
        &mut self.particles
    }
    /// Simulated time, s.
    pub fn time(&self) -> f64 {
        self.time
    }
    /// Substeps taken.
    pub fn steps(&self) -> u64 {
        self.steps
    }
    /// Substep size: the fixed one, or under `dt = "auto"` the one the
    /// current state allows ([`YarnSim::auto_dt`]).
    pub fn dt(&self) -> f64 {
        match self.stepping {
            Stepping::Fixed(_) => self.dt,
            Stepping::Auto { .. } => self.auto_dt(),
        }
    }
    /// How the substeps are chosen.
    pub fn stepping(&self) -> Stepping {
        self.stepping
    }
    /// Whether the substeps are chosen adaptively (`dt = "auto"`).
    pub fn is_auto(&self) -> bool {
        matches!(self.stepping, Stepping::Auto { .. })
    }
    /// The adaptive substep of the current state:
    /// `min(safety * stable_dt, dt_max)` ([`YarnSim::stable_dt`]: the
    /// elastic-wave plus particle-speed CFL bound and the bending bound;
    /// under the implicit integrator the advection limit alone, with the
    /// speed gravity adds over the substep, [`timestep::implicit_auto_dt`],
    /// `dt_max` defaulting to `frame_dt`); with a fixed `dt`, safety
    /// [`DEFAULT_SAFETY`] and no cap.
    pub fn auto_dt(&self) -> f64 {
        let (safety, dt_max) = match self.stepping {
            Stepping::Auto { safety, dt_max } => (safety, dt_max),
            Stepping::Fixed(_) => (DEFAULT_SAFETY, f64::INFINITY),
        };
        if self.is_implicit() {
            let dx = self.advection_length();
            let g = self.gravity().norm();
            return timestep::implicit_auto_dt(dx, self.max_speed(), g, safety).min(dt_max);
        }
        (safety * self.stable_dt()).min(dt_max)
    }
    /// The length a particle may cross in one implicit substep under
    /// `dt = "auto"` (times the safety and [`timestep::COURANT`]):
    /// the grid spacing, or without the grid (`"implicit-vertices"`) the
    /// shortest rest segment, so that a vertex moves less than a segment
    /// (the contacts' tangent-line constraint and their friction stay
    /// valid over the substep).
    pub fn advection_length(&self) -> f64 {
        if self.is_gridless() {
            let l = self
                .particles
                .quad
                .l0
                .iter()
                .copied()
                .fold(f64::INFINITY, f64::min);
            if l.is_finite() {
                return l;
            }
        }
        self.grid_geom().dx
    }
    /// Count and sizes of the substeps since the last
    /// [`YarnSim::reset_dt_stats`] (or since the start).
    pub fn dt_stats(&self) -> DtStats {
        self.dt_stats
    }
    /// Starts the substep statistics ([`DtStats`]) afresh.
    pub fn reset_dt_stats(&mut self) {
        self.dt_stats = DtStats::default();
    }
    /// The grid's geometry and its current window.
    pub fn grid_geom(&self) -> GridGeom {
        self.grid.geom
    }
    /// The yarn material's energy (from the scene's material).
    pub fn energy_model(&self) -> &YarnEnergy {
        &self.energy
    }
    /// Gravity, m/s^2.
    pub fn gravity(&self) -> Vec2 {
        self.gravity
    }
    /// The attractor as it is set now.
    pub fn attractor(&self) -> Attractor {
        self.attractor
    }
    /// Bytes the grid holds now: its window of nodes and the scatter
    /// buffers, and under `axial = "implicit"` with FLIP the share's node
    /// buffers (all follow the particles' bounding box, not the domain).
    pub fn grid_memory_bytes(&self) -> usize {
        self.grid.memory_bytes()
            + self.fields.as_ref().map_or(0, Fields::memory_bytes)
            + self.axial_scratch.grid_memory_bytes()
    }
    /// Whether the yarns move in more than one velocity field
    /// (`crate::mpm::laws::fields`): held and free yarns, or several free
    /// yarns under the per-yarn partition.
    pub fn has_two_fields(&self) -> bool {
        self.fields.is_some()
    }
    /// Number of velocity fields the yarns scatter into (1: one field for
    /// all; `crate::mpm::laws::fields`).
    pub fn velocity_fields(&self) -> usize {
        self.fields.as_ref().map_or(1, Fields::count)
    }
    /// Number of blocks (8x8 nodes) the last substep touched.
    pub fn active_blocks(&self) -> usize {
        self.grid.active.len()
    }
    /// Newton and CG iterations of the implicit substeps so far.
    pub fn implicit_stats(&self) -> ImplicitStats {
        self.implicit_stats
    }
    /// Whether the substeps are backward Euler (`[time] integrator`), on
    /// the grid or on the vertices.
    pub fn is_implicit(&self) -> bool {
        self.scene.time.integrator.is_implicit()
    }
    /// Whether the substeps are backward Euler on the vertices without the
    /// grid (`integrator = "implicit-vertices"` or `"midpoint-vertices"`,
    /// `crate::mpm::implicit_vertex`).
    pub fn is_gridless(&self) -> bool {
        self.scene.time.integrator.is_gridless()
    }
    /// The error that stopped the simulation, if any.
    pub fn failure(&self) -> Option<&SimError> {
        self.failed.as_ref()
    }
    /// Number of yarns.
    pub fn num_yarns(&self) -> usize {
        self.particles.num_yarns()
    }
    /// The transfer scheme; under `transfer.flip_time` its FLIP ratio is 1
    /// here and each substep of `dt` takes `exp(-dt / flip_time)`
    /// ([`Transfer::at_step`]).
    pub fn transfer(&self) -> Transfer {
        self.transfer
    }
    /// The pins of the scene, in `[[pins]]` order.
    pub fn pins(&self) -> &[Pin] {
        &self.pins
    }
    /// Force (N per m of depth) each pin exerted on its yarn over the last
    /// substep, in `[[pins]]` order: the yarn pulls on the pin with the
    /// opposite force. Zero before the first substep.
    pub fn pin_reactions(&self) -> &[Vec2] {
        &self.pin_reactions
    }
    /// The normal impulse (N s per m of depth) the obstacles' contact law
    /// of the grid update delivered over the last substep, summed over the
    /// contact nodes of the grid (the impulse that bounds the obstacle
    /// friction, `crate::mpm::laws::contact`); divided by the substep,
    /// the total normal force on the obstacles.
    pub fn obstacle_normal_impulse(&self) -> f64 {
        self.grid.contacts.iter().flatten().map(|c| c.impulse).sum()
    }

    /// Sets the target of the `motion = "input"` pin `pin` (index in
    /// `[[pins]]` order) from now on: its first vertex at
    /// `x(t) = position + velocity (t - now)` with velocity `velocity` in
    /// every following substep, its other vertices translated rigidly with
    /// it; see [`YarnSim::set_pin_target_at`].
    pub fn set_pin_target(
        &mut self,
        pin: usize,
        position: Vec2,
        velocity: Vec2,
    ) -> Result<(), SimError> {
        let now = self.time;
        self.set_pin_target_at(pin, position, velocity, now)
    }

    /// Sets the target of the `motion = "input"` pin `pin`:
    /// `x(t) = position + velocity (t - since)` for the first vertex (`t`
    /// on the simulation's clock, which starts at 0), velocity `velocity`.
    /// The pin's vertices take the velocity now (the momentum they carry
    /// to the grid in the next substep) and the position at the end of the
    /// next substep. Rejects pins that do not exist or are not input pins,
    /// non-finite values, positions beyond 1e6 m and speeds above 1e6 m/s.
    pub fn set_pin_target_at(
        &mut self,
        pin: usize,
        position: Vec2,
        velocity: Vec2,
        since: f64,
    ) -> Result<(), SimError> {
        let n = self.pins.len();
        let Some(p) = self.pins.get_mut(pin) else {
            return Err(SimError::BadInput(format!(
                "pin {pin} does not exist: the scene has {n} pins"
            )));
        };
        if !matches!(p.motion, crate::mpm::PinMotion::Input { .. }) {
            return Err(SimError::BadInput(format!(
                "pin {pin} has motion {:?}, not \"input\": its path is fixed by the scene",
                p.motion
            )));
        }
        Self::check_pin_target(pin, position, velocity)?;
        if !since.is_finite() {
            return Err(SimError::BadInput(format!(
                "pin {pin} target time {since} must be finite"
            )));
        }
        p.motion = crate::mpm::PinMotion::Input {
            position,
            velocity,
            since,
        };
        for &i in &p.vertices {
            self.particles.vert.v[i] = velocity;
            self.particles.vert.c[i] = nalgebra::Matrix2::zeros();
        }
        Ok(())
    }

    /// A driven pin's target limits, the one check every caller (the
    /// setter, the FMU's pin inputs) applies: finite, `|position| <= 1e6` m,
    /// `|velocity| <= 1e6` m/s.
    pub fn check_pin_target(pin: usize, position: Vec2, velocity: Vec2) -> Result<(), SimError> {
        let finite = [position.x, position.y, velocity.x, velocity.y]
            .iter()
            .all(|v| v.is_finite());
        if !finite || position.norm() > 1e6 || velocity.norm() > 1e6 {
            return Err(SimError::BadInput(format!(
                "pin {pin} target position ({}, {}) m or velocity ({}, {}) m/s is absurd: both must be finite, within 1e6 m and 1e6 m/s",
                position.x, position.y, velocity.x, velocity.y
            )));
        }
        Ok(())
    }

    /// Sets an input pin's motion as stored in a state (no checks, no
    /// change of the particles).
    pub(crate) fn restore_pin_target(&mut self, pin: usize, motion: crate::mpm::PinMotion) {
        self.pins[pin].motion = motion;
    }

    /// Sets gravity; rejects non-finite or absurd values (|g| > 1e6 m/s^2).
    pub fn set_gravity(&mut self, g: Vec2) -> Result<(), SimError> {
        Self::check_gravity(g)?;
        self.gravity = g;
        Ok(())
    }

    /// The gravity input's limits, the one check every caller (the
    /// simulation's setter, the FMU, a restored state) applies: finite and
    /// `|g| <= 1e6` m/s^2.
    pub fn check_gravity(g: Vec2) -> Result<(), SimError> {
        if !(g.x.is_finite() && g.y.is_finite()) || g.norm() > 1e6 {
            return Err(SimError::BadInput(format!(
                "gravity ({}, {}) must be finite and at most 1e6 m/s^2",
                g.x, g.y
            )));
        }
        Ok(())
    }

    /// Sets the attractor; refuses one that fails [`Attractor::check`].
    pub fn set_attractor(&mut self, a: Attractor) -> Result<(), SimError> {
        a.check()?;
        self.attractor = a;
        Ok(())
    }

    /// Which optional passes run.
    pub fn passes(&self) -> Passes {
        let s = &self.scene;
        Passes {
            bending: s.material.bending > 0.0,
            plasticity: s.material.plasticity,
            obstacles: !s.obstacles.is_empty(),
            attractor: self.attractor.active && self.attractor.strength != 0.0,
            walls: s.walls.mode != WallMode::None,
        }
    }

    /// Accumulated pass timings.
    pub fn timings(&self) -> PassTimes {
        self.timings
    }
    /// Starts the pass timings afresh.
    pub fn reset_timings(&mut self) {
        self.timings = PassTimes::default();
    }

    /// One substep of the scene's `dt` (under `dt = "auto"`: of
    /// [`YarnSim::auto_dt`]).
    pub fn step(&mut self) -> Result<(), SimError> {
        self.step_dt(self.dt())
    }

    /// `n` substeps (on a rayon worker, see [`crate::pool`]).
    pub fn steps_n(&mut self, n: u64) -> Result<(), SimError> {
        crate::pool::on_pool(|| {
            for _ in 0..n {
                self.step()?;
            }
            Ok(())
        })
    }

    /// Advances by `duration` seconds: in `round(duration / dt)` substeps
    /// with a fixed `dt`, under `dt = "auto"` to the time `now + duration`
    /// exactly ([`YarnSim::advance_to`]).
    pub fn advance(&mut self, duration: f64) -> Result<(), SimError> {
        match self.stepping {
            Stepping::Fixed(_) => {
                let n = (duration / self.dt).round().max(0.0) as u64;
                self.steps_n(n)
            }
            Stepping::Auto { .. } => self.advance_to(self.time + duration),
        }
    }

    /// The next substep toward the time `until` under `dt = "auto"`, or
    /// `None` when the simulation is there: the bound `b`
    /// ([`YarnSim::auto_dt`]) when more than `2 b` remain, half the rest
    /// when between `b` and `2 b` remain (no sliver step before the end),
    /// else the rest. Every substep is at most the bound of the state it
    /// starts from.
    pub fn substep_toward(&self, until: f64) -> Option<f64> {
        let rest = until - self.time;
        if rest <= 0.0 || !rest.is_finite() {
            return None;
        }
        let b = self.auto_dt();
        Some(if rest <= b {
            rest
        } else if rest <= 2.0 * b {
            0.5 * rest
        } else {
            b
        })
    }

    /// Runs adaptive substeps ([`YarnSim::substep_toward`]) until the time
    /// is `until` exactly (the last substep lands on it; its clock is set
    /// to `until`, not to the rounded sum). With a fixed `dt`, runs
    /// `round((until - now) / dt)` substeps of it.
    pub fn advance_to(&mut self, until: f64) -> Result<(), SimError> {
        if let Stepping::Fixed(_) = self.stepping {
            let n = ((until - self.time) / self.dt).round().max(0.0) as u64;
            return self.steps_n(n);
        }
        crate::pool::on_pool(|| {
            while self.step_toward(until)? {}
            Ok(())
        })
    }

    /// One adaptive substep toward `until` ([`YarnSim::substep_toward`]);
    /// `Ok(false)` when already there (no substep run). After the last
    /// substep the clock reads `until` exactly.
    pub fn step_toward(&mut self, until: f64) -> Result<bool, SimError> {
        let Some(dt) = self.substep_toward(until) else {
            return Ok(false);
        };
        let last = dt == until - self.time;
        self.step_dt(dt)?;
        if last {
            self.time = until;
        }
        Ok(true)
    }

    /// Estimated substeps to reach `until` at the current bound (adaptive)
    /// or the fixed `dt`: `ceil(rest / dt)`, at least 1 when any time
    /// remains (the adaptive count can grow when the particles speed up).
    pub fn substeps_to(&self, until: f64) -> u64 {
        let rest = until - self.time;
        if rest <= 0.0 || rest.is_nan() {
            return 0;
        }
        (rest / self.dt()).ceil().clamp(1.0, u64::MAX as f64) as u64
    }

    /// One substep of size `dt` (on a rayon worker, see [`crate::pool`]).
    pub fn step_dt(&mut self, dt: f64) -> Result<(), SimError> {
        crate::pool::on_pool(|| self.substep(dt))
    }
}
