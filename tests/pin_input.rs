//! `motion = "input"` pins: driven at run time through
//! `YarnSim::set_pin_target`, equal to the scene-driven paths, part of the
//! state bytes, bad targets refused.

mod common;

use common::{pin_end, pin_vertex, straight, SceneBuilder};
use yarnsim::math::Vec2;
use yarnsim::mpm::{PinMotion, SimError};
use yarnsim::scene::{PinMotionKind, PinSpec, YarnEnd, YarnScene};
use yarnsim::YarnSim;

/// Two yarns of 20 vertices on a 32^2 grid, plastic, under gravity, with `pins`.
fn two_yarns(pins: &[PinSpec]) -> YarnScene {
    pins.iter()
        .fold(
            SceneBuilder::bare()
                .resolution(32)
                .dt(2e-4)
                .gravity([0.0, -9.8])
                .material(|m| m.plasticity = true)
                .yarn(straight([0.25, 0.7], [0.65, 0.7], 20))
                .yarn(straight([0.3, 0.4], [0.7, 0.4], 20)),
            |b, pin| b.pin(pin.clone()),
        )
        .build()
}

/// `pin` moved by `motion`.
fn moved(motion: PinMotionKind, pin: PinSpec) -> PinSpec {
    PinSpec { motion, ..pin }
}

fn bits(sim: &YarnSim) -> Vec<u64> {
    let p = sim.particles();
    p.vert
        .x
        .iter()
        .chain(&p.vert.v)
        .chain(&p.quad.x)
        .flat_map(|v| [v.x.to_bits(), v.y.to_bits()])
        .collect()
}

/// An input pin given the line's start and velocity once at t = 0 follows
/// the `line` pin's path bit for bit: same trajectory of every particle.
#[test]
fn input_pin_set_once_equals_the_line_pin_bitwise() {
    let start = pin_end(0, YarnEnd::Start, 2);
    let line = two_yarns(&[PinSpec {
        velocity: Some([0.2, -0.1]),
        ..moved(PinMotionKind::Line, start.clone())
    }]);
    let input = two_yarns(&[moved(PinMotionKind::Input, start)]);
    let mut a = YarnSim::new(&line).unwrap();
    let mut b = YarnSim::new(&input).unwrap();
    let x0 = b.particles().vert.x[0];
    assert_eq!(
        b.pins()[0].motion,
        PinMotion::Input {
            position: x0,
            velocity: Vec2::zeros(),
            since: 0.0
        }
    );
    b.set_pin_target(0, x0, Vec2::new(0.2, -0.1)).unwrap();
    // The pinned vertices took the velocity at once, as the line pin's at t = 0.
    assert_eq!(b.particles().vert.v[1], Vec2::new(0.2, -0.1));
    for _ in 0..400 {
        a.step().unwrap();
        b.step().unwrap();
    }
    assert_eq!(bits(&a), bits(&b));
    // The pinned pair moved as one: the second vertex keeps its offset.
    let p = b.particles();
    let t = b.time();
    let expect = x0 + Vec2::new(0.2, -0.1) * t;
    assert_eq!(p.vert.x[0], expect);
    assert_eq!(p.vert.x[1] - p.vert.x[0], input_offset(&input));
}

fn input_offset(s: &YarnScene) -> Vec2 {
    let sim = YarnSim::new(s).unwrap();
    sim.particles().vert.x[1] - sim.particles().vert.x[0]
}

/// Left alone, an input pin is a fixed pin.
#[test]
fn input_pin_without_a_target_is_fixed() {
    let fixed = two_yarns(&[pin_vertex(1, 9, 3)]);
    let input = two_yarns(&[moved(PinMotionKind::Input, pin_vertex(1, 9, 3))]);
    let mut a = YarnSim::new(&fixed).unwrap();
    let mut b = YarnSim::new(&input).unwrap();
    a.steps_n(200).unwrap();
    b.steps_n(200).unwrap();
    assert_eq!(bits(&a), bits(&b));
}

/// The targets are part of the state bytes: a restored state continues
/// with the target it was saved with.
#[test]
fn input_targets_survive_a_state_round_trip() {
    let s = two_yarns(&[moved(PinMotionKind::Input, pin_end(0, YarnEnd::End, 1))]);
    let mut sim = YarnSim::new(&s).unwrap();
    let x = sim.particles().vert.x[19];
    sim.set_pin_target(0, x, Vec2::new(0.0, 0.3)).unwrap();
    sim.steps_n(50).unwrap();
    let saved = sim.save_state();
    assert_eq!(saved.len(), sim.state_size());
    sim.steps_n(50).unwrap();
    let end = bits(&sim);
    let mut other = YarnSim::new(&s).unwrap();
    other.load_state(&saved).unwrap();
    assert_eq!(other.pins()[0].motion, sim.pins()[0].motion);
    other.steps_n(50).unwrap();
    assert_eq!(bits(&other), end);
}

#[test]
fn bad_pin_targets_are_refused() {
    let s = two_yarns(&[
        moved(PinMotionKind::Input, pin_end(0, YarnEnd::End, 1)),
        pin_end(1, YarnEnd::End, 1),
    ]);
    let mut sim = YarnSim::new(&s).unwrap();
    let ok = Vec2::new(0.5, 0.5);
    let bad = |r: Result<(), SimError>, what: &str| match r {
        Err(SimError::BadInput(m)) => assert!(m.contains(what), "{m}"),
        other => panic!("expected a bad input, got {other:?}"),
    };
    bad(sim.set_pin_target(2, ok, ok), "does not exist");
    bad(sim.set_pin_target(1, ok, ok), "not \"input\"");
    bad(
        sim.set_pin_target(0, Vec2::new(f64::NAN, 0.0), ok),
        "finite",
    );
    bad(
        sim.set_pin_target(0, ok, Vec2::new(0.0, f64::INFINITY)),
        "finite",
    );
    bad(sim.set_pin_target(0, Vec2::new(2e6, 0.0), ok), "1e6");
    // Nothing changed.
    assert!(matches!(
        sim.pins()[0].motion,
        PinMotion::Input { velocity, .. } if velocity == Vec2::zeros()
    ));
}
