//! # yarnsim-evidence
//!
//! Evidence of speed and accuracy of the `yarnsim` library:
//! work-precision diagrams, stability stress maps and the "skip what a scene
//! doesn't need" benchmark. A crate of its own so that `yarnsim` holds physics
//! only; the CLI (`yarnsim bench precision`, `yarnsim stress`,
//! `yarnsim bench skip`) and the `evidence` example run it.
//!
//! * [`precision`]: run time against error for every scene and integrator,
//!   with the observed convergence order and the fastest method per error level.
//! * [`stress`]: the largest stable step per integrator and stiffness (or yarn
//!   parameter), found by bisection, next to the theoretical bound.
//! * [`skip`]: the cost of obstacles, attractor, plasticity and bending, grid
//!   work against grid size, and the per-pass breakdown of the reference scene.
//! * [`roofline`]: this core's peak flop/s and bandwidth (simple kernels),
//!   flops and bytes per particle of each pass (counted from the kernels)
//!   and where each pass of the reference scene sits against that limit.
//! * [`plot`]: SVG line plots and bar charts (`plotters`, SVG backend).
//!
//! Every report renders as CSV ([`Table::to_csv`]), a text table
//! ([`Table::to_text`]) and an SVG plot, and [`write_report`] stores them in a
//! directory. Wall times are measured in this build on this machine; errors
//! and stability limits are deterministic.

pub mod bundle_precision;
pub mod chain;
pub mod plot;
pub mod precision;
pub mod roofline;
mod scene;
pub mod skip;
pub mod stress;
pub mod trajectory;

pub use scene::small_yarn_scene;

use std::fmt::Write;
use std::path::Path;

use yarnsim::massspring::V3;

/// A table of strings with a header, rendered as CSV or aligned text.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Table {
    pub header: Vec<String>,
    pub rows: Vec<Vec<String>>,
}

impl Table {
    pub fn new(header: &[&str]) -> Table {
        Table {
            header: header.iter().map(|s| s.to_string()).collect(),
            rows: Vec::new(),
        }
    }
    pub fn push(&mut self, row: Vec<String>) {
        debug_assert_eq!(row.len(), self.header.len());
        self.rows.push(row);
    }
    /// RFC 4180 CSV (fields with commas or quotes are quoted).
    pub fn to_csv(&self) -> String {
        let field = |s: &String| {
            if s.contains([',', '"', '\n']) {
                format!("\"{}\"", s.replace('"', "\"\""))
            } else {
                s.clone()
            }
        };
        let mut out = String::new();
        for r in std::iter::once(&self.header).chain(&self.rows) {
            let _ = writeln!(out, "{}", r.iter().map(field).collect::<Vec<_>>().join(","));
        }
        out
    }
    /// Columns padded to a common width, for a terminal or Markdown.
    pub fn to_text(&self) -> String {
        let n = self.header.len();
        let mut w = vec![0; n];
        for r in std::iter::once(&self.header).chain(&self.rows) {
            for (i, c) in r.iter().enumerate().take(n) {
                w[i] = w[i].max(c.chars().count());
            }
        }
        let line = |r: &Vec<String>| {
            let cells: Vec<String> = r
                .iter()
                .enumerate()
                .map(|(i, c)| format!("{c:<width$}", width = w[i]))
                .collect();
            format!("| {} |", cells.join(" | "))
        };
        let mut out = String::new();
        let _ = writeln!(out, "{}", line(&self.header));
        let _ = writeln!(
            out,
            "|{}|",
            w.iter()
                .map(|&k| "-".repeat(k + 2))
                .collect::<Vec<_>>()
                .join("|")
        );
        for r in &self.rows {
            let _ = writeln!(out, "{}", line(r));
        }
        out
    }
}

/// Formats a number in 4 significant digits, `-` when absent/non-finite.
pub fn num(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.4e}")
    } else if v == f64::INFINITY {
        "inf".into()
    } else {
        "-".into()
    }
}

/// Largest side of the bounding box of mass-spring positions (at least
/// 1e-12): the length that makes position errors relative.
pub fn extent(x: &[V3]) -> f64 {
    let mut lo = V3::repeat(f64::INFINITY);
    let mut hi = V3::repeat(f64::NEG_INFINITY);
    for p in x {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    (hi - lo).max().max(1e-12)
}

/// Writes `files` (name, contents) into `dir`, creating it.
pub fn write_report(dir: &Path, files: &[(String, String)]) -> std::io::Result<Vec<String>> {
    std::fs::create_dir_all(dir)?;
    let mut written = Vec::new();
    for (name, text) in files {
        let p = dir.join(name);
        std::fs::write(&p, text)?;
        written.push(p.display().to_string());
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_quotes_and_text_aligns() {
        let mut t = Table::new(&["a", "b"]);
        t.push(vec!["x,y".into(), "1".into()]);
        assert_eq!(t.to_csv(), "a,b\n\"x,y\",1\n");
        let text = t.to_text();
        assert!(text
            .lines()
            .all(|l| l.len() == text.lines().next().unwrap().len()));
    }
}
