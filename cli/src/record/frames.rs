//! The frame loop of a recording: run the schedule, log the selected
//! frames, close the stream whatever happened.

use std::path::Path;

use rerun::{RecordingStream, SeriesLines};

use super::sink::{Server, Sink};
use super::style::series_color;
use super::{TIMELINE_FRAME, TIMELINE_SIM_TIME};
use crate::driver::{run_frames_shown, FrameInfo, FrameRun, Outcome, Stepper};
use crate::error::CliError;
use crate::schedule::Schedule;

/// What to record: the sink and which frames.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RecordOptions {
    pub sink: Sink,
    /// Log every `every`-th frame (1 = all); frame 0 and the last frame are always logged.
    pub every: u64,
}

impl RecordOptions {
    /// All frames into `path` (checked like `-o`).
    pub fn file(path: &Path) -> Result<Self, CliError> {
        Ok(RecordOptions {
            sink: Sink::output(path)?,
            every: 1,
        })
    }

    fn logs(&self, frame: &FrameInfo) -> bool {
        frame.last || frame.frame.is_multiple_of(self.every.max(1))
    }
}

/// How a `record` command ended.
#[derive(Debug)]
pub struct RecordOutcome {
    pub outcome: Outcome,
    pub particles: usize,
    pub frames_logged: u64,
    /// Adaptive substeps (`dt = "auto"`): their `min / mean / max`.
    pub adaptive_dt: Option<String>,
    /// The simulation error that stopped the run early; the recording holds
    /// the frames before it and is complete.
    pub failure: Option<CliError>,
    /// The `--serve` server, still serving the recording after the run (not
    /// after an interruption: Ctrl-C during the run stops both).
    pub server: Option<Server>,
}

/// Runs `schedule` on `sim`, logging the frames `opts` selects with `log`
/// (at their frame number and simulated time since the start, on the
/// timelines [`TIMELINE_FRAME`] and [`TIMELINE_SIM_TIME`]), then flushes and closes the stream whatever happened (divergence,
/// Ctrl-C, SIGTERM), so a file ends readable.
pub(super) fn record_frames<S: Stepper + Send>(
    rec: RecordingStream,
    sim: &mut S,
    schedule: &Schedule,
    label: &str,
    opts: &RecordOptions,
    mut log: impl FnMut(&RecordingStream, &S, FrameInfo) -> rerun::RecordingStreamResult<()>,
) -> Result<RecordOutcome, CliError> {
    let mut frames_logged = 0;
    let t0 = sim.time();
    let result = run_frames_shown(sim, schedule, label, |sim, frame| {
        if opts.logs(&frame) {
            rec.set_time_sequence(TIMELINE_FRAME, frame.frame as i64);
            rec.set_duration_secs(TIMELINE_SIM_TIME, sim.time() - t0);
            log(&rec, sim, frame).map_err(|e| opts.sink.error(e))?;
            frames_logged += 1;
        }
        Ok(())
    });
    let flushed = rec.flush_blocking();
    let keep_serving = matches!(&result, Ok(run) if !run.outcome.interrupted);
    let server = match &opts.sink {
        Sink::Serve(s) if keep_serving => {
            // Completes the file of `--save` (its footer); the server stays.
            rec.finalize_deferred_sinks();
            Some(Server { rec, url: s.url() })
        }
        _ => {
            drop(rec);
            None
        }
    };
    let FrameRun { outcome, failure } = result?;
    flushed.map_err(|e| opts.sink.error(e))?;
    Ok(RecordOutcome {
        outcome,
        particles: sim.num_particles(),
        frames_logged,
        adaptive_dt: None,
        failure,
        server,
    })
}

/// The scalars that open both kinds of recording, from the diagnostics
/// `$d`: the kinetic, elastic and potential energies (the last at the path
/// `$path`, from the field `$potential`), the momentum's x and y. A macro
/// for the reason of [`crate::table::energy_rows`]: the yarn's and the
/// mass-spring's diagnostics name these fields alike but share no trait.
macro_rules! energy_scalars {
    ($d:expr, $path:expr, $potential:ident) => {{
        let d = $d;
        [
            ($crate::record::paths::KINETIC, d.kinetic_energy),
            ($crate::record::paths::ELASTIC, d.elastic_energy),
            ($path, d.$potential),
            ($crate::record::paths::MOMENTUM_X, d.momentum.x),
            ($crate::record::paths::MOMENTUM_Y, d.momentum.y),
        ]
    }};
}
pub(crate) use energy_scalars;

/// Names and colours the plotted series `series` (entity path, display
/// name), statically: the series tables of [`super::paths`].
pub fn log_series(
    rec: &RecordingStream,
    series: &[(&str, &str)],
) -> rerun::RecordingStreamResult<()> {
    for &(path, name) in series {
        rec.log_static(
            path,
            &SeriesLines::new()
                .with_names([name])
                .with_colors([series_color(series, path)]),
        )?;
    }
    Ok(())
}

/// Logs a frame's plotted scalars (entity path, value) and, when the frame
/// ran substeps, the wall time per substep (`plots/step_time`).
pub fn log_scalars(
    rec: &RecordingStream,
    scalars: &[(&str, f64)],
    frame: &FrameInfo,
) -> rerun::RecordingStreamResult<()> {
    for &(path, value) in scalars {
        rec.log(path, &rerun::Scalars::single(value))?;
    }
    if frame.substeps > 0 {
        rec.log(
            super::paths::STEP_TIME,
            &rerun::Scalars::single(frame.step_seconds / frame.substeps as f64),
        )?;
    }
    Ok(())
}
