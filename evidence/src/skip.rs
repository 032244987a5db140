//! Skip what a scene doesn't need: the cost of each optional pass, grid
//! work against grid size, and the per-pass breakdown.
//!
//! Every variant starts from its initial state, runs `warmup` untimed
//! substeps, then `steps` timed ones; the best of `repeats` timings is kept
//! (the machine is shared, the minimum is the least disturbed), and the
//! repeats go round-robin over the variants.
//!
//! * Features: the reference scene with the attractor switched on (at
//!   (0.5, 0.9), strength 10 m/s^2) as "all on", then each of obstacles,
//!   attractor, plasticity and bending off, then all off.
//! * Grid: the reference bundle on its 256^2 grid over 1 m against the same
//!   bundle at the same cell size on a 1024^2 grid over 4 m (16x the nodes,
//!   the same occupied region). If grid work is limited to the blocks the
//!   particles touch, the two run in about the same time.

use std::time::Instant;

use crate::plot::bar_chart;
use crate::{num, Table};
use yarnsim::mpm::{PassTimes, YarnSim};
use yarnsim::scene::{builtin::yarn_reference, YarnScene};

/// What to run.
#[derive(Clone, Debug)]
pub struct SkipOptions {
    pub steps: u64,
    pub warmup: u64,
    pub repeats: usize,
}

impl Default for SkipOptions {
    fn default() -> Self {
        SkipOptions {
            steps: 60,
            warmup: 20,
            repeats: 12,
        }
    }
}

/// One variant's measurement.
#[derive(Clone, Debug)]
pub struct Variant {
    pub name: String,
    pub particles: usize,
    pub grid: u32,
    pub steps: u64,
    /// Best wall time per substep, in s.
    pub per_step: f64,
    /// Pass timings of the best repeat.
    pub passes: PassTimes,
    /// Blocks (8x8 nodes) touched by the last substep.
    pub active_blocks: usize,
}

impl Variant {
    pub fn throughput(&self) -> f64 {
        self.particles as f64 / self.per_step
    }
}

/// The whole report.
#[derive(Clone, Debug)]
pub struct SkipReport {
    pub features: Vec<Variant>,
    pub grids: Vec<Variant>,
    pub threads: usize,
}

/// Times `steps` substeps of every scene after `warmup`, best of `repeats`.
/// The repeats go round-robin over the variants, so a disturbance of the
/// shared machine hits them alike rather than one variant.
pub fn measure_all(
    variants: &[(String, YarnScene)],
    opts: &SkipOptions,
) -> Result<Vec<Variant>, String> {
    let mut starts = Vec::new();
    for (_, scene) in variants {
        let mut sim = YarnSim::new(scene).map_err(|e| e.to_string())?;
        sim.steps_n(opts.warmup).map_err(|e| e.to_string())?;
        starts.push(sim);
    }
    let mut best: Vec<Option<(f64, PassTimes, usize)>> = vec![None; variants.len()];
    for _ in 0..opts.repeats.max(1) {
        for (k, start) in starts.iter().enumerate() {
            let mut s = start.clone();
            s.reset_timings();
            let t0 = Instant::now();
            s.steps_n(opts.steps).map_err(|e| e.to_string())?;
            let w = t0.elapsed().as_secs_f64() / opts.steps.max(1) as f64;
            if best[k].as_ref().is_none_or(|b| w < b.0) {
                best[k] = Some((w, s.timings(), s.active_blocks()));
            }
        }
    }
    Ok(variants
        .iter()
        .zip(starts)
        .zip(best)
        .map(|(((name, scene), sim), b)| {
            let (per_step, passes, active_blocks) = b.expect("at least one repeat");
            Variant {
                name: name.clone(),
                particles: sim.particles().len(),
                grid: scene.grid.resolution,
                steps: opts.steps,
                per_step,
                passes,
                active_blocks,
            }
        })
        .collect())
}

/// The feature variants: (name, scene).
pub fn feature_variants() -> Vec<(String, YarnScene)> {
    let base = yarn_reference();
    let mut on = base.clone();
    on.attractor.active = true;
    on.attractor.position = [0.5, 0.9];
    on.attractor.strength = 10.0;
    let mut v = vec![
        ("reference (as built in)".to_string(), base),
        ("all on (+attractor)".to_string(), on.clone()),
    ];
    let mut s = on.clone();
    s.obstacles.clear();
    v.push(("obstacles off".into(), s));
    let mut s = on.clone();
    s.attractor.active = false;
    v.push(("attractor off".into(), s));
    let mut s = on.clone();
    s.material.plasticity = false;
    v.push(("plasticity off".into(), s));
    let mut s = on.clone();
    s.material.bending = 0.0;
    v.push(("bending off".into(), s));
    let mut s = on;
    s.obstacles.clear();
    s.attractor.active = false;
    s.material.plasticity = false;
    s.material.bending = 0.0;
    v.push(("all off".into(), s));
    v
}

/// The grid variants: the reference bundle on 256^2 over 1 m, and on 1024^2 over 4 m.
pub fn grid_variants() -> Vec<(String, YarnScene)> {
    let small = yarn_reference();
    let mut big = small.clone();
    big.grid.resolution = 1024;
    big.grid.size = 4.0;
    vec![
        ("256^2 grid, 1 m".to_string(), small),
        ("1024^2 grid, 4 m (same dx)".to_string(), big),
    ]
}

/// Runs the benchmark.
pub fn run(opts: &SkipOptions) -> Result<SkipReport, String> {
    let features = measure_all(&feature_variants(), opts)?;
    let grids = measure_all(&grid_variants(), opts)?;
    Ok(SkipReport {
        features,
        grids,
        threads: rayon::current_num_threads(),
    })
}

impl SkipReport {
    fn variant_table(vs: &[Variant], base: &Variant) -> Table {
        let mut header: Vec<String> = [
            "variant",
            "grid",
            "particles",
            "ms_per_substep",
            "particle_substeps_per_s",
            "vs_first",
            "active_blocks",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        // One column per pass of the solver, named as PassTimes names them.
        header.extend(
            base.passes
                .entries()
                .iter()
                .map(|(n, _)| format!("{n} (ms)")),
        );
        let mut t = Table {
            header,
            rows: Vec::new(),
        };
        for v in vs {
            let per = |x: f64| format!("{:.4}", 1e3 * x / v.passes.substeps.max(1) as f64);
            let mut row = vec![
                v.name.clone(),
                format!("{0}^2", v.grid),
                v.particles.to_string(),
                format!("{:.4}", v.per_step * 1e3),
                num(v.throughput()),
                format!("{:.3}", v.per_step / base.per_step),
                v.active_blocks.to_string(),
            ];
            row.extend(v.passes.entries().iter().map(|(_, s)| per(*s)));
            t.push(row);
        }
        t
    }

    /// Feature variants (ratios against "all on").
    pub fn features_table(&self) -> Table {
        Self::variant_table(
            &self.features,
            &self.features[1.min(self.features.len() - 1)],
        )
    }

    /// Grid variants (ratio against 256^2).
    pub fn grids_table(&self) -> Table {
        Self::variant_table(&self.grids, &self.grids[0])
    }

    /// Run time on the big grid over the small one.
    pub fn grid_ratio(&self) -> f64 {
        self.grids[1].per_step / self.grids[0].per_step
    }

    /// Per-pass breakdown of the reference scene.
    pub fn breakdown_table(&self) -> Table {
        let v = &self.features[0];
        let total = v.passes.total();
        let mut t = Table::new(&["pass", "ms_per_substep", "share"]);
        for (name, s) in v.passes.entries() {
            t.push(vec![
                name.to_string(),
                format!("{:.4}", 1e3 * s / v.passes.substeps.max(1) as f64),
                format!("{:.1}%", 100.0 * s / total),
            ]);
        }
        t
    }

    pub fn to_text(&self) -> String {
        format!(
            "Skip what a scene doesn't need ({} threads; best of the repeats, {} timed substeps each)\n\nOptional passes (vs_first = time relative to \"all on\")\n\n{}\nGrid size (same bundle, same dx)\n\n{}\nratio 1024^2 / 256^2 run time: {:.3}\n\nPer-pass breakdown, reference scene\n\n{}",
            self.threads,
            self.features.first().map_or(0, |v| v.steps),
            self.features_table().to_text(),
            self.grids_table().to_text(),
            self.grid_ratio(),
            self.breakdown_table().to_text()
        )
    }

    /// Files: `skip.csv`, `skip_grid.csv`, `skip_passes.csv`, `skip.txt`, `skip.svg`.
    pub fn files(&self) -> Vec<(String, String)> {
        let bars: Vec<(String, f64)> = self
            .features
            .iter()
            .chain(&self.grids)
            .map(|v| (v.name.clone(), v.per_step * 1e3))
            .collect();
        vec![
            ("skip.csv".into(), self.features_table().to_csv()),
            ("skip_grid.csv".into(), self.grids_table().to_csv()),
            ("skip_passes.csv".into(), self.breakdown_table().to_csv()),
            ("skip.txt".into(), self.to_text()),
            (
                "skip.svg".into(),
                bar_chart(
                    "yarn reference scene: ms per substep",
                    "ms per substep",
                    &bars,
                ),
            ),
        ]
    }
}
