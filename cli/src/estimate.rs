//! Memory and recording-size estimates, printed before a large scene starts
//! so that nobody waits for a run the machine cannot hold.
//!
//! The figures come from the scene description alone (nothing is built) and
//! from per-particle costs measured with this build on 2 cores (peak RSS of
//! `run`/`record` of a 2.4e6-particle bundle and a 500x500 cloth, file sizes
//! of their recordings); they are meant to be right within a factor of 2.

use yarnsim::scene::Scene;

/// Bytes of memory per MPM particle (vertex or quadrature particle: state,
/// APIC matrices, stencils, frames): 272 measured (`run`, 2.4e6 particles).
pub const YARN_BYTES_PER_PARTICLE: f64 = 280.0;
/// Bytes of memory per node of the grid's window (the grid node, 32, and
/// four scatter nodes of 64; the window is the yarns' bounding box with a
/// margin of two 8-node blocks, not the domain): 288.
pub const YARN_BYTES_PER_NODE: f64 = 288.0;
/// Extra memory of `record` per yarn vertex (Rerun's buffers of a frame): 237 measured.
pub const YARN_RECORDING_MEMORY_PER_VERTEX: f64 = 240.0;
/// Bytes of a recording per yarn vertex and frame (a vertex and a quadrature
/// particle: positions, colours, velocities, stretch and yield values, the
/// line-strip point), after Rerun's compression: 15 measured on a bundle in
/// free fall, 29 on a scene of 1e7 vertices.
pub const YARN_RECORDING_BYTES_PER_VERTEX: f64 = 25.0;
/// Bytes of memory per mass-spring particle with its springs (state, solver
/// vectors, sparse matrix; backward Euler): 2230 measured (500x500 cloth).
pub const MS_BYTES_PER_PARTICLE: f64 = 2200.0;
/// Extra memory of `record` per mass-spring particle: 250 measured.
pub const MS_RECORDING_MEMORY_PER_PARTICLE: f64 = 250.0;
/// Bytes of a recording per mass-spring particle and frame (the point and
/// about three spring strips): 38 measured (500x500 cloth).
pub const MS_RECORDING_BYTES_PER_PARTICLE: f64 = 40.0;

/// Estimates above these are printed before the run starts.
pub const MEMORY_THRESHOLD: f64 = 1e9;
pub const RECORDING_THRESHOLD: f64 = 1e9;

/// What a run of a scene will need.
#[derive(Clone, Debug, PartialEq)]
pub struct Estimate {
    pub scene: String,
    /// Particles (MPM: vertices + quadrature particles).
    pub particles: f64,
    /// Peak memory in bytes.
    pub memory: f64,
    /// Recording bytes per logged frame.
    pub recording_per_frame: f64,
    /// Frames a recording would hold; `None` when nothing is recorded.
    pub frames: Option<f64>,
}

impl Estimate {
    /// The estimate for `duration` seconds of `scene`; `every` is `Some(N)`
    /// for a recording of every Nth frame, `None` when nothing is recorded.
    pub fn of(scene: &Scene, duration: f64, every: Option<u64>) -> Estimate {
        let recording = every.is_some();
        let (particles, mut memory, per_frame, frame_dt) = match scene {
            Scene::Yarn(y) => {
                let vertices: f64 = y
                    .yarns
                    .iter()
                    .map(|s| s.vertices as f64 * s.count as f64)
                    .sum();
                let quads: f64 = y
                    .yarns
                    .iter()
                    .map(|s| (s.vertices.saturating_sub(1)) as f64 * s.count as f64)
                    .sum();
                let nodes = window_nodes(y);
                let mut memory =
                    YARN_BYTES_PER_PARTICLE * (vertices + quads) + YARN_BYTES_PER_NODE * nodes;
                if recording {
                    memory += YARN_RECORDING_MEMORY_PER_VERTEX * vertices;
                }
                (
                    vertices + quads,
                    memory,
                    YARN_RECORDING_BYTES_PER_VERTEX * vertices,
                    y.time.frame_dt,
                )
            }
            Scene::MassSpring(l) => {
                let n = l.particle_count() as f64;
                (
                    n,
                    MS_BYTES_PER_PARTICLE * n,
                    MS_RECORDING_BYTES_PER_PARTICLE * n,
                    l.time.frame_time,
                )
            }
        };
        if recording {
            if let Scene::MassSpring(_) = scene {
                memory += MS_RECORDING_MEMORY_PER_PARTICLE * particles;
            }
        }
        let frames = every.map(|k| ((duration / frame_dt).ceil() / k.max(1) as f64).ceil() + 1.0);
        Estimate {
            scene: scene.name().to_string(),
            particles,
            memory,
            recording_per_frame: per_frame,
            frames,
        }
    }

    /// Estimated size of the whole recording, if one is made.
    pub fn recording(&self) -> Option<f64> {
        self.frames.map(|f| f * self.recording_per_frame)
    }

    /// The note printed before a large run, `None` below the thresholds.
    pub fn note(&self) -> Option<String> {
        let recording = self.recording().unwrap_or(0.0);
        if self.memory <= MEMORY_THRESHOLD && recording <= RECORDING_THRESHOLD {
            return None;
        }
        let mut text = format!(
            "note: scene `{}` has {:.3e} particles and needs about {} of memory",
            self.scene,
            self.particles,
            bytes(self.memory)
        );
        if let Some(frames) = self.frames {
            text += &format!(
                "; the recording will be about {} ({frames:.0} frames of about {}; \
                 --every N logs every Nth frame)",
                bytes(recording),
                bytes(self.recording_per_frame)
            );
        }
        Some(text)
    }
}

/// Nodes of the grid window at the start: the yarns' bounding box in
/// cells, plus the stencil and a margin of two blocks per side, at most
/// the whole grid. (The window follows the yarns; if they spread, it grows.)
fn window_nodes(y: &yarnsim::scene::YarnScene) -> f64 {
    let n = y.grid.resolution as f64;
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in y.curves().iter().flatten() {
        for a in 0..2 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    if lo[0] > hi[0] {
        return 0.0;
    }
    let side = |a: usize| ((hi[a] - lo[a]) / y.dx() + 3.0 + 2.0 * 2.0 * 8.0 + 8.0).min(n + 8.0);
    side(0) * side(1)
}

/// Prints the note of a large run on stderr.
pub fn announce(e: &Estimate) {
    if let Some(text) = e.note() {
        eprintln!("{text}");
    }
}

/// A byte count for people: `540 MB`, `5.4 GB`.
pub fn bytes(b: f64) -> String {
    let (v, unit) = if b >= 1e9 {
        (b / 1e9, "GB")
    } else if b >= 1e6 {
        (b / 1e6, "MB")
    } else if b >= 1e3 {
        (b / 1e3, "kB")
    } else {
        (b, "B")
    };
    if v >= 100.0 || unit == "B" {
        format!("{v:.0} {unit}")
    } else {
        format!("{v:.1} {unit}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_scenes_print_nothing_large_ones_their_figures() {
        let small = Scene::resolve("yarn-reference").unwrap();
        assert_eq!(Estimate::of(&small, 1.0, Some(1)).note(), None);
        let Scene::Yarn(mut y) = small else {
            unreachable!()
        };
        y.yarns[0].vertices = 1_000_000;
        y.yarns[0].count = 10;
        let e = Estimate::of(&Scene::Yarn(y), 1.0 / 60.0, Some(1));
        assert_eq!(e.frames, Some(2.0));
        let note = e.note().unwrap();
        assert!(note.contains("2.000e7 particles"), "{note}");
        assert!(note.contains("GB of memory"), "{note}");
        assert!(note.contains("2 frames"), "{note}");
        assert_eq!(bytes(5.4e9), "5.4 GB");
        assert_eq!(bytes(577e6), "577 MB");
    }
}
