//! Work-precision of the reference bundle (`yarn-reference`: 12 yarns
//! falling onto three circles, 256^2): each setting of a ladder (transfer
//! scheme, contact fields, step size, integrator) is recorded with
//! [`crate::trajectory::record`] and compared with a reference trajectory with
//! [`crate::trajectory::compare`] over the common time window: the largest
//! distance over the frames of the centre of mass (the converging
//! observable) and of the 24 yarn ends (measured; they are sensitive to a
//! 1e-9 perturbation, `/docs/performance/bundle-convergence.md`), against
//! the wall time per simulated second. Whole trajectories are compared
//! (Hairer, Norsett, Wanner, "Solving Ordinary Differential Equations I",
//! 2nd ed., Springer 1993, section II.4). A run that the step control
//! refuses part-way (the grid implicit integrator under `time.dt = "auto"`)
//! is compared up to its refusal, and its row says where and why it stopped.

use crate::plot::{LinePlot, Marker, Series};
use crate::trajectory::{compare, record, Stopped, Trajectory};
use crate::{num, Table};

/// The scene every setting runs.
pub const SCENE: &str = "yarn-reference";

/// The measured reference trajectory shipped with the repository
/// (per-yarn fields, FLIP, dt 2.5e-6, 1 s).
pub const SHIPPED_REFERENCE: &str = include_str!("../../docs/performance/bundle_reference.csv");

/// One rung of the ladder.
#[derive(Clone, Debug, PartialEq)]
pub struct Setting {
    /// Short name, e.g. `flip per-yarn 1e-5`.
    pub name: String,
    /// The scene overrides (`KEY=VALUE`, as `--set` takes them).
    pub overrides: Vec<String>,
    /// `time.dt` as written (`auto` or a number).
    pub dt: String,
    /// Simulated time asked for, s (the grid implicit integrator's rungs
    /// may be given less: [`ladder`]'s `implicit_duration`).
    pub duration: f64,
}

fn setting(scheme: &str, fields: &str, dt: &str, integrator: &str, duration: f64) -> Setting {
    let name = if integrator == "explicit" {
        format!("{scheme} {fields} {dt}")
    } else {
        format!("{integrator} {scheme} {fields} {dt}")
    };
    Setting {
        name,
        overrides: vec![
            format!("transfer.scheme={scheme}"),
            format!("contact.fields={fields}"),
            format!("time.dt={dt}"),
            format!("time.integrator={integrator}"),
        ],
        dt: dt.to_string(),
        duration,
    }
}

/// The ladder over `duration` s: explicit FLIP held-free and per-yarn at
/// dt 4e-5, 2e-5, 1e-5 and `auto`, APIC per-yarn at 4e-5 and 1e-5, and the
/// grid implicit integrator (FLIP, held-free) at `auto` and at a fixed
/// 2e-4, both over `implicit_duration` s (at most `duration`; the CLI's
/// `--implicit-duration`, by default the whole `duration`: the implicit
/// rungs are the slow ones, minutes per simulated second on this scene).
/// Under `auto` the step control may refuse a substep it cannot keep within
/// the stretch band of `material.k`; that run then ends there
/// ([`Trajectory::stopped`]) and is compared up to it. `quick`: only the
/// two coarse explicit steps and `auto`, no implicit rung (with a short
/// `duration`, a run of seconds, for tests).
pub fn ladder(duration: f64, implicit_duration: f64, quick: bool) -> Vec<Setting> {
    let dts: &[&str] = if quick {
        &["4e-5", "auto"]
    } else {
        &["4e-5", "2e-5", "1e-5", "auto"]
    };
    let mut v = Vec::new();
    for fields in ["held-free", "per-yarn"] {
        for dt in dts {
            v.push(setting("flip", fields, dt, "explicit", duration));
        }
    }
    if !quick {
        for dt in ["4e-5", "1e-5"] {
            v.push(setting("apic", "per-yarn", dt, "explicit", duration));
        }
        for dt in ["auto", "2e-4"] {
            v.push(setting(
                "flip",
                "held-free",
                dt,
                "implicit",
                implicit_duration.min(duration),
            ));
        }
    }
    v
}

/// One setting's result.
#[derive(Clone, Debug, PartialEq)]
pub struct BundleRun {
    pub setting: Setting,
    pub steps: u64,
    pub wall_per_second: f64,
    /// End of the compared window, s.
    pub window: f64,
    pub com_max: f64,
    pub ends_max: f64,
    /// Kinetic, elastic, potential, dissipated energy at the end, J per m.
    pub energy: [f64; 4],
    /// Where and why the run ended before its duration, if it did.
    pub stopped: Option<Stopped>,
}

/// The whole study.
#[derive(Clone, Debug, PartialEq)]
pub struct BundleReport {
    /// The reference's label (its first `#` line).
    pub reference: String,
    pub runs: Vec<BundleRun>,
    /// The settings that could not be run or compared, with the error:
    /// the others' results are kept (a ladder takes half an hour; one
    /// failing rung must not lose them).
    pub failed: Vec<(String, String)>,
}

/// Compares `run` (of `setting`) with `reference` over their common window
/// (an error does not name the setting: [`run`] files it under its name).
pub fn measure(
    setting: &Setting,
    run: &Trajectory,
    reference: &Trajectory,
) -> Result<BundleRun, String> {
    let c = compare(run, reference)?;
    let last = run.frames.last().ok_or("no frames")?;
    Ok(BundleRun {
        setting: setting.clone(),
        steps: run.steps,
        wall_per_second: run.wall_per_second(),
        window: c.curve.last().map_or(0.0, |p| p.0),
        com_max: c.com_max,
        ends_max: c.ends_max,
        energy: last.energy,
        stopped: run.stopped.clone(),
    })
}

/// Runs every setting (whose name contains one of `only`, if any is given)
/// and compares it with `reference`; a setting whose run or comparison
/// fails goes to [`BundleReport::failed`] and the others go on.
pub fn run(settings: &[Setting], reference: &Trajectory, only: &[String]) -> BundleReport {
    let mut runs = Vec::new();
    let mut failed = Vec::new();
    for s in settings {
        if !only.is_empty() && !only.iter().any(|o| s.name.contains(o.as_str())) {
            continue;
        }
        let measured = record(SCENE, &s.overrides, s.duration, 1.0 / 60.0)
            .map_err(|e| e.to_string())
            .and_then(|t| measure(s, &t, reference));
        match measured {
            Ok(r) => runs.push(r),
            Err(e) => failed.push((s.name.clone(), e)),
        }
    }
    BundleReport {
        reference: reference.label.clone(),
        runs,
        failed,
    }
}

impl BundleReport {
    pub fn table(&self) -> Table {
        let mut t = Table::new(&[
            "setting",
            "dt_s",
            "substeps",
            "window_s",
            "wall_s_per_sim_s",
            "com_max_m",
            "ends_max_m",
            "kinetic_J",
            "elastic_J",
            "potential_J",
            "dissipated_J",
            "stopped_at_s",
        ]);
        for r in &self.runs {
            let mut row = vec![
                r.setting.name.clone(),
                r.setting.dt.clone(),
                r.steps.to_string(),
                num(r.window),
                num(r.wall_per_second),
                num(r.com_max),
                num(r.ends_max),
            ];
            row.extend(r.energy.iter().map(|&e| num(e)));
            row.push(r.stopped.as_ref().map_or(num(f64::NAN), |st| num(st.time)));
            t.push(row);
        }
        t
    }

    /// Centre-of-mass (circles) and yarn-end (squares) error against wall
    /// time per simulated second, log-log, one colour per setting.
    pub fn plot(&self) -> String {
        let mut series = Vec::new();
        for (i, r) in self.runs.iter().enumerate() {
            for (what, err, marker) in [
                ("com", r.com_max, Marker::Circle),
                ("ends", r.ends_max, Marker::Square),
            ] {
                series.push(Series {
                    name: format!("{} {what}", r.setting.name),
                    points: vec![(r.wall_per_second, err)],
                    markers_only: true,
                    color: Some(i),
                    marker,
                    ..Default::default()
                });
            }
        }
        LinePlot {
            title: "yarn-reference: error against cost".into(),
            x_label: "wall s per simulated s".into(),
            y_label: "largest distance from the reference, m".into(),
            log_x: true,
            log_y: true,
            series,
        }
        .to_svg()
    }

    pub fn to_text(&self) -> String {
        let mut s = format!(
            "Reference bundle ({SCENE}) against the reference trajectory \"{}\": \
             largest distance over the frames (1/60 s) of the centre of mass \
             and of the 24 yarn ends, over each run's window.\n",
            self.reference
        );
        for r in self.runs.iter().filter(|r| r.setting.duration < 0.999) {
            s += &format!(
                "{} ran and was compared over {} s only.\n",
                r.setting.name,
                num(r.setting.duration)
            );
        }
        for (name, e) in &self.failed {
            s += &format!("{name} failed, not in the table: {e}\n");
        }
        for r in &self.runs {
            if let Some(st) = &r.stopped {
                s += &format!(
                    "{} stopped at t = {} s: {}\n",
                    r.setting.name,
                    num(st.time),
                    st.reason
                );
            }
        }
        s + &self.table().to_text()
    }

    /// `bundle_precision.csv`, `bundle_precision.svg`, `bundle_precision.txt`.
    pub fn files(&self) -> Vec<(String, String)> {
        vec![
            ("bundle_precision.csv".into(), self.table().to_csv()),
            ("bundle_precision.svg".into(), self.plot()),
            ("bundle_precision.txt".into(), self.to_text()),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shipped reference parses: 61 frames (1 s at 1/60 s), 24 ends,
    /// and its comparison with itself is exactly 0.
    #[test]
    fn shipped_reference_parses_and_matches_itself() {
        let r = Trajectory::from_csv(SHIPPED_REFERENCE).unwrap();
        assert_eq!(r.frames.len(), 61);
        assert_eq!(r.frames[0].ends.len(), 24);
        let s = setting("flip", "per-yarn", "2.5e-6", "explicit", 1.0);
        let m = measure(&s, &r, &r).unwrap();
        assert_eq!((m.com_max, m.ends_max), (0.0, 0.0));
        assert_eq!(m.stopped, None);
    }

    /// The full ladder has the two grid implicit rungs (`auto` and 2e-4)
    /// over `implicit_duration`, at most `duration`; the quick one none.
    #[test]
    fn implicit_rungs_run_over_the_implicit_duration() {
        let implicit = |l: Vec<Setting>| -> Vec<(String, f64)> {
            l.into_iter()
                .filter(|s| s.overrides.contains(&"time.integrator=implicit".into()))
                .map(|s| (s.name, s.duration))
                .collect()
        };
        let names = |d: f64| {
            vec![
                ("implicit flip held-free auto".to_string(), d),
                ("implicit flip held-free 2e-4".to_string(), d),
            ]
        };
        assert_eq!(implicit(ladder(1.0, 1.0, false)), names(1.0));
        assert_eq!(implicit(ladder(1.0, 0.3, false)), names(0.3));
        assert_eq!(implicit(ladder(0.5, 1.0, false)), names(0.5));
        assert!(implicit(ladder(1.0, 1.0, true)).is_empty());
        assert!(ladder(1.0, 1.0, false)
            .iter()
            .all(|s| s.overrides.contains(&format!("time.dt={}", s.dt))));
    }

    /// A run stopped at 0.12 s (the shipped reference cut after its frame
    /// at 7/60 s): compared over its 8 frames (window 7/60 s, distance 0
    /// against the reference itself), and the table's `stopped_at_s` and
    /// the text's line name the stop; a run that was not stopped has `-`.
    #[test]
    fn a_stopped_run_is_compared_up_to_its_stop_and_reported() {
        let r = Trajectory::from_csv(SHIPPED_REFERENCE).unwrap();
        let mut cut = r.clone();
        cut.frames.truncate(8);
        cut.stopped = Some(Stopped {
            time: 0.12,
            reason: "substep refused after step 9 (t = 0.120000 s): why".into(),
        });
        let l = ladder(1.0, 1.0, false);
        // the grid implicit rung at `dt = "auto"`, the one the step
        // control can refuse
        let auto = l
            .iter()
            .find(|s| s.name == "implicit flip held-free auto")
            .unwrap();
        let report = BundleReport {
            reference: r.label.clone(),
            runs: vec![
                measure(&l[0], &r, &r).unwrap(),
                measure(auto, &cut, &r).unwrap(),
            ],
            failed: Vec::new(),
        };
        let stopped = &report.runs[1];
        assert!(
            (stopped.window - 7.0 / 60.0).abs() < 1e-3,
            "{}",
            stopped.window
        );
        assert_eq!((stopped.com_max, stopped.ends_max), (0.0, 0.0));
        let csv = report.table().to_csv();
        let mut lines = csv.lines();
        assert!(lines.next().unwrap().ends_with(",stopped_at_s"));
        assert!(lines.next().unwrap().ends_with(",-"));
        assert!(lines.next().unwrap().ends_with(",1.2000e-1"));
        let text = report.to_text();
        assert!(
            text.contains(&format!(
                "{} stopped at t = 1.2000e-1 s: substep refused after step 9",
                auto.name
            )),
            "{text}"
        );
        assert_eq!(text.matches("stopped at t =").count(), 1, "{text}");
    }

    /// A rung that cannot run (here `time.dt = -1`, refused by the scene)
    /// is reported with its error and the other rungs are kept: the quick
    /// explicit rung at 4e-5 over 0.05 s is measured (release: 1,250
    /// substeps).
    #[test]
    #[cfg_attr(debug_assertions, ignore = "runs the bundle; release only")]
    fn a_failing_rung_is_reported_and_the_others_kept() {
        let r = Trajectory::from_csv(SHIPPED_REFERENCE).unwrap();
        let good = setting("flip", "held-free", "4e-5", "explicit", 0.05);
        let bad = setting("flip", "held-free", "-1", "explicit", 0.05);
        let report = run(&[good.clone(), bad.clone()], &r, &[]);
        assert_eq!(report.runs.len(), 1);
        assert_eq!(report.runs[0].setting, good);
        assert_eq!(report.failed.len(), 1);
        assert_eq!(report.failed[0].0, bad.name);
        assert!(
            report.failed[0].1.contains("time.dt"),
            "{:?}",
            report.failed
        );
        let text = report.to_text();
        assert!(text.contains(&format!("{} failed, not in the table:", bad.name)));
        // named once: the error itself does not repeat the setting
        assert_eq!(text.matches(bad.name.as_str()).count(), 1, "{text}");
    }
}
