//! The summary table printed by `yarnsim run`.

use std::fmt::Write as _;

use yarnsim::mpm::Diagnostics;

/// One diagnostic row of the summary: name, value at the start, value at the end.
pub type DiagRow = (&'static str, f64, f64);

/// Everything the summary table shows.
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    pub scene: String,
    /// The model and its solver, e.g. `yarn (MPM)` or `mass-spring, backward-euler`.
    pub model: String,
    /// Particles (the unit of the throughput figure).
    pub particles: usize,
    /// What the particles are, e.g. `120 vertices + 108 quadrature, 12 yarns`.
    pub particles_detail: String,
    pub dt: f64,
    pub substeps: u64,
    pub frames: u64,
    pub sim_time: f64,
    /// Wall-clock seconds spent stepping.
    pub wall_seconds: f64,
    pub interrupted: bool,
    /// Diagnostics at the start and at the end of the run.
    pub diagnostics: Vec<DiagRow>,
}

impl Summary {
    /// Particle-substeps per wall-clock second; 0 when nothing was timed.
    pub fn throughput(&self) -> f64 {
        if self.wall_seconds > 0.0 {
            self.particles as f64 * self.substeps as f64 / self.wall_seconds
        } else {
            0.0
        }
    }
}

/// The summary rows of a yarn run.
pub fn yarn_rows(a: &Diagnostics, b: &Diagnostics) -> Vec<DiagRow> {
    let total = |d: &Diagnostics| d.kinetic_energy + d.elastic_energy + d.potential_energy;
    vec![
        ("time [s]", a.time, b.time),
        ("kinetic energy", a.kinetic_energy, b.kinetic_energy),
        ("elastic energy", a.elastic_energy, b.elastic_energy),
        ("potential energy", a.potential_energy, b.potential_energy),
        ("total energy", total(a), total(b)),
        ("momentum x", a.momentum.x, b.momentum.x),
        ("momentum y", a.momentum.y, b.momentum.y),
        ("angular momentum", a.angular_momentum, b.angular_momentum),
        ("min stretch", a.min_stretch, b.min_stretch),
        ("max stretch", a.max_stretch, b.max_stretch),
    ]
}

/// Whether the wall-clock figures (wall time, throughput) are printed or
/// replaced by `[timing]`: redaction gives output that depends only on the
/// scene and the physics, for snapshot tests.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Timing {
    Show,
    Redact,
}

/// A number in engineering-friendly form: fixed point for moderate
/// magnitudes, scientific otherwise.
pub fn num(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else if !x.is_finite() {
        format!("{x}")
    } else if (1e-3..1e6).contains(&x.abs()) {
        format!("{x:.6}")
    } else {
        format!("{x:.6e}")
    }
}

/// The summary table as text, one row per quantity, the diagnostics in two
/// columns (initial state, final state).
pub fn format_summary(s: &Summary, timing: Timing) -> String {
    let mut out = String::new();
    let (wall, rate) = match timing {
        Timing::Show => (
            format!("{:.3} s", s.wall_seconds),
            format!("{:.4e} particle-substeps/s", s.throughput()),
        ),
        Timing::Redact => ("[timing]".into(), "[timing]".into()),
    };
    let status = if s.interrupted {
        " (interrupted by Ctrl-C)"
    } else {
        ""
    };
    let rows: [(&str, String); 8] = [
        ("scene", s.scene.clone()),
        ("model", s.model.clone()),
        (
            "particles",
            format!("{} ({})", s.particles, s.particles_detail),
        ),
        ("substeps", format!("{} of dt = {} s", s.substeps, s.dt)),
        ("frames", format!("{}{status}", s.frames)),
        ("simulated time", format!("{:.6} s", s.sim_time)),
        ("wall time", wall),
        ("throughput", rate),
    ];
    for (k, v) in rows {
        let _ = writeln!(out, "{k:<18} {v}");
    }
    let _ = writeln!(out);
    let _ = writeln!(out, "{:<18} {:>16} {:>16}", "", "initial", "final");
    for (k, x, y) in &s.diagnostics {
        let _ = writeln!(out, "{k:<18} {:>16} {:>16}", num(*x), num(*y));
    }
    out
}
