//! Which substep each output frame falls on.

use crate::error::CliError;

/// Frames of a run: frame `k` is the state after `round(k * frame_dt / dt)`
/// substeps (frame 0 is the initial state), clamped to the run's total of
/// `round(duration / dt)` substeps; the last frame is the end of the run.
///
/// An adaptive schedule ([`Schedule::adaptive`], the yarn's `dt = "auto"`)
/// puts frame `k` at the time `k * frame_dt` exactly (the last at the end of
/// the run); `dt` and `total_steps` are then the estimate at the start.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Schedule {
    pub dt: f64,
    pub frame_dt: f64,
    pub total_steps: u64,
    /// Adaptive substeps: the run's duration in s.
    pub adaptive: Option<f64>,
}

/// The most substeps one command will run (about 30 years of wall time at 1e3/s).
pub const MAX_STEPS: u64 = 1_000_000_000_000;

impl Schedule {
    /// The schedule of a run of `duration` seconds with substep `dt` and frame interval `frame_dt`.
    pub fn new(duration: f64, dt: f64, frame_dt: f64) -> Result<Self, CliError> {
        let steps = (duration / dt).round();
        if steps < 1.0 {
            return Err(CliError::Usage(format!(
                "duration {duration} s is shorter than one substep (dt = {dt} s)"
            )));
        }
        if steps > MAX_STEPS as f64 {
            return Err(CliError::Usage(format!(
                "duration {duration} s needs {steps:.3e} substeps of {dt} s; at most {MAX_STEPS:.0e} are supported"
            )));
        }
        Ok(Schedule {
            dt,
            frame_dt,
            total_steps: steps as u64,
            adaptive: None,
        })
    }

    /// The schedule of a run of `duration` seconds with adaptive substeps,
    /// `dt_estimate` the first one (for the progress bar).
    pub fn adaptive(duration: f64, dt_estimate: f64, frame_dt: f64) -> Result<Self, CliError> {
        if !(duration > 0.0 && duration.is_finite()) {
            return Err(CliError::Usage(format!(
                "duration {duration} s must be finite and > 0"
            )));
        }
        let steps = (duration / dt_estimate).ceil();
        Ok(Schedule {
            dt: dt_estimate,
            frame_dt,
            total_steps: if steps.is_finite() {
                steps.clamp(1.0, MAX_STEPS as f64) as u64
            } else {
                MAX_STEPS
            },
            adaptive: Some(duration),
        })
    }

    /// Adaptive schedules: the time of frame `frame` after the start,
    /// `min(frame * frame_dt, duration)`.
    pub fn time_at_frame(&self, frame: u64) -> f64 {
        let t = frame as f64 * self.frame_dt;
        self.adaptive.map_or(t, |d| t.min(d))
    }

    fn unclamped(&self, frame: u64) -> u64 {
        (frame as f64 * self.frame_dt / self.dt).round() as u64
    }

    /// Substeps done at frame `frame`.
    pub fn steps_at_frame(&self, frame: u64) -> u64 {
        self.unclamped(frame).min(self.total_steps)
    }

    /// Index of the last frame (the number of frames after the initial one).
    pub fn last_frame(&self) -> u64 {
        if let Some(d) = self.adaptive {
            // The frames strictly before the end, then the end (a frame
            // within 1e-9 of a frame time is that frame).
            let k = (d / self.frame_dt * (1.0 - 1e-9)).ceil().max(1.0);
            return k as u64;
        }
        let mut k = (self.total_steps as f64 * self.dt / self.frame_dt).floor() as u64;
        while self.unclamped(k) < self.total_steps {
            k += 1;
        }
        while k > 0 && self.unclamped(k - 1) >= self.total_steps {
            k -= 1;
        }
        k
    }

    /// Simulated duration of the whole run.
    pub fn duration(&self) -> f64 {
        self.adaptive.unwrap_or(self.total_steps as f64 * self.dt)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_cover_the_run() {
        let s = Schedule::new(1.0, 4e-5, 1.0 / 60.0).unwrap();
        assert_eq!(s.total_steps, 25_000);
        assert_eq!(s.last_frame(), 60);
        assert_eq!(s.steps_at_frame(0), 0);
        assert_eq!(s.steps_at_frame(1), 417);
        assert_eq!(s.steps_at_frame(60), 25_000);
        // A run that ends between two frames gets a last, shorter frame.
        let s = Schedule::new(0.025, 1e-3, 0.01).unwrap();
        assert_eq!(s.last_frame(), 3);
        assert_eq!(s.steps_at_frame(2), 20);
        assert_eq!(s.steps_at_frame(3), 25);
        for k in 1..=s.last_frame() {
            assert!(s.steps_at_frame(k) > s.steps_at_frame(k - 1));
        }
    }

    #[test]
    fn adaptive_frames_fall_on_frame_times() {
        let s = Schedule::adaptive(0.025, 1e-4, 0.01).unwrap();
        assert_eq!(s.last_frame(), 3);
        assert_eq!(s.time_at_frame(2), 0.02);
        assert_eq!(s.time_at_frame(3), 0.025);
        let s = Schedule::adaptive(1.0, 1e-4, 1.0 / 60.0).unwrap();
        assert_eq!(s.last_frame(), 60);
        assert_eq!(s.time_at_frame(60), 1.0);
        assert_eq!(s.duration(), 1.0);
        assert!(Schedule::adaptive(0.0, 1e-4, 0.01).is_err());
    }

    #[test]
    fn rejects_durations_below_one_substep() {
        assert!(Schedule::new(1e-6, 4e-5, 0.01).is_err());
    }
}
