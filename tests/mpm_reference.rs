//! The seed's reference scene and its upright twin, run to t = 0.5 s
//! (release builds; in debug they are ignored as too slow).

use yarnsim::math::Vec2;
use yarnsim::scene::{builtin, Scene};
use yarnsim::YarnSim;

fn run_to_half_second(name: &str) -> YarnSim {
    let Some(Scene::Yarn(scene)) = builtin(name) else {
        panic!("{name} is a yarn scene")
    };
    let mut sim = YarnSim::new(&scene).unwrap();
    sim.advance(0.5).unwrap_or_else(|e| panic!("{name}: {e}"));
    sim
}

fn check_landed(sim: &YarnSim) {
    let scene = sim.scene();
    let p = sim.particles();
    assert!((sim.time() - 0.5).abs() < 1e-9);
    for (k, s) in sim.stretches().iter().enumerate() {
        assert!((0.97..=1.05).contains(s), "segment {k} stretch {s}");
    }
    let half_dx = 0.5 * scene.dx();
    for o in &scene.obstacles {
        let c = Vec2::from(o.center);
        for x in p.vert.x.iter().chain(&p.quad.x) {
            let depth = o.radius - (x - c).norm();
            assert!(
                depth <= half_dx,
                "particle {x} is {depth} m inside obstacle at {c}"
            );
        }
    }
    for x in p
        .vert
        .x
        .iter()
        .chain(&p.quad.x)
        .chain(&p.vert.v)
        .chain(&p.quad.v)
    {
        assert!(x.x.is_finite() && x.y.is_finite());
    }
    // they did land: the bundle rests on the circles, well below its start
    let d = sim.diagnostics();
    assert!(d.center_of_mass.y < 0.7, "{d:?}");
}

#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn reference_scene_lands_on_the_circles_without_overstretching() {
    let sim = run_to_half_second("yarn-reference");
    assert_eq!(sim.particles().len(), 4788);
    check_landed(&sim);
}

#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn upright_yarns_behave_like_horizontal_ones() {
    let sim = run_to_half_second("yarn-vertical");
    check_landed(&sim);
}
