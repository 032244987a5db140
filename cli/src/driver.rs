//! The frame loop shared by `run` and `record`: steps a simulation frame by
//! frame, shows a progress bar, and stops early on Ctrl-C.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use yarnsim::YarnSim;

use crate::error::CliError;
use crate::schedule::Schedule;

/// What the frame loop needs from a simulation.
pub trait Stepper {
    /// One substep.
    fn step(&mut self) -> Result<(), CliError>;
    /// Substeps done so far.
    fn steps(&self) -> u64;
    /// Number of particles (the unit of the throughput figure).
    fn num_particles(&self) -> usize;
}

impl Stepper for YarnSim {
    fn step(&mut self) -> Result<(), CliError> {
        YarnSim::step(self).map_err(CliError::from)
    }
    fn steps(&self) -> u64 {
        YarnSim::steps(self)
    }
    fn num_particles(&self) -> usize {
        self.particles().len()
    }
}

/// One finished frame.
#[derive(Clone, Copy, Debug)]
pub struct FrameInfo {
    /// Frame index; 0 is the initial state.
    pub frame: u64,
    /// Substeps run to reach this frame from the previous one (0 for frame 0).
    pub substeps: u64,
    /// Wall-clock seconds those substeps took.
    pub step_seconds: f64,
}

/// How a run of frames ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outcome {
    /// Index of the last frame reached.
    pub last_frame: u64,
    /// Substeps run.
    pub substeps: u64,
    /// Wall-clock seconds spent stepping (frame callbacks excluded).
    pub step_seconds: f64,
    /// Whether Ctrl-C stopped the run before its end.
    pub interrupted: bool,
}

/// The Ctrl-C flag, installed once per process. When the handler cannot be
/// installed (e.g. no signal support), the flag simply never gets set.
pub fn interrupt_flag() -> Arc<AtomicBool> {
    static FLAG: OnceLock<Arc<AtomicBool>> = OnceLock::new();
    FLAG.get_or_init(|| {
        let flag = Arc::new(AtomicBool::new(false));
        let f = flag.clone();
        if let Err(e) = ctrlc::set_handler(move || f.store(true, Ordering::SeqCst)) {
            eprintln!("warning: cannot install the Ctrl-C handler: {e}");
        }
        flag
    })
    .clone()
}

/// A progress bar over substeps, with rate and ETA, drawn on stderr only
/// when stderr is a terminal (indicatif hides it otherwise).
pub fn progress_bar(total_steps: u64, label: &str) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(Some(total_steps), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template(
            "{prefix} [{bar:30}] {human_pos}/{human_len} substeps  {per_sec}  ETA {eta}",
        )
        .expect("valid progress template")
        .progress_chars("=> "),
    );
    bar.set_prefix(label.to_string());
    bar.enable_steady_tick(Duration::from_millis(250));
    bar
}

/// Runs `schedule` frame by frame: calls `on_frame` with the initial state
/// (frame 0), then after each frame's substeps. Stops after the current
/// substep when `interrupt` is set, and then calls `on_frame` once more for
/// the state reached (a partial frame), so nothing stepped is lost.
pub fn run_frames<S: Stepper>(
    sim: &mut S,
    schedule: &Schedule,
    interrupt: &AtomicBool,
    progress: &ProgressBar,
    mut on_frame: impl FnMut(&S, FrameInfo) -> Result<(), CliError>,
) -> Result<Outcome, CliError> {
    let start_steps = sim.steps();
    on_frame(
        sim,
        FrameInfo {
            frame: 0,
            substeps: 0,
            step_seconds: 0.0,
        },
    )?;
    let mut outcome = Outcome {
        last_frame: 0,
        substeps: 0,
        step_seconds: 0.0,
        interrupted: false,
    };
    for frame in 1..=schedule.last_frame() {
        let target = start_steps + schedule.steps_at_frame(frame);
        let before = sim.steps();
        let t0 = Instant::now();
        while sim.steps() < target {
            if interrupt.load(Ordering::Relaxed) {
                outcome.interrupted = true;
                break;
            }
            sim.step()?;
        }
        let secs = t0.elapsed().as_secs_f64();
        let substeps = sim.steps() - before;
        outcome.step_seconds += secs;
        outcome.substeps += substeps;
        progress.set_position(sim.steps() - start_steps);
        if substeps > 0 {
            on_frame(
                sim,
                FrameInfo {
                    frame,
                    substeps,
                    step_seconds: secs,
                },
            )?;
            outcome.last_frame = frame;
        }
        if outcome.interrupted {
            break;
        }
    }
    progress.finish_and_clear();
    Ok(outcome)
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Counter(u64);
    impl Stepper for Counter {
        fn step(&mut self) -> Result<(), CliError> {
            self.0 += 1;
            Ok(())
        }
        fn steps(&self) -> u64 {
            self.0
        }
        fn num_particles(&self) -> usize {
            1
        }
    }

    #[test]
    fn calls_every_frame_with_its_substeps() {
        let schedule = Schedule::new(0.025, 1e-3, 0.01).unwrap();
        let mut seen = Vec::new();
        let out = run_frames(
            &mut Counter(0),
            &schedule,
            &AtomicBool::new(false),
            &ProgressBar::hidden(),
            |s, f| {
                seen.push((f.frame, f.substeps, s.0));
                Ok(())
            },
        )
        .unwrap();
        assert_eq!(seen, vec![(0, 0, 0), (1, 10, 10), (2, 10, 20), (3, 5, 25)]);
        assert_eq!(out.substeps, 25);
        assert_eq!(out.last_frame, 3);
        assert!(!out.interrupted);
    }

    #[test]
    fn interrupt_stops_after_the_initial_frame() {
        let schedule = Schedule::new(1.0, 1e-3, 0.01).unwrap();
        let mut frames = 0;
        let out = run_frames(
            &mut Counter(0),
            &schedule,
            &AtomicBool::new(true),
            &ProgressBar::hidden(),
            |_, _| {
                frames += 1;
                Ok(())
            },
        )
        .unwrap();
        assert!(out.interrupted);
        assert_eq!((frames, out.substeps, out.last_frame), (1, 0, 0));
    }
}
