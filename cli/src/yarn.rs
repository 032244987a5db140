//! Yarn (MPM) scenes in the CLI: how `run`, `record` and `bench` start one
//! (the mass-spring flags refused with a pointer to the scene field, a fixed
//! `time.dt` checked against the stable bound) and how a divergence is
//! reported (with the bound and `time.dt = "auto"`).
//!
//! The bound is the library's, [`YarnSim::stable_dt`] (the one the FMU
//! warns with at initialization): `dx / (c + |v|max)` with the fastest
//! elastic wave `c` and, with bending, the flexural bound, see
//! [`yarnsim::mpm::driver::timestep`]. Measured on `yarn-small`, the largest stable
//! substep lies at 1.3 to 1.8 times it when `k`, `E`, friction, gravity or
//! the attractor change (docs/performance/stress.md), so a
//! step above the bound is warned about and one above [`REFUSE_FACTOR`]
//! times it, beyond all of those, is refused. (A stiff shear `gamma` is the
//! exception: there the bound is pessimistic, up to 10x, and
//! `--allow-unstable` runs such a step.)

use yarnsim::mpm::driver::timestep::{self, WITHOUT_PLASTICITY};
use yarnsim::scene::{Integrator, YarnScene};
use yarnsim::{SimError, YarnSim};

use crate::driver::Stepper;
use crate::error::CliError;

/// A fixed `time.dt` above this multiple of the stable bound is refused
/// without `--allow-unstable`: the largest stable substep measured is at
/// most 1.83x the bound outside a stiff shear (see the module documentation).
pub const REFUSE_FACTOR: f64 = 2.0;

/// How to ask for the adaptive step, in the file and on the command line.
const AUTO: &str = "set time.dt = \"auto\" (--set time.dt=auto)";

/// The mass-spring flags given to a `run`, `record` or `bench` command,
/// and `--allow-unstable`, which both kinds of scene take.
#[derive(Clone, Copy, Debug, Default)]
pub struct YarnFlags<'a> {
    /// `--integrator NAME`.
    pub integrator: Option<&'a str>,
    /// The `--option KEY=VALUE` arguments.
    pub options: &'a [String],
    /// `--allow-unstable`.
    pub allow_unstable: bool,
}

/// Starts a yarn scene for `run`, `record` or `bench`: refuses the
/// mass-spring flags (naming the scene field that does their job), builds
/// the simulation and checks a fixed substep against the stable bound:
/// above it a warning on stderr, above [`REFUSE_FACTOR`] times it an error
/// unless `flags.allow_unstable`.
pub fn start(scene: &YarnScene, flags: YarnFlags) -> Result<YarnSim, CliError> {
    refuse_massspring_flags(flags)?;
    let sim = YarnSim::new(scene)?;
    for warning in scene.warnings() {
        eprintln!("warning: {warning}");
    }
    if let Some(dt) = scene.time.dt.fixed() {
        if let Some(warning) = check_step(dt, sim.stable_dt(), flags.allow_unstable)? {
            eprintln!("warning: {warning}");
        }
    }
    Ok(sim)
}

/// `--integrator` and `--option` belong to mass-spring scenes; a yarn
/// scene chooses its integrator with the scene field `time.integrator`.
pub fn refuse_massspring_flags(flags: YarnFlags) -> Result<(), CliError> {
    let names = Integrator::NAMES.join(", ");
    if let Some(name) = flags.integrator {
        let set = if Integrator::NAMES.contains(&name) {
            format!("--set time.integrator={name}")
        } else {
            "--set time.integrator=NAME".into()
        };
        return Err(CliError::Usage(format!(
            "--integrator applies to mass-spring scenes; a yarn scene takes its integrator from \
             the scene field time.integrator: {set} (one of {names})"
        )));
    }
    if let Some(option) = flags.options.first() {
        return Err(CliError::Usage(format!(
            "--option {option} applies to mass-spring scenes; set a yarn scene's fields with \
             --set KEY=VALUE, e.g. --set time.dt=auto or --set time.integrator=implicit"
        )));
    }
    Ok(())
}

/// The verdict on a fixed substep `dt` against the stable `bound` (s):
/// nothing at or below it, a warning above it (also above
/// [`REFUSE_FACTOR`] times it when `allow`), else the refusal.
pub fn check_step(dt: f64, bound: f64, allow: bool) -> Result<Option<String>, CliError> {
    if bound.is_nan() || dt <= bound * (1.0 + 1e-9) {
        return Ok(None);
    }
    let ratio = dt / bound;
    let over = format!(
        "substep dt = {dt} s exceeds the stability bound {bound:.6e} s of this yarn scene \
         ({ratio:.1}x)"
    );
    if ratio <= REFUSE_FACTOR {
        return Ok(Some(format!(
            "{over}; the run may diverge; {AUTO} to step within the bound"
        )));
    }
    if allow {
        return Ok(Some(format!("{over}; running anyway (--allow-unstable)")));
    }
    Err(CliError::Usage(format!(
        "{over}, more than {REFUSE_FACTOR}x: it would diverge; {AUTO} or a dt below the bound, \
         or pass --allow-unstable to run it anyway"
    )))
}

/// A failed substep of `sim` as the CLI reports it: a divergence with the
/// hint to the stable step, or to the return mapping where the explicit
/// step was within its bound and the scene runs without it
/// ([`YarnSim::diverges_without_plasticity`]); other errors as they are.
pub fn explain(sim: &YarnSim, e: SimError) -> CliError {
    if !matches!(e, SimError::NonFinite { .. }) {
        return CliError::Sim(e);
    }
    let sc = sim.scene();
    if sim.diverges_without_plasticity() {
        let hint = format!("{WITHOUT_PLASTICITY} (--set material.plasticity=true)");
        return CliError::Diverged { error: e, hint };
    }
    let hint = match sc.time.dt.fixed() {
        None => format!(
            "dt = \"auto\" stepped at time.safety = {} of the stability bound; a lower one \
             (--set time.safety=0.4) takes shorter substeps",
            sc.time.safety.unwrap_or(yarnsim::scene::DEFAULT_SAFETY)
        ),
        Some(dt) if sim.is_implicit() => format!(
            "the substep dt = {dt} s of integrator = \"{}\" must keep every particle within one \
             grid cell; {AUTO}, or a smaller dt",
            sc.time.integrator.name()
        ),
        Some(dt) => {
            // The bound of the scene at rest: the state that diverged has
            // no bound left to compute.
            let bound =
                timestep::explicit_stable_dt(&sc.material, sc.time.axial, sc.dx(), 0.0, 1.0);
            let ratio = dt / bound;
            let relation = if ratio > 1.0 + 1e-9 {
                format!("{ratio:.1}x the stability bound {bound:.6e} s of this yarn scene at rest")
            } else {
                format!(
                    "within the stability bound {bound:.6e} s of this yarn scene at rest, which \
                     falls as the yarns speed up"
                )
            };
            format!("the substep dt = {dt} s is {relation}; {AUTO}, or a smaller dt")
        }
    };
    CliError::Diverged { error: e, hint }
}

impl Stepper for YarnSim {
    fn step(&mut self) -> Result<(), CliError> {
        YarnSim::step(self).map_err(|e| explain(self, e))
    }
    fn steps(&self) -> u64 {
        YarnSim::steps(self)
    }
    fn num_particles(&self) -> usize {
        self.particles().len()
    }
    fn time(&self) -> f64 {
        YarnSim::time(self)
    }
    fn step_toward(&mut self, until: f64) -> Result<bool, CliError> {
        YarnSim::step_toward(self, until).map_err(|e| explain(self, e))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_step_is_passed_warned_or_refused_by_its_ratio_to_the_bound() {
        assert_eq!(check_step(1e-5, 1e-5, false).unwrap(), None);
        assert_eq!(check_step(0.5e-5, 1e-5, false).unwrap(), None);
        let w = check_step(1.5e-5, 1e-5, false).unwrap().unwrap();
        assert_eq!(
            w,
            "substep dt = 0.000015 s exceeds the stability bound 1.000000e-5 s of this yarn \
             scene (1.5x); the run may diverge; set time.dt = \"auto\" (--set time.dt=auto) to \
             step within the bound"
        );
        let e = check_step(3e-5, 1e-5, false).unwrap_err();
        assert_eq!(e.exit_code(), 2);
        assert_eq!(
            e.to_string(),
            "substep dt = 0.00003 s exceeds the stability bound 1.000000e-5 s of this yarn \
             scene (3.0x), more than 2x: it would diverge; set time.dt = \"auto\" (--set \
             time.dt=auto) or a dt below the bound, or pass --allow-unstable to run it anyway"
        );
        let w = check_step(3e-5, 1e-5, true).unwrap().unwrap();
        assert!(
            w.ends_with("(3.0x); running anyway (--allow-unstable)"),
            "{w}"
        );
    }

    #[test]
    fn the_integrator_flag_points_to_the_scene_field() {
        let e = refuse_massspring_flags(YarnFlags {
            integrator: Some("implicit"),
            ..Default::default()
        })
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "--integrator applies to mass-spring scenes; a yarn scene takes its integrator \
             from the scene field time.integrator: --set time.integrator=implicit (one of \
             explicit, implicit, implicit-vertices, midpoint-vertices)"
        );
        let e = refuse_massspring_flags(YarnFlags {
            integrator: Some("pbd"),
            ..Default::default()
        })
        .unwrap_err();
        assert!(
            e.to_string()
                .contains("--set time.integrator=NAME (one of explicit, implicit,"),
            "{e}"
        );
        assert!(refuse_massspring_flags(YarnFlags {
            allow_unstable: true,
            ..Default::default()
        })
        .is_ok());
    }
}
