//! The yarn MPM's stable substep bound (`yarnsim::mpm::driver::timestep`) and the
//! divergence report of a substep that breaks it.

mod common;

use common::{straight, SceneBuilder};
use yarnsim::mpm::driver::timestep::{stable_dt, wave_speed};
use yarnsim::{SimError, YarnScene, YarnSim};

/// The bare 64^2 scene with one straight yarn of 60 vertices.
fn scene() -> YarnScene {
    SceneBuilder::bare()
        .yarn(straight([0.3, 0.5], [0.7, 0.5], 60))
        .build()
}

#[test]
fn stable_dt_is_the_cfl_wave_bound() {
    let s = scene();
    let m = &s.material;
    // 2 mu + lambda = 1.4 E is the stiffest of k, gamma, 1.4 E here.
    assert_eq!(wave_speed(m), (1.4f64 * 1000.0).sqrt());
    let dx = 1.0 / 64.0;
    assert_eq!(stable_dt(m, dx, 0.0), dx / 1400f64.sqrt());
    assert_eq!(stable_dt(m, dx, 10.0), dx / (1400f64.sqrt() + 10.0));
    // A scene at rest: the elastic bound.
    let sim = YarnSim::new(&s).unwrap();
    assert_eq!(sim.max_speed(), 0.0);
    assert_eq!(sim.stable_dt(), stable_dt(m, s.dx(), 0.0));
    // 100x stiffer fiber: 10x smaller bound.
    let mut stiff = s.clone();
    stiff.material.k *= 100.0;
    let r = stable_dt(&s.material, dx, 0.0) / stable_dt(&stiff.material, dx, 0.0);
    assert!((r - (1e5f64 / 1400.0).sqrt()).abs() < 1e-12, "{r}");
    // The built-in scenes run inside their bound.
    for (name, _) in yarnsim::scene::builtin_names() {
        if let Ok(yarnsim::Scene::Yarn(y)) = yarnsim::Scene::resolve(name) {
            let sim = YarnSim::new(&y).unwrap();
            assert!(
                sim.dt() <= sim.stable_dt(),
                "{name}: {} > {}",
                sim.dt(),
                sim.stable_dt()
            );
        }
    }
}

/// Inside the bound a run is quiet; at 4x the bound it diverges.
#[test]
fn a_substep_beyond_the_bound_diverges() {
    let base = scene();
    let bound = YarnSim::new(&base).unwrap().stable_dt();
    let run = |dt: f64| {
        let mut s = base.clone();
        s.time.dt = dt.into();
        let mut sim = YarnSim::new(&s).unwrap();
        {
            let p = yarnsim::testing::particles_mut(&mut sim);
            for (k, x) in p.vert.x.iter_mut().enumerate() {
                x.y += if k % 2 == 0 { 0.002 } else { -0.002 };
            }
        }
        let n = (0.05 / dt).ceil() as u64;
        sim.steps_n(n)
    };
    assert!(run(0.5 * bound).is_ok());
    assert!(run(4.0 * bound).is_err());
}

/// The divergence message reports the speed that tripped the one-cell check
/// (the grid's velocity at the vertex), not the stored velocity after the
/// wall projection set it to zero.
#[test]
fn divergence_message_reports_the_velocity_that_tripped_the_check() {
    let mut s = scene();
    s.gravity = [0.0, -1.0e6];
    s.time.dt = 2e-3.into();
    let mut sim = YarnSim::new(&s).unwrap();
    let e = sim.step().expect_err("1e6 m/s2 for 2 ms is 2000 m/s");
    let SimError::NonFinite { what, .. } = &e else {
        panic!("{e}")
    };
    // "vertex I moves V m/s, more than one cell per substep (CFL limit L m/s)"
    let num_after = |key: &str| -> f64 {
        let rest = &what[what.find(key).unwrap_or_else(|| panic!("{what}")) + key.len()..];
        rest.split_whitespace().next().unwrap().parse().unwrap()
    };
    let v = num_after("moves ");
    let limit = num_after("CFL limit ");
    assert!(v > limit, "{what}");
    // The grid gave the vertex about g dt = 2000 m/s.
    assert!((v - 2000.0).abs() < 100.0, "{what}");
    // The stored velocity was clamped at the grid's edge.
    let i: usize = what["vertex ".len()..]
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(sim.particles().vert.v[i].norm() < v, "{what}");
}
