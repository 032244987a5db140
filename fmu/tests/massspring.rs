//! The MassSpring FMU (the same library with a mass-spring scene in its
//! resources) driven through its exported C functions: the same bits as the
//! library, every integrator through the `integrator` parameter, the driven
//! end on its circle, non-penetration of the cloth, gravity inputs, the
//! `dt` parameter, FMU states, bad input, a trajectory snapshot, and the
//! generated model description.

mod common;

use common::*;
use yarnsim::massspring::scenes::{cloth, wire};
use yarnsim::massspring::{Integrator, IntegratorOptions, MassSpringScene, Simulation, V3};
use yarnsim::scene::Scene;
use yarnsim_fmu::fmi2::*;
use yarnsim_fmu::models::massspring::*;
use yarnsim_fmu::SceneFmu;

/// The wire's frame time, used as the communication step.
const H: f64 = 0.05;

fn particle_vrs(n: usize) -> Vec<u32> {
    (0..3 * n as u32).map(|k| VR_PARTICLE_BASE + k).collect()
}

/// Particle positions followed by kinetic, elastic, gravitational, total
/// energy and the largest strain.
fn outputs(f: &Fmu) -> Vec<f64> {
    let mut vrs = particle_vrs(f.yarns);
    vrs.extend(VR_KINETIC_ENERGY..=VR_MAX_STRAIN);
    f.get_real(&vrs)
        .unwrap_or_else(|s| panic!("fmi2GetReal: {s} {:?}", f.lines()))
}

/// The library run the FMU promises: substep k starts at time k dt.
fn library_steps(sim: &mut Simulation, from: u64, to: u64) {
    let dt = sim.dt();
    for k in from..to {
        sim.state_mut().t = k as f64 * dt;
        sim.step(dt).unwrap();
    }
}

fn library_outputs(sim: &Simulation) -> Vec<f64> {
    let mut v: Vec<f64> = sim
        .positions()
        .iter()
        .flat_map(|p| [p.x, p.y, p.z])
        .collect();
    let e = sim.energies();
    v.extend([e.kinetic, e.elastic, e.gravity, e.total(), sim.max_strain()]);
    v
}

#[test]
fn every_integrator_gives_the_library_bits_on_the_wire() {
    let layout = wire();
    for integrator in Integrator::ALL {
        let f = Fmu::mass_spring(&layout);
        assert_eq!(f.yarns, 11);
        assert_eq!(f.set_string(VR_INTEGRATOR, integrator.name()), fmi2OK);
        f.init();
        assert_eq!(f.get_string(VR_INTEGRATOR), integrator.name());
        let mut sim = Simulation::new(&layout, integrator, IntegratorOptions::default()).unwrap();
        let dt = sim.dt();
        let mut done = 0;
        for k in 0..10 {
            let t = k as f64 * H;
            assert_eq!(f.do_step(t, H), fmi2OK, "{integrator}: {:?}", f.lines());
            let target = ((t + H) / dt).round() as u64;
            library_steps(&mut sim, done, target);
            done = target;
            assert_eq!(f.substeps() as u64, done, "{integrator}");
            assert_eq!(
                outputs(&f),
                library_outputs(&sim),
                "{integrator}, t = {}",
                t + H
            );
        }
    }
}

/// The driven top particle stays on its circle of radius 0.5 in the plane
/// y = 0, at the angle of the FMU's time (period 5 s), whatever the master's
/// step sizes.
#[test]
fn the_driven_end_follows_its_circle_on_the_substep_grid() {
    let f = Fmu::mass_spring(&wire());
    f.init();
    let sim = Simulation::new(&wire(), DEFAULT_INTEGRATOR, IntegratorOptions::default()).unwrap();
    let dt = sim.dt();
    let steps = [0.05, 0.013, 0.2, 0.037, 0.1];
    let mut t = 0.0;
    for h in steps {
        assert_eq!(f.do_step(t, h), fmi2OK, "{:?}", f.lines());
        t += h;
        let p = f
            .get_real(&[VR_PARTICLE_BASE, VR_PARTICLE_BASE + 1, VR_PARTICLE_BASE + 2])
            .unwrap();
        let r = (p[0] * p[0] + p[2] * p[2]).sqrt();
        assert!((r - 0.5).abs() < 1e-12, "radius {r} at t = {t}");
        assert_eq!(p[1], 0.0);
        // Where the scene drives it at the substep grid's time, which is
        // within dt/2 of the FMU's time.
        let ts = (t / dt).round() * dt;
        let (x, _) = sim.system().kinematics[0].at(ts).unwrap();
        assert!(
            (x - V3::from_column_slice(&p)).norm() < 1e-12,
            "{x:?} vs {p:?} at {t}"
        );
    }
}

/// Cloth falls onto the sphere: no particle inside it after any step, the
/// two pinned corners do not move, energy is bounded.
#[test]
fn cloth_through_the_fmu_stays_outside_the_sphere() {
    let layout = cloth();
    let f = Fmu::mass_spring(&layout);
    assert_eq!(f.yarns, 441);
    f.init();
    let h = layout.time.frame_time;
    let first = outputs(&f);
    let sphere = &layout.spheres[0];
    let c = V3::from(sphere.center);
    for k in 0..45 {
        assert_eq!(f.do_step(k as f64 * h, h), fmi2OK, "{:?}", f.lines());
        let out = outputs(&f);
        for i in 0..441 {
            let p = V3::new(out[3 * i], out[3 * i + 1], out[3 * i + 2]);
            assert!(
                (p - c).norm() >= sphere.radius * (1.0 - 1e-9),
                "particle {i} inside the sphere at frame {k}"
            );
        }
        for i in [0, 20] {
            assert_eq!(out[3 * i..3 * i + 3], first[3 * i..3 * i + 3]);
        }
        assert!(out[3 * 441 + 3] <= first[3 * 441 + 3] + 1e-9, "energy grew");
    }
}

#[test]
fn forward_euler_on_the_undamped_cloth_is_refused_at_initialization() {
    let f = Fmu::mass_spring(&cloth());
    assert_eq!(f.set_string(VR_INTEGRATOR, "forward-euler"), fmi2OK);
    assert_eq!(f.init_status(), fmi2Error);
    assert!(f.last_error().contains("no damping"), "{}", f.last_error());
    // An unknown integrator is refused when it is set.
    let g = Fmu::mass_spring(&wire());
    assert_eq!(g.set_string(VR_INTEGRATOR, "runge-kutta"), fmi2Error);
    assert!(g.last_error().contains("unknown integrator"));
}

#[test]
fn gravity_inputs_act_and_bad_values_are_refused() {
    let layout = wire();
    let run = |g: Option<[f64; 3]>| {
        let f = Fmu::mass_spring(&layout);
        f.init();
        if let Some(g) = g {
            assert_eq!(
                f.set_real(&[VR_GRAVITY_X, VR_GRAVITY_Y, VR_GRAVITY_Z], &g),
                fmi2OK
            );
        }
        f.steps_ok(0..10, H);
        outputs(&f)
    };
    let down = run(None);
    let sideways = run(Some([5.0, -9.81, 0.0]));
    // The bottom particle (10) is pushed to +x relative to the plain run.
    assert!(
        sideways[30] > down[30] + 1e-3,
        "{} vs {}",
        sideways[30],
        down[30]
    );
    let f = Fmu::mass_spring(&layout);
    f.init();
    assert_eq!(
        f.get_real(&[VR_GRAVITY_X, VR_GRAVITY_Y, VR_GRAVITY_Z])
            .unwrap(),
        [0.0, -9.81, 0.0]
    );
    assert_eq!(f.set_real(&[VR_GRAVITY_Y], &[f64::NAN]), fmi2Error);
    assert!(
        f.last_error()
            .contains("gravity.y = NaN refused: inputs must be finite"),
        "{}",
        f.last_error()
    );
    let g = Fmu::mass_spring(&layout);
    g.init();
    assert_eq!(g.set_real(&[VR_GRAVITY_X], &[2e6]), fmi2Error);
    assert!(g.last_error().contains("1e6"), "{}", g.last_error());
}

/// Symplectic Euler far beyond its stability bound (dt 0.5 s) with a
/// sideways gravity of 1e5: the energies overflow to inf while the positions
/// are still finite (about 1e157). The step that overflows returns Discard
/// with the terminated flag, never OK, and its outputs are those of the last
/// good state.
#[test]
fn diverging_wire_is_discarded_never_ok_with_inf_outputs() {
    let f = Fmu::mass_spring(&wire());
    assert_eq!(f.setup(0.0, None), fmi2OK);
    // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every pointer
    // argument is a local that outlives the call.
    assert_eq!(unsafe { fmi2EnterInitializationMode(f.c) }, fmi2OK);
    assert_eq!(f.set_string(VR_INTEGRATOR, "symplectic-euler"), fmi2OK);
    assert_eq!(f.set_real(&[VR_DT], &[0.5]), fmi2OK);
    // dt is beyond the stability bound: a warning, not an error.
    // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every pointer
    // argument is a local that outlives the call.
    assert!(unsafe { fmi2ExitInitializationMode(f.c) } <= fmi2Warning);
    assert_eq!(f.set_real(&[VR_GRAVITY_X], &[1e5]), fmi2OK);
    let h = 0.5;
    let mut t = 0.0;
    let mut status = fmi2OK;
    let mut before = outputs(&f);
    let mut steps = 0;
    while steps < 1000 {
        status = f.do_step(t, h);
        if status != fmi2OK {
            break;
        }
        // Every output of an OK step is finite (fmi2GetReal would refuse
        // a non-finite one).
        before = outputs(&f);
        assert!(before.iter().all(|v| v.is_finite()));
        t += h;
        steps += 1;
    }
    assert_eq!(status, fmi2Discard, "{:?}", f.lines());
    assert!(steps > 2, "diverged only after {steps} steps");
    f.assert_discarded_at(t);
    assert_eq!(outputs(&f), before);
    assert_eq!(f.substeps(), steps);
    assert!(f.do_step(t, h) >= fmi2Error);
}

#[test]
fn dt_parameter_sets_the_substep() {
    let f = Fmu::mass_spring(&wire());
    assert_eq!(f.setup(0.0, None), fmi2OK);
    // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every pointer
    // argument is a local that outlives the call.
    assert_eq!(unsafe { fmi2EnterInitializationMode(f.c) }, fmi2OK);
    assert_eq!(f.get_real(&[VR_DT]).unwrap(), [0.0]);
    assert_eq!(f.set_real(&[VR_DT], &[0.01]), fmi2OK);
    // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every pointer
    // argument is a local that outlives the call.
    assert_eq!(unsafe { fmi2ExitInitializationMode(f.c) }, fmi2OK);
    assert_eq!(f.get_real(&[VR_DT]).unwrap(), [0.01]);
    assert_eq!(f.do_step(0.0, H), fmi2OK);
    assert_eq!(f.substeps(), 5);
    // Fixed: not after initialization.
    assert_eq!(f.set_real(&[VR_DT], &[0.02]), fmi2Error);
    assert!(f.last_error().contains("dt is a fixed parameter"));
    let g = Fmu::mass_spring(&wire());
    assert_eq!(g.set_real(&[VR_DT], &[-1.0]), fmi2Error);
}

#[test]
fn fmu_state_round_trip_gives_identical_bits() {
    let f = Fmu::mass_spring(&wire());
    assert_eq!(f.set_string(VR_INTEGRATOR, "trapezoidal"), fmi2OK);
    f.init();
    f.steps_ok(0..5, H);
    let s = f.get_state();
    let bytes = f.serialize(s);
    assert_eq!(&bytes[..8], b"MSFMUST\0");
    let run_on = |f: &Fmu| -> Vec<Vec<f64>> {
        (5..10)
            .map(|k| {
                assert_eq!(f.do_step(k as f64 * H, H), fmi2OK);
                outputs(f)
            })
            .collect()
    };
    let first = run_on(&f);
    let restored = f.set_state_from(&bytes);
    // 5 frames of 10 substeps (the scene's time_step 0.005 s).
    assert_eq!(f.substeps(), 50);
    assert_eq!(f.get_string(VR_INTEGRATOR), "trapezoidal");
    assert_eq!(run_on(&f), first);
    // Into a fresh instance (default integrator): the state carries its
    // parameters.
    let g = Fmu::mass_spring(&wire());
    g.init();
    let s2 = g.set_state_from(&bytes);
    assert_eq!(run_on(&g), first);
    g.free_state(s2);
    f.free_state(restored);
    f.free_state(s);

    // Truncated, corrupt or foreign bytes are refused.
    let h = Fmu::mass_spring(&wire());
    h.init();
    assert_eq!(h.deserialize(&bytes[..bytes.len() - 1]).0, fmi2Error);
    let h = Fmu::mass_spring(&wire());
    h.init();
    let mut bad = bytes.clone();
    let n = bad.len();
    bad[n - 3] ^= 0x40;
    assert_eq!(h.deserialize(&bad).0, fmi2Error);
    assert!(h.last_error().contains("checksum"), "{}", h.last_error());
    let y = Fmu::initialized(&small_scene());
    assert_eq!(y.deserialize(&bytes).0, fmi2Error);
    assert!(y.last_error().contains("other kind"), "{}", y.last_error());
}

/// Gravity switching sideways every 0.5 s for 2 s on the wire (backward
/// Euler): the bottom particle, energies and strain every 0.1 s.
#[test]
fn wire_with_switching_gravity_trajectory() {
    let f = Fmu::mass_spring(&wire());
    f.init();
    let bottom = [
        VR_PARTICLE_BASE + 30,
        VR_PARTICLE_BASE + 31,
        VR_PARTICLE_BASE + 32,
        VR_KINETIC_ENERGY,
        VR_ELASTIC_ENERGY,
        VR_TOTAL_ENERGY,
        VR_MAX_STRAIN,
    ];
    let mut snap = Vec::new();
    for k in 0..40 {
        let t = k as f64 * H;
        let gx = if (t / 0.5) as i64 % 2 == 0 { 4.0 } else { -4.0 };
        assert_eq!(f.set_real(&[VR_GRAVITY_X], &[gx]), fmi2OK);
        assert_eq!(f.do_step(t, H), fmi2OK);
        if k % 2 == 1 {
            snap.push(fmt_row(t + H, &f.get_real(&bottom).unwrap()));
        }
    }
    // Backward Euler steps at the scene's time_step, 0.005 s.
    assert_eq!(f.substeps(), 400);
    insta::assert_snapshot!(snap.join("\n"));
}

#[test]
fn model_description_of_the_wire() {
    let layout = wire();
    let vars = variables(&layout).unwrap();
    let scene = Scene::MassSpring(layout.clone());
    let xml = scene.model_description().unwrap();
    assert!(xml.contains("modelIdentifier=\"MassSpring\""));
    assert!(xml.contains(&format!("guid=\"{}\"", guid(&layout))));
    let outputs = vars.iter().filter(|v| v.causality == "output").count();
    assert_eq!(outputs, 3 * 11 + 6);
    let mut vrs: Vec<(u32, String)> = vars.iter().map(|v| (v.vr, format!("{:?}", v.ty))).collect();
    vrs.sort();
    vrs.dedup();
    assert_eq!(vrs.len(), vars.len());
    for v in &vars {
        if let Some(u) = v.unit {
            assert!(xml.contains(&format!("<Unit name=\"{u}\">")), "{u}");
        }
    }
    // Only the units in use are defined.
    assert!(!xml.contains("<Unit name=\"Pa\">"));
    assert!(xml.contains("name=\"particle[10].z\""));
    assert!(xml.contains("stopTime=\"5.0\" stepSize=\"0.05\""));
    let checked_in = include_str!("../../modelDescription/MassSpring-wire.xml");
    assert!(
        checked_in == xml,
        "modelDescription/MassSpring-wire.xml drifted from the generator; refresh it with\n  cargo run --release -p yarnsim-fmu-pack --bin build-fmu -- --scene wire --model-description modelDescription/MassSpring-wire.xml"
    );
    // The GUID follows the layout.
    let mut other: MassSpringScene = layout.clone();
    other.gravity[1] = -9.8;
    assert_ne!(guid(&other), guid(&layout));
}
