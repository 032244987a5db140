//! Run time against error (work-precision), after SciMLBenchmarks.
//!
//! For each scene and integrator the scene runs to a fixed end time at a
//! ladder of step sizes; every run's wall time (the stepping only, not the
//! set-up) and its error against a reference solution are recorded.
//!
//! * Error: the largest particle position difference from the reference at
//!   the end time, divided by the scene's extent (wire 1 m, cloth 10 m, yarn
//!   domain 1 m), so the levels 1e-2, 1e-4, 1e-6 mean the same for every scene.
//! * Mass-spring reference: the trapezoidal rule iterated to convergence
//!   (8 chord-Newton iterations, CG tolerance 1e-14) at a step 2^-4 of the
//!   finest ladder step; its own error is estimated by Richardson from the
//!   same run at twice the step (`|x_h - x_2h| / 3`, order 2) and printed.
//! * Yarn: against a physical oracle, the hanging chain's first-mode
//!   frequency ([`crate::chain`]), over a dt ladder and a grid ladder per
//!   transfer scheme, with the cheapest setting per error level. The
//!   optional `yarn_reference` scene is still measured against a finer run
//!   of itself (MPM at a step 2^-3 of the finest ladder step, error estimate
//!   `|x_h - x_2h|`): self-convergence, not accuracy.
//! * Observed order: least-squares slope of log error against log step over
//!   the runs whose error is at least 10x the reference's error estimate.
//!
//! The wire and cloth integrators all solve the same ODE (the cloth without
//! its sphere here, whose collision projection is not smooth in time); the
//! Chebyshev-Jacobi scheme is backward Euler solved by a fixed number of
//! Jacobi iterations, so it has an error floor set by its iteration count.

use std::time::Instant;

use crate::chain::{self, ChainReport};
use crate::plot::{LinePlot, Series};
use crate::{extent, num, Table};
use yarnsim::massspring::{scenes, Integrator, IntegratorOptions, Simulation, System, V3};
use yarnsim::mpm::YarnSim;
use yarnsim::scene::{builtin::yarn_reference, YarnScene};

/// What to run.
#[derive(Clone, Debug, Default)]
pub struct PrecisionOptions {
    /// Fewer step sizes and shorter runs (for tests and a first look).
    pub quick: bool,
    /// Also run the yarn reference scene (slow: about a minute;
    /// self-convergence, not accuracy).
    pub yarn_reference: bool,
    /// Leave out the yarn hanging-chain study ([`crate::chain`]).
    pub no_chain: bool,
}

/// One run.
#[derive(Clone, Debug, PartialEq)]
pub struct Run {
    pub scene: String,
    /// Integrator name, with the iteration count for Chebyshev (`chebyshev-jacobi/32`).
    pub method: String,
    pub dt: f64,
    pub steps: u64,
    /// Wall time of the stepping, in s.
    pub wall: f64,
    /// Relative end-time position error (NaN when the run failed).
    pub error: f64,
    /// `ok`, or why the run failed (e.g. `diverged at step 12`).
    pub status: String,
}

impl Run {
    /// A run of `method` on `scene` at step `dt`, from its
    /// `(error, wall, steps, status)`.
    fn new(scene: &str, method: &str, dt: f64, outcome: (f64, f64, u64, String)) -> Run {
        let (error, wall, steps, status) = outcome;
        Run {
            scene: scene.into(),
            method: method.into(),
            dt,
            steps,
            wall,
            error,
            status,
        }
    }
}

/// One scene's results.
#[derive(Clone, Debug)]
pub struct SceneResult {
    pub scene: String,
    pub end_time: f64,
    /// How the reference was computed.
    pub reference: String,
    /// Estimated relative error of the reference itself.
    pub reference_error: f64,
    pub runs: Vec<Run>,
}

/// The whole report.
#[derive(Clone, Debug)]
pub struct PrecisionReport {
    /// Mass-spring scenes (and the optional yarn reference scene).
    pub scenes: Vec<SceneResult>,
    /// The yarn against the hanging-chain oracle.
    pub chain: Option<ChainReport>,
    /// Rayon worker threads during the yarn runs.
    pub threads: usize,
}

/// Error levels of the summary.
pub const LEVELS: [f64; 3] = [1e-2, 1e-4, 1e-6];

fn max_diff(a: &[V3], b: &[V3]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| (p - q).norm())
        .fold(0.0, f64::max)
}

/// Runs a mass-spring system to `t_end` at step `dt`; returns the positions,
/// the wall time of the stepping and the step count.
pub fn run_massspring(
    sys: &System,
    integrator: Integrator,
    mut options: IntegratorOptions,
    dt: f64,
    t_end: f64,
) -> Result<(Vec<V3>, f64, u64), String> {
    options.dt = Some(dt);
    let mut sim =
        Simulation::from_system(sys.clone(), integrator, options).map_err(|e| e.to_string())?;
    let t0 = Instant::now();
    let n = sim.run_to(t_end).map_err(|e| e.to_string())?;
    let wall = t0.elapsed().as_secs_f64();
    Ok((sim.positions().to_vec(), wall, n as u64))
}

/// Runs a yarn scene to `t_end` at substep `dt` (rounded so the steps land on `t_end`).
pub fn run_yarn(scene: &YarnScene, dt: f64, t_end: f64) -> Result<(Vec<V3>, f64, u64), String> {
    let n = (t_end / dt).round().max(1.0) as u64;
    let mut s = scene.clone();
    s.time.dt = (t_end / n as f64).into();
    let mut sim = YarnSim::new(&s).map_err(|e| e.to_string())?;
    let t0 = Instant::now();
    sim.steps_n(n).map_err(|e| e.to_string())?;
    let wall = t0.elapsed().as_secs_f64();
    let x = sim
        .particles()
        .vert
        .x
        .iter()
        .map(|p| V3::new(p.x, p.y, 0.0))
        .collect();
    Ok((x, wall, n))
}

fn ladder(h0: f64, n: usize) -> Vec<f64> {
    (0..n).map(|k| h0 / (1u64 << k) as f64).collect()
}

fn reference_options() -> IntegratorOptions {
    IntegratorOptions {
        newton_iterations: 8,
        newton_tolerance: 1e-14,
        cg_tolerance: 1e-14,
        cg_max_iterations: 5000,
        ..Default::default()
    }
}

/// Work-precision of a mass-spring system.
fn massspring_scene(
    name: &str,
    sys: &System,
    t_end: f64,
    h0: f64,
    levels: usize,
    cheb_iters: &[usize],
) -> Result<SceneResult, String> {
    let hs = ladder(h0, levels);
    let h_ref = hs[levels - 1] / 16.0;
    let (x_ref, _, _) = run_massspring(
        sys,
        Integrator::Trapezoidal,
        reference_options(),
        h_ref,
        t_end,
    )?;
    let (x_ref2, _, _) = run_massspring(
        sys,
        Integrator::Trapezoidal,
        reference_options(),
        2.0 * h_ref,
        t_end,
    )?;
    let scale = extent(&sys.positions);
    let ref_err = max_diff(&x_ref, &x_ref2) / 3.0 / scale;
    let mut methods: Vec<(String, Integrator, IntegratorOptions)> = vec![
        (
            "forward-euler".into(),
            Integrator::ForwardEuler,
            IntegratorOptions::default(),
        ),
        (
            "symplectic-euler".into(),
            Integrator::SymplecticEuler,
            IntegratorOptions::default(),
        ),
        (
            "trapezoidal".into(),
            Integrator::Trapezoidal,
            IntegratorOptions::default(),
        ),
        (
            "backward-euler".into(),
            Integrator::BackwardEuler,
            IntegratorOptions::default(),
        ),
    ];
    for &it in cheb_iters {
        methods.push((
            format!("chebyshev-jacobi/{it}"),
            Integrator::ChebyshevJacobi,
            IntegratorOptions {
                iterations: it,
                ..Default::default()
            },
        ));
    }
    let mut runs = Vec::new();
    for (mname, integ, opt) in methods {
        for &h in &hs {
            let outcome = match run_massspring(sys, integ, opt.clone(), h, t_end) {
                Ok((x, wall, n)) => {
                    let e = max_diff(&x, &x_ref) / scale;
                    if e.is_finite() && e < 10.0 {
                        (e, wall, n, "ok".to_string())
                    } else {
                        (f64::NAN, wall, n, "unbounded (error > 10x extent)".into())
                    }
                }
                Err(e) => (f64::NAN, f64::NAN, 0, e),
            };
            runs.push(Run::new(name, &mname, h, outcome));
        }
    }
    Ok(SceneResult {
        scene: name.into(),
        end_time: t_end,
        reference: format!(
            "trapezoidal, 8 chord-Newton iterations, dt = {h_ref:.4e} s; Richardson estimate of its error from dt = {:.4e} s",
            2.0 * h_ref
        ),
        reference_error: ref_err,
        runs,
    })
}

/// Work-precision of a yarn scene (MPM, symplectic Euler on the grid).
fn yarn_scene(
    name: &str,
    scene: &YarnScene,
    t_end: f64,
    h0: f64,
    levels: usize,
) -> Result<SceneResult, String> {
    let hs = ladder(h0, levels);
    let h_ref = hs[levels - 1] / 8.0;
    let (x_ref, _, _) = run_yarn(scene, h_ref, t_end)?;
    let (x_ref2, _, _) = run_yarn(scene, 2.0 * h_ref, t_end)?;
    let scale = scene.grid.size;
    let ref_err = max_diff(&x_ref, &x_ref2) / scale;
    let mut runs = Vec::new();
    for &h in &hs {
        let outcome = match run_yarn(scene, h, t_end) {
            Ok((x, wall, n)) => (max_diff(&x, &x_ref) / scale, wall, n, "ok".to_string()),
            Err(e) => (f64::NAN, f64::NAN, 0, e),
        };
        runs.push(Run::new(name, "mpm", h, outcome));
    }
    Ok(SceneResult {
        scene: name.into(),
        end_time: t_end,
        reference: format!("MPM at dt = {h_ref:.4e} s; error estimate |x_h - x_2h| (first order)"),
        reference_error: ref_err,
        runs,
    })
}

/// The course lecture notes' wire as a system.
pub fn wire_system() -> System {
    scenes::wire().build().expect("built-in wire builds")
}

/// The cloth (Wang 2015; Provot 1995) without its sphere (see the module documentation).
pub fn cloth_system() -> System {
    let mut l = scenes::cloth();
    l.spheres.clear();
    l.build().expect("built-in cloth builds")
}

/// Runs the work-precision study.
pub fn run(opts: &PrecisionOptions) -> Result<PrecisionReport, String> {
    let q = opts.quick;
    let mut scenes = Vec::new();
    scenes.push(massspring_scene(
        "wire",
        &wire_system(),
        if q { 0.25 } else { 0.5 },
        0.025,
        if q { 8 } else { 11 },
        &[8, 32, 128],
    )?);
    scenes.push(massspring_scene(
        "cloth",
        &cloth_system(),
        if q { 0.2 } else { 0.5 },
        1.0 / 30.0,
        if q { 4 } else { 6 },
        &[8, 32, 128],
    )?);
    if opts.yarn_reference {
        scenes.push(yarn_scene(
            "yarn-reference",
            &yarn_reference(),
            0.02,
            4e-5,
            3,
        )?);
    }
    let chain = (!opts.no_chain).then(|| chain::run(q));
    Ok(PrecisionReport {
        scenes,
        chain,
        threads: rayon::current_num_threads(),
    })
}

/// Least-squares slope of `log e` against `log h` over `(h, e)`.
pub fn fit_order(points: &[(f64, f64)]) -> Option<f64> {
    let p: Vec<(f64, f64)> = points
        .iter()
        .filter(|(h, e)| h.is_finite() && e.is_finite() && *h > 0.0 && *e > 0.0)
        .map(|(h, e)| (h.ln(), e.ln()))
        .collect();
    if p.len() < 2 {
        return None;
    }
    let n = p.len() as f64;
    let mx = p.iter().map(|a| a.0).sum::<f64>() / n;
    let my = p.iter().map(|a| a.1).sum::<f64>() / n;
    let sxx: f64 = p.iter().map(|a| (a.0 - mx).powi(2)).sum();
    let sxy: f64 = p.iter().map(|a| (a.0 - mx) * (a.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

impl SceneResult {
    /// Method names in first-seen order.
    pub fn methods(&self) -> Vec<String> {
        let mut m: Vec<String> = Vec::new();
        for r in &self.runs {
            if !m.contains(&r.method) {
                m.push(r.method.clone());
            }
        }
        m
    }

    /// Observed order of `method`: the least-squares slope over its three
    /// finest successful runs (none with fewer) whose error is at least 10x the reference's
    /// (the asymptotic range; coarse steps of stiff scenes are not in it).
    pub fn order(&self, method: &str) -> Option<f64> {
        let floor = 10.0 * self.reference_error;
        let mut pts: Vec<(f64, f64)> = self
            .runs
            .iter()
            .filter(|r| r.method == method && r.status == "ok" && r.error >= floor)
            .map(|r| (r.dt, r.error))
            .collect();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        pts.truncate(3);
        if pts.len() < 3 {
            return None;
        }
        fit_order(&pts)
    }

    /// The fastest successful run with error <= `level`, if any.
    pub fn fastest(&self, level: f64) -> Option<&Run> {
        self.runs
            .iter()
            .filter(|r| r.status == "ok" && r.error <= level && r.wall.is_finite())
            .min_by(|a, b| a.wall.total_cmp(&b.wall))
    }

    /// The work-precision diagram.
    pub fn plot(&self) -> LinePlot {
        LinePlot {
            title: format!(
                "work-precision: {} (t = {} s, reference error {:.1e})",
                self.scene, self.end_time, self.reference_error
            ),
            x_label: "wall time (s)".into(),
            y_label: "relative position error at end time".into(),
            log_x: true,
            log_y: true,
            series: self
                .methods()
                .into_iter()
                .map(|m| Series {
                    points: self
                        .runs
                        .iter()
                        .filter(|r| r.method == m && r.status == "ok")
                        .map(|r| (r.wall, r.error))
                        .collect(),
                    name: match self.order(&m) {
                        Some(p) => format!("{m} (p={p:.2})"),
                        None => m,
                    },
                    ..Series::default()
                })
                .collect(),
        }
    }
}

impl PrecisionReport {
    /// Every run (CSV columns: scene, method, dt_s, steps, wall_s, error, status).
    pub fn runs_table(&self) -> Table {
        let mut t = Table::new(&[
            "scene", "method", "dt_s", "steps", "wall_s", "error", "status",
        ]);
        for s in &self.scenes {
            for r in &s.runs {
                t.push(vec![
                    r.scene.clone(),
                    r.method.clone(),
                    num(r.dt),
                    r.steps.to_string(),
                    num(r.wall),
                    num(r.error),
                    r.status.clone(),
                ]);
            }
        }
        t
    }

    /// Observed order per scene and method.
    pub fn orders_table(&self) -> Table {
        let mut t = Table::new(&["scene", "method", "observed_order", "successful_runs"]);
        for s in &self.scenes {
            for m in s.methods() {
                let ok = s
                    .runs
                    .iter()
                    .filter(|r| r.method == m && r.status == "ok")
                    .count();
                t.push(vec![
                    s.scene.clone(),
                    m.clone(),
                    s.order(&m).map_or("-".into(), |p| format!("{p:.2}")),
                    format!("{ok}/{}", s.runs.iter().filter(|r| r.method == m).count()),
                ]);
            }
        }
        t
    }

    /// Fastest method per scene and error level.
    pub fn summary_table(&self) -> Table {
        let mut t = Table::new(&[
            "scene",
            "error_level",
            "fastest_method",
            "dt_s",
            "wall_s",
            "error",
        ]);
        for s in &self.scenes {
            for &lvl in &LEVELS {
                let row = if lvl < s.reference_error * 10.0 {
                    vec![
                        "below the reference's accuracy".into(),
                        "-".into(),
                        "-".into(),
                        "-".into(),
                    ]
                } else {
                    match s.fastest(lvl) {
                        Some(r) => vec![r.method.clone(), num(r.dt), num(r.wall), num(r.error)],
                        None => vec!["not reached".into(), "-".into(), "-".into(), "-".into()],
                    }
                };
                let mut full = vec![s.scene.clone(), format!("{lvl:.0e}")];
                full.extend(row);
                t.push(full);
            }
        }
        t
    }

    /// Reference solutions, one line per scene.
    pub fn references(&self) -> String {
        let mut out = String::new();
        for s in &self.scenes {
            out.push_str(&format!(
                "{}: end time {} s; reference: {}; reference error estimate {:.2e}\n",
                s.scene, s.end_time, s.reference, s.reference_error
            ));
        }
        out
    }

    /// Files to write: `precision.csv`, `precision_orders.csv`,
    /// `precision_summary.csv`, `precision_<scene>.svg`, `precision.txt`,
    /// and with the chain study `precision_chain.csv`,
    /// `precision_chain_summary.csv`, `precision_chain.svg`.
    pub fn files(&self) -> Vec<(String, String)> {
        let mut f = vec![
            ("precision.csv".to_string(), self.runs_table().to_csv()),
            (
                "precision_orders.csv".to_string(),
                self.orders_table().to_csv(),
            ),
            (
                "precision_summary.csv".to_string(),
                self.summary_table().to_csv(),
            ),
            ("precision.txt".to_string(), self.to_text()),
        ];
        for s in &self.scenes {
            f.push((format!("precision_{}.svg", s.scene), s.plot().to_svg()));
        }
        if let Some(c) = &self.chain {
            f.push(("precision_chain.csv".into(), c.runs_table().to_csv()));
            f.push((
                "precision_chain_summary.csv".into(),
                c.summary_table().to_csv(),
            ));
            f.push(("precision_chain.svg".into(), c.plot().to_svg()));
        }
        f
    }

    /// The human-readable report.
    pub fn to_text(&self) -> String {
        let mut t = format!(
            "Work-precision (error = max particle position error / scene extent; wall time = stepping only; {} threads)\n\n{}\nObserved convergence order (slope of log error vs log dt)\n\n{}\nFastest method per error level\n\n{}",
            self.threads,
            self.references(),
            self.orders_table().to_text(),
            self.summary_table().to_text()
        );
        if let Some(c) = &self.chain {
            t.push('\n');
            t.push_str(&c.to_text());
        }
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn order_fit_recovers_a_power_law() {
        let pts: Vec<(f64, f64)> = (0..5)
            .map(|k| {
                let h = 0.1 / 2f64.powi(k);
                (h, 3.0 * h * h)
            })
            .collect();
        assert!((fit_order(&pts).unwrap() - 2.0).abs() < 1e-12);
        assert_eq!(fit_order(&pts[..1]), None);
    }

    /// The study's observed orders on the wire: trapezoidal 2, the Euler
    /// schemes 1 (the convergence oracles, measured through this module).
    #[test]
    #[cfg_attr(debug_assertions, ignore = "runs the wire ladder; release only")]
    fn wire_orders_match_the_schemes() {
        let r = massspring_scene("wire", &wire_system(), 0.25, 0.025, 8, &[]).unwrap();
        assert!(r.reference_error < 1e-8, "{}", r.reference_error);
        let trap = r.order("trapezoidal").unwrap();
        let be = r.order("backward-euler").unwrap();
        assert!((trap - 2.0).abs() < 0.15, "trapezoidal order {trap}");
        assert!((be - 1.0).abs() < 0.15, "backward Euler order {be}");
        // Forward Euler cannot run above its CFL bound: the coarse steps fail.
        assert!(r
            .runs
            .iter()
            .any(|x| x.method == "forward-euler" && x.status != "ok"));
        // Smaller steps of a convergent scheme give smaller errors.
        let errs: Vec<f64> = r
            .runs
            .iter()
            .filter(|x| x.method == "trapezoidal")
            .map(|x| x.error)
            .collect();
        assert!(errs.windows(2).all(|w| w[1] < w[0]), "{errs:?}");
        let csv = PrecisionReport {
            scenes: vec![r],
            chain: None,
            threads: 1,
        }
        .runs_table()
        .to_csv();
        assert!(csv.starts_with("scene,method,dt_s,steps,wall_s,error,status\n"));
    }
}
