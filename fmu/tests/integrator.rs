//! The YarnBundle FMU's `integrator` parameter (String, `"explicit"` or
//! `"implicit"`, the scene's `time.integrator`), FMI 2.0 and FMI 3.0: the
//! implicit hanging chain gives the library's bits and the chain's period,
//! a scene outside the implicit step's scope is refused at the end of
//! initialization naming the field, and a Newton solve that fails in a step
//! is a Discard with its reason.

mod common;
mod common3;

use std::ffi::CString;

use common::*;
use common3::Fmu3;
use yarnsim::scene::{Integrator, StepSize, YarnScene};
use yarnsim::testing::{hanging_chain_floor_period, hanging_chain_toml, ZeroCrossings};
use yarnsim::YarnSim;
use yarnsim_fmu::fmi2::*;
use yarnsim_fmu::fmi3::common::*;
use yarnsim_fmu::fmi3::values::fmi3SetString;
use yarnsim_fmu::fmi3::*;
use yarnsim_fmu::models::yarn::variables::*;

/// The hanging chain (25 vertices, 16^2, dt 1e-3), explicit as written.
fn chain_text() -> String {
    hanging_chain_toml(25, 16, "1e-3")
}

/// The chain beside a free yarn: some yarns pinned, some not (two
/// velocity fields).
fn mixed_text() -> String {
    chain_text() + "[[yarns]]\npoints = [[0.2, 0.2], [0.3, 0.2]]\nvertices = 5\n"
}

fn mixed_scene() -> YarnScene {
    YarnScene::from_toml_str(&mixed_text()).unwrap()
}

/// The reason of a substep that failed at every cutback.
const FAILED: &str = "after 5 cutbacks of the implicit substep";

fn chain() -> YarnScene {
    YarnScene::from_toml_str(&chain_text()).unwrap()
}

/// Steps the library's `sim` over one communication step of 0.01 s (10
/// substeps of the chain's dt 1e-3) and asserts that the FMU's yarn-end
/// outputs are its bits.
fn assert_ends_are_the_library_bits(f: &Fmu, sim: &mut YarnSim, what: &str) {
    sim.steps_n(10).unwrap();
    let (l, r) = sim.yarn_endpoints(0);
    assert_eq!(
        bits(&f.outputs()[..4]),
        bits(&[l.x, l.y, r.x, r.y]),
        "{what}"
    );
}

/// `integrator = "implicit"` on the chain: the library's bits for the
/// same scene with `time.integrator = "implicit"` at every communication
/// point, other outputs than the explicit step's, and over four periods
/// the free end's period within 0.5 % of the linearised discrete extensible
/// chain (the library's test measures +0.28 % at this resolution).
#[test]
fn integrator_parameter_runs_the_implicit_chain_with_the_library_bits() {
    let scene = chain();
    let explicit = Fmu::initialized(&scene);
    assert_eq!(explicit.get_string(VR_INTEGRATOR), "explicit");
    let f = Fmu::initialized_with(&scene, VR_INTEGRATOR, "implicit");
    assert_eq!(f.get_string(VR_INTEGRATOR), "implicit");
    let mut lib = scene.clone();
    lib.time.integrator = Integrator::Implicit;
    let mut sim = YarnSim::new(&lib).unwrap();
    let h = 0.01;
    let end = VR_YARN_BASE + 2; // yarn[0].right.x
    let mut crossings = ZeroCrossings::new(f.get_real(&[end]).unwrap()[0] - 0.5);
    let mut k = 0;
    while crossings.times.len() < 9 {
        let t = k as f64 * h;
        assert_eq!(f.do_step(t, h), fmi2OK, "{:?}", f.lines());
        if k < 20 {
            assert_eq!(explicit.do_step(t, h), fmi2OK);
            assert_ends_are_the_library_bits(&f, &mut sim, &format!("step {k}"));
            if k == 19 {
                assert_ne!(bits(&f.outputs()[..4]), bits(&explicit.outputs()[..4]));
            }
        }
        let u = f.get_real(&[end]).unwrap()[0] - 0.5;
        crossings.push(t + h, h, u);
        k += 1;
        assert!(k < 800, "no nine zero crossings in 8 s");
    }
    let floor = hanging_chain_floor_period(24, scene.material.k, scene.material.density);
    let err = crossings.period() / floor - 1.0;
    eprintln!(
        "FMU implicit chain (25 vertices, 16^2, dt 1e-3): period {:+.3} % off the extensible floor",
        100.0 * err
    );
    assert!(err.abs() < 5e-3, "period {err:+.4} off the floor");
}

/// The integrator acts through the substeps only: at initialization the
/// outputs are those of the explicit instance, bit for bit (the declared
/// initial dependencies do not name it).
#[test]
fn integrator_changes_no_output_at_initialization() {
    let scene = chain();
    let a = Fmu::initialized(&scene);
    let b = Fmu::initialized_with(&scene, VR_INTEGRATOR, "implicit");
    let vrs = [VR_KINETIC_ENERGY, VR_ELASTIC_ENERGY, VR_MAX_STRETCH];
    assert_eq!(a.get_real(&vrs).unwrap(), b.get_real(&vrs).unwrap());
    assert_eq!(a.outputs(), b.outputs());
    let d = yarnsim_fmu::models::yarn::variables::description(&scene);
    assert!(d
        .dependencies
        .iter()
        .all(|x| !x.initial.contains(&VR_INTEGRATOR)));
}

/// An unknown name is refused at once (fmi2Error naming the parameter and
/// the choices); `"implicit"` runs a scene with held and free yarns (two
/// velocity fields), the small scene (shear, cross-section energy, walls)
/// and the chain with bending; the parameter is fixed after
/// initialization.
#[test]
fn integrator_parameter_takes_the_two_names_and_is_fixed_after_initialization() {
    let f = Fmu::new(&chain());
    assert_eq!(f.set_string(VR_INTEGRATOR, "backward-euler"), fmi2Error);
    f.assert_error_contains("integrator = \"backward-euler\" is not an integrator");
    f.assert_error_contains(
        "\"explicit\", \"implicit\", \"implicit-vertices\" or \"midpoint-vertices\"",
    );

    let g = Fmu::new(&mixed_scene());
    assert_eq!(g.set_string(VR_INTEGRATOR, "implicit"), fmi2OK);
    assert_eq!(g.init_status(), fmi2OK, "{:?}", g.lines());
    assert_eq!(g.do_step(0.0, 0.01), fmi2OK, "{:?}", g.lines());
    let small = Fmu::new(&small_scene());
    assert_eq!(small.set_string(VR_INTEGRATOR, "implicit"), fmi2OK);
    assert_eq!(small.init_status(), fmi2OK, "{:?}", small.lines());
    let b = Fmu::new(&chain());
    assert_eq!(b.set_string(VR_INTEGRATOR, "implicit"), fmi2OK);
    assert_eq!(b.set_real(&[VR_BENDING], &[1e-4]), fmi2OK);
    assert_eq!(b.init_status(), fmi2OK, "{:?}", b.lines());

    let ok = Fmu::new(&chain());
    assert_eq!(ok.set_string(VR_INTEGRATOR, "implicit"), fmi2OK);
    assert_eq!(ok.init_status(), fmi2OK, "{:?}", ok.lines());
    assert_eq!(ok.get_string(VR_INTEGRATOR), "implicit");
    assert_eq!(ok.set_string(VR_INTEGRATOR, "explicit"), fmi2Error);
    ok.assert_error_contains("integrator is a fixed parameter");
}

/// `"implicit-vertices"` and `"midpoint-vertices"` (one yarn's vertices,
/// no grid): the chain gives the library's bits at every communication
/// point; a scene outside their scope (two yarns, a shear stiffness) is
/// refused at the end of initialization naming the scene field.
#[test]
fn gridless_integrators_give_the_library_bits_and_refuse_out_of_scope_scenes() {
    for (name, integ) in [
        ("implicit-vertices", Integrator::ImplicitVertices),
        ("midpoint-vertices", Integrator::MidpointVertices),
    ] {
        let scene = chain();
        let f = Fmu::initialized_with(&scene, VR_INTEGRATOR, name);
        assert_eq!(f.get_string(VR_INTEGRATOR), name);
        let mut lib = scene.clone();
        lib.time.integrator = integ;
        let mut sim = YarnSim::new(&lib).unwrap();
        for k in 0..30 {
            assert_eq!(f.do_step(k as f64 * 0.01, 0.01), fmi2OK, "{:?}", f.lines());
            assert_ends_are_the_library_bits(&f, &mut sim, &format!("{name} step {k}"));
        }
        let two = Fmu::new(&mixed_scene());
        assert_eq!(two.set_string(VR_INTEGRATOR, name), fmi2OK);
        assert_eq!(two.init_status(), fmi2Error, "{:?}", two.lines());
        let log = format!("{:?}", two.lines());
        assert!(log.contains("yarns") && log.contains(name), "{log}");
        let small = Fmu::new(&small_scene());
        assert_eq!(small.set_string(VR_INTEGRATOR, name), fmi2OK);
        assert_eq!(small.init_status(), fmi2Error, "{:?}", small.lines());
        let log = format!("{:?}", small.lines());
        assert!(
            log.contains("material.gamma") || log.contains("yarns"),
            "{log}"
        );
    }
}

/// A step whose implicit substep fails at every cutback (dt 1.6e-2 and
/// gravity 1e6 m/s^2, the largest input allowed: even dt / 32 moves the
/// free end 4 cells, as the library reports for the same scene) returns
/// fmi2Discard with the reason; the outputs are those of the last good
/// state.
#[test]
fn an_implicit_substep_failing_at_every_cutback_is_discarded_with_its_reason() {
    let mut lib = chain();
    lib.time.integrator = Integrator::Implicit;
    lib.time.dt = StepSize::Fixed(1.6e-2);
    lib.gravity = [0.0, -1e6];
    let e = YarnSim::new(&lib)
        .unwrap()
        .steps_n(2)
        .unwrap_err()
        .to_string();
    assert!(e.contains(FAILED), "{e}");

    let f = Fmu::new(&chain());
    assert_eq!(f.set_string(VR_INTEGRATOR, "implicit"), fmi2OK);
    assert_eq!(f.set_real(&[VR_DT], &[1.6e-2]), fmi2OK);
    assert_eq!(
        f.set_real(&[VR_GRAVITY_X, VR_GRAVITY_Y], &[0.0, -1e6]),
        fmi2OK
    );
    f.init();
    let before = f.outputs();
    assert_eq!(f.do_step(0.0, 0.016), fmi2Discard);
    eprintln!("discarded: {}", f.last_error());
    f.assert_error_contains(FAILED);
    f.assert_discarded_at(0.0);
    assert_eq!(f.outputs(), before);
}

fn set_string3(f: &Fmu3, vr: u32, v: &str) -> fmi3Status {
    let s = CString::new(v).unwrap();
    let p = s.as_ptr();
    // SAFETY: `f.c` is a live instance; one value reference and one live string.
    unsafe { fmi3SetString(f.c, &vr, 1, &p, 1) }
}

/// Enter and exit initialization mode (start 0); the exit's status.
fn init3_status(f: &Fmu3) -> fmi3Status {
    // SAFETY: `f.c` is a live instance.
    unsafe {
        assert_eq!(
            fmi3EnterInitializationMode(f.c, false, 0.0, 0.0, false, 0.0),
            fmi3OK
        );
        fmi3ExitInitializationMode(f.c)
    }
}

/// FMI 3.0: the same parameter runs the implicit chain with the library's
/// bits, takes a scene with two velocity fields, refuses an unknown name with fmi3Error, and a
/// substep that fails at every cutback is an fmi3Discard with its reason.
#[test]
fn fmi3_integrator_parameter() {
    let text = chain_text();
    let f = Fmu3::new(&text);
    assert_eq!(set_string3(&f, VR_INTEGRATOR, "implicit"), fmi3OK);
    f.init();
    let mut lib = chain();
    lib.time.integrator = Integrator::Implicit;
    let mut sim = YarnSim::new(&lib).unwrap();
    let ends = [
        VR_YARN_BASE,
        VR_YARN_BASE + 1,
        VR_YARN_BASE + 2,
        VR_YARN_BASE + 3,
    ];
    for k in 0..10 {
        assert_eq!(f.step(k as f64 * 0.01, 0.01).0, fmi3OK, "{:?}", f.lines());
        sim.steps_n(10).unwrap();
    }
    let (l, r) = sim.yarn_endpoints(0);
    let (s, out) = f.get(&ends, 4);
    assert_eq!(s, fmi3OK);
    assert_eq!(out, vec![l.x, l.y, r.x, r.y]);

    let g = Fmu3::new(&mixed_text());
    assert_eq!(set_string3(&g, VR_INTEGRATOR, "implicit"), fmi3OK);
    assert_eq!(init3_status(&g), fmi3OK, "{:?}", g.lines());
    assert_eq!(set_string3(&Fmu3::small(), VR_INTEGRATOR, "rk4"), fmi3Error);

    let d = Fmu3::new(&text);
    assert_eq!(set_string3(&d, VR_INTEGRATOR, "implicit"), fmi3OK);
    assert_eq!(d.set(&[VR_DT], &[1.6e-2]), fmi3OK);
    assert_eq!(d.set(&[VR_GRAVITY_X, VR_GRAVITY_Y], &[0.0, -1e6]), fmi3OK);
    d.init();
    assert_eq!(d.step(0.0, 0.016).0, fmi3Discard);
    d.assert_error_contains(FAILED);
}

/// The integrator is part of the FMU state: an implicit instance's
/// serialized state set into an explicit instance of the same scene makes
/// it run the implicit step, with the implicit instance's bits.
#[test]
fn integrator_travels_in_the_serialized_state() {
    let scene = chain();
    let f = Fmu::initialized_with(&scene, VR_INTEGRATOR, "implicit");
    f.steps_ok(0..5, 0.01);
    let bytes = f.state_bytes();
    let g = Fmu::initialized_from(&scene, &bytes);
    assert_eq!(g.get_string(VR_INTEGRATOR), "implicit");
    assert_eq!(f.output_bits(5..10, 0.01), g.output_bits(5..10, 0.01));
}
