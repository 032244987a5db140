//! Scene-independent time integrators (the course notes' "driver" side). Each one
//! advances a [`State`] of a [`System`] by one step `h`; the frame loop and
//! the choice of `h` live in `crate::massspring::driver`.
//!
//! * [`Integrator::ForwardEuler`], [`Integrator::SymplecticEuler`]: explicit,
//!   step bounded by [`stability::StabilityInfo`].
//! * [`Integrator::BackwardEuler`], [`Integrator::Trapezoidal`]: the velocity
//!   system solved by PCG (Jacobi or IC(0)), see `implicit`.
//! * [`Integrator::ChebyshevJacobi`]: Wang 2015's optimisation form of
//!   backward Euler, Jacobi iterations with Chebyshev acceleration.
//! * [`Integrator::Pbd`]: Müller et al. 2007's position-based model (inertia, gravity
//!   and strain limiting, no spring forces).

/// `Display` (the value's `name()`) and `FromStr` of a choice named on the
/// command line: any case, `_` for `-`, each value's spellings as listed;
/// an unknown name is refused naming `what` and every canonical name
/// (`ALL`). A macro: it writes the two trait impls of each type.
macro_rules! named_choice {
    ($ty:ident, $what:literal, { $($($spelling:literal)|+ => $value:ident,)+ }) => {
        impl fmt::Display for $ty {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(self.name())
            }
        }

        impl FromStr for $ty {
            type Err = String;
            fn from_str(s: &str) -> Result<Self, String> {
                match s.to_ascii_lowercase().replace('_', "-").as_str() {
                    $($($spelling)|+ => Ok($ty::$value),)+
                    _ => Err(format!(
                        concat!("unknown ", $what, " {:?}; known: {}"),
                        s,
                        $ty::ALL.map(|v| v.name()).join(", ")
                    )),
                }
            }
        }
    };
}

pub(crate) mod chebyshev;
pub(crate) mod explicit;
pub(crate) mod implicit;
pub(crate) mod pbd;
pub mod stability;

use std::fmt;
use std::str::FromStr;

use super::linear::PreconditionerKind;
use crate::scene::massspring::{System, V3};
pub use pbd::StrainSolver;

/// Positions, velocities and time of a simulation.
#[derive(Clone, Debug, PartialEq)]
pub struct State {
    /// Positions in m.
    pub x: Vec<V3>,
    /// Velocities in m/s.
    pub v: Vec<V3>,
    /// Time in s.
    pub t: f64,
}

impl State {
    /// The system's initial state at `t = 0` (kinematic particles placed).
    pub fn initial(sys: &System) -> State {
        let mut s = State {
            x: sys.positions.clone(),
            v: sys.velocities.clone(),
            t: 0.0,
        };
        set_kinematics(sys, 0.0, &mut s.x, &mut s.v);
        s
    }
}

/// Puts pinned and driven particles where they are prescribed at time `t`.
pub fn set_kinematics(sys: &System, t: f64, x: &mut [V3], v: &mut [V3]) {
    for (i, k) in sys.kinematics.iter().enumerate() {
        if let Some((p, vel)) = k.at(t) {
            x[i] = p;
            v[i] = vel;
        }
    }
}

/// The time integration scheme: one argument switches it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Integrator {
    /// `x += h v; v += h f(x, v) / m`, step from the CFL bound (course notes).
    ForwardEuler,
    /// `v += h f(x, v) / m; x += h v`.
    SymplecticEuler,
    /// Trapezoidal rule, linearised (one Newton step) or iterated.
    Trapezoidal,
    /// Backward Euler, linearised (Baraff-Witkin 1998) or iterated.
    BackwardEuler,
    /// Wang 2015: backward Euler as a minimisation, Chebyshev-accelerated Jacobi.
    ChebyshevJacobi,
    /// Müller et al. 2007: position-based dynamics with strain limiting (Provot 1995).
    Pbd,
}

impl Integrator {
    /// Every integrator, in documentation order.
    pub const ALL: [Integrator; 6] = [
        Integrator::ForwardEuler,
        Integrator::SymplecticEuler,
        Integrator::Trapezoidal,
        Integrator::BackwardEuler,
        Integrator::ChebyshevJacobi,
        Integrator::Pbd,
    ];

    /// The canonical name (what [`FromStr`] reads and [`fmt::Display`] writes).
    pub fn name(self) -> &'static str {
        match self {
            Integrator::ForwardEuler => "forward-euler",
            Integrator::SymplecticEuler => "symplectic-euler",
            Integrator::Trapezoidal => "trapezoidal",
            Integrator::BackwardEuler => "backward-euler",
            Integrator::ChebyshevJacobi => "chebyshev-jacobi",
            Integrator::Pbd => "pbd",
        }
    }

    /// The canonical names of every integrator, in documentation order.
    pub fn names() -> [&'static str; 6] {
        Integrator::ALL.map(|i| i.name())
    }

    /// One line describing the scheme.
    pub fn description(self) -> &'static str {
        match self {
            Integrator::ForwardEuler => {
                "explicit Euler, step cfl x the computed stability bound (course notes); needs spring damping"
            }
            Integrator::SymplecticEuler => {
                "semi-implicit Euler (velocity first), step cfl x the bound 2/w_max"
            }
            Integrator::Trapezoidal => {
                "trapezoidal rule, velocity system by PCG with IC(0) or Jacobi (course notes), 2nd order"
            }
            Integrator::BackwardEuler => {
                "backward Euler, velocity system by PCG (Baraff-Witkin 1998), 1st order, unconditionally stable"
            }
            Integrator::ChebyshevJacobi => {
                "backward Euler as a minimisation, Jacobi iterations with Chebyshev acceleration (Wang 2015)"
            }
            Integrator::Pbd => {
                "position-based dynamics: inertia + gravity, then strain limiting (Müller et al. 2007)"
            }
        }
    }

    /// Whether the step is limited by the explicit stability bound.
    pub fn is_explicit(self) -> bool {
        matches!(self, Integrator::ForwardEuler | Integrator::SymplecticEuler)
    }
}

named_choice!(Integrator, "integrator", {
    "forward-euler" | "fe" | "explicit-euler" | "euler" => ForwardEuler,
    "symplectic-euler" | "se" | "semi-implicit-euler" => SymplecticEuler,
    "trapezoidal" | "trap" | "trapezoid" => Trapezoidal,
    "backward-euler" | "be" | "implicit-euler" => BackwardEuler,
    "chebyshev-jacobi" | "chebyshev" | "jacobi" | "optimization" | "optimisation" => ChebyshevJacobi,
    "pbd" | "position-based" | "strain-limiting" => Pbd,
});

/// Options of the integrators. Every field has a default; the CLI can set
/// them by name with [`IntegratorOptions::set`].
#[derive(Clone, Debug, PartialEq)]
pub struct IntegratorOptions {
    /// Step size in s; overrides the scene's `time_step` and the CFL choice.
    pub dt: Option<f64>,
    /// Fraction of the stability bound for the explicit schemes (default: the scene's).
    pub cfl_number: Option<f64>,
    /// CG preconditioner of the implicit schemes (default IC(0)).
    pub preconditioner: PreconditionerKind,
    /// Relative residual at which CG stops (default 1e-10).
    pub cg_tolerance: f64,
    /// CG iteration cap (default 1000).
    pub cg_max_iterations: usize,
    /// Newton (chord) iterations of the implicit schemes; 1 = the linearised
    /// step of the course notes and Baraff-Witkin (default 1).
    pub newton_iterations: usize,
    /// Newton stops when the residual is below this fraction of `|h f|` (default 1e-10).
    pub newton_tolerance: f64,
    /// Chebyshev spectral-radius estimate rho (default 0.995, Wang 2015); 0 = plain Jacobi.
    pub rho: f64,
    /// Jacobi iterations per step of `chebyshev-jacobi` (default 32, Wang 2015).
    pub iterations: usize,
    /// Strain limit; overrides the scene's `time.strain_limit`.
    pub strain_limit: Option<f64>,
    /// Passes of the strain-limiting projection (default 32, as the Unity cloth scripts).
    pub strain_iterations: usize,
    /// How a strain-limiting pass visits the springs (default Jacobi, as the Unity cloth scripts).
    pub strain_solver: StrainSolver,
}

impl Default for IntegratorOptions {
    fn default() -> Self {
        IntegratorOptions {
            dt: None,
            cfl_number: None,
            preconditioner: PreconditionerKind::Ic0,
            cg_tolerance: 1e-10,
            cg_max_iterations: 1000,
            newton_iterations: 1,
            newton_tolerance: 1e-10,
            rho: 0.995,
            iterations: 32,
            strain_limit: None,
            strain_iterations: 32,
            strain_solver: StrainSolver::Jacobi,
        }
    }
}

impl IntegratorOptions {
    /// The option names [`IntegratorOptions::set`] knows.
    pub const KEYS: [&'static str; 12] = [
        "dt",
        "cfl",
        "preconditioner",
        "cg-tol",
        "cg-max-iter",
        "newton-iter",
        "newton-tol",
        "rho",
        "iterations",
        "strain-limit",
        "strain-iterations",
        "strain-solver",
    ];

    /// Sets one option from text, e.g. `set("rho", "0.99")`,
    /// `set("preconditioner", "jacobi")`. Underscores and dashes are equivalent.
    pub fn set(&mut self, key: &str, value: &str) -> Result<(), String> {
        let k = key.to_ascii_lowercase().replace('_', "-");
        let num = |lo: f64, hi: f64| -> Result<f64, String> {
            let v: f64 = value
                .trim()
                .parse()
                .map_err(|_| format!("option {key}: {value:?} is not a number"))?;
            if v.is_finite() && v >= lo && v <= hi {
                Ok(v)
            } else {
                Err(format!("option {key}: {v} is outside [{lo}, {hi}]"))
            }
        };
        let count = |lo: usize| -> Result<usize, String> {
            let v: usize = value
                .trim()
                .parse()
                .map_err(|_| format!("option {key}: {value:?} is not a whole number"))?;
            if v >= lo {
                Ok(v)
            } else {
                Err(format!("option {key}: must be at least {lo}"))
            }
        };
        match k.as_str() {
            "dt" => {
                let v: f64 = value
                    .trim()
                    .parse()
                    .map_err(|_| format!("option {key}: {value:?} is not a number"))?;
                if !(v > 0.0 && v.is_finite()) {
                    return Err(format!(
                        "option {key}: must be a positive, finite step in seconds, got {}",
                        value.trim()
                    ));
                }
                self.dt = Some(v)
            }
            "cfl" | "cfl-number" => {
                let v = num(0.0, 1.0)?;
                if v == 0.0 {
                    return Err("option cfl: must be > 0".into());
                }
                self.cfl_number = Some(v)
            }
            "preconditioner" | "pc" => self.preconditioner = value.parse()?,
            "cg-tol" | "cg-tolerance" => self.cg_tolerance = num(0.0, 1.0)?,
            "cg-max-iter" | "cg-max-iterations" => self.cg_max_iterations = count(1)?,
            "newton-iter" | "newton-iterations" => self.newton_iterations = count(1)?,
            "newton-tol" | "newton-tolerance" => self.newton_tolerance = num(0.0, 1.0)?,
            "rho" => {
                let v = num(0.0, 1.0)?;
                if v >= 1.0 {
                    return Err("option rho: must be < 1".into());
                }
                self.rho = v
            }
            "iterations" | "jacobi-iterations" => self.iterations = count(1)?,
            "strain-limit" => {
                let v = num(0.0, 1.0)?;
                if v >= 1.0 {
                    return Err("option strain-limit: must be < 1".into());
                }
                self.strain_limit = Some(v)
            }
            "strain-iterations" => self.strain_iterations = count(0)?,
            "strain-solver" => self.strain_solver = value.parse()?,
            _ => {
                return Err(format!(
                    "unknown integrator option {key:?}; known: {}",
                    Self::KEYS.join(", ")
                ))
            }
        }
        Ok(())
    }
}

/// What one step did (solver effort and post-passes).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct StepStats {
    /// Step size in s.
    pub dt: f64,
    /// CG iterations summed over the step's linear solves.
    pub cg_iterations: usize,
    /// Linear solves (Newton iterations) of the step.
    pub linear_solves: usize,
    /// Last CG relative residual.
    pub cg_residual: f64,
    /// Relative nonlinear residual after the last Newton iteration (NaN if not computed).
    pub newton_residual: f64,
    /// Gradient norm after the last Chebyshev-Jacobi iteration (NaN otherwise).
    pub gradient_norm: f64,
    /// Strain-limiting passes run.
    pub strain_passes: usize,
    /// Largest `|l/l0 - 1|` right after strain limiting (NaN if no limiting).
    pub strain_after_limiting: f64,
    /// Particles projected out of a sphere.
    pub collisions: usize,
}

impl StepStats {
    pub(crate) fn new(dt: f64) -> StepStats {
        StepStats {
            dt,
            cg_residual: f64::NAN,
            newton_residual: f64::NAN,
            gradient_norm: f64::NAN,
            strain_after_limiting: f64::NAN,
            ..Default::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for i in Integrator::ALL {
            assert_eq!(i.name().parse::<Integrator>().unwrap(), i);
        }
        assert!("leapfrog".parse::<Integrator>().is_err());
        assert_eq!(
            "chebyshev".parse::<Integrator>().unwrap(),
            Integrator::ChebyshevJacobi
        );
        assert_eq!(Integrator::names().len(), Integrator::ALL.len());
        let e = "leapfrog".parse::<Integrator>().unwrap_err();
        assert!(Integrator::names().iter().all(|n| e.contains(n)), "{e}");
    }

    /// The named choices read their canonical names and aliases in any
    /// case with `_` for `-`, write their canonical names, and refuse an
    /// unknown name naming the choice and every canonical name (exact
    /// messages).
    #[test]
    fn named_choices_parse_write_and_refuse() {
        for s in StrainSolver::ALL {
            assert_eq!(s.to_string().parse::<StrainSolver>().unwrap(), s);
        }
        assert_eq!("GS".parse::<StrainSolver>(), Ok(StrainSolver::GaussSeidel));
        assert_eq!(
            "Gauss_Seidel".parse::<StrainSolver>(),
            Ok(StrainSolver::GaussSeidel)
        );
        assert_eq!(
            "sor".parse::<StrainSolver>().unwrap_err(),
            "unknown strain solver \"sor\"; known: jacobi, gauss-seidel"
        );
        assert_eq!(
            "Backward_Euler".parse::<Integrator>(),
            Ok(Integrator::BackwardEuler)
        );
        assert_eq!(Integrator::Pbd.to_string(), "pbd");
        assert_eq!(
            "leapfrog".parse::<Integrator>().unwrap_err(),
            "unknown integrator \"leapfrog\"; known: forward-euler, symplectic-euler, \
             trapezoidal, backward-euler, chebyshev-jacobi, pbd"
        );
    }

    #[test]
    fn options_parse_and_reject() {
        let mut o = IntegratorOptions::default();
        o.set("rho", "0.9").unwrap();
        o.set("preconditioner", "jacobi").unwrap();
        o.set("cg_tol", "1e-8").unwrap();
        assert_eq!(o.rho, 0.9);
        assert_eq!(o.preconditioner, PreconditionerKind::Jacobi);
        assert!(o.set("rho", "1.5").is_err());
        assert!(o.set("bogus", "1").is_err());
        assert!(o.set("iterations", "-3").is_err());
    }
}
