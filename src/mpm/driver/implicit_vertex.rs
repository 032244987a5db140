//! The grid-free implicit substep of a single yarn
//! (`[time] integrator = "implicit-vertices"` or `"midpoint-vertices"`,
//! [`crate::mpm::implicit_vertex`]) as the simulation runs it.
//!
//! `"midpoint-vertices"` is the generalized midpoint rule `x1 = x0 + dt w`,
//! `v1 = (w - (1 - theta) v0) / theta` with `M (w - v0) = theta dt f(x0 +
//! theta dt w)`: a backward Euler step of `theta dt` for the mean velocity
//! `w`, then an extrapolation, so the same minimisation at a shorter step.
//! `theta = 1/2` is the implicit midpoint rule (second order, no damping,
//! but unstable on a stiff string at dt 1e-2: the undamped fibre modes
//! grow, measured); [`THETA`] keeps its period error on the first mode
//! (+0.015 % at `omega dt = 0.042`, against backward Euler's +0.059 %) and
//! damps it 1.3 % per period (backward Euler 12 %) while every mode far
//! above `1 / dt` loses 18 % per step. A vertex in contact keeps the
//! normal part of `w` (the contact is inelastic: extrapolated, a stopped
//! normal velocity would rebound) and, where friction holds it (`|w_t| <=
//! eps_v`), the tangential part too; a sliding contact is extrapolated
//! along the surface like a free vertex.

use std::time::Instant;

use super::substep::active_obstacles;
use super::{SimError, YarnSim};
use crate::math::{Mat2, Vec2};
use crate::mpm::implicit_vertex::{self, Rod, Settings};
use crate::mpm::laws::contact::project_out;
use crate::scene::Integrator;

/// The `theta` of `"midpoint-vertices"`.
pub const THETA: f64 = 0.55;

impl YarnSim {
    /// The yarn's step energy at the current state over `dt`.
    fn rod(&self, dt: f64) -> Rod {
        let p = &self.particles;
        let mut m = Vec::new();
        p.lumped_masses(&mut m);
        let segments = (p.quad.vol.iter().zip(&p.quad.l0))
            .map(|(&vol, &l0)| (vol * self.energy.k, l0))
            .collect();
        let passes = self.passes();
        Rod {
            x: p.vert.x.clone(),
            m,
            vstar: p.vert.v.iter().map(|v| v + self.gravity * dt).collect(),
            dt,
            segments,
            bending: self.active_bending(passes),
            bend: p.vert.bend.clone(),
            attractor: self.active_attractor(passes),
        }
    }

    /// One grid-free substep of `dt`; on a `SimError` the state is
    /// unchanged and the error is recorded in `failed`.
    pub(super) fn substep_gridless(&mut self, dt: f64) -> Result<(), SimError> {
        let t0 = Instant::now();
        let midpoint = self.scene.time.integrator == Integrator::MidpointVertices;
        // the solve's own step: theta dt for the midpoint rule's mean velocity
        let theta = if midpoint { THETA } else { 1.0 };
        let h = theta * dt;
        let rod = self.rod(h);
        let end = self.time + dt;
        let mut fixed: Vec<Option<Vec2>> = vec![None; rod.len()];
        for pin in &self.pins {
            for (k, &i) in pin.vertices.iter().enumerate() {
                let (x, _) = pin.target(k, end);
                fixed[i] = Some((x - rod.x[i]) / dt);
            }
        }
        let obstacles = active_obstacles(&self.obstacles, self.passes());
        let settings = Settings::default();
        let out = match implicit_vertex::step(&rod, &fixed, obstacles, None, dt, &settings) {
            Ok(out) => out,
            Err(what) => {
                let e = SimError::NonFinite {
                    step: self.steps + 1,
                    time: end,
                    what: format!("the vertex solve failed: {what}"),
                };
                self.failed = Some(e.clone());
                return Err(e);
            }
        };
        if out.v.iter().any(|v| !(v.x.is_finite() && v.y.is_finite())) {
            let e = SimError::NonFinite {
                step: self.steps + 1,
                time: end,
                what: "the vertex solve gave a velocity that is not finite".into(),
            };
            self.failed = Some(e.clone());
            return Err(e);
        }
        // pin reactions: the impulse each pin delivered, per dt
        self.pin_reactions.resize(self.pins.len(), Vec2::zeros());
        for (pin, r) in self.pins.iter().zip(self.pin_reactions.iter_mut()) {
            *r = pin
                .vertices
                .iter()
                .fold(Vec2::zeros(), |a, &i| a + out.gradient[i] / h);
        }
        let vert = &mut self.particles.vert;
        for (i, v) in out.v.iter().enumerate() {
            vert.x[i] += v * dt;
            vert.v[i] = if midpoint {
                (v - vert.v[i] * (1.0 - theta)) / theta
            } else {
                *v
            };
            vert.c[i] = Mat2::zeros();
        }
        if midpoint {
            // a contact keeps the mean velocity's normal part (inelastic:
            // extrapolated, a stopped normal velocity would rebound), and
            // its tangential part where friction holds it
            for c in &out.contacts {
                let (n, w) = (c.normal, out.v[c.vertex]);
                let t = Vec2::new(-n.y, n.x);
                let held =
                    obstacles[c.obstacle].friction > 0.0 && t.dot(&w).abs() <= settings.eps_v;
                let v = &mut vert.v[c.vertex];
                *v += n * (n.dot(&w) - n.dot(v));
                if held {
                    *v += t * (t.dot(&w) - t.dot(v));
                }
            }
        }
        for c in &out.contacts {
            let i = c.vertex;
            project_out(&obstacles[c.obstacle], &mut vert.x[i], &mut vert.v[i]);
        }
        // no clamp to the grid's interior: without the grid a vertex may
        // leave the square (walls "none" keeps only the grid's stencils on
        // it); the pins at their targets with their velocities
        crate::mpm::laws::pins::place(&self.pins, vert, end);
        self.follow_vertices();
        self.frames_stale = true;
        let st = &mut self.implicit_stats;
        st.substeps += 1;
        st.newton += out.newton as u64;
        st.max_newton = st.max_newton.max(out.newton as u64);
        self.timings.grid += t0.elapsed().as_secs_f64();
        self.timings.substeps += 1;
        self.dt_stats.record(dt);
        self.steps += 1;
        self.time = end;
        Ok(())
    }

    /// The quadrature particles after their vertices: at the midpoint with
    /// the mean velocity, `d1` the edge, `d2` turned as the edge turned.
    fn follow_vertices(&mut self) {
        let p = &mut self.particles;
        for q in 0..p.quad.m.len() {
            let l = p.quad.left[q] as usize;
            let (a, b) = (p.vert.x[l], p.vert.x[l + 1]);
            p.quad.x[q] = (a + b) * 0.5;
            p.quad.v[q] = (p.vert.v[l] + p.vert.v[l + 1]) * 0.5;
            p.quad.c[q] = Mat2::zeros();
            let d = &mut p.quad.d[q];
            let (old, new) = (Vec2::new(d[(0, 0)], d[(1, 0)]), b - a);
            let (no, nn) = (old.norm(), new.norm());
            let d2 = Vec2::new(d[(0, 1)], d[(1, 1)]);
            let d2 = if no > 0.0 && nn > 0.0 {
                let (c, s) = (
                    old.dot(&new) / (no * nn),
                    crate::math::cross(old, new) / (no * nn),
                );
                Vec2::new(c * d2.x - s * d2.y, s * d2.x + c * d2.y)
            } else {
                d2
            };
            *d = Mat2::new(new.x, d2.x, new.y, d2.y);
        }
    }
}
