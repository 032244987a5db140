//! The implicit substep's cutback (src/mpm/driver/cutback.rs): a backward
//! Euler substep that fails (Newton does not converge, or a vertex would
//! move more than one cell) is undone and run as two halves, at most
//! `MAX_CUTBACKS` halvings deep. A cut substep is the same bits as the two
//! halves stepped by hand, the clock reads the outer step's end, and a
//! substep that fails at every depth is a `SimError` that says so.

mod common;

use common::same_bits_on_one_and_two_threads;
use yarnsim::mpm::driver::MAX_CUTBACKS;
use yarnsim::scene::builtin::yarn_reference;
use yarnsim::scene::{Integrator, StepSize, YarnScene};
use yarnsim::testing::hanging_chain_toml;
use yarnsim::{SimError, YarnSim};

/// The reference bundle under backward Euler with a fixed `dt`.
fn reference(dt: f64) -> YarnScene {
    let mut s = yarn_reference();
    s.time.integrator = Integrator::Implicit;
    s.time.dt = StepSize::Fixed(dt);
    s
}

/// The particles' state as text (Debug prints each f64 so that it reads
/// back to the same bits: equal text, equal bits).
fn bits(sim: &YarnSim) -> String {
    format!("{:?}", sim.particles())
}

/// Asserts what the step control of `sim` did so far:
/// `(cutbacks, undone, deepest_cut)`.
fn assert_cuts(sim: &YarnSim, expected: (u64, u64, u32)) {
    let st = sim.implicit_stats();
    assert_eq!((st.cutbacks, st.undone, st.deepest_cut), expected, "{st:?}");
}

/// Steps `by_hand` (the state before `cut`'s cut substep) by two plain
/// halves `step_dt(dt / 2)`, which must not cut, and asserts the same bits
/// as `cut`.
fn assert_equals_two_halves(cut: &YarnSim, by_hand: &mut YarnSim, dt: f64) {
    by_hand.step_dt(0.5 * dt).unwrap();
    by_hand.step_dt(0.5 * dt).unwrap();
    assert_eq!(by_hand.implicit_stats().cutbacks, 0);
    assert_eq!(bits(cut), bits(by_hand));
}

/// At dt 1e-2 the free-falling bundle passes one cell (dx / dt = 0.391
/// m/s) in its 4th substep (v = 4 g dt = 0.392 m/s): that substep is cut
/// once, into two of 5e-3 (limit 0.781 m/s), and its result is the same bits
/// as two `step_dt(5e-3)` from the same state; the clock reads 4e-2.
#[test]
fn the_substep_that_passes_a_cell_is_run_as_two_halves() {
    let dt = 1e-2;
    let s = reference(dt);
    let limit = s.dx() / dt;
    let k = (limit / (9.8 * dt)).ceil() as u64;
    assert_eq!(k, 4);
    let mut cut = YarnSim::new(&s).unwrap();
    cut.steps_n(k - 1).unwrap();
    let mut by_hand = cut.clone();
    assert_eq!(cut.implicit_stats().cutbacks, 0);

    cut.step().unwrap();
    // cut before it was tried: (0.294 + 9.8 dt) dt = 3.92e-3 m > dx
    assert_cuts(&cut, (1, 0, 1));
    assert_eq!(cut.steps(), k + 1, "two substeps for the cut one");
    assert!((cut.time() - 4e-2).abs() < 1e-15, "{}", cut.time());

    assert_equals_two_halves(&cut, &mut by_hand, dt);
    let vmax = cut
        .particles()
        .vert
        .v
        .iter()
        .map(|v| v.norm())
        .fold(0.0, f64::max);
    // the speed that tripped the full step, within the halves' limit
    assert!(vmax > limit && vmax < 2.0 * limit, "{vmax}");
}

/// A substep tried and undone: the hanging chain (dx = 1/16 m) under an
/// attractor of 300 m/s^2 (which the advection limit of the starting state
/// does not count), dt 1.6e-2 (limit 3.9 m/s). From rest the step is
/// tried; the attractor takes the vertices to about 4.8 m/s, past a cell,
/// so it is undone and run as two halves of 8e-3 s (2.4 and 4.8 m/s,
/// within their 7.8 m/s), the same bits as `step_dt(8e-3)` twice.
#[test]
fn a_substep_undone_after_a_vertex_passes_a_cell_equals_its_two_halves() {
    let dt = 1.6e-2;
    let mut s = YarnScene::from_toml_str(&hanging_chain_toml(25, 16, &format!("{dt}"))).unwrap();
    s.time.integrator = Integrator::Implicit;
    s.attractor.active = true;
    s.attractor.strength = 300.0;
    s.attractor.position = [0.95, 0.1];
    let mut cut = YarnSim::new(&s).unwrap();
    let mut by_hand = cut.clone();
    cut.step().unwrap();
    assert_cuts(&cut, (1, 1, 1));
    assert_eq!((cut.steps(), cut.time()), (2, dt));
    assert_equals_two_halves(&cut, &mut by_hand, dt);
    assert_eq!(cut.pin_reactions(), by_hand.pin_reactions());
    let vmax = cut.max_speed();
    // past the full step's cell, within the halves'
    assert!(vmax * dt > s.dx() && vmax * 0.5 * dt < s.dx(), "{vmax}");
}

/// With cutbacks the run is still the same bits on one and two threads:
/// the reference bundle at dt 1e-2 through its first cut (the 4th substep)
/// and two more.
#[test]
fn cut_substeps_give_the_same_bits_on_one_and_two_threads() {
    let st = same_bits_on_one_and_two_threads(&reference(1e-2), 6);
    assert!(st.cutbacks >= 1, "{st:?}");
}

/// A substep that fails at every depth is a `SimError` naming the last
/// attempt's reason and the cutbacks, kept for every later step: the
/// hanging chain (dx 1/16 m) at dt 1.6e-2 under the largest gravity an
/// input may have, 1e6 m/s^2, where even dt / 32 = 5e-4 s takes the free
/// end 500 m/s x 5e-4 s = 0.25 m = 4 cells in its first substep.
#[test]
fn a_substep_that_fails_at_every_depth_is_an_error_saying_so() {
    let mut s = YarnScene::from_toml_str(&hanging_chain_toml(25, 16, "1.6e-2")).unwrap();
    s.gravity = [0.0, -1e6];
    s.time.integrator = Integrator::Implicit;
    let mut sim = YarnSim::new(&s).unwrap();
    let e = sim.steps_n(2).unwrap_err();
    eprintln!("{e}");
    match &e {
        SimError::NonFinite { what, .. } => {
            assert!(
                what.contains(&format!("after {MAX_CUTBACKS} cutbacks"))
                    && (what.contains("did not converge") || what.contains("one cell")),
                "{what}"
            );
        }
        e => panic!("{e:?}"),
    }
    let st = sim.implicit_stats();
    assert_eq!(st.deepest_cut, MAX_CUTBACKS, "{st:?}");
    assert_eq!(sim.failure(), Some(&e));
    assert_eq!(sim.step().unwrap_err(), e);
}
