//! The built-in mass-spring scenes.

use super::{
    ChainSpec, DrivenSpec, MassSpringScene, ParticleSpec, SheetSpec, SphereSpec, SpringSpec,
    TimeParams,
};

/// `(name, one-line description)` of each built-in mass-spring scene.
pub fn names() -> Vec<(&'static str, &'static str)> {
    vec![
        (
            "wire",
            "course notes: 11-particle wire (mass 1, length 1), top end driven on a circle, 100 frames of 0.05 s",
        ),
        (
            "three-particle",
            "Baraff-Witkin 1998: three particles joined by two springs, the 9x9 backward-Euler system",
        ),
        (
            "cloth",
            "Wang 2015, Provot 1995: 21x21 sheet (10x10 m, k 8000) pinned at two corners falls onto a sphere",
        ),
    ]
}

/// A built-in mass-spring scene by name.
pub fn by_name(name: &str) -> Option<MassSpringScene> {
    match name {
        "wire" => Some(wire()),
        "three-particle" => Some(three_particle()),
        "cloth" => Some(cloth()),
        _ => None,
    }
}

/// The course lecture notes' wire: 11 particles from `(0, 0, 0.5)` to `(0, -1, 0.5)`, total
/// mass 1, `youngs_modulus` 100 (k = 1000 N/m per spring), damping 100 N s/m,
/// gravity 9.81, the top particle driven on the circle of radius 0.5 about the
/// origin in the x-z plane with period 5 s (= 100 frames of 0.05 s).
pub fn wire() -> MassSpringScene {
    MassSpringScene {
        kind: "wire".into(),
        name: "wire".into(),
        description: "course notes: 11-particle wire, top end driven on a circle".into(),
        gravity: [0.0, -9.81, 0.0],
        pinned: vec![],
        time: TimeParams {
            frame_time: 0.05,
            frames: 100,
            time_step: Some(0.005),
            cfl_number: 0.5,
            velocity_damping: 1.0,
            strain_limit: None,
        },
        particles: vec![],
        chains: vec![ChainSpec {
            start: [0.0, 0.0, 0.5],
            end: [0.0, -1.0, 0.5],
            particles: 11,
            mass: 1.0,
            youngs_modulus: 100.0,
            damping: 100.0,
        }],
        sheets: vec![],
        springs: vec![],
        driven: vec![DrivenSpec {
            particle: 0,
            center: [0.0, 0.0, 0.0],
            u: [0.5, 0.0, 0.0],
            v: [0.0, 0.0, 0.5],
            period: 5.0,
            phase: 0.0,
        }],
        spheres: vec![],
    }
}

/// Baraff and Witkin 1998's three-particle system: masses 1, 2 and 1.5 kg, springs 0-1 and
/// 1-2 (stiffness 50 N/m, both stretched), no constraints, so the whole 9x9
/// system `A = M - h^2 K` is solved.
pub fn three_particle() -> MassSpringScene {
    let p = |position: [f64; 3], velocity: [f64; 3], mass: f64| ParticleSpec {
        position,
        velocity,
        mass,
    };
    let s = |a: usize, b: usize, rest: f64| SpringSpec {
        particles: [a, b],
        stiffness: 50.0,
        damping: 0.0,
        rest_length: Some(rest),
    };
    MassSpringScene {
        kind: "three-particle".into(),
        name: "three-particle".into(),
        description:
            "Baraff-Witkin 1998: three particles, two springs, one backward-Euler solve per step"
                .into(),
        gravity: [0.0, -9.81, 0.0],
        pinned: vec![],
        time: TimeParams {
            frame_time: 0.1,
            frames: 50,
            time_step: None,
            cfl_number: 0.5,
            velocity_damping: 1.0,
            strain_limit: None,
        },
        particles: vec![
            p([0.0, 0.0, 0.0], [0.0, 0.5, 0.0], 1.0),
            p([1.0, -0.2, 0.1], [0.1, 0.0, -0.2], 2.0),
            p([1.8, -0.9, 0.3], [0.0, 0.0, 0.3], 1.5),
        ],
        chains: vec![],
        sheets: vec![],
        springs: vec![s(0, 1, 0.9), s(1, 2, 0.8)],
        driven: vec![],
        spheres: vec![],
    }
}

/// The cloth (Wang 2015; Müller et al. 2007; Provot 1995): 21 x 21 vertices spanning 10 x 10 m in the plane y = 0,
/// vertex `(i, j)` at `(5 - 10 i/20, 0, 5 - 10 j/20)`, mass 1 each, springs of
/// k = 8000 N/m on the triangle edges, vertices 0 and 20 pinned,
/// h = 1/30 s, velocity damping 0.99 per step, gravity 9.8, and a sphere of
/// radius 2.7 centred at `(0, -3, 0)` (the Unity cloth scripts move it with the mouse; this
/// position puts it in the path of the swinging sheet).
pub fn cloth() -> MassSpringScene {
    MassSpringScene {
        kind: "cloth".into(),
        name: "cloth".into(),
        description:
            "Wang 2015, Provot 1995: 21x21 sheet pinned at two corners falls onto a sphere".into(),
        gravity: [0.0, -9.8, 0.0],
        pinned: vec![0, 20],
        time: TimeParams {
            frame_time: 1.0 / 30.0,
            frames: 150,
            time_step: None,
            cfl_number: 0.5,
            velocity_damping: 0.99,
            strain_limit: None,
        },
        particles: vec![],
        chains: vec![],
        sheets: vec![SheetSpec {
            origin: [5.0, 0.0, 5.0],
            edge_u: [-10.0, 0.0, 0.0],
            edge_v: [0.0, 0.0, -10.0],
            nu: 21,
            nv: 21,
            mass: 1.0,
            stiffness: 8000.0,
            damping: 0.0,
            diagonals: true,
        }],
        springs: vec![],
        driven: vec![],
        spheres: vec![SphereSpec {
            center: [0.0, -3.0, 0.0],
            radius: 2.7,
        }],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtins_build_and_round_trip() {
        for (name, _) in names() {
            let l = by_name(name).unwrap();
            l.validate().unwrap();
            let back = MassSpringScene::from_toml_str(&l.to_toml_string()).unwrap();
            assert_eq!(back, l, "{name}");
        }
    }
}
