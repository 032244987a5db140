//! The roofline run (the reference scene on one thread against the peaks)
//! and its tables and text.

use yarnsim::mpm::{PassTimes, YarnSim};
use yarnsim::scene::{builtin::yarn_reference, YarnScene};

use super::counts::*;
use super::peaks::{measure_peaks, Peaks};
use crate::Table;

/// What to run.
#[derive(Clone, Debug)]
pub struct RooflineOptions {
    /// Timed substeps per repeat.
    pub steps: u64,
    pub warmup: u64,
    /// Repeats of the substep timing (the fastest is kept) and of each peak
    /// kernel (the median is kept).
    pub repeats: usize,
    /// Particle-substeps/s of the reference Taichi implementation on this host (low, high), for
    /// the 20x goal.
    pub reference_rate: (f64, f64),
    /// The goal as a multiple of the reference Taichi implementation's rate.
    pub goal_factor: f64,
}

impl Default for RooflineOptions {
    fn default() -> Self {
        RooflineOptions {
            steps: 200,
            warmup: 100,
            repeats: 7,
            // tools/bench/taichi_bench.sh on this host (docs/performance/throughput.md, "Against the
            // reference Taichi implementation")
            reference_rate: (1.9e6, 2.7e6),
            goal_factor: 20.0,
        }
    }
}

/// One pass on the roofline.
#[derive(Clone, Debug, PartialEq)]
pub struct PassPoint {
    pub work: PassWork,
    /// Measured seconds per substep.
    pub seconds: f64,
}

impl PassPoint {
    pub fn flop_rate(&self) -> f64 {
        self.work.flops as f64 / self.seconds
    }
    pub fn byte_rate(&self) -> f64 {
        self.work.bytes as f64 / self.seconds
    }
    pub fn intensity(&self) -> f64 {
        self.work.flops as f64 / self.work.bytes as f64
    }
}

/// `min(peak, intensity x bandwidth)`.
pub fn bound(peak_flops: f64, intensity: f64, bandwidth: f64) -> f64 {
    peak_flops.min(intensity * bandwidth)
}

/// The whole report.
#[derive(Clone, Debug)]
pub struct RooflineReport {
    pub peaks: Peaks,
    pub passes: Vec<PassPoint>,
    pub particles: u64,
    pub vertices: u64,
    pub quads: u64,
    pub grid: GridWork,
    pub sim_active_blocks: usize,
    pub steps: u64,
    pub opts: RooflineOptions,
}

/// Runs the study: the peaks, then the reference scene on 1 thread.
pub fn run(opts: &RooflineOptions) -> Result<RooflineReport, String> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| e.to_string())?;
    pool.install(|| run_on_this_thread(opts))
}

fn run_on_this_thread(opts: &RooflineOptions) -> Result<RooflineReport, String> {
    let peaks = measure_peaks(opts.repeats);
    let scene: YarnScene = yarn_reference();
    let mut start = YarnSim::new(&scene).map_err(|e| e.to_string())?;
    start.steps_n(opts.warmup).map_err(|e| e.to_string())?;
    let mut best: Option<(f64, PassTimes, GridWork, usize)> = None;
    for _ in 0..opts.repeats.max(1) {
        let mut s = start.clone();
        s.reset_timings();
        s.steps_n(opts.steps.max(1)).map_err(|e| e.to_string())?;
        let tm = s.timings();
        if best.as_ref().is_none_or(|b| tm.total() < b.0) {
            best = Some((tm.total(), tm, GridWork::of(&s), s.active_blocks()));
        }
    }
    let (_, tm, grid, sim_active_blocks) = best.expect("at least one repeat");
    let p = start.particles();
    let (nv, nq) = (p.vert.x.len() as u64, p.quad.x.len() as u64);
    let work = pass_work(nv, nq, scene.obstacles.len() as u64, &grid);
    let per = |s: f64| s / tm.substeps.max(1) as f64;
    let secs = [
        per(tm.scatter + tm.forces),
        per(tm.grid),
        per(tm.gather_vertices),
        per(tm.gather_quads),
    ];
    Ok(RooflineReport {
        peaks,
        passes: work
            .into_iter()
            .zip(secs)
            .map(|(work, seconds)| PassPoint { work, seconds })
            .collect(),
        particles: nv + nq,
        vertices: nv,
        quads: nq,
        grid,
        sim_active_blocks,
        steps: opts.steps,
        opts: opts.clone(),
    })
}

impl RooflineReport {
    pub fn peaks_table(&self) -> Table {
        let mut t = Table::new(&["kernel", "detail", "median", "unit"]);
        for p in self.peaks.flops.iter().chain(&self.peaks.bandwidth) {
            let (v, unit) = if p.unit == "flop/s" {
                (p.value / 1e9, "GFLOP/s")
            } else {
                (p.value / 1e9, "GB/s")
            };
            t.push(vec![
                p.kernel.clone(),
                p.detail.clone(),
                format!("{v:.2}"),
                unit.into(),
            ]);
        }
        t
    }

    /// Everything of one pass or the total, for the pass table.
    fn row(&self, name: &str, flops: u64, bytes: u64, seconds: f64) -> Vec<String> {
        let pk = self.peaks.peak_flops();
        let ai = flops as f64 / bytes as f64;
        let rate = flops as f64 / seconds;
        let b_dram = bound(pk, ai, self.peaks.dram());
        let b_l3 = bound(pk, ai, self.peaks.l3());
        let b_l2 = bound(pk, ai, self.peaks.l2());
        let n = self.particles as f64;
        vec![
            name.to_string(),
            format!("{:.1}", seconds * 1e6),
            format!("{:.0}", flops as f64 / n),
            format!("{:.0}", bytes as f64 / n),
            format!("{ai:.3}"),
            format!("{:.2}", rate / 1e9),
            format!("{:.2}", bytes as f64 / seconds / 1e9),
            format!("{:.1}", b_dram / 1e9),
            format!("{:.1}%", 100.0 * rate / b_dram),
            format!("{:.1}", b_l3 / 1e9),
            format!("{:.1}%", 100.0 * rate / b_l3),
            format!("{:.1}", b_l2 / 1e9),
            format!("{:.1}%", 100.0 * rate / b_l2),
        ]
    }

    fn total(&self) -> (u64, u64, f64) {
        self.passes.iter().fold((0, 0, 0.0), |(f, b, s), p| {
            (f + p.work.flops, b + p.work.bytes, s + p.seconds)
        })
    }

    pub fn passes_table(&self) -> Table {
        let mut t = Table::new(&[
            "pass",
            "us_per_substep",
            "flop_per_particle",
            "byte_per_particle",
            "flop_per_byte",
            "GFLOP_per_s",
            "GB_per_s",
            "bound_DRAM_GFLOP_per_s",
            "of_DRAM_bound",
            "bound_L3_GFLOP_per_s",
            "of_L3_bound",
            "bound_L2_GFLOP_per_s",
            "of_L2_bound",
        ]);
        for p in &self.passes {
            t.push(self.row(p.work.name, p.work.flops, p.work.bytes, p.seconds));
        }
        let (f, b, s) = self.total();
        t.push(self.row("total", f, b, s));
        t
    }

    /// The goal: `goal_factor` x the reference Taichi implementation's rate, as time per substep and
    /// as a fraction of the roofline bound of the whole substep.
    pub fn goal_table(&self) -> Table {
        let (f, b, s) = self.total();
        let n = self.particles as f64;
        let pk = self.peaks.peak_flops();
        let ai = f as f64 / b as f64;
        let mut t = Table::new(&[
            "rate",
            "particle_substeps_per_s",
            "us_per_substep",
            "GFLOP_per_s",
            "GB_per_s",
            "of_DRAM_bound",
            "of_L3_bound",
            "of_L2_bound",
        ]);
        let mut push = |name: String, rate: f64| {
            let secs = n / rate;
            let fr = f as f64 / secs;
            t.push(vec![
                name,
                format!("{:.2} M", rate / 1e6),
                format!("{:.1}", secs * 1e6),
                format!("{:.2}", fr / 1e9),
                format!("{:.2}", b as f64 / secs / 1e9),
                format!("{:.1}%", 100.0 * fr / bound(pk, ai, self.peaks.dram())),
                format!("{:.1}%", 100.0 * fr / bound(pk, ai, self.peaks.l3())),
                format!("{:.1}%", 100.0 * fr / bound(pk, ai, self.peaks.l2())),
            ]);
        };
        push("measured (1 thread)".into(), n / s);
        let (lo, hi) = self.opts.reference_rate;
        let g = self.opts.goal_factor;
        push(format!("goal {g}x Taichi ({:.1} M)", lo / 1e6), g * lo);
        push(format!("goal {g}x Taichi ({:.1} M)", hi / 1e6), g * hi);
        push(
            "roofline bound (L3)".into(),
            n * bound(pk, ai, self.peaks.l3()) / f as f64,
        );
        t
    }

    /// The count tables, term by term.
    pub fn counts_table(&self) -> Table {
        let obstacles = 3u64;
        let mut t = Table::new(&["pass", "per", "term", "source", "flops", "bytes"]);
        let groups: [(&str, &str, &[Term]); 8] = [
            ("P2G", "vertex", P2G_VERTEX),
            ("P2G", "quadrature particle", P2G_QUAD),
            (
                "grid",
                "buffer touching the block, per node",
                GRID_PER_SOURCE,
            ),
            ("grid", "node of an active block", GRID_NODE),
            ("grid", "node with mass", GRID_MASS_NODE),
            (
                "grid",
                "node with mass near an obstacle",
                GRID_NEAR_OBSTACLE,
            ),
            ("G2P vertices", "vertex", G2P_VERTEX),
            ("G2P quadrature", "quadrature particle", G2P_QUAD),
        ];
        for (pass, per, terms) in
            groups
                .into_iter()
                .chain([("G2P quadrature (spin balance)", "particle", SPIN_BALANCE)])
        {
            for term in terms {
                let k = if term.per_obstacle { obstacles } else { 1 };
                t.push(vec![
                    pass.into(),
                    per.into(),
                    if term.per_obstacle {
                        format!("{} (x{obstacles})", term.what)
                    } else {
                        term.what.into()
                    },
                    term.source.into(),
                    (k * term.flops).to_string(),
                    (k * term.bytes).to_string(),
                ]);
            }
            let (f, b) = totals(terms, obstacles);
            t.push(vec![
                pass.into(),
                per.into(),
                "total".into(),
                String::new(),
                f.to_string(),
                b.to_string(),
            ]);
        }
        t
    }

    pub fn to_text(&self) -> String {
        let g = &self.grid;
        format!(
            "Roofline of the yarn substep on one core\n\nPeaks (median of {} repeats)\n\n{}\nCounts per particle-substep (1 flop per add, mul, div, sqrt, ln; bytes loaded and stored by the kernel as written), measured time of the fastest of {} repeats of {} substeps (yarn-reference, 1 thread, {} particles: {} vertices, {} quadrature particles; grid: {} active blocks ({} by the simulator), {:.2} scatter buffers per block, {} nodes with mass, {} near an obstacle). Bounds: min(peak {:.2} GFLOP/s, flop/byte x triad bandwidth (DRAM {:.1} GB/s, L3 {:.1} GB/s, L2 {:.1} GB/s))\n\n{}\nThe goal against the bound of the whole substep\n\n{}",
            self.peaks.flops.first().map_or(0, |p| p.repeats),
            self.peaks_table().to_text(),
            self.opts.repeats,
            self.steps,
            self.particles,
            self.vertices,
            self.quads,
            g.active_blocks,
            self.sim_active_blocks,
            g.block_sources as f64 / g.active_blocks.max(1) as f64,
            g.mass_nodes,
            g.mass_nodes_near_obstacle,
            self.peaks.peak_flops() / 1e9,
            self.peaks.dram() / 1e9,
            self.peaks.l3() / 1e9,
            self.peaks.l2() / 1e9,
            self.passes_table().to_text(),
            self.goal_table().to_text(),
        )
    }

    /// Files: `roofline_peaks.csv`, `roofline_passes.csv`,
    /// `roofline_goal.csv`, `roofline_counts.csv`, `roofline.txt`.
    pub fn files(&self) -> Vec<(String, String)> {
        vec![
            ("roofline_peaks.csv".into(), self.peaks_table().to_csv()),
            ("roofline_passes.csv".into(), self.passes_table().to_csv()),
            ("roofline_goal.csv".into(), self.goal_table().to_csv()),
            ("roofline_counts.csv".into(), self.counts_table().to_csv()),
            ("roofline.txt".into(), self.to_text()),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bound_is_the_lower_roof() {
        assert_eq!(bound(100.0, 0.1, 50.0), 5.0);
        assert_eq!(bound(100.0, 10.0, 50.0), 100.0);
    }
}
