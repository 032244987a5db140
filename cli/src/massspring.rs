//! Mass-spring scenes (wire, cloth, three-particle) in the CLI: the choice of
//! integrator, a fixed-step wrapper for the frame loop, and the diagnostics
//! the summary table, CSV and recording show.

use yarnsim::massspring::{
    Integrator, IntegratorOptions, MassSpringError, MassSpringScene, Simulation, V3,
};

use crate::driver::Stepper;
use crate::error::CliError;

/// The integrator used when `--integrator` is not given.
pub const DEFAULT_INTEGRATOR: Integrator = Integrator::BackwardEuler;

/// Integrator settings from the command line: `--integrator NAME` and
/// repeated `--option KEY=VALUE`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct IntegratorArgs {
    pub integrator: Option<String>,
    pub options: Vec<String>,
    /// Run an explicit integrator with a `dt` above its stability bound.
    pub allow_unstable: bool,
}

impl IntegratorArgs {
    /// Whether nothing was given (the only valid case for yarn scenes).
    pub fn is_empty(&self) -> bool {
        self.integrator.is_none() && self.options.is_empty() && !self.allow_unstable
    }

    /// Parses the integrator name and options.
    pub fn parse(&self) -> Result<(Integrator, IntegratorOptions), CliError> {
        let integrator = match &self.integrator {
            Some(name) => name.parse::<Integrator>().map_err(CliError::Usage)?,
            None => DEFAULT_INTEGRATOR,
        };
        let mut options = IntegratorOptions::default();
        for kv in &self.options {
            let (k, v) = kv.split_once('=').ok_or_else(|| {
                CliError::Usage(format!(
                    "--option {kv:?}: expected KEY=VALUE; keys: {}",
                    IntegratorOptions::KEYS.join(", ")
                ))
            })?;
            options.set(k.trim(), v.trim()).map_err(CliError::Usage)?;
        }
        Ok((integrator, options))
    }
}

fn ms_error(e: MassSpringError) -> CliError {
    match e {
        MassSpringError::Scene(s) => CliError::Scene(s),
        MassSpringError::Unsupported { .. } | MassSpringError::Argument(_) => {
            CliError::Usage(e.to_string())
        }
        MassSpringError::Solver { .. } | MassSpringError::Diverged { .. } => {
            CliError::Failed(e.to_string())
        }
    }
}

/// Refuses a step `h` above the stability bound of an explicit integrator
/// (forward or symplectic Euler, bound of the system linearised at its
/// initial state), unless `allow` is set; then it warns.
pub fn check_stability(sim: &Simulation, h: f64, allow: bool) -> Result<(), CliError> {
    let (Some(st), true) = (sim.stability(), sim.integrator().is_explicit()) else {
        return Ok(());
    };
    let bound = match sim.integrator() {
        Integrator::ForwardEuler => st.forward_euler,
        _ => st.symplectic_euler,
    };
    if h <= bound * (1.0 + 1e-9) {
        return Ok(());
    }
    let name = sim.integrator();
    let why = if bound > 0.0 {
        format!(
            "the step {h:.4e} s is {:.1}x the stability bound of {name} for this scene, \
             {bound:.4e} s (linearised at the initial state)",
            h / bound
        )
    } else {
        format!(
            "{name} is unstable at every step size here: the springs have no damping \
             (its bound b/k is 0)"
        )
    };
    if allow {
        eprintln!("warning: {why}; running anyway (--allow-unstable)");
        Ok(())
    } else {
        Err(CliError::Usage(format!(
            "{why}; it would blow up. Use a smaller dt, leave dt out (the step is then a \
             CFL fraction of the bound), choose an implicit integrator, or pass --allow-unstable \
             to run it anyway"
        )))
    }
}

/// A mass-spring simulation advanced in equal steps of `h = frame_time / n`,
/// `n` the number of steps of the driver's step size per frame, so frames
/// land exactly on step boundaries (as in [`Simulation::step_frame`]).
pub struct MassSpringRun {
    /// The scene's name.
    pub name: String,
    pub sim: Simulation,
    /// The step in s.
    pub h: f64,
    /// Steps per frame.
    pub steps_per_frame: u64,
    steps: u64,
    t0: f64,
}

impl MassSpringRun {
    /// Builds the simulation of `layout` with the integrator from `args`.
    /// Refuses an explicit integrator whose `--option dt` lies above its
    /// stability bound (unless `args.allow_unstable`), and says on stderr
    /// when the step actually taken differs from the `dt` asked for.
    pub fn new(layout: &MassSpringScene, args: &IntegratorArgs) -> Result<Self, CliError> {
        let (integrator, options) = args.parse()?;
        let asked_dt = options.dt;
        let sim = Simulation::new(layout, integrator, options).map_err(ms_error)?;
        let ft = sim.system().frame_time;
        let n = (ft / sim.dt() * (1.0 - 1e-12)).ceil().max(1.0);
        let h = ft / n;
        if let Some(dt) = asked_dt {
            if dt > ft {
                eprintln!(
                    "warning: --option dt={dt} is longer than a frame of this scene; \
                     clamped to the frame time {ft} s"
                );
            } else if h < dt * (1.0 - 1e-9) {
                eprintln!(
                    "note: --option dt={dt} rounded down to {h} s, so that {n} equal steps fill a frame of {ft} s"
                );
            }
            check_stability(&sim, h, args.allow_unstable)?;
        }
        let t0 = sim.time();
        Ok(MassSpringRun {
            name: layout.name.clone(),
            sim,
            h,
            steps_per_frame: n as u64,
            steps: 0,
            t0,
        })
    }

    /// Simulated time after `steps` steps.
    fn clock(&self, steps: u64) -> f64 {
        let n = self.steps_per_frame;
        let ft = self.sim.system().frame_time;
        let (frame, k) = (steps / n, steps % n);
        self.t0 + frame as f64 * ft + k as f64 * self.h
    }

    /// Simulated time now.
    pub fn time(&self) -> f64 {
        self.sim.time()
    }

    /// Diagnostics of the current state.
    pub fn diagnostics(&self) -> MsDiagnostics {
        MsDiagnostics::of(&self.sim, self.steps)
    }
}

impl Stepper for MassSpringRun {
    fn step(&mut self) -> Result<(), CliError> {
        // The clock of Simulation::step_frame: frame start plus k steps (no
        // drift from summing h, and the same bits as the library's frames).
        self.sim.state_mut().t = self.clock(self.steps);
        self.sim.step(self.h).map_err(ms_error)?;
        self.steps += 1;
        self.sim.state_mut().t = self.clock(self.steps);
        Ok(())
    }
    fn steps(&self) -> u64 {
        self.steps
    }
    fn num_particles(&self) -> usize {
        self.sim.system().len()
    }
    fn time(&self) -> f64 {
        MassSpringRun::time(self)
    }
    fn check_finite(&self) -> Result<(), CliError> {
        let finite = |v: &[V3]| v.iter().all(|x| x.iter().all(|c| c.is_finite()));
        let e = self.sim.energies();
        let energy = e.kinetic + e.elastic + e.gravity;
        if finite(self.sim.positions()) && finite(self.sim.velocities()) && energy.is_finite() {
            Ok(())
        } else {
            Err(CliError::Failed(format!(
                "the simulation diverged: its state or energy is no longer finite after step {} (t = {:.6} s)",
                self.steps,
                self.time()
            )))
        }
    }
}

/// Summary quantities of a mass-spring state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MsDiagnostics {
    pub time: f64,
    pub steps: u64,
    pub kinetic_energy: f64,
    pub elastic_energy: f64,
    /// `-sum m g . x`.
    pub gravity_energy: f64,
    /// `sum m v` over all particles (driven and pinned ones included).
    pub momentum: V3,
    /// `sum x x m v` about the origin.
    pub angular_momentum: V3,
    /// Largest `|l / l0 - 1|` over the springs.
    pub max_strain: f64,
    pub center_of_mass: V3,
}

impl MsDiagnostics {
    /// The diagnostics of `sim` after `steps` steps.
    pub fn of(sim: &Simulation, steps: u64) -> Self {
        let e = sim.energies();
        let sys = sim.system();
        let (mut p, mut l, mut mx, mut m) = (V3::zeros(), V3::zeros(), V3::zeros(), 0.0);
        for ((x, v), &mi) in sim
            .positions()
            .iter()
            .zip(sim.velocities())
            .zip(&sys.masses)
        {
            p += v * mi;
            l += x.cross(&(v * mi));
            mx += x * mi;
            m += mi;
        }
        MsDiagnostics {
            time: sim.time(),
            steps,
            kinetic_energy: e.kinetic,
            elastic_energy: e.elastic,
            gravity_energy: e.gravity,
            momentum: p,
            angular_momentum: l,
            max_strain: sim.max_strain(),
            center_of_mass: if m > 0.0 { mx / m } else { V3::zeros() },
        }
    }
}

/// `|l / l0 - 1|` of every spring now.
pub fn spring_strains(sim: &Simulation) -> Vec<f64> {
    let x = sim.positions();
    sim.system()
        .springs
        .iter()
        .map(|s| ((x[s.a] - x[s.b]).norm() / s.rest_length - 1.0).abs())
        .collect()
}

/// Signed `l / l0` of every spring now (1 = rest length).
pub fn spring_stretches(sim: &Simulation) -> Vec<f64> {
    let x = sim.positions();
    sim.system()
        .springs
        .iter()
        .map(|s| (x[s.a] - x[s.b]).norm() / s.rest_length)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use yarnsim::massspring::scenes;

    #[test]
    fn integrator_args_parse_names_and_options() {
        let a = IntegratorArgs {
            integrator: Some("symplectic_euler".into()),
            options: vec!["cfl=0.5".into()],
            ..Default::default()
        };
        let (i, o) = a.parse().unwrap();
        assert_eq!(i, Integrator::SymplecticEuler);
        assert_eq!(o.cfl_number, Some(0.5));
        assert_eq!(
            IntegratorArgs::default().parse().unwrap().0,
            DEFAULT_INTEGRATOR
        );
        for bad in [
            IntegratorArgs {
                integrator: Some("rk4".into()),
                ..Default::default()
            },
            IntegratorArgs {
                options: vec!["cfl".into()],
                ..Default::default()
            },
            IntegratorArgs {
                options: vec!["warp=9".into()],
                ..Default::default()
            },
        ] {
            assert!(matches!(bad.parse(), Err(CliError::Usage(_))), "{bad:?}");
        }
    }

    #[test]
    fn explicit_steps_above_the_stability_bound_are_refused() {
        let args = |dt: &str, allow: bool| IntegratorArgs {
            integrator: Some("symplectic-euler".into()),
            options: vec![format!("dt={dt}")],
            allow_unstable: allow,
        };
        let sim = Simulation::new(
            &scenes::wire(),
            Integrator::SymplecticEuler,
            IntegratorOptions::default(),
        )
        .unwrap();
        let bound = sim.stability().unwrap().symplectic_euler;
        // Below the bound: accepted.
        assert!(
            MassSpringRun::new(&scenes::wire(), &args(&format!("{}", 0.5 * bound), false)).is_ok()
        );
        // 10x above: refused, naming the step, the factor and the bound.
        let Err(CliError::Usage(m)) =
            MassSpringRun::new(&scenes::wire(), &args(&format!("{}", 10.0 * bound), false))
        else {
            panic!("accepted an unstable step")
        };
        // (h = frame / n for a whole n, a little under 10x the bound)
        assert!(
            m.contains("x the stability bound of symplectic-euler"),
            "{m}"
        );
        assert!(m.contains(&format!("{bound:.4e}")), "{m}");
        assert!(m.contains("--allow-unstable"), "{m}");
        // Unless the user insists.
        assert!(
            MassSpringRun::new(&scenes::wire(), &args(&format!("{}", 10.0 * bound), true)).is_ok()
        );
    }

    #[test]
    fn stepping_a_frame_matches_the_library_frame() {
        // The CLI's fixed-step wrapper and Simulation::step_frame take the same
        // steps, so they must give the same bits.
        let args = IntegratorArgs::default();
        let mut run = MassSpringRun::new(&scenes::wire(), &args).unwrap();
        let (i, o) = args.parse().unwrap();
        let mut lib = Simulation::new(&scenes::wire(), i, o).unwrap();
        for frame in 1..=3 {
            let report = lib.step_frame().unwrap();
            for _ in 0..report.steps {
                run.step().unwrap();
            }
            assert_eq!(run.steps(), frame * report.steps as u64);
            assert_eq!(run.sim.positions(), lib.positions());
            assert_eq!(run.time(), lib.time());
        }
    }
}
