//! No divergence below the stability bound: bundles of 12 yarns of the
//! built-in material at any orientation (0-90 degrees), spacing (0.5-3
//! cells along their normal) and drop height onto the built-in scene's
//! three circles run their whole second at the built-in dt (4e-5) and at
//! `dt = "auto"`, with every segment's stretch within [0.8, 1.25] at every
//! 0.05 s. A few seeded scenes (drawn with `common::Rng`) and the bundle
//! tilted 45 degrees, 1 cm apart. Release-only.

mod common;

use common::Rng;
use yarnsim::scene::builtin::yarn_reference;
use yarnsim::scene::{StepSize, YarnScene, YarnSpec};
use yarnsim::YarnSim;

/// Highest point of a bundle at the start: 3 cells below the domain's top.
const TOP: f64 = 1.0 - 3.0 / 256.0;

/// The built-in scene with its 12 yarns `length` long (`vertices`
/// vertices) tilted `angle` degrees down from +x, `spacing` m apart along
/// their normal, centred in x, its highest point `lower` m below [`TOP`]
/// (the drop height onto the circles follows: a bundle that starts within
/// a cell of a circle is refused by [`clear_of_circles`]).
fn bundle(angle: f64, spacing: f64, lower: f64, length: f64, vertices: u32) -> YarnScene {
    let mut s = yarn_reference();
    let a = angle.to_radians();
    let dir = [a.cos(), -a.sin()];
    let normal = [a.sin(), a.cos()];
    let width = 11.0 * spacing;
    // half extents of the bundle's bounding box in y
    let half_y = 0.5 * (length * a.sin() + width * a.cos());
    let (cx, cy) = (0.5, TOP - lower - half_y);
    let start = [
        cx - dir[0] * length / 2.0 - normal[0] * width / 2.0,
        cy - dir[1] * length / 2.0 - normal[1] * width / 2.0,
    ];
    s.yarns = vec![YarnSpec {
        start: Some(start),
        direction: Some(dir),
        length: Some(length),
        vertices,
        count: 12,
        spacing: [normal[0] * spacing, normal[1] * spacing],
        ..Default::default()
    }];
    s
}

/// Whether every vertex of `s` starts more than a cell away from every circle.
fn clear_of_circles(s: &YarnScene) -> bool {
    let sim = YarnSim::new(s).unwrap();
    let dx = s.dx();
    sim.particles().vert.x.iter().all(|x| {
        s.obstacles.iter().all(|o| {
            let d = ((x.x - o.center[0]).powi(2) + (x.y - o.center[1]).powi(2)).sqrt();
            d > o.radius + dx
        })
    })
}

/// Runs `s` for 1 s; the error, if it diverged, or the stretch range
/// sampled every 0.05 s.
fn run(s: &YarnScene) -> Result<(f64, f64), String> {
    let mut sim = YarnSim::new(s).map_err(|e| format!("scene: {e}"))?;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for k in 1..=20 {
        sim.advance_to(0.05 * k as f64)
            .map_err(|e| format!("{e}"))?;
        for st in sim.stretches() {
            lo = lo.min(st);
            hi = hi.max(st);
        }
    }
    Ok((lo, hi))
}

#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn bundles_at_any_orientation_spacing_and_drop_run_their_second() {
    let dx = 1.0 / 256.0;
    // the bundle tilted 45 degrees, 1 cm apart, 0.5 m long
    let mut scenes = vec![(45.0, 0.01, 0.0, 0.5, 125)];
    let mut rng = Rng::new(39);
    while scenes.len() < 4 {
        let angle = rng.uniform(0.0, 90.0);
        let spacing = rng.uniform(0.5, 3.0) * dx;
        let lower = rng.uniform(0.0, 0.1);
        if clear_of_circles(&bundle(angle, spacing, lower, 0.4, 100)) {
            scenes.push((angle, spacing, lower, 0.4, 100));
        }
    }
    let mut runs = Vec::new();
    for &(angle, spacing, lower, length, vertices) in &scenes {
        for dt in [StepSize::Fixed(4e-5), StepSize::Auto] {
            let mut s = bundle(angle, spacing, lower, length, vertices);
            s.time.dt = dt;
            let name = format!(
                "{angle:.1} deg, spacing {:.2} cells, top {:.1} mm lower, {length} m, dt {dt:?}",
                spacing / dx,
                lower * 1e3
            );
            runs.push((name, s));
        }
    }
    let results: Vec<Result<(f64, f64), String>> = std::thread::scope(|sc| {
        let mut out = Vec::new();
        for pair in runs.chunks(2) {
            let h: Vec<_> = pair.iter().map(|(_, s)| sc.spawn(move || run(s))).collect();
            out.extend(h.into_iter().map(|h| h.join().unwrap()));
        }
        out
    });
    let mut failed = Vec::new();
    for ((name, _), r) in runs.iter().zip(&results) {
        let line = match r {
            Ok((lo, hi)) => format!("{name}: stretch [{lo:.4}, {hi:.4}]"),
            Err(e) => format!("{name}: diverged: {e}"),
        };
        eprintln!("{line}");
        // tolerance: no divergence, stretch within [0.8, 1.25]
        if !matches!(r, Ok((lo, hi)) if *lo >= 0.8 && *hi <= 1.25) {
            failed.push(line);
        }
    }
    assert!(failed.is_empty(), "{failed:#?}");
}

/// A bundle that collapsed under `dt = "auto"` while `dt = "auto"` took the
/// cross-section's rest stiffness for its elastic bound: the ninth clear
/// draw of seed 7 (12 yarns of 0.4 m tilted 16.4 degrees, 1.18 cells
/// apart, the top 91.3 mm lower). The yarns crush each other's
/// cross-section where they pile on a circle, and a crushed cross-section
/// is up to 65x stiffer than at rest (`YarnEnergy::normal_tangent`); with
/// the rest bound a segment shrank to 0.003 of its length (of 16 draws of
/// seed 7, the one that failed; the crushed bound runs all 16). Tolerance:
/// no divergence, stretch within [0.8, 1.25], as above.
#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn crushed_bundle_runs_its_second_under_auto_dt() {
    let dx = 1.0 / 256.0;
    let mut rng = Rng::new(7);
    let mut clear = Vec::new();
    while clear.len() < 9 {
        let (angle, spacing, lower) = (
            rng.uniform(0.0, 90.0),
            rng.uniform(0.5, 3.0) * dx,
            rng.uniform(0.0, 0.1),
        );
        if clear_of_circles(&bundle(angle, spacing, lower, 0.4, 100)) {
            clear.push((angle, spacing, lower));
        }
    }
    let (angle, spacing, lower) = clear[8];
    assert!((angle - 16.4).abs() < 0.05, "the draws changed: {angle}");
    let mut s = bundle(angle, spacing, lower, 0.4, 100);
    s.time.dt = StepSize::Auto;
    let r = run(&s);
    eprintln!(
        "{angle:.1} deg, spacing {:.2} cells, top {:.1} mm lower, dt auto: {r:?}",
        spacing / dx,
        lower * 1e3
    );
    assert!(
        matches!(r, Ok((lo, hi)) if lo >= 0.8 && hi <= 1.25),
        "{r:?}"
    );
}
