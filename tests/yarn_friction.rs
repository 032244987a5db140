//! Fibre-fibre friction oracle, release-only: a yarn lying on a pinned
//! straight yarn (a bed) under gravity tilted by `theta`.
//!
//! What `material.friction` (`c_f`) means: the return mapping
//! (`constitutive.rs`) caps the fibre-frame shear stress `|A01| = gamma
//! |r12| r22` at `c_f` times the normal pressure `-A11 = -(2 mu + lambda)
//! ln r22`. The Kirchhoff stress is `tau = P G^T = Q A Q^T`, so `A01` and
//! `A11` are the shear and normal tractions on the plane along the fibre
//! (normal `q2`): the yield condition is Coulomb's `|tau_t| <= c_f
//! |tau_n|` on that plane, and a yarn whose weight is carried through its
//! cross-section onto a bed along its fibres should hold for `tan theta <
//! c_f` and slide for `tan theta > c_f` with acceleration `g (sin theta -
//! c_f cos theta)` (the incline law, `/docs/obstacle-contact.md`).
//!
//! The bed is held by a pin and the top yarn is free, so they move in two
//! velocity fields (`src/mpm/laws/fields.rs`) whose contact is Coulomb's law in
//! impulse terms with `mu = c_f`: the same coefficient as the return
//! mapping's, so the top yarn slips on the bed, not within its own
//! cross-section, at the same `tan theta = c_f`.

mod common;

use common::{
    friction_scene as yarn_scene_stepped, incline_yarns_toml, on_threads, pin_end, straight,
    with_diameter, worst_momentum_balance, yarns_and_pins_toml,
};
use yarnsim::scene::{TransferScheme, YarnEnd};
use yarnsim::YarnSim;

/// Gravity of the incline scenes.
const G: f64 = 9.8;
/// Time the top yarn settles on the bed before its slip is measured.
const SETTLE: f64 = 0.1;

/// Bed yarn (0.8 m, all vertices pinned) along x at y = 0.4 on 128^2, a
/// second yarn of 0.3 m one cell above it, the built-in material with
/// fibre friction `c_f` and no bending, gravity g tilted by `theta`
/// (downhill along +x), dt 1e-4.
fn incline(theta: f64, c_f: f64, scheme: TransferScheme) -> YarnSim {
    incline_stepped(theta, c_f, scheme, EXPLICIT, None)
}

/// The explicit step of the incline scenes: `[time]` lines.
const EXPLICIT: &str = "dt = 1e-4";
/// Backward Euler at 10x the explicit step.
const IMPLICIT: &str = "dt = 1e-3\nintegrator = \"implicit\"";

/// [`incline`] with the `[time]` lines `time` and the yarn diameter `d`
/// (`material.diameter`, none given: `None`).
fn incline_stepped(
    theta: f64,
    c_f: f64,
    scheme: TransferScheme,
    time: &str,
    d: Option<f64>,
) -> YarnSim {
    let res = 128;
    let yarns = incline_yarns_toml(res);
    let gravity = [G * theta.sin(), -G * theta.cos()];
    let s = yarn_scene_stepped(gravity, res, scheme, c_f, &yarns, time);
    YarnSim::new(&with_diameter(s, d)).unwrap()
}

/// A scene of the built-in material with fibre friction `c_f`, no bending,
/// no walls, dt 1e-4, on `res`^2, with the `[[yarns]]` and `[[pins]]` of
/// `yarns`.
fn yarn_scene(
    gravity: [f64; 2],
    res: u32,
    scheme: TransferScheme,
    c_f: f64,
    yarns: &str,
) -> yarnsim::YarnScene {
    yarn_scene_stepped(gravity, res, scheme, c_f, yarns, EXPLICIT)
}

/// Downhill displacements of the top yarn's centre at the times `ts`
/// (increasing) after settling.
fn slips<const N: usize>(theta: f64, c_f: f64, scheme: TransferScheme, ts: [f64; N]) -> [f64; N] {
    slips_stepped(theta, c_f, scheme, ts, EXPLICIT, None)
}

/// [`slips`] with the `[time]` lines `time` and the yarn diameter `d`.
fn slips_stepped<const N: usize>(
    theta: f64,
    c_f: f64,
    scheme: TransferScheme,
    ts: [f64; N],
    time: &str,
    d: Option<f64>,
) -> [f64; N] {
    let mut sim = incline_stepped(theta, c_f, scheme, time, d);
    sim.advance(SETTLE).unwrap();
    let centre = |sim: &YarnSim| {
        let (a, b) = sim.yarn_endpoints(1);
        0.5 * (a.x + b.x)
    };
    let x0 = centre(&sim);
    let mut now = 0.0;
    ts.map(|t| {
        sim.advance(t - now).unwrap();
        now = t;
        centre(&sim) - x0
    })
}

/// Downhill displacement of the top yarn's centre over `t` after settling.
fn slip(theta: f64, c_f: f64, scheme: TransferScheme, t: f64) -> f64 {
    slips(theta, c_f, scheme, [t])[0]
}

/// Slid: the top yarn moved downhill more than 5 mm (0.64 cells) in 0.5 s
/// (a Coulomb slide at tan theta = 1.1 c_f, c_f = 0.2, covers 27 mm).
fn slides(theta: f64, c_f: f64, scheme: TransferScheme) -> bool {
    slip(theta, c_f, scheme, 0.5) > 5e-3
}

/// Threshold of `tan theta` at `c_f` = 0.2 by three bisection steps between
/// 0.5 c_f and 2 c_f (bracket 0.19 c_f, the midpoint within 9.4 % of the
/// crossing); returns (held at 0.5 c_f, slid at 2 c_f, threshold, bracket).
fn threshold(c_f: f64, scheme: TransferScheme) -> (bool, bool, f64, f64, f64) {
    let held = !slides((0.5 * c_f).atan(), c_f, scheme);
    let slid = slides((2.0 * c_f).atan(), c_f, scheme);
    let (mut lo, mut hi) = (0.5 * c_f, 2.0 * c_f);
    for _ in 0..3 {
        let mid = 0.5 * (lo + hi);
        if slides(mid.atan(), c_f, scheme) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    (held, slid, 0.5 * (lo + hi), lo, hi)
}

/// Mean downhill acceleration over T = 0.3 s after settling at tan theta =
/// 2 c_f, from the second difference `4 (x(T) - 2 x(T/2)) / T^2` (a yarn
/// that slides from the start already moves at the settling time, so
/// `2 x(T) / T^2` would count that speed as acceleration: 1.67 times the
/// Coulomb rate for a slide at that rate from t = 0), and the incline law's
/// `g (sin theta - c_f cos theta)`.
fn acceleration(c_f: f64, scheme: TransferScheme) -> (f64, f64) {
    let theta = (2.0 * c_f).atan();
    let t = 0.3;
    let [half, full] = slips(theta, c_f, scheme, [0.5 * t, t]);
    let a = 4.0 * (full - 2.0 * half) / (t * t);
    (a, G * (theta.sin() - c_f * theta.cos()))
}

/// FLIP (the default transfer): the top yarn holds for tan theta below
/// `c_f` and slides above it, threshold within 15 % of `c_f` = 0.2.
#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn yarn_on_an_inclined_bed_holds_below_and_slides_above_its_friction_flip() {
    let c_f = 0.2;
    let (held, slid, c, lo, hi) = threshold(c_f, TransferScheme::Flip);
    let err = (c - c_f) / c_f;
    eprintln!(
        "incline Flip c_f {c_f}: tan 0.5 c_f held {held}, tan 2 c_f slid {slid}, threshold tan \
         {c:.3} in [{lo:.3}, {hi:.3}] ({:+.1} %)",
        100.0 * err
    );
    // tolerances: holds at 0.5 c_f, slides at 2 c_f, threshold within 15 %
    assert!(held && slid, "held {held}, slid {slid}");
    assert!(err.abs() <= 0.15, "threshold error {err:+.3}");
}

/// The sliding acceleration within 10 % of `g (sin theta - c_f cos theta)`
/// under FLIP and APIC, and APIC's threshold within 15 % of `c_f` (held at
/// 0.5 c_f, slid at 2 c_f).
#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn yarn_on_an_inclined_bed_slides_at_the_coulomb_rate_and_apic_matches() {
    let c_f = 0.2;
    let mut failures = Vec::new();
    for scheme in [TransferScheme::Flip, TransferScheme::Apic] {
        let (a, a_coulomb) = acceleration(c_f, scheme);
        let aerr = (a - a_coulomb) / a_coulomb;
        eprintln!(
            "incline {scheme:?} c_f {c_f}: acceleration at tan 2 c_f {a:.3} m/s^2 against \
             g (sin - c_f cos) {a_coulomb:.3} ({:+.1} %)",
            100.0 * aerr
        );
        // tolerance 10 % on the acceleration
        if aerr.abs() > 0.10 {
            failures.push(format!("{scheme:?}: acceleration {aerr:+.3}"));
        }
        if scheme == TransferScheme::Apic {
            let (held, slid, c, lo, hi) = threshold(c_f, scheme);
            let err = (c - c_f) / c_f;
            eprintln!(
                "incline Apic c_f {c_f}: tan 0.5 c_f held {held}, tan 2 c_f slid {slid}, \
                 threshold tan {c:.3} in [{lo:.3}, {hi:.3}] ({:+.1} %)",
                100.0 * err
            );
            // tolerance: threshold within 15 %
            if !held || !slid || err.abs() > 0.15 {
                failures.push(format!("Apic: threshold {err:+.3}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}

/// A two-field scene (the bed held, the top yarn free) gives the same bits
/// with 1 and 2 threads, and the bed's pin carries the top yarn's weight:
/// held at tan theta = 0.5 c_f, the pin's reaction is the weight of both
/// yarns, `-(m_bed + m_top) g`, within 1 %.
#[test]
fn two_fields_are_bit_identical_for_one_and_two_threads_and_the_pin_carries_the_top_yarn() {
    let t_end = if cfg!(debug_assertions) { 0.005 } else { 0.1 };
    let theta = 0.1_f64.atan();
    let run = |threads: usize| {
        on_threads(threads, || {
            let mut sim = incline(theta, 0.2, TransferScheme::Flip);
            assert!(sim.has_two_fields());
            sim.advance(t_end).unwrap();
            (sim.save_state(), sim.pin_reactions()[0])
        })
    };
    let (a, reaction) = run(1);
    let (b, _) = run(2);
    assert!(a == b, "states differ");
    if !cfg!(debug_assertions) {
        // density 1: 1.1 kg per m of depth in both yarns
        let weight = 1.1 * G;
        let expect = [weight * theta.sin(), weight * theta.cos()];
        let err = ((reaction.x + expect[0]).hypot(reaction.y - expect[1])) / weight;
        eprintln!("incline pin reaction {reaction:?} against the weight {expect:?} ({err:.2e})");
        assert!(err <= 0.01, "pin reaction {reaction:?}, weight {expect:?}");
    }
}

/// The two-field contact conserves momentum: a free yarn dropped on a
/// held tightrope (pinned at both ends only, so most contact nodes are not
/// kinematic) changes the momentum of all particles, every substep, by
/// exactly gravity's impulse plus the pins' (`dt` times
/// [`YarnSim::pin_reactions`], which include what the contact delivers at
/// pinned nodes), to round-off, under both schemes.
#[test]
fn two_field_contact_conserves_momentum_on_a_held_tightrope() {
    // the rope: 0.6 m, 77 vertices, pinned 3 at each end; the yarn: 0.2 m,
    // 26 vertices, 20 mm (1.28 cells) above its middle
    let yarns = yarns_and_pins_toml(
        &[
            straight([0.2, 0.5], [0.8, 0.5], 77),
            straight([0.4, 0.52], [0.6, 0.52], 26),
        ],
        &[pin_end(0, YarnEnd::Start, 3), pin_end(0, YarnEnd::End, 3)],
    );
    for scheme in [TransferScheme::Flip, TransferScheme::Apic] {
        let s = yarn_scene([1.0, -9.8], 64, scheme, 0.2, &yarns);
        let mut sim = YarnSim::new(&s).unwrap();
        assert!(sim.has_two_fields());
        let steps = if cfg!(debug_assertions) { 50 } else { 1500 };
        let worst = worst_momentum_balance(&mut sim, steps);
        // the top yarn rests on the sagging rope, its middle vertex more
        // than half a cell (7.8 mm) above the rope's (vertices 89 and 38)
        let x = &sim.particles().vert.x;
        let gap = x[89].y - x[38].y;
        eprintln!(
            "tightrope {scheme:?}: worst momentum balance {worst:.2e}; rope middle at y {:.4}, top yarn {gap:.4} above it",
            x[38].y
        );
        assert!(
            gap > 0.5 / 64.0,
            "{scheme:?}: the top yarn sank into the rope ({gap:.4})"
        );
        assert!(worst < 1e-12, "{scheme:?}: momentum balance {worst:.3e}");
    }
}

/// Backward Euler at 10x the explicit step (dt 1e-3) with two velocity
/// fields (the bed held, the top yarn free; one solve per field, the
/// fields' Coulomb contact after them, as in the explicit step): the top
/// yarn holds at tan theta = 0.9 c_f and slides at 1.1 c_f (threshold
/// within 10 %), and at tan theta = 2 c_f slides at `g (sin theta - c_f
/// cos theta)` within 5 %.
#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn implicit_two_field_incline_holds_below_and_slides_above_its_friction() {
    let c_f: f64 = 0.2;
    let slides = |k: f64| {
        let [s] = slips_stepped(
            (k * c_f).atan(),
            c_f,
            TransferScheme::Flip,
            [0.5],
            IMPLICIT,
            None,
        );
        eprintln!("implicit incline tan theta = {k} c_f: slip {s:.3e} m in 0.5 s");
        s > 5e-3
    };
    assert!(!slides(0.9), "slid at tan theta = 0.9 c_f");
    assert!(slides(1.1), "held at tan theta = 1.1 c_f");
    let theta = (2.0 * c_f).atan();
    let t = 0.3;
    let [half, full] = slips_stepped(
        theta,
        c_f,
        TransferScheme::Flip,
        [0.5 * t, t],
        IMPLICIT,
        None,
    );
    let a = 4.0 * (full - 2.0 * half) / (t * t);
    let law = G * (theta.sin() - c_f * theta.cos());
    eprintln!(
        "implicit incline tan theta = 2 c_f: acceleration {a:.4} m/s^2, law {law:.4} ({:+.2} %)",
        100.0 * (a - law) / law
    );
    assert!((a - law).abs() <= 0.05 * law, "acceleration {a}, law {law}");
}

/// The two-field scene under backward Euler gives the same bits for 1 and
/// 2 threads.
#[test]
fn implicit_two_fields_are_bit_identical_for_one_and_two_threads() {
    let n = if cfg!(debug_assertions) { 3 } else { 30 };
    let run = |threads: usize| {
        on_threads(threads, || {
            let mut sim = incline_stepped(0.3f64.atan(), 0.2, TransferScheme::Flip, IMPLICIT, None);
            assert!(sim.has_two_fields());
            sim.steps_n(n).unwrap();
            sim.save_state()
        })
    };
    assert!(run(1) == run(2), "states differ");
}

/// The incline with a yarn diameter d = 6 mm (`material.diameter`, 0.77
/// cells at 128^2; the bed and the top yarn are then in contact only where
/// their centre lines are closer than d, `src/mpm/laws/fields.rs`): the
/// top yarn, started one cell above the bed, settles d above it and keeps
/// Coulomb's threshold: holds at tan theta = 0.85 c_f and slides at 1.15
/// c_f (threshold within 15 % of c_f = 0.2, as without a diameter).
#[test]
#[cfg_attr(debug_assertions, ignore = "release-mode test (cargo test --release)")]
fn incline_with_a_yarn_diameter_keeps_its_coulomb_threshold() {
    let c_f: f64 = 0.2;
    let d = 6e-3;
    let slip = |k: f64| {
        let theta = (k * c_f).atan();
        let [s] = slips_stepped(theta, c_f, TransferScheme::Flip, [0.5], EXPLICIT, Some(d));
        eprintln!("incline with d = {d} m, tan theta = {k} c_f: slip {s:.3e} m in 0.5 s");
        s
    };
    // tolerance: the 5 mm slip criterion of `slides`
    assert!(slip(0.85) <= 5e-3, "slid at tan theta = 0.85 c_f");
    assert!(slip(1.15) > 5e-3, "held at tan theta = 1.15 c_f");
    // the top yarn rests d above the bed, within 15 %
    let mut sim = incline_stepped(0.0, c_f, TransferScheme::Flip, EXPLICIT, Some(d));
    sim.advance(0.3).unwrap();
    let p = sim.particles();
    let top = &p.vert.x[p.yarn_vertices[1]..p.yarn_vertices[2]];
    let gap = top.iter().map(|x| x.y - 0.4).sum::<f64>() / top.len() as f64;
    eprintln!("incline with d = {d} m: top yarn {gap:.4e} m above the bed");
    assert!((gap - d).abs() <= 0.15 * d, "gap {gap}, d {d}");
}
