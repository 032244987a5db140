//! The hanging-chain study's tables, summary and work-precision plot.

use super::*;

impl ChainReport {
    fn ok(&self) -> impl Iterator<Item = &ChainRun> {
        self.runs
            .iter()
            .filter(|r| r.status == "ok" && r.error.is_finite() && r.wall.is_finite())
    }

    /// The cheapest successful run (least wall time) with error <= `level`,
    /// of `scheme` or of any scheme.
    pub fn cheapest(&self, level: f64, scheme: Option<&str>) -> Option<&ChainRun> {
        self.ok()
            .filter(|r| r.error <= level && scheme.is_none_or(|s| r.scheme == s))
            .min_by(|a, b| a.wall.total_cmp(&b.wall))
    }

    /// Every run (CSV).
    pub fn runs_table(&self) -> Table {
        let mut t = Table::new(&[
            "scheme",
            "ladder",
            "resolution",
            "vertices",
            "dt_s",
            "steps",
            "wall_s",
            "repeats",
            "omega",
            "omega_oracle",
            "signed_error",
            "rel_error",
            "status",
        ]);
        for r in &self.runs {
            t.push(vec![
                r.scheme.clone(),
                r.ladder.clone(),
                r.resolution.to_string(),
                r.vertices.to_string(),
                num(r.dt),
                r.steps.to_string(),
                num(r.wall),
                r.repeats.to_string(),
                format!("{:.6}", r.omega),
                format!("{:.6}", r.omega_oracle),
                num(r.omega / r.omega_oracle - 1.0),
                num(r.error),
                r.status.clone(),
            ]);
        }
        t
    }

    /// Cheapest setting per error level: any scheme first, then per scheme.
    pub fn summary_table(&self) -> Table {
        let mut t = Table::new(&[
            "error_level",
            "among",
            "scheme",
            "ladder",
            "resolution",
            "dt_s",
            "wall_s",
            "rel_error",
        ]);
        let mut among: Vec<Option<String>> = vec![None];
        among.extend(schemes().into_iter().map(|s| Some(s.name)));
        for &lvl in &LEVELS {
            for a in &among {
                let mut row = vec![
                    format!("{lvl:.0e}"),
                    a.clone().unwrap_or_else(|| "any scheme".into()),
                ];
                match self.cheapest(lvl, a.as_deref()) {
                    Some(r) => row.extend([
                        r.scheme.clone(),
                        r.ladder.clone(),
                        format!("{}^2", r.resolution),
                        num(r.dt),
                        num(r.wall),
                        num(r.error),
                    ]),
                    None => row.extend(["not reached", "-", "-", "-", "-", "-"].map(String::from)),
                }
                t.push(row);
            }
        }
        t
    }

    /// Error against wall time: a colour per scheme, a line per ladder
    /// (dt ladder solid with circles, grid ladder dashed with squares).
    pub fn plot(&self) -> LinePlot {
        let mut series = Vec::new();
        for (i, s) in schemes().iter().enumerate() {
            for (ladder, label) in [
                ("dt", format!("dt ladder, {}^2", dt_ladder_grid(self.quick))),
                ("grid", format!("grid ladder, CFL {CFL}")),
            ] {
                series.push(Series {
                    name: format!("{}: {label}", s.name),
                    points: self
                        .ok()
                        .filter(|r| r.scheme == s.name && r.ladder == ladder)
                        .map(|r| (r.wall, r.error))
                        .collect(),
                    color: Some(i),
                    dashed: ladder == "grid",
                    marker: if ladder == "grid" {
                        Marker::Square
                    } else {
                        Marker::Circle
                    },
                    ..Series::default()
                });
            }
        }
        for (i, s) in schemes().iter().enumerate() {
            series.push(Series {
                name: format!(
                    "{}: dt = \"auto\" (safety {DEFAULT_SAFETY}), {}^2",
                    s.name,
                    dt_ladder_grid(self.quick)
                ),
                points: self
                    .ok()
                    .filter(|r| r.scheme == s.name && r.ladder == "auto")
                    .map(|r| (r.wall, r.error))
                    .collect(),
                color: Some(i),
                markers_only: true,
                ..Series::default()
            });
        }
        LinePlot {
            title: "yarn work-precision: hanging chain, first-mode frequency vs oracle".into(),
            x_label: "wall time (s)".into(),
            y_label: "|omega / omega_1 - 1|, omega_1 = 1.2024 sqrt(g/L)".into(),
            log_x: true,
            log_y: true,
            series,
        }
    }

    /// Set-up, one paragraph, and the model floor.
    pub fn setup(&self) -> String {
        let m = chain_material();
        let floor = model_floor();
        format!(
            "hanging chain: L = {LENGTH} m pinned at ({}, {}), g = {GRAVITY}, rho = {DENSITY}, k = {:.0} (top strain {STRAIN_TOP:.0e}), gamma = {}, E = {}, no bending, no plasticity; amplitude {AMPLITUDE} L in the J0 mode shape; {} oracle periods per run; {VERTICES_PER_CELL} vertices per cell; dt ladder at {}^2 from CFL {CFL} (dt = {:.3e} s) halving; dt = \"auto\" (safety {DEFAULT_SAFETY}, dt_s its mean substep) at the same grid; grid ladder at CFL {CFL} (c = {:.1} m/s); wall time = stepping only, median of 3 for runs under {REPEAT_BELOW_S} s\nmodel floor: stretching under its own weight shifts the frequency by {floor:+.2e} (discrete extensible chain, 4000 segments, against the same chain with k -> infinity); the amplitude by about (A/L)^2 = 1e-4 or less\n",
            TOP[0],
            TOP[1],
            m.k,
            m.gamma,
            m.youngs_modulus,
            self.periods,
            dt_ladder_grid(self.quick),
            cfl_dt(dt_ladder_grid(self.quick)),
            wave_speed(&m)
        )
    }

    /// The printed part of the report.
    pub fn to_text(&self) -> String {
        format!(
            "Yarn against a physical oracle (study took {:.1} s)\n\n{}\n{}\nCheapest setting per error level\n\n{}",
            self.elapsed,
            self.setup(),
            self.runs_table().to_text(),
            self.summary_table().to_text()
        )
    }
}
