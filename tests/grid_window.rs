//! The grid stores a window around the particles, not the domain: memory
//! follows the yarns, and where the window sits changes no result.

use yarnsim::mpm::YarnSim;
use yarnsim::scene::{WallMode, YarnScene};

/// Positions, velocities, affine matrices and frames of every particle,
/// bit for bit.
fn same_particles(a: &YarnSim, b: &YarnSim) -> bool {
    let (p, q) = (a.particles(), b.particles());
    p.vert.x == q.vert.x
        && p.vert.v == q.vert.v
        && p.vert.c == q.vert.c
        && p.quad.x == q.quad.x
        && p.quad.v == q.quad.v
        && p.quad.d == q.quad.d
}

fn reference() -> YarnScene {
    match yarnsim::scene::builtin("yarn-reference") {
        Some(yarnsim::Scene::Yarn(s)) => s,
        _ => unreachable!(),
    }
}

/// The reference bundle at the same dx on a 32x larger domain (8192^2
/// nodes over 32 m): the grid holds under 64 MB (dense storage of the
/// domain and its four scatter buffers would be 17 GB) and the run gives
/// the same bits as on the 256^2 grid. Walls are off in both, so that the
/// domain's edge is the only difference.
#[test]
fn a_bundle_on_a_huge_grid_stores_its_window_and_gives_the_same_bits() {
    let mut small = reference();
    small.walls.mode = WallMode::None;
    let mut huge = small.clone();
    huge.grid.resolution = 8192;
    huge.grid.size = 32.0;
    assert_eq!(huge.grid.size / 8192.0, small.grid.size / 256.0);
    let mut a = YarnSim::new(&small).unwrap();
    let mut b = YarnSim::new(&huge).unwrap();
    a.steps_n(200).unwrap();
    b.steps_n(200).unwrap();
    assert!(same_particles(&a, &b), "the window changed a result");
    let (ma, mb) = (a.grid_memory_bytes(), b.grid_memory_bytes());
    eprintln!("grid memory: 256^2 {ma} B, 8192^2 {mb} B");
    assert!(mb < 64 << 20, "8192^2 grid holds {mb} B");
    assert!(
        mb <= ma,
        "the huge grid holds more ({mb} B) than the small one ({ma} B)"
    );
}

/// A bundle that moves across the domain takes its window along: memory
/// stays bounded by the bundle's size, and the run is the same as one on a
/// grid the bundle fills.
#[test]
fn the_window_follows_a_moving_bundle() {
    let mut s = reference();
    s.walls.mode = WallMode::None;
    s.obstacles.clear();
    s.yarns.truncate(1);
    s.yarns[0].count = 2;
    s.gravity = [0.0, 0.0];
    for y in &mut s.yarns {
        y.velocity = [0.0, -3.0];
    }
    let mut huge = s.clone();
    huge.grid.resolution = 2048;
    huge.grid.size = 8.0;
    let mut a = YarnSim::new(&s).unwrap();
    let mut b = YarnSim::new(&huge).unwrap();
    let mut peak = 0;
    for _ in 0..20 {
        a.steps_n(50).unwrap();
        if let Err(e) = b.steps_n(50) {
            panic!("{e}");
        }
        peak = peak.max(b.grid_memory_bytes());
    }
    assert!(same_particles(&a, &b));
    // two yarns span 0.8 m x 0.01 m: about 26 x 3 blocks plus margins
    assert!(peak < 8 << 20, "peak grid memory {peak} B");
}
