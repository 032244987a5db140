//! The built-in scenes.

use super::yarn::{
    AttractorSpec, GridSpec, Integrator, Material, Obstacle, StepSize, TimeSpec, Walls, YarnScene,
    YarnSpec,
};
use super::Scene;

/// The scene used when none is named.
pub const DEFAULT_SCENE: &str = "yarn-reference";

/// `(name, one-line description)` of every built-in scene.
pub fn builtin_names() -> Vec<(&'static str, &'static str)> {
    vec![
        (
            "yarn-reference",
            "Jiang et al. 2017 reference: 12 yarns x 200 vertices fall onto three circles (256^2 grid, dt 4e-5)",
        ),
        (
            "yarn-vertical",
            "the reference bundle turned upright: 12 vertical yarns drop onto the circles",
        ),
        (
            "yarn-drape",
            "one diagonal yarn of 400 vertices drapes over a single circle",
        ),
    ]
    .into_iter()
    .chain(super::massspring::builtin::names())
    .collect()
}

/// A built-in scene by name.
pub fn builtin(name: &str) -> Option<Scene> {
    match name {
        "yarn-reference" | "reference" | "default" => Some(Scene::Yarn(yarn_reference())),
        "yarn-vertical" => Some(Scene::Yarn(yarn_vertical())),
        "yarn-drape" => Some(Scene::Yarn(yarn_drape())),
        "wire" | "three-particle" | "cloth" => {
            super::massspring::builtin::by_name(name).map(Scene::MassSpring)
        }
        _ => None,
    }
}

/// The material of the reference scene.
fn reference_material() -> Material {
    Material {
        k: 1000.0,
        gamma: 500.0,
        youngs_modulus: 1000.0,
        friction: 0.05,
        bending: 1e-3,
        density: 1.0,
        plasticity: true,
    }
}

fn reference_obstacles() -> Vec<Obstacle> {
    [[0.25, 0.6], [0.5, 0.3], [0.75, 0.5]]
        .into_iter()
        .map(|center| Obstacle {
            center,
            radius: 0.08,
            friction: 0.3,
        })
        .collect()
}

/// The reference scene (the reference Taichi implementation of Jiang et al. 2017's yarn bundle): 12 horizontal yarns of 200 vertices (4788
/// particles), 256^2 grid, dt 4e-5, three circles of radius 0.08.
pub fn yarn_reference() -> YarnScene {
    YarnScene {
        kind: "yarn".into(),
        name: "yarn-reference".into(),
        description: "Jiang et al. 2017 reference: 12 yarns x 200 vertices fall onto three circles"
            .into(),
        grid: GridSpec {
            resolution: 256,
            size: 1.0,
        },
        time: TimeSpec {
            dt: StepSize::Fixed(4e-5),
            safety: None,
            dt_max: None,
            frame_dt: 1.0 / 60.0,
            integrator: Integrator::Explicit,
        },
        material: reference_material(),
        gravity: [0.0, -9.8],
        attractor: AttractorSpec::default(),
        walls: Walls::default(),
        obstacles: reference_obstacles(),
        transfer: Default::default(),
        pins: Vec::new(),
        yarns: vec![YarnSpec {
            start: Some([0.1, 0.75]),
            direction: Some([1.0, 0.0]),
            length: Some(0.8),
            vertices: 200,
            count: 12,
            spacing: [0.0, 0.01],
            ..Default::default()
        }],
    }
}

/// The reference bundle standing upright: yarns start vertical.
pub fn yarn_vertical() -> YarnScene {
    let mut s = yarn_reference();
    s.name = "yarn-vertical".into();
    s.description = "12 vertical yarns drop onto the circles".into();
    s.yarns = vec![YarnSpec {
        start: Some([0.42, 0.92]),
        direction: Some([0.0, -1.0]),
        length: Some(0.5),
        vertices: 125,
        count: 12,
        spacing: [0.01, 0.0],
        ..Default::default()
    }];
    s
}

/// One diagonal yarn draping over a circle.
pub fn yarn_drape() -> YarnScene {
    let mut s = yarn_reference();
    s.name = "yarn-drape".into();
    s.description = "one diagonal yarn of 400 vertices drapes over a single circle".into();
    s.obstacles = vec![Obstacle {
        center: [0.5, 0.45],
        radius: 0.1,
        friction: 0.3,
    }];
    s.yarns = vec![YarnSpec::straight([0.15, 0.55], [0.85, 0.85], 400)];
    s
}
