//! The summary table printed by `yarnsim run`.

use std::fmt::Write as _;

use yarnsim::mpm::Diagnostics;

use crate::driver::FrameRun;

/// One diagnostic row of the summary: name, value at the start, value at the end.
pub type DiagRow = (&'static str, f64, f64);

/// Everything the summary table shows.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Summary {
    pub scene: String,
    /// The model and its solver, e.g. `yarn (MPM)` or `mass-spring, backward-euler`.
    pub model: String,
    /// Particles (the unit of the throughput figure).
    pub particles: usize,
    /// What the particles are, e.g. `120 vertices + 108 quadrature, 12 yarns`.
    pub particles_detail: String,
    pub dt: f64,
    /// Adaptive substeps (`dt = "auto"`): their `min / mean / max`.
    pub adaptive_dt: Option<String>,
    pub substeps: u64,
    pub frames: u64,
    pub sim_time: f64,
    /// Wall-clock seconds spent stepping.
    pub wall_seconds: f64,
    pub interrupted: bool,
    /// Why the run stopped early (divergence, solver failure); the final
    /// column then holds the last frame before the failure.
    pub failure: Option<String>,
    /// Diagnostics at the start and at the end of the run.
    pub diagnostics: Vec<DiagRow>,
    /// A yarn material given per yarn: the sheet it stands for (spacing,
    /// yarns per metre of depth, preset).
    pub sheet: Option<String>,
    /// Rows with their unit in the name, after the diagnostics: the pins'
    /// forces per metre of depth and per yarn, for a material given per yarn.
    pub forces: Vec<(String, f64, f64)>,
}

impl Summary {
    /// The summary of a run of frames that simulated `sim_time` seconds:
    /// its substeps, frames, wall time and how it ended; the caller fills in
    /// what was run.
    pub fn of_run(run: FrameRun, sim_time: f64) -> Self {
        Summary {
            substeps: run.outcome.substeps,
            frames: run.outcome.last_frame,
            sim_time,
            wall_seconds: run.outcome.step_seconds,
            interrupted: run.outcome.interrupted,
            failure: run.failure.map(|e| e.to_string()),
            ..Default::default()
        }
    }

    /// Particle-substeps per wall-clock second; 0 when nothing was timed.
    pub fn throughput(&self) -> f64 {
        if self.wall_seconds > 0.0 {
            self.particles as f64 * self.substeps as f64 / self.wall_seconds
        } else {
            0.0
        }
    }
}

/// The rows that open every run's summary, from the diagnostics `$a` at
/// the start and `$b` at the end: the time (the row `$time`), the kinetic,
/// elastic and potential energies (the field `$potential`, the row
/// `$name`), their total, the momentum's x and y. A macro, not a function:
/// the yarn's and the mass-spring's diagnostics name these fields alike
/// but share no trait.
macro_rules! energy_rows {
    ($a:expr, $b:expr, $time:literal, $potential:ident, $name:literal) => {{
        let (a, b) = ($a, $b);
        let rows: Vec<$crate::table::DiagRow> = vec![
            ($time, a.time, b.time),
            ("kinetic energy", a.kinetic_energy, b.kinetic_energy),
            ("elastic energy", a.elastic_energy, b.elastic_energy),
            ($name, a.$potential, b.$potential),
            (
                "total energy",
                a.kinetic_energy + a.elastic_energy + a.$potential,
                b.kinetic_energy + b.elastic_energy + b.$potential,
            ),
            ("momentum x", a.momentum.x, b.momentum.x),
            ("momentum y", a.momentum.y, b.momentum.y),
        ];
        rows
    }};
}
pub(crate) use energy_rows;

/// The summary rows of a yarn run.
pub fn yarn_rows(a: &Diagnostics, b: &Diagnostics) -> Vec<DiagRow> {
    let mut rows = energy_rows!(a, b, "time", potential_energy, "potential energy");
    rows.extend([
        ("angular momentum", a.angular_momentum, b.angular_momentum),
        ("min stretch", a.min_stretch, b.min_stretch),
        ("max stretch", a.max_stretch, b.max_stretch),
    ]);
    rows
}

/// The unit of a diagnostic row by its quantity (the row's name up to its
/// axis: `momentum x` is a `momentum`), shown after the name.
const UNITS: [(&str, &str); 8] = [
    ("time", "s"),
    ("energy", "J"),
    ("momentum", "kg m/s"),
    ("angular momentum", "kg m^2/s"),
    ("ang. momentum", "kg m^2/s"),
    ("stretch", "l/l0"),
    ("strain", "|l/l0 - 1|"),
    ("centre of mass", "m"),
];

/// A diagnostic row's name with its unit: `kinetic energy [J]`,
/// `momentum x [kg m/s]`, `min stretch [l/l0]`.
pub fn with_unit(name: &str) -> String {
    let quantity = name
        .strip_suffix(" x")
        .or_else(|| name.strip_suffix(" y"))
        .or_else(|| name.strip_suffix(" z"))
        .unwrap_or(name);
    // The longest quantity the name ends with: `angular momentum` before `momentum`.
    let unit = UNITS
        .iter()
        .filter(|(q, _)| quantity == *q || quantity.ends_with(&format!(" {q}")))
        .max_by_key(|(q, _)| q.len())
        .map(|(_, u)| *u);
    match unit {
        Some(u) if !name.contains('[') => format!("{name} [{u}]"),
        _ => name.to_string(),
    }
}

/// `1 yarn`, `12 yarns`: a count with its noun in the right number.
pub fn count(n: usize, noun: &str) -> String {
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}

/// Width of the name column of the diagnostic rows (`angular momentum [kg m^2/s]`).
const NAME_WIDTH: usize = 28;

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
    let status = if s.failure.is_some() {
        " (stopped: the simulation failed after the last one)"
    } else if s.interrupted {
        " (interrupted)"
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
        (
            "substeps",
            match &s.adaptive_dt {
                Some(range) => format!(
                    "{} adaptive (dt = \"auto\"), dt min / mean / max = {range}",
                    s.substeps
                ),
                None => format!("{} of dt = {} s", s.substeps, s.dt),
            },
        ),
        ("frames", format!("{}{status}", s.frames)),
        ("simulated time", format!("{:.6} s", s.sim_time)),
        ("wall time", wall),
        ("throughput", rate),
    ];
    for (k, v) in rows {
        let _ = writeln!(out, "{k:<18} {v}");
    }
    if let Some(sheet) = &s.sheet {
        let _ = writeln!(out, "{:<18} {sheet}", "yarn sheet");
    }
    let _ = writeln!(out);
    let last = if s.failure.is_some() {
        "last frame"
    } else {
        "final"
    };
    let _ = writeln!(out, "{:<NAME_WIDTH$} {:>16} {:>16}", "", "initial", last);
    for (k, x, y) in &s.diagnostics {
        let k = with_unit(k);
        let _ = writeln!(out, "{k:<NAME_WIDTH$} {:>16} {:>16}", num(*x), num(*y));
    }
    for (k, x, y) in &s.forces {
        let _ = writeln!(out, "{k:<NAME_WIDTH$} {:>16} {:>16}", num(*x), num(*y));
    }
    if s.model.starts_with("yarn") {
        let _ = writeln!(out, "(2D model: energies and momenta are per m of depth)");
    }
    if !s.forces.is_empty() {
        let _ = writeln!(
            out,
            "(pin forces: on the yarn over the last substep, 0 before the first; per yarn = per m of depth x spacing)"
        );
    }
    out
}

/// Widest line the CLI prints (tables and reports); the full data of the
/// evidence studies stays in their CSV files.
pub const MAX_WIDTH: usize = 100;

/// Longest table cell shown; longer ones are cut with `~` (the CSV has them whole).
const MAX_CELL: usize = 30;

/// Fits a report into `width` columns: pipe tables (`| a | b |` with a
/// `|---|` rule) wider than that are split into several tables of fewer
/// columns, each repeating the first (key) column, with over-long cells
/// cut; other long lines are wrapped at spaces. Text that fits is unchanged.
pub fn fit_tables(text: &str, width: usize) -> String {
    let mut out = String::new();
    let lines: Vec<&str> = text.lines().collect();
    let mut i = 0;
    while i < lines.len() {
        let is_row = |l: &str| l.starts_with('|') && l.ends_with('|') && l.len() > 1;
        if is_row(lines[i]) {
            let start = i;
            while i < lines.len() && is_row(lines[i]) {
                i += 1;
            }
            let block = &lines[start..i];
            if block.iter().all(|l| l.chars().count() <= width) {
                for l in block {
                    let _ = writeln!(out, "{l}");
                }
            } else {
                out += &split_table(block, width);
            }
            continue;
        }
        out += &wrap_line(lines[i], width);
        i += 1;
    }
    if !text.ends_with('\n') {
        out.pop();
    }
    out
}

/// Word-wraps one line (with its newline); continuation lines keep the indent.
fn wrap_line(line: &str, width: usize) -> String {
    if line.chars().count() <= width {
        return format!("{line}\n");
    }
    let indent: String = line.chars().take_while(|c| *c == ' ').collect();
    let mut out = String::new();
    let mut cur = String::new();
    for word in line.split(' ').filter(|w| !w.is_empty()) {
        if !cur.is_empty() && cur.chars().count() + 1 + word.chars().count() > width {
            let _ = writeln!(out, "{cur}");
            cur.clear();
        }
        if cur.is_empty() {
            cur.push_str(&indent);
        } else {
            cur.push(' ');
        }
        cur.push_str(word);
    }
    let _ = writeln!(out, "{cur}");
    out
}

/// Splits a pipe table into column groups that fit `width`.
fn split_table(block: &[&str], width: usize) -> String {
    let cut = |c: &str| -> String {
        let c = c.trim();
        if c.chars().count() > MAX_CELL {
            let mut s: String = c.chars().take(MAX_CELL - 1).collect();
            s.push('~');
            s
        } else {
            c.to_string()
        }
    };
    let rows: Vec<Vec<String>> = block
        .iter()
        .filter(|l| !l.starts_with("|-"))
        .map(|l| l[1..l.len() - 1].split(" | ").map(cut).collect())
        .collect();
    let n = rows.iter().map(Vec::len).max().unwrap_or(0);
    let col_width = |j: usize| {
        rows.iter()
            .map(|r| r.get(j).map_or(0, |c| c.chars().count()))
            .max()
            .unwrap_or(0)
    };
    let w: Vec<usize> = (0..n).map(col_width).collect();
    // Key columns, repeated in every part: the first column and the text
    // columns right after it (scene, integrator, ...), within half the width.
    let numeric = |j: usize| {
        rows.iter().skip(1).all(|r| {
            r.get(j).is_none_or(|c| {
                c.starts_with(|ch: char| ch.is_ascii_digit() || "-+.><=".contains(ch))
            })
        })
    };
    let mut keys = 1.min(n);
    let mut key_width = 4 + w.first().copied().unwrap_or(0);
    while keys < n && !numeric(keys) && key_width + 3 + w[keys] <= width / 2 {
        key_width += 3 + w[keys];
        keys += 1;
    }
    // Column groups after the keys: as many as fit beside them.
    let mut groups: Vec<Vec<usize>> = Vec::new();
    let mut cur: Vec<usize> = Vec::new();
    let mut used = key_width;
    for (j, &wj) in w.iter().enumerate().skip(keys) {
        if !cur.is_empty() && used + 3 + wj > width {
            groups.push(std::mem::take(&mut cur));
            used = key_width;
        }
        cur.push(j);
        used += 3 + wj;
    }
    if !cur.is_empty() || groups.is_empty() {
        groups.push(cur);
    }
    let mut out = String::new();
    for (g, cols) in groups.iter().enumerate() {
        if g > 0 {
            let _ = writeln!(out);
        }
        let cols: Vec<usize> = (0..keys).chain(cols.iter().copied()).collect();
        for (r, row) in rows.iter().enumerate() {
            let cells: Vec<String> = cols
                .iter()
                .map(|&j| {
                    let c = row.get(j).map_or("", String::as_str);
                    format!("{c:<width$}", width = w[j])
                })
                .collect();
            let _ = writeln!(out, "| {} |", cells.join(" | "));
            if r == 0 {
                let rule: Vec<String> = cols.iter().map(|&j| "-".repeat(w[j] + 2)).collect();
                let _ = writeln!(out, "|{}|", rule.join("|"));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wide_tables_are_split_and_text_wrapped() {
        let header: Vec<String> = (0..12).map(|j| format!("column number {j}")).collect();
        let row: Vec<String> = (0..12).map(|j| format!("{}", j as f64 * 1.2345)).collect();
        let table = format!(
            "intro\n| {} |\n|{}|\n| {} |\n{}\n",
            header.join(" | "),
            ["---"; 12].join("|"),
            row.join(" | "),
            "word ".repeat(40).trim_end()
        );
        let fitted = fit_tables(&table, MAX_WIDTH);
        assert!(
            fitted.lines().all(|l| l.chars().count() <= MAX_WIDTH),
            "{fitted}"
        );
        // Every header and value is still there, the key column in every part.
        for h in header.iter().chain(&row) {
            assert!(fitted.contains(h.as_str()), "{h} missing: {fitted}");
        }
        let parts = fitted.matches("| column number 0 ").count();
        assert!(parts >= 2, "{fitted}");
        assert_eq!(fitted.matches("word").count(), 40);
        // What fits stays as it was.
        let small = "| a | b |\n|---|---|\n| 1 | 2 |\n";
        assert_eq!(fit_tables(small, MAX_WIDTH), small);
    }

    #[test]
    fn long_cells_are_cut() {
        let long = "x".repeat(80);
        let t = format!("| k | {long} | {long} |\n|---|---|---|\n| 1 | 2 | 3 |\n");
        let fitted = fit_tables(&t, MAX_WIDTH);
        assert!(
            fitted.lines().all(|l| l.chars().count() <= MAX_WIDTH),
            "{fitted}"
        );
        assert!(fitted.contains(&format!("{}~", "x".repeat(MAX_CELL - 1))));
    }
}
