//! Obstacle and yarn-on-yarn friction at a real yarn's measured EA with
//! `[time] axial = "implicit"` (APIC, `dt = "auto"`): the heavy-rope
//! capstan of `yarn_oracles` (128^2, the capstan oracles' grid) and the
//! incline of `yarn_friction` (64^2, the coarsest that carries it: the
//! top yarn starts one cell, 15.6 mm, above the bed) with the polyester
//! and nylon presets, against their analytic thresholds. Release only.
//!
//! The capstan's yarn lies with its centre line `d / 2` from the circle
//! ([`preset_capstan_toml`]: on the circle that contact sees, grown by
//! half the preset's diameter). The oracle's rope is flexible, so `EI =
//! 0` (the nylon monofilament's bending length `sqrt(EI / T)` is 0.14 m
//! at the heavy end's tension, as long as the drum's radius and the
//! strands); the incline's straight yarns take `EI = 0` too, which only
//! spares the bending bound on the step.

mod common;

use common::{capstan_slip, incline_yarns_toml, preset_capstan_toml, scene};
use yarnsim::scene::presets::preset;
use yarnsim::YarnSim;

/// The axial solve's `[time]` lines under `dt = "auto"`.
const AXIAL: &str = "dt = \"auto\"\naxial = \"implicit\"";

/// [`preset_capstan_toml`] (R `r`, the yarn `drop` above the circle,
/// friction `factor` times mu*) with the preset `name` at its measured EA
/// and the axial solve under APIC.
fn capstan_sim(name: &str, r: f64, drop: f64, factor: f64) -> YarnSim {
    let text = preset_capstan_toml(name, r, drop, factor).replace(
        "dt = \"auto\"\n",
        &format!("{AXIAL}\n[transfer]\nscheme = \"apic\"\n"),
    );
    YarnSim::new(&scene(&text)).unwrap()
}

/// Whether the capstan of [`capstan_sim`] slid ([`capstan_slip`]: an end
/// moved by more than 0.5 % of its hanging length in the second after
/// loading), the largest relative end displacement, and the wall time.
fn capstan(name: &str, r: f64, drop: f64, factor: f64) -> (bool, f64, f64) {
    let t = std::time::Instant::now();
    let mut sim = capstan_sim(name, r, drop, factor);
    let (slid, rel) = capstan_slip(&mut sim, 0.1, 0.3, |_| {});
    let wall = t.elapsed().as_secs_f64();
    eprintln!(
        "capstan {name} R {r} drop {} mm at {factor} mu*: {} ({rel:.2e}), {wall:.1} s",
        drop * 1e3,
        if slid { "slid" } else { "held" }
    );
    (slid, rel, wall)
}

/// The capstan holds at 1.4 mu* and slides at 0.7 mu* for each `(R,
/// drop)` of `cases` with the preset `name`.
fn holds_and_slides(name: &str, cases: &[(f64, f64)]) {
    for &(r, drop) in cases {
        let (slid, rel, _) = capstan(name, r, drop, 1.4);
        assert!(
            !slid,
            "{name} R {r} drop {drop}: slid at 1.4 mu* ({rel:.2e})"
        );
        let (slid, rel, _) = capstan(name, r, drop, 0.7);
        assert!(
            slid,
            "{name} R {r} drop {drop}: held at 0.7 mu* ({rel:.2e})"
        );
    }
}

/// Polyester 167 dtex (EA 167 N) laid on the drum and dropped from 3 mm
/// above it, at R 0.1 and 0.05: holds at 1.4 mu*, slides at 0.7 mu*
/// (measured 2026-12-06: held with the ends moved 1.2e-3 to 2.0e-3 of
/// their lengths, slid by 5.4e-3 to 6.5e-3 at the first check past 5e-3;
/// about 10 s in all).
#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn polyester_capstan_holds_above_and_slides_below_the_threshold() {
    holds_and_slides(
        "polyester-167dtex",
        &[(0.1, 0.0), (0.1, 0.003), (0.05, 0.0), (0.05, 0.003)],
    );
}

/// Nylon 6.6 monofilament 0.30 mm (EA 176.7 N) dropped from 3 mm at R
/// 0.1 and laid at R 0.05: holds at 1.4 mu*, slides at 0.7 mu* (measured
/// 2026-12-06: held at 7.2e-4 and 2.8e-4; about 45 s; laid at R 0.1 it
/// held at 4.87e-3, too near the criterion's 5e-3 to assert, see
/// `docs/performance/softened.md`).
#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn nylon_capstan_holds_above_and_slides_below_the_threshold() {
    holds_and_slides("nylon66-mono-0.30mm", &[(0.1, 0.003), (0.05, 0.0)]);
}

/// Gravity of the incline.
const G: f64 = 9.8;
/// Time the incline's top yarn settles on the bed, s.
const SETTLE: f64 = 0.05;
/// Time over which its slip is measured, s.
const SLIDE: f64 = 0.25;

/// The incline of `yarn_friction.rs` (a 0.3 m yarn one cell above a held
/// 0.8 m bed, here on 64^2, gravity g tilted by `theta`) with the preset `name`
/// for both yarns (yarn-on-yarn friction `c_f` the preset's) and the axial
/// solve: the top yarn's downhill slip in [`SLIDE`] after it settled for
/// [`SETTLE`].
fn incline_slip(name: &str, theta: f64) -> f64 {
    let res = 64;
    let yarns = incline_yarns_toml(res);
    let gravity = [G * theta.sin(), -G * theta.cos()];
    let text = format!(
        "gravity = [{}, {}]\n[grid]\nresolution = {res}\n[time]\n{AXIAL}\n[transfer]\n\
         scheme = \"apic\"\n[material]\n[walls]\nmode = \"none\"\n{yarns}",
        gravity[0], gravity[1]
    );
    let text = text.replace(
        "[material]\n",
        &format!("[material]\npreset = \"{name}\"\nEI = 0.0\nplasticity = true\n"),
    );
    let mut sim = YarnSim::new(&scene(&text)).unwrap();
    sim.advance(SETTLE).unwrap();
    let centre = |sim: &YarnSim| {
        let (a, b) = sim.yarn_endpoints(1);
        0.5 * (a.x + b.x)
    };
    let x0 = centre(&sim);
    sim.advance(SLIDE).unwrap();
    centre(&sim) - x0
}

/// The incline with each preset: holds at tan theta = 0.85 c_f, slides
/// at 1.15 c_f (slid: more than 5 mm downhill in 0.25 s, the threshold of
/// `yarn_friction.rs`; a Coulomb slide at 1.15 c_f from rest covers g (sin
/// theta - c_f cos theta) t^2 / 2, 11.0 mm at the polyester's c_f 0.25 and
/// 8.9 mm at the nylon's 0.2; measured 2026-12-06: 1.1 mm and 0.57 mm at
/// 0.85 c_f, 20.9 mm and 12.3 mm at 1.15 c_f, 25 s in all).
#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn incline_with_a_preset_holds_below_and_slides_above_its_friction() {
    for name in ["polyester-167dtex", "nylon66-mono-0.30mm"] {
        let c_f = preset(name).unwrap().friction;
        let held = incline_slip(name, (0.85 * c_f).atan());
        let slid = incline_slip(name, (1.15 * c_f).atan());
        eprintln!(
            "incline {name} c_f {c_f}: slip {held:.3e} m at 0.85 c_f, {slid:.3e} m at 1.15 c_f"
        );
        assert!(held.abs() < 5e-3, "{name}: slid {held:.3e} m at 0.85 c_f");
        assert!(slid > 5e-3, "{name}: held ({slid:.3e} m) at 1.15 c_f");
    }
}

/// The capstan rows of `docs/performance/softened.md` at the measured EA:
/// per preset, radius and drop (and laid on the bare circle, inside the
/// grown one: drop `-d / 2`), the outcome at 1.4 and 0.7 mu* and the
/// grid's normal force on the drum at the end of the hold (the normal
/// impulse of its last substep over the substep) against the resting
/// rope's, `pi w l1 + 2 w R` to `pi w l2 + 2 w R` (the tension over R
/// along the arc, between the strands' weights, plus the weight's normal
/// part); `--ignored --nocapture`.
#[test]
#[ignore = "measurement: cargo test --release --test capstan_real_ea -- --ignored --nocapture"]
fn real_ea_table() {
    for name in ["polyester-167dtex", "nylon66-mono-0.30mm"] {
        let bare = -0.5 * preset(name).unwrap().diameter;
        for (r, drop) in [
            (0.1, bare),
            (0.1, 0.0),
            (0.1, 0.003),
            (0.1, 0.01),
            (0.05, 0.0),
            (0.05, 0.003),
            (0.05, 0.01),
        ] {
            let mut row = format!("| {name} | {r} | {:.2} |", drop * 1e3);
            for factor in [1.4, 0.7] {
                let mut sim = capstan_sim(name, r, drop, factor);
                let (slid, rel) = capstan_slip(&mut sim, 0.1, 0.3, |_| {});
                row += &format!(" {} ({rel:.2e}) |", if slid { "slid" } else { "held" });
                if factor == 1.4 {
                    let w = sim.gravity().norm() * preset(name).unwrap().tex * 1e-6
                        / sim.scene().material.per_yarn().unwrap().spacing;
                    let rest = |l: f64| std::f64::consts::PI * w * l + 2.0 * w * r;
                    row += &format!(
                        " {:.3e} ({:.3e} to {:.3e}) |",
                        sim.obstacle_normal_impulse() / sim.dt(),
                        rest(0.1),
                        rest(0.3)
                    );
                }
            }
            eprintln!("{row}");
        }
    }
}
