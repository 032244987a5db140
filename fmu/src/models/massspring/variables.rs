//! The MassSpring FMU's variables: the value references, the static table
//! (`MASS_SPRING_VARIABLES`) and the per-particle outputs, the output
//! dependencies, the GUID and the description its `modelDescription.xml`
//! is written from, all derived from the bundled layout.

use yarnsim::massspring::{Integrator, MassSpringScene};

use super::arrays::positions_array;
use crate::model_description::{
    output, var, Causality::*, Description, Start, VarSpec, VarType, Variable,
};

/// The FMI model identifier of a mass-spring FMU.
pub const MODEL_IDENTIFIER: &str = "MassSpring";

/// Bumped whenever the variable layout changes; part of the GUID.
pub const INTERFACE_VERSION: u32 = 2;

/// The integrator an instance uses unless the `integrator` parameter says
/// otherwise (the CLI's default too).
pub const DEFAULT_INTEGRATOR: Integrator = Integrator::BackwardEuler;

// Value references, unique across all types.
pub const VR_GRAVITY_X: u32 = 1;
pub const VR_GRAVITY_Y: u32 = 2;
pub const VR_GRAVITY_Z: u32 = 3;
pub const VR_DT: u32 = 10;
pub const VR_INTEGRATOR: u32 = 11; // String
pub const VR_KINETIC_ENERGY: u32 = 100;
pub const VR_ELASTIC_ENERGY: u32 = 101;
pub const VR_GRAVITY_ENERGY: u32 = 102;
pub const VR_TOTAL_ENERGY: u32 = 103;
pub const VR_MAX_STRAIN: u32 = 104;
/// The substep count, common to every model ([`crate::model_description::COMMON_VARIABLES`]).
pub use crate::model_description::VR_SUBSTEPS;
/// `particle[i].x` has `VR_PARTICLE_BASE + 3 i`, then `.y`, `.z`.
pub const VR_PARTICLE_BASE: u32 = 1000;

/// Number of particles the layout creates (fixes the outputs).
pub fn num_particles(layout: &MassSpringScene) -> Result<usize, String> {
    layout
        .build()
        .map(|s| s.len())
        .map_err(|e| format!("scene {:?}: {e}", layout.name))
}

/// The MassSpring's variables before the ones every model has
/// ([`crate::model_description::COMMON_VARIABLES`]) and the per-particle outputs, in
/// `ModelVariables` order; start values come from the layout.
pub static MASS_SPRING_VARIABLES: [VarSpec<MassSpringScene>; 10] = [
    var(Input, "gravity.x", VR_GRAVITY_X, Some("m/s2"), Start::Real(|l| l.gravity[0]), "Gravity x, |g| at most 1e6"),
    var(Input, "gravity.y", VR_GRAVITY_Y, Some("m/s2"), Start::Real(|l| l.gravity[1]), "Gravity y, |g| at most 1e6"),
    var(Input, "gravity.z", VR_GRAVITY_Z, Some("m/s2"), Start::Real(|l| l.gravity[2]), "Gravity z, |g| at most 1e6"),
    var(Parameter, "dt", VR_DT, Some("s"), Start::Real(|_| 0.0), "Substep size; 0: the integrator's own (CFL-limited for the explicit schemes, the scene's time_step otherwise). A communication step runs an integer number of substeps"),
    var(Parameter, "integrator", VR_INTEGRATOR, None, Start::Text(DEFAULT_INTEGRATOR_NAME), "Time integrator: one of forward-euler, symplectic-euler, trapezoidal, backward-euler, chebyshev-jacobi, pbd"),
    output("kinetic_energy", VR_KINETIC_ENERGY, Some("J"), "Kinetic energy"),
    output("elastic_energy", VR_ELASTIC_ENERGY, Some("J"), "Elastic energy of the springs"),
    output("gravity_energy", VR_GRAVITY_ENERGY, Some("J"), "Gravitational energy -sum m g.x"),
    output("total_energy", VR_TOTAL_ENERGY, Some("J"), "Kinetic + elastic + gravitational energy"),
    output("max_strain", VR_MAX_STRAIN, None, "Largest spring strain |l / l0 - 1|"),
];

/// Name of [`DEFAULT_INTEGRATOR`] (the `integrator` start value).
const DEFAULT_INTEGRATOR_NAME: &str = "backward-euler";

/// Every variable of the FMU for this layout, in `ModelVariables` order:
/// [`MASS_SPRING_VARIABLES`], the common ones, then `particle[i].x/y/z`.
pub fn variables(layout: &MassSpringScene) -> Result<Vec<Variable>, String> {
    let n = num_particles(layout)?;
    let mut v: Vec<Variable> = MASS_SPRING_VARIABLES
        .iter()
        .map(|s| s.variable(layout))
        .collect();
    v.extend(crate::model_description::common_variables());
    for i in 0..n {
        for (k, axis) in ["x", "y", "z"].into_iter().enumerate() {
            v.push(Variable {
                name: format!("particle[{i}].{axis}"),
                vr: VR_PARTICLE_BASE + 3 * i as u32 + k as u32,
                ty: VarType::Real,
                causality: "output",
                variability: "continuous",
                unit: Some("m"),
                start: None,
                description: format!("Particle {i}, position {axis}"),
            });
        }
    }
    Ok(v)
}

/// The gravitational and the total energy change as soon as `gravity.*` is
/// set (`-sum m g . x` with the current gravity), at initialization and
/// between steps; every other output depends on no input and no parameter
/// at the same instant (`dt` and `integrator` act through the substeps).
pub fn dependencies() -> Vec<crate::model_description::Dependency> {
    let gravity = vec![VR_GRAVITY_X, VR_GRAVITY_Y, VR_GRAVITY_Z];
    [VR_GRAVITY_ENERGY, VR_TOTAL_ENERGY]
        .into_iter()
        .map(|output| crate::model_description::Dependency {
            output,
            step: gravity.clone(),
            initial: gravity.clone(),
        })
        .collect()
}

/// The GUID of the FMU for this layout: a hash of the interface version and
/// the layout's normalized TOML text.
pub fn guid(layout: &MassSpringScene) -> String {
    crate::model_description::guid_of(&format!(
        "{MODEL_IDENTIFIER} fmi2 interface {INTERFACE_VERSION}\n{}",
        layout.to_toml_string()
    ))
}

/// What `modelDescription.xml` is written from.
pub fn description(layout: &MassSpringScene) -> Result<Description, String> {
    let what = if layout.description.is_empty() {
        format!("Mass-spring scene {}", layout.name)
    } else {
        format!("Mass-spring scene {}: {}", layout.name, layout.description)
    };
    Ok(Description {
        identifier: MODEL_IDENTIFIER,
        guid: guid(layout),
        description: what,
        variables: variables(layout)?,
        stop_time: layout.time.frame_time * layout.time.frames as f64,
        step_size: layout.time.frame_time,
        dependencies: dependencies(),
        arrays: vec![positions_array(num_particles(layout)?)],
    })
}

#[cfg(test)]
mod table_tests {
    use super::*;

    /// `integrator`'s description lists the library's integrators.
    #[test]
    fn integrator_names_match_the_library() {
        let names = Integrator::ALL.map(|i| i.name()).join(", ");
        assert_eq!(MASS_SPRING_VARIABLES[4].name, "integrator");
        assert!(
            MASS_SPRING_VARIABLES[4].description.ends_with(&names),
            "{names}"
        );
        assert_eq!(DEFAULT_INTEGRATOR_NAME, DEFAULT_INTEGRATOR.name());
    }
}
