//! The frame loop shared by `run` and `record`: steps a simulation frame by
//! frame, shows a progress bar, and stops early on Ctrl-C.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

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
    /// The simulation's clock, s (adaptive schedules; the recordings'
    /// simulated-time timeline).
    fn time(&self) -> f64 {
        0.0
    }
    /// One adaptive substep toward the time `until`, the last landing on
    /// it; `Ok(false)` when already there (adaptive schedules only).
    fn step_toward(&mut self, until: f64) -> Result<bool, CliError> {
        let _ = until;
        Err(CliError::Failed(
            "this simulation has no adaptive substeps".into(),
        ))
    }
    /// Checked after every frame: an error when the state is no longer
    /// finite (for simulations whose `step` does not check it itself).
    fn check_finite(&self) -> Result<(), CliError> {
        Ok(())
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
    /// Whether this is the run's last frame (its end, or the state reached
    /// when it was interrupted): `record --every N` always logs it.
    pub last: bool,
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
    /// Whether Ctrl-C (or SIGTERM, SIGHUP) stopped the run before its end.
    pub interrupted: bool,
}

/// A run of frames: how far it got and, when a substep failed (divergence,
/// solver failure), why it stopped. The frames before the failure were all
/// handed to the frame callback.
#[derive(Debug)]
pub struct FrameRun {
    pub outcome: Outcome,
    pub failure: Option<CliError>,
}

/// The interrupt flag, set by SIGINT (Ctrl-C), SIGTERM and SIGHUP, installed once per process. When the handler cannot be
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

/// A spinner with the elapsed time for work whose length is not known in
/// steps (the evidence studies), drawn on stderr only when it is a terminal.
pub fn spinner(label: &str) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template("{spinner} {prefix} {elapsed_precise}  {msg}")
            .expect("valid spinner template"),
    );
    bar.set_prefix(label.to_string());
    bar.enable_steady_tick(Duration::from_millis(200));
    bar
}

/// [`run_frames`] with a progress bar labelled `label` and the process's
/// interrupt flag ([`interrupt_flag`]): how the commands run a schedule.
pub fn run_frames_shown<S: Stepper + Send>(
    sim: &mut S,
    schedule: &Schedule,
    label: &str,
    on_frame: impl FnMut(&S, FrameInfo) -> Result<(), CliError>,
) -> Result<FrameRun, CliError> {
    let progress = progress_bar(schedule.total_steps, label);
    run_frames(sim, schedule, &interrupt_flag(), &progress, on_frame)
}

/// Runs `schedule` frame by frame: calls `on_frame` with the initial state
/// (frame 0), then after each frame's substeps. Stops after the current
/// substep when `interrupt` is set, and then calls `on_frame` once more for
/// the state reached (a partial frame), so nothing stepped is lost. A failing
/// substep stops the run: the frames before it have been handed over, and
/// the error comes back in [`FrameRun::failure`]. Errors of `on_frame`
/// (output) end the run with `Err`.
pub fn run_frames<S: Stepper + Send>(
    sim: &mut S,
    schedule: &Schedule,
    interrupt: &AtomicBool,
    progress: &ProgressBar,
    mut on_frame: impl FnMut(&S, FrameInfo) -> Result<(), CliError>,
) -> Result<FrameRun, CliError> {
    let start_steps = sim.steps();
    let start_time = sim.time();
    let last_frame = schedule.last_frame();
    on_frame(
        sim,
        FrameInfo {
            frame: 0,
            substeps: 0,
            step_seconds: 0.0,
            last: last_frame == 0,
        },
    )?;
    let mut outcome = Outcome {
        last_frame: 0,
        substeps: 0,
        step_seconds: 0.0,
        interrupted: false,
    };
    let mut failure = None;
    for frame in 1..=last_frame {
        let target = start_steps + schedule.steps_at_frame(frame);
        let before = sim.steps();
        let t0 = Instant::now();
        let until = start_time + schedule.time_at_frame(frame);
        // the frame's substeps in one go on a rayon worker (see
        // yarnsim::pool), not one hand-over to the pool per substep
        let (interrupted, stepped) = yarnsim::pool::on_pool(|| loop {
            let more = match schedule.adaptive {
                Some(_) => sim.time() < until,
                None => sim.steps() < target,
            };
            if !more {
                return (false, Ok(()));
            }
            if interrupt.load(Ordering::Relaxed) {
                return (true, Ok(()));
            }
            let stepped = match schedule.adaptive {
                Some(_) => sim.step_toward(until).map(|_| ()),
                None => sim.step(),
            };
            if stepped.is_err() {
                return (false, stepped);
            }
        });
        outcome.interrupted |= interrupted;
        if let Err(e) = stepped {
            failure = Some(e);
        }
        if failure.is_none() {
            failure = sim.check_finite().err();
        }
        let secs = t0.elapsed().as_secs_f64();
        let substeps = sim.steps() - before;
        outcome.step_seconds += secs;
        outcome.substeps += substeps;
        progress.set_position(sim.steps() - start_steps);
        if failure.is_some() {
            break;
        }
        if substeps > 0 {
            on_frame(
                sim,
                FrameInfo {
                    frame,
                    substeps,
                    step_seconds: secs,
                    last: frame == last_frame || outcome.interrupted,
                },
            )?;
            outcome.last_frame = frame;
        }
        if outcome.interrupted {
            break;
        }
    }
    progress.finish_and_clear();
    Ok(FrameRun { outcome, failure })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Counts its substeps in `.0`; fails at substep `.1 + 1` (when set),
    /// like a diverging simulation.
    struct Counter(u64, Option<u64>);
    impl Stepper for Counter {
        fn step(&mut self) -> Result<(), CliError> {
            if Some(self.0) == self.1 {
                return Err(CliError::Failed("diverged".into()));
            }
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

    /// [`run_frames`] without a progress bar, interrupted from the start
    /// or not.
    fn quiet(
        sim: &mut Counter,
        schedule: &Schedule,
        interrupted: bool,
        on_frame: impl FnMut(&Counter, FrameInfo) -> Result<(), CliError>,
    ) -> Result<FrameRun, CliError> {
        let flag = AtomicBool::new(interrupted);
        run_frames(sim, schedule, &flag, &ProgressBar::hidden(), on_frame)
    }

    #[test]
    fn calls_every_frame_with_its_substeps() {
        let schedule = Schedule::new(0.025, 1e-3, 0.01).unwrap();
        let mut seen = Vec::new();
        let out = quiet(&mut Counter(0, None), &schedule, false, |s, f| {
            seen.push((f.frame, f.substeps, s.0, f.last));
            Ok(())
        })
        .unwrap()
        .outcome;
        assert_eq!(
            seen,
            vec![
                (0, 0, 0, false),
                (1, 10, 10, false),
                (2, 10, 20, false),
                (3, 5, 25, true)
            ]
        );
        assert_eq!(out.substeps, 25);
        assert_eq!(out.last_frame, 3);
        assert!(!out.interrupted);
    }

    #[test]
    fn interrupt_stops_after_the_initial_frame() {
        let schedule = Schedule::new(1.0, 1e-3, 0.01).unwrap();
        let mut frames = 0;
        let out = quiet(&mut Counter(0, None), &schedule, true, |_, _| {
            frames += 1;
            Ok(())
        })
        .unwrap()
        .outcome;
        assert!(out.interrupted);
        assert_eq!((frames, out.substeps, out.last_frame), (1, 0, 0));
    }

    #[test]
    fn a_failing_substep_keeps_the_frames_before_it() {
        let schedule = Schedule::new(0.025, 1e-3, 0.01).unwrap();
        let mut seen = Vec::new();
        let run = quiet(&mut Counter(0, Some(14)), &schedule, false, |s, f| {
            seen.push((f.frame, s.0));
            Ok(())
        })
        .unwrap();
        assert_eq!(seen, vec![(0, 0), (1, 10)]);
        assert_eq!(run.outcome.last_frame, 1);
        assert_eq!(run.outcome.substeps, 14);
        assert!(matches!(run.failure, Some(CliError::Failed(_))));
    }
}
