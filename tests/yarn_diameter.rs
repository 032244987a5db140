//! The yarn diameter in contact (`material.diameter`), release-only: a
//! straight yarn laid or dropped across a circle (radius 0.1 m, centre
//! (0.5, 0.5), friction 0.5, 1 m domain) drapes over it and comes to rest
//! with its centre line at `d / 2` from the surface; a second, shorter
//! yarn draped over the first (`[contact] fields = "per-yarn"`, both free)
//! rests with its centre line `d` from the first's. What is measured is
//! the mean distance from the circle's centre of each yarn's vertices
//! within 15 degrees of the top, after 0.5 s under g = 9.8 m/s^2 (the
//! built-in material of the friction oracles, `common::friction_scene`,
//! plus the diameter), at two grid resolutions (d fixed, so its size in
//! cells changes) and two diameters.

mod common;

use common::{friction_scene, with_diameter};
use yarnsim::scene::{SceneError, TransferScheme, YarnScene, MAX_DIAMETER_CELLS};
use yarnsim::YarnSim;

/// The circle.
const C: [f64; 2] = [0.5, 0.5];
const R: f64 = 0.1;

/// How the yarns start.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Start {
    /// A quarter cell above where they rest.
    Laid,
    /// Four cells above where they rest.
    Dropped,
}

/// The circle, a yarn of 0.4 m across its top and, with `two`, a yarn of
/// 0.2 m above that, on `res`^2 with diameter `d` (`None`: none given);
/// each yarn starts straight, `start`'s gap above its rest height
/// (`d / 2` over the circle, `d` over the lower yarn; 0 without a
/// diameter).
fn scene(res: u32, d: Option<f64>, start: Start, two: bool) -> YarnScene {
    let dx = 1.0 / res as f64;
    let gap = match start {
        Start::Laid => 0.25 * dx,
        Start::Dropped => 4.0 * dx,
    };
    let dd = d.unwrap_or(0.0);
    let y0 = C[1] + R + 0.5 * dd + gap;
    let y1 = y0 + dd + gap;
    let n = |l: f64| (l / (0.5 * dx)).round() as u32 + 1;
    let mut yarns = format!(
        "[contact]\nfields = \"per-yarn\"\n[[obstacles]]\ncenter = [{}, {}]\nradius = {R}\nfriction = 0.5\n\
         [[yarns]]\nstart = [0.3, {y0}]\nend = [0.7, {y0}]\nvertices = {}\n",
        C[0],
        C[1],
        n(0.4)
    );
    if two {
        yarns += &format!(
            "[[yarns]]\nstart = [0.4, {y1}]\nend = [0.6, {y1}]\nvertices = {}\n",
            n(0.2)
        );
    }
    let dt = 1e-2 / res as f64;
    let s = friction_scene(
        [0.0, -9.8],
        res,
        TransferScheme::Apic,
        0.3,
        &yarns,
        &format!("dt = {dt}"),
    );
    with_diameter(s, d)
}

/// Mean distance from the circle's centre of yarn `y`'s vertices within
/// 15 degrees of the top.
fn top_radius(sim: &YarnSim, y: usize) -> f64 {
    let p = sim.particles();
    let r = p.yarn_vertices[y]..p.yarn_vertices[y + 1];
    let (mut sum, mut n) = (0.0, 0);
    for x in &p.vert.x[r] {
        let (dx, dy) = (x.x - C[0], x.y - C[1]);
        if dy > 0.0 && dx.abs() < dy * 15f64.to_radians().tan() {
            sum += (dx * dx + dy * dy).sqrt();
            n += 1;
        }
    }
    assert!(n > 0, "yarn {y} has no vertex on the top");
    sum / n as f64
}

/// After 0.5 s: the lower yarn's rest distance from the surface and, with
/// `two`, the upper yarn's from the lower one (m).
fn rest(res: u32, d: Option<f64>, start: Start, two: bool) -> (f64, Option<f64>) {
    let mut sim = YarnSim::new(&scene(res, d, start, two)).unwrap();
    sim.advance(0.5).unwrap();
    let r0 = top_radius(&sim, 0);
    let sep = two.then(|| top_radius(&sim, 1) - r0);
    (r0 - R, sep)
}

/// The measured rest distances printed (mm and cells), for the docs.
#[test]
#[ignore = "measurement: cargo test --release --test yarn_diameter -- --ignored --nocapture"]
fn measure_rest_distances() {
    let ds: Vec<Option<f64>> = std::env::var("DIAMETERS")
        .map(|v| {
            v.split(',')
                .map(|s| s.parse().ok().filter(|&d: &f64| d > 0.0))
                .collect()
        })
        .unwrap_or(vec![None]);
    for res in [256, 512] {
        for &d in &ds {
            for start in [Start::Laid, Start::Dropped] {
                let dx = 1.0 / res as f64;
                let (h, sep) = rest(res, d, start, true);
                let sep = sep.unwrap();
                println!(
                    "{res} d {:?} {start:?}: circle {:.3} mm ({:.2} cells), yarns {:.3} mm ({:.2} cells)",
                    d.map(|d| d * 1e3),
                    h * 1e3,
                    h / dx,
                    sep * 1e3,
                    sep / dx
                );
            }
        }
    }
}

/// The rest distances of the lower yarn from the circle (`d / 2`) and of
/// the upper yarn from the lower one (`d`), each within 15 %, laid and
/// dropped: d = 3 mm at 256^2 and 512^2 (0.77 and 1.54 cells), 4.5 mm at
/// 256^2 (1.15 cells), 2.5 mm at 512^2 (1.28 cells). The runs go in
/// parallel threads (each is deterministic for any thread count).
#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn yarns_rest_half_a_diameter_off_a_circle_and_a_diameter_apart() {
    let cases = [(256, 3e-3), (512, 3e-3), (256, 4.5e-3), (512, 2.5e-3)];
    let runs: Vec<(u32, f64, Start)> = cases
        .iter()
        .flat_map(|&(res, d)| [Start::Laid, Start::Dropped].map(|s| (res, d, s)))
        .collect();
    let results: Vec<(f64, f64)> = std::thread::scope(|sc| {
        let handles: Vec<_> = runs
            .iter()
            .map(|&(res, d, start)| {
                sc.spawn(move || {
                    let (h, sep) = rest(res, Some(d), start, true);
                    (h, sep.unwrap())
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    let mut failed = Vec::new();
    for (&(res, d, start), &(h, sep)) in runs.iter().zip(&results) {
        let line = format!(
            "{res}^2 d {d} m ({:.2} cells) {start:?}: circle {h:.4e} m ({:+.1} % of d/2), \
             yarns {sep:.4e} m ({:+.1} % of d)",
            d * res as f64,
            100.0 * (h - 0.5 * d) / (0.5 * d),
            100.0 * (sep - d) / d
        );
        eprintln!("{line}");
        // tolerances: 15 % of d / 2 from the circle, 15 % of d between the yarns
        if (h - 0.5 * d).abs() > 0.15 * 0.5 * d || (sep - d).abs() > 0.15 * d {
            failed.push(line);
        }
    }
    assert!(failed.is_empty(), "{failed:#?}");
}

/// Two yarns in per-yarn fields with a diameter of 2 cells (above
/// [`MAX_DIAMETER_CELLS`]) are refused, naming `material.diameter` and the
/// coarsest-resolution bound that carries it; one yarn is not (nothing to
/// meet), nor are two in the shared field without pins.
#[test]
fn a_diameter_beyond_the_grid_is_refused_with_the_resolution_it_needs() {
    let d = 2.0 / 256.0;
    let e = with_diameter(scene(256, None, Start::Laid, true), Some(d))
        .validate()
        .unwrap_err();
    let SceneError::Invalid { field, message, .. } = &e else {
        panic!("{e}");
    };
    assert_eq!(field, "material.diameter");
    // at most floor(1.75 / 2 * 256) = 224 cells carry 2 / 256 m
    let most = (MAX_DIAMETER_CELLS * 256.0 / 2.0).floor();
    assert!(
        message.contains(&format!("grid.resolution to at most {most}")),
        "{message}"
    );
    assert!(with_diameter(scene(256, None, Start::Laid, false), Some(d))
        .validate()
        .is_ok());
    let mut shared = with_diameter(scene(256, None, Start::Laid, true), Some(d));
    shared.contact.fields = yarnsim::scene::FieldPartition::HeldFree;
    assert!(shared.validate().is_ok());
}

/// A diameter with the free yarns in one field (`"held-free"`, the
/// default) warns that it does not act between them; per-yarn fields and
/// no diameter do not warn.
#[test]
fn a_diameter_with_shared_fields_warns() {
    let mut s = scene(256, Some(3e-3), Start::Laid, true);
    assert_eq!(s.diameter_warning(), None);
    s.contact.fields = yarnsim::scene::FieldPartition::HeldFree;
    let w = s.diameter_warning().expect("a warning");
    assert!(
        w.contains("material.diameter") && w.contains("per-yarn"),
        "{w}"
    );
    assert_eq!(scene(256, None, Start::Laid, true).diameter_warning(), None);
}

/// A yarn laid on the bare circle starts inside the circle that contact
/// sees (grown by d / 2): the scene warns, naming the obstacle and the
/// radius to lay it at; laid at R + d / 2 (and without a diameter) it
/// does not.
#[test]
fn a_yarn_laid_inside_half_its_diameter_warns() {
    let d = yarnsim::scene::presets::preset("polyester-167dtex")
        .unwrap()
        .diameter;
    let on = |drop: f64| {
        let text = common::preset_capstan_toml("polyester-167dtex", 0.1, drop, 1.4);
        yarnsim::scene::YarnScene::from_toml_str(&text).unwrap()
    };
    let w = on(-0.5 * d).start_gap_warning().expect("a warning");
    assert!(
        w.contains("obstacle 0") && w.contains("material.diameter / 2") && w.contains("0.10008"),
        "{w}"
    );
    assert_eq!(on(-0.5 * d).warnings(), vec![w]);
    assert_eq!(on(0.0).start_gap_warning(), None);
    assert_eq!(on(0.0).warnings(), Vec::<String>::new());
    assert_eq!(
        scene(256, None, Start::Laid, true).start_gap_warning(),
        None
    );
}
