//! The FMI 3.0 Co-Simulation front end driven through its exported C
//! functions: its outputs against the FMI 2.0 front end's (bit for bit),
//! the array outputs against the library's own run, FMU-state round trips,
//! the variable dependencies against the modelDescription, and an insta
//! snapshot of a short run.

mod common;
mod common3;

use common::{fmt_row, small_scene, Fmu};
use common3::*;
use yarnsim::mpm::YarnSim;
use yarnsim::scene::Scene;
use yarnsim_fmu::fmi2::fmi2OK;
use yarnsim_fmu::fmi3::fmu_state::*;
use yarnsim_fmu::fmi3::*;
use yarnsim_fmu::model_description::*;
use yarnsim_fmu::models::yarn::arrays::array_vr;
use yarnsim_fmu::models::yarn::variables::*;
use yarnsim_fmu::SceneFmu;

const H: f64 = 0.01;

/// The vertex counts of the small scene's yarns.
fn vertex_counts() -> Vec<usize> {
    small_scene().curves().iter().map(|c| c.len()).collect()
}

/// All arrays of the small scene (positions, velocities of each yarn) and
/// their total length.
fn all_arrays() -> (Vec<u32>, usize) {
    let n = vertex_counts();
    let vrs = (0..n.len())
        .flat_map(|y| [array_vr(y, false), array_vr(y, true)])
        .collect();
    (vrs, n.iter().map(|k| 4 * k).sum())
}

/// The scalar outputs the FMI 2.0 FMU has: yarn ends, energies, stretch.
fn scalar_vrs(yarns: usize) -> Vec<u32> {
    let mut v: Vec<u32> = (0..4 * yarns as u32).map(|k| VR_YARN_BASE + k).collect();
    v.extend([VR_KINETIC_ENERGY, VR_ELASTIC_ENERGY, VR_MAX_STRETCH]);
    v
}

/// The attractor input of the FMI 2.0 trajectory test at step k.
fn attractor(k: usize) -> [f64; 2] {
    let w = 2.0 * std::f64::consts::PI * (k as f64 * H) / 0.4;
    [0.5 + 0.2 * w.cos(), 0.5 + 0.2 * w.sin()]
}

#[test]
fn outputs_equal_the_fmi2_fmu_bit_for_bit() {
    let scene = small_scene();
    let two = Fmu::new(&scene);
    two.init();
    let three = Fmu3::small();
    three.init();
    let yarns = two.yarns;
    let vrs = scalar_vrs(yarns);
    let (avrs, alen) = all_arrays();
    let inputs = [VR_GRAVITY_X, VR_GRAVITY_Y, VR_ATTRACTOR_STRENGTH];
    assert_eq!(two.set_real(&inputs, &[0.0, 0.0, 40.0]), fmi2OK);
    assert_eq!(three.set(&inputs, &[0.0, 0.0, 40.0]), fmi3OK);
    assert_eq!(two.set_bool(VR_ATTRACTOR_ACTIVE, true), fmi2OK);
    assert_eq!(three.set_bool(VR_ATTRACTOR_ACTIVE, true), fmi3OK);
    let mut compared = 0;
    for k in 0..30 {
        let t = k as f64 * H;
        let p = attractor(k);
        assert_eq!(two.set_real(&[VR_ATTRACTOR_X, VR_ATTRACTOR_Y], &p), fmi2OK);
        assert_eq!(three.set(&[VR_ATTRACTOR_X, VR_ATTRACTOR_Y], &p), fmi3OK);
        assert_eq!(two.do_step(t, H), fmi2OK);
        let (s, term, early, ev, last) = three.step(t, H);
        assert_eq!(
            (s, term, early, ev),
            (fmi3OK, false, false, false),
            "{:?}",
            three.lines()
        );
        assert_eq!(last, t + H);
        let a = two.get_real(&vrs).unwrap();
        let (s, b) = three.get(&vrs, vrs.len());
        assert_eq!(s, fmi3OK);
        for (x, y) in a.iter().zip(&b) {
            assert_eq!(x.to_bits(), y.to_bits());
            compared += 1;
        }
        // The arrays' first and last vertex are the yarn ends.
        let (s, arr) = three.get(&avrs, alen);
        assert_eq!(s, fmi3OK);
        let mut at = 0;
        for (y, n) in vertex_counts().into_iter().enumerate() {
            let pos = &arr[at..at + 2 * n];
            let ends = [pos[0], pos[1], pos[2 * n - 2], pos[2 * n - 1]];
            assert_eq!(ends, b[4 * y..4 * y + 4], "yarn {y}");
            at += 4 * n;
        }
    }
    assert_eq!(compared, 30 * vrs.len());
    // time (the independent variable) follows the steps
    assert_eq!(three.get(&[VR_TIME], 1), (fmi3OK, vec![30.0 * H]));
}

#[test]
fn arrays_equal_the_library_run() {
    let scene = small_scene();
    let f = Fmu3::small();
    f.init();
    let (avrs, alen) = all_arrays();
    let mut sim = YarnSim::new(&scene).unwrap();
    let dt = scene.time.dt.fixed().unwrap();
    let mut done = 0u64;
    let mut compared = 0;
    for k in 0..10 {
        let t = k as f64 * H;
        assert_eq!(f.step(t, H).0, fmi3OK);
        let target = ((t + H) / dt).round() as u64;
        while done < target {
            sim.step().unwrap();
            done += 1;
        }
        let (s, arr) = f.get(&avrs, alen);
        assert_eq!(s, fmi3OK);
        let p = sim.particles();
        let mut at = 0;
        for y in 0..p.num_yarns() {
            let r = p.yarn_vertices[y]..p.yarn_vertices[y + 1];
            for field in [&p.vert.x, &p.vert.v] {
                for v in &field[r.clone()] {
                    assert_eq!(arr[at].to_bits(), v.x.to_bits());
                    assert_eq!(arr[at + 1].to_bits(), v.y.to_bits());
                    at += 2;
                    compared += 2;
                }
            }
        }
        assert_eq!(at, alen);
    }
    assert_eq!(compared, 10 * alen);
}

#[test]
fn fmu_state_round_trip_through_bytes_continues_with_the_same_bits() {
    let f = Fmu3::small();
    f.init();
    let (avrs, alen) = all_arrays();
    for k in 0..5 {
        assert_eq!(f.step(k as f64 * H, H).0, fmi3OK);
    }
    let s = f.get_state();
    let bytes = f.serialize(s);
    f.free_state(s);
    let run = |f: &Fmu3| -> Vec<u64> {
        let mut bits = Vec::new();
        for k in 5..10 {
            assert_eq!(f.set(&[VR_GRAVITY_X], &[k as f64]), fmi3OK);
            assert_eq!(f.step(k as f64 * H, H).0, fmi3OK);
            bits.extend(f.get(&avrs, alen).1.iter().map(|v| v.to_bits()));
        }
        bits
    };
    let first = run(&f);
    // another instance picks the state up from its bytes
    let g = Fmu3::small();
    g.init();
    let (st, s) = g.deserialize(&bytes);
    assert_eq!(st, fmi3OK, "{:?}", g.lines());
    // SAFETY: a live instance and a state it made.
    assert_eq!(unsafe { fmi3SetFMUState(g.c, s) }, fmi3OK);
    g.free_state(s);
    assert_eq!(run(&g), first);
}

#[test]
fn variable_dependencies_match_the_model_description() {
    let scene = Scene::from_toml_str(SMALL_SCENE).unwrap();
    let d = scene.description().unwrap();
    let xml = scene.model_description_fmi3().unwrap();
    let f = Fmu3::small();
    let mut checked = 0;
    for (vr, step, _) in fmi3_outputs(&d) {
        let mut n = usize::MAX;
        // SAFETY: a live instance; `n` is a local.
        let s = unsafe { fmi3GetNumberOfVariableDependencies(f.c, vr, &mut n) };
        assert_eq!(s, fmi3OK, "{:?}", f.lines());
        assert_eq!(n, step.len());
        let deps = step
            .iter()
            .map(u32::to_string)
            .collect::<Vec<_>>()
            .join(" ");
        let line = format!("<Output valueReference=\"{vr}\" dependencies=\"{deps}\"/>");
        assert!(xml.contains(&line), "{line}");
        checked += 1;
    }
    // every array and scalar output: 3 yarns x (4 ends + 2 arrays) + 3 + substeps
    assert_eq!(checked, 3 * 6 + 4);
    // an input has no <Output>: refused
    let mut n = 0;
    // SAFETY: as above.
    let s = unsafe { fmi3GetNumberOfVariableDependencies(f.c, VR_GRAVITY_X, &mut n) };
    assert_eq!(s, fmi3Error);
    f.assert_error_contains("is not an output");
}

#[test]
fn model_description_has_the_arrays_with_their_dimensions() {
    let scene = Scene::from_toml_str(SMALL_SCENE).unwrap();
    let xml = scene.model_description_fmi3().unwrap();
    assert!(xml.contains("fmiVersion=\"3.0\""));
    assert!(xml.contains(&format!("instantiationToken=\"{}\"", scene.guid())));
    assert!(xml.contains("causality=\"independent\""));
    for (y, n) in vertex_counts().into_iter().enumerate() {
        for (what, vel) in [("positions", false), ("velocities", true)] {
            let head = format!(
                "<Float64 name=\"yarn[{y}].{what}\" valueReference=\"{}\"",
                array_vr(y, vel)
            );
            let at = xml.find(&head).unwrap_or_else(|| panic!("{head}"));
            let rest = &xml[at..];
            let dims = format!("<Dimension start=\"{n}\"/>\n      <Dimension start=\"2\"/>");
            assert!(
                rest[..rest.find("</Float64>").unwrap()].contains(&dims),
                "{head}"
            );
        }
    }
    // The FMI 2.0 description of the same scene has no arrays.
    assert!(!scene.model_description().unwrap().contains("Dimension"));
}

/// A short run (gravity off, attractor on a circle): the yarn ends, the
/// energies and the first two vertices' positions and velocities of yarn 0.
#[test]
fn fmi3_attractor_on_a_circle_snapshot() {
    let f = Fmu3::small();
    f.init();
    let inputs = [VR_GRAVITY_X, VR_GRAVITY_Y, VR_ATTRACTOR_STRENGTH];
    assert_eq!(f.set(&inputs, &[0.0, 0.0, 40.0]), fmi3OK);
    assert_eq!(f.set_bool(VR_ATTRACTOR_ACTIVE, true), fmi3OK);
    let vrs = scalar_vrs(3);
    let n = vertex_counts()[0];
    let mut snap = Vec::new();
    for k in 0..12 {
        let t = k as f64 * H;
        assert_eq!(
            f.set(&[VR_ATTRACTOR_X, VR_ATTRACTOR_Y], &attractor(k)),
            fmi3OK
        );
        assert_eq!(f.step(t, H).0, fmi3OK);
        if k % 3 == 2 {
            let (_, mut out) = f.get(&vrs, vrs.len());
            let (_, pos) = f.get(&[array_vr(0, false)], 2 * n);
            let (_, vel) = f.get(&[array_vr(0, true)], 2 * n);
            out.extend(&pos[..4]);
            out.extend(&vel[..4]);
            snap.push(fmt_row(t + H, &out));
        }
    }
    insta::assert_snapshot!(snap.join("\n"));
}

/// The checked-in FMI 3.0 modelDescriptions of the default scene and the
/// wire are what the generator writes (refresh with `build-fmu
/// --fmi-version 3 [--scene wire] --model-description FILE`).
#[test]
fn checked_in_fmi3_model_descriptions_are_current() {
    let yarn = Scene::Yarn(yarnsim::scene::builtin::yarn_reference());
    let wire = Scene::MassSpring(yarnsim::massspring::scenes::wire());
    for (scene, checked_in, file) in [
        (
            yarn,
            include_str!("../../modelDescription/YarnBundle-fmi3.xml"),
            "YarnBundle-fmi3.xml",
        ),
        (
            wire,
            include_str!("../../modelDescription/MassSpring-wire-fmi3.xml"),
            "MassSpring-wire-fmi3.xml",
        ),
    ] {
        assert!(
            scene.model_description_fmi3().unwrap() == checked_in,
            "modelDescription/{file} drifted from the generator"
        );
        assert!(!checked_in.contains("fmi2"), "{file}");
    }
}
