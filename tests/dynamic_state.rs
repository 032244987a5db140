//! `YarnSim::dynamic_state` / `set_dynamic_state`: the copy of the dynamic
//! state (no grid, no scratch) that the FMU's `fmi2GetFMUstate` keeps.
//! Restored into the same or a fresh simulation it continues bit for bit,
//! under APIC and FLIP, with a driven pin; its bytes are `save_state`'s.

mod common;

use common::{bundle, pin_end, SceneBuilder};
use yarnsim::math::Vec2;
use yarnsim::mpm::driver::state::StateError;
use yarnsim::scene::{PinMotionKind, PinSpec, TransferScheme, WallMode, YarnEnd, YarnScene};
use yarnsim::YarnSim;

/// Two yarns falling onto a circle under `scheme`, the first one's start
/// vertex pinned with `motion`; `count` copies of the yarn.
fn pinned(scheme: TransferScheme, count: u32, motion: PinMotionKind) -> YarnScene {
    SceneBuilder::bare()
        .resolution(32)
        .dt(2e-4)
        .gravity([0.0, -9.8])
        .material(|m| m.plasticity = true)
        .scheme(scheme)
        .walls(WallMode::Sticky)
        .obstacle([0.5, 0.45], 0.1, 0.3)
        .yarn(bundle([0.25, 0.7], [0.75, 0.7], 20, count, [0.0, 0.05]))
        .pin(PinSpec {
            motion,
            ..pin_end(0, YarnEnd::Start, 1)
        })
        .build()
}

/// The scene of the tests: two yarns, the first one's start driven (`input`).
fn input_pinned(scheme: TransferScheme) -> YarnScene {
    pinned(scheme, 2, PinMotionKind::Input)
}

/// Every particle array the stepper reads, and the pin reactions, as bits.
fn bits(sim: &YarnSim) -> Vec<u64> {
    let p = sim.particles();
    let vecs = p
        .vert
        .x
        .iter()
        .chain(&p.vert.v)
        .chain(&p.quad.x)
        .chain(&p.quad.v);
    let mats = p.vert.c.iter().chain(&p.quad.c).chain(&p.quad.d);
    vecs.flat_map(|v| [v.x.to_bits(), v.y.to_bits()])
        .chain(mats.flat_map(|m| m.iter().map(|e| e.to_bits()).collect::<Vec<_>>()))
        .chain(
            sim.pin_reactions()
                .iter()
                .flat_map(|r| [r.x.to_bits(), r.y.to_bits()]),
        )
        .chain([sim.time().to_bits(), sim.steps()])
        .collect()
}

/// Drives the pin along a curve, one target per 10 substeps, from substep `k0`.
fn run(sim: &mut YarnSim, k0: u64, n: u64) {
    for k in k0..k0 + n {
        if k % 10 == 0 {
            let t = sim.time();
            let x = Vec2::new(0.25 + 0.3 * t, 0.7 + 0.1 * (20.0 * t).sin());
            let v = Vec2::new(0.3, 2.0 * (20.0 * t).cos());
            sim.set_pin_target_at(0, x, v, t).unwrap();
        }
        sim.step().unwrap();
    }
}

#[test]
fn dynamic_state_continues_bit_for_bit() {
    for scheme in [TransferScheme::Apic, TransferScheme::Flip] {
        let s = input_pinned(scheme);
        let mut sim = YarnSim::new(&s).unwrap();
        run(&mut sim, 0, 45);
        let saved = sim.dynamic_state();
        assert_eq!(saved.steps(), 45);
        run(&mut sim, 45, 60);
        let first = bits(&sim);

        // Back into the same simulation (its grid holds the later steps).
        sim.set_dynamic_state(&saved).unwrap();
        assert_eq!(sim.steps(), 45);
        run(&mut sim, 45, 60);
        assert_eq!(bits(&sim), first, "{scheme:?}: same simulation");

        // Into a fresh simulation of the scene.
        let mut fresh = YarnSim::new(&s).unwrap();
        fresh.set_dynamic_state(&saved).unwrap();
        run(&mut fresh, 45, 60);
        assert_eq!(bits(&fresh), first, "{scheme:?}: fresh simulation");

        // Its bytes are save_state's, and they decode to it.
        let mut at = YarnSim::new(&s).unwrap();
        at.set_dynamic_state(&saved).unwrap();
        let bytes = at.save_state();
        assert_eq!(sim.encode_state(&saved).unwrap(), bytes);
        assert_eq!(fresh.decode_state(&bytes).unwrap(), saved);
    }
}

#[test]
fn a_dynamic_state_of_another_scene_is_refused_and_changes_nothing() {
    let s = input_pinned(TransferScheme::Apic);
    let mut sim = YarnSim::new(&s).unwrap();
    run(&mut sim, 0, 5);
    let other = pinned(TransferScheme::Apic, 3, PinMotionKind::Input);
    let foreign = YarnSim::new(&other).unwrap().dynamic_state();
    let before = bits(&sim);
    assert!(matches!(
        sim.set_dynamic_state(&foreign),
        Err(StateError::CountMismatch { .. })
    ));
    assert!(sim.encode_state(&foreign).is_err());
    assert_eq!(bits(&sim), before);
    // No input pin: the pin targets do not fit either.
    let unpinned = pinned(TransferScheme::Apic, 2, PinMotionKind::Fixed);
    let fixed = YarnSim::new(&unpinned).unwrap().dynamic_state();
    assert_eq!(sim.set_dynamic_state(&fixed), Err(StateError::OtherScene));
    assert_eq!(bits(&sim), before);
}
