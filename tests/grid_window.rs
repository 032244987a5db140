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

/// Under `axial = "implicit"` with FLIP the share's node buffers (one per
/// velocity field, the size of its grid's window) are counted, and they
/// follow the window as the grid does: on an 8192^2 grid the bundle still
/// holds less than on its own 256^2 one, and the buffers add about as many
/// bytes as three values per window node.
#[test]
fn the_axial_share_is_counted_and_follows_the_window() {
    let mut s = reference();
    s.walls.mode = WallMode::None;
    s.material.k = 1e7;
    s.transfer.flip_time = Some(0.002);
    let mut axial = s.clone();
    axial.time.axial = yarnsim::scene::Axial::Implicit;
    let mut huge = axial.clone();
    huge.grid.resolution = 8192;
    huge.grid.size = 32.0;
    let memory = |scene: &YarnScene| {
        let mut sim = YarnSim::new(scene).unwrap();
        sim.steps_n(20).unwrap();
        (sim.grid_memory_bytes(), sim.active_blocks())
    };
    let ((plain, blocks), (with_share, _), (on_huge, _)) =
        (memory(&s), memory(&axial), memory(&huge));
    eprintln!("grid memory: {plain} B, with the share {with_share} B, on 8192^2 {on_huge} B");
    // at least the active blocks' 64 nodes of 24 bytes each
    assert!(
        with_share >= plain + blocks * 64 * 24,
        "{with_share} against {plain}"
    );
    assert!(on_huge <= with_share, "{on_huge} against {with_share}");
}
