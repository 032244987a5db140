//! The transfer-scheme parameters and the driven pins of the YarnBundle FMU:
//! `transfer.scheme` / `transfer.flip_ratio` give the library's bits and
//! refuse bad values; `pin[i].*` inputs drive a `motion = "input"` pin on a
//! path the test chooses (compared with the library's `line` and `circle`
//! pins), and `pin[i].force.*` carries a hanging yarn's weight.

mod common;

use common::*;
use yarnsim::math::Vec2;
use yarnsim::mpm::YarnSim;
use yarnsim::scene::{PinMotionKind, TransferScheme, YarnScene, YarnSpec};
use yarnsim::testing::{hanging_chain_toml, CHAIN_GRAVITY};
use yarnsim_fmu::fmi2::*;
use yarnsim_fmu::models::yarn::variables::*;

const H: f64 = 0.01;

/// The FMU's yarn ends and energies after 8 steps of `H`.
fn fmu_run(f: &Fmu) -> Vec<f64> {
    f.steps_ok(0..8, H);
    f.outputs()
}

/// The same outputs from the library.
fn library_run(scene: &YarnScene) -> Vec<f64> {
    let mut sim = YarnSim::new(scene).unwrap();
    sim.steps_n(8 * 50).unwrap();
    library_outputs(&sim)
}

#[test]
fn transfer_parameters_give_the_library_bits() {
    let scene = small_scene();
    assert_eq!(scene.transfer.scheme, TransferScheme::Flip);
    let default = {
        let f = Fmu::initialized(&scene);
        assert_eq!(f.get_string(VR_TRANSFER_SCHEME), "flip");
        assert_eq!(f.get_real(&[VR_FLIP_RATIO]), Ok(vec![1.0]));
        fmu_run(&f)
    };
    assert_eq!(bits(&default), bits(&library_run(&scene)));
    let mut outs = Vec::new();
    for (scheme, ratio) in [("apic", None), ("flip", Some(0.9)), ("apic", Some(0.5))] {
        let f = Fmu::new(&scene);
        assert_eq!(f.set_string(VR_TRANSFER_SCHEME, scheme), fmi2OK);
        if let Some(r) = ratio {
            assert_eq!(f.set_real(&[VR_FLIP_RATIO], &[r]), fmi2OK);
        }
        f.init();
        assert_eq!(f.get_string(VR_TRANSFER_SCHEME), scheme);
        let out = fmu_run(&f);
        let mut lib = scene.clone();
        lib.transfer.scheme = if scheme == "apic" {
            TransferScheme::Apic
        } else {
            TransferScheme::Flip
        };
        if let Some(r) = ratio {
            lib.transfer.flip_ratio = r;
        }
        assert_eq!(bits(&out), bits(&library_run(&lib)), "{scheme} {ratio:?}");
        assert_ne!(bits(&out), bits(&default), "{scheme} {ratio:?}");
        outs.push(out);
    }
    // APIC ignores the FLIP ratio.
    assert_eq!(bits(&outs[0]), bits(&outs[2]));
}

#[test]
fn bad_transfer_values_are_refused_with_a_log_line() {
    let f = Fmu::new(&small_scene());
    for bad in ["", "FLIP", "asflip", "pic"] {
        assert_eq!(f.set_string(VR_TRANSFER_SCHEME, bad), fmi2Error, "{bad}");
        let e = f.last_error();
        assert!(
            e.contains("transfer.scheme") && e.contains("\"flip\" or \"apic\""),
            "{e}"
        );
        // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
        // pointer argument is a local that outlives the call.
        unsafe { assert_eq!(fmi2Reset(f.c), fmi2OK) };
    }
    for bad in [1.5, -0.1, 1.0 + 1e-12] {
        assert_eq!(f.set_real(&[VR_FLIP_RATIO], &[bad]), fmi2Error, "{bad}");
        assert!(f.last_error().contains("at most 1"), "{}", f.last_error());
        // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
        // pointer argument is a local that outlives the call.
        unsafe { assert_eq!(fmi2Reset(f.c), fmi2OK) };
    }
    assert_eq!(f.set_real(&[VR_FLIP_RATIO], &[f64::NAN]), fmi2Error);
    // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every pointer
    // argument is a local that outlives the call.
    unsafe { assert_eq!(fmi2Reset(f.c), fmi2OK) };
    // The bounds themselves are accepted.
    for ok in [0.0, 1.0] {
        assert_eq!(f.set_real(&[VR_FLIP_RATIO], &[ok]), fmi2OK);
    }
    f.init();
    assert_eq!(f.get_string(VR_TRANSFER_SCHEME), "flip");
    assert_eq!(f.get_real(&[VR_FLIP_RATIO]), Ok(vec![1.0]));
    // Fixed parameters: refused after initialization.
    assert_eq!(f.set_string(VR_TRANSFER_SCHEME, "apic"), fmi2Error);
}

#[test]
fn transfer_parameters_travel_in_the_fmu_state() {
    let scene = small_scene();
    let f = Fmu::initialized_with(&scene, VR_TRANSFER_SCHEME, "apic");
    f.steps_ok(0..3, H);
    let bytes = f.state_bytes();
    f.steps_ok(3..6, H);
    let end = f.outputs();
    // A fresh instance with the default scheme takes the state's.
    let g = Fmu::initialized_from(&scene, &bytes);
    assert_eq!(g.get_string(VR_TRANSFER_SCHEME), "apic");
    g.steps_ok(3..6, H);
    assert_eq!(bits(&g.outputs()), bits(&end));
}

// ---- driven pins -------------------------------------------------------------

/// One yarn of 24 vertices with its start pinned by `motion` (TOML lines),
/// a second free yarn, gravity, 48^2 grid, dt 2e-4.
fn pinned_scene(motion: &str) -> YarnScene {
    let text = SMALL_SCENE.replace(
        "count = 3\nspacing = [0.0, 0.03]",
        &format!(
            "count = 2\nspacing = [0.0, 0.1]\n\n[[pins]]\nyarn = 0\nend = \"start\"\n{motion}\n"
        ),
    );
    assert_ne!(text, SMALL_SCENE);
    YarnScene::from_toml_str(&text).unwrap()
}

fn pin_vrs(i: u32) -> [u32; 4] {
    let b = VR_PIN_BASE + 8 * i;
    [b, b + 1, b + 2, b + 3]
}

fn force_vrs(i: u32) -> [u32; 2] {
    let b = VR_PIN_BASE + 8 * i + PIN_FORCE;
    [b, b + 1]
}

/// Everything the FMU serves of the pinned scenes: yarn ends, energies,
/// the pin force.
fn pin_outputs(f: &Fmu) -> Vec<f64> {
    let mut v = f.outputs();
    v.extend(f.get_real(&force_vrs(0)).unwrap());
    v
}

/// [`library_outputs`] and the pin's force.
fn library_outputs_with(sim: &YarnSim, force: Vec2) -> Vec<f64> {
    let mut out = library_outputs(sim);
    out.extend([force.x, force.y]);
    out
}

/// The pin variables exist for this scene, with start values at the
/// pinned vertex, and bad pin inputs are refused.
#[test]
fn pin_variables_follow_the_scene() {
    let s = pinned_scene("motion = \"input\"");
    let vars = variables(&s);
    let names: Vec<&str> = vars
        .iter()
        .filter(|v| v.vr >= VR_PIN_BASE)
        .map(|v| v.name.as_str())
        .collect();
    assert_eq!(
        names,
        [
            "pin[0].x",
            "pin[0].y",
            "pin[0].vx",
            "pin[0].vy",
            "pin[0].force.x",
            "pin[0].force.y"
        ]
    );
    let f = Fmu::new(&s);
    let enter = |f: &Fmu| {
        assert_eq!(f.setup(0.0, None), fmi2OK);
        // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
        // pointer argument is a local that outlives the call.
        assert_eq!(unsafe { fmi2EnterInitializationMode(f.c) }, fmi2OK);
    };
    enter(&f);
    assert_eq!(
        f.get_real(&pin_vrs(0)),
        Ok(vec![0.25, 0.65, 0.0, 0.0]),
        "start values: the pinned vertex at rest"
    );
    assert_eq!(f.get_real(&force_vrs(0)), Ok(vec![0.0, 0.0]));
    for (vals, what) in [
        ([f64::NAN, 0.5, 0.0, 0.0], "pin[0].x = NaN refused"),
        ([0.5, 0.5, f64::INFINITY, 0.0], "pin[0].vx = inf refused"),
        ([2e6, 0.5, 0.0, 0.0], "absurd"),
        ([0.5, 0.5, 0.0, -3e6], "absurd"),
    ] {
        assert_eq!(f.set_real(&pin_vrs(0), &vals), fmi2Error);
        assert!(f.last_error().contains(what), "{}", f.last_error());
        // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every
        // pointer argument is a local that outlives the call.
        unsafe { assert_eq!(fmi2Reset(f.c), fmi2OK) };
        enter(&f);
    }
    assert_eq!(f.get_real(&pin_vrs(0)), Ok(vec![0.25, 0.65, 0.0, 0.0]));
    // A fixed pin has outputs only.
    let fixed = pinned_scene("");
    let vars = variables(&fixed);
    assert!(vars
        .iter()
        .all(|v| !(VR_PIN_BASE..VR_PIN_BASE + 4).contains(&v.vr)));
    let g = Fmu::new(&fixed);
    assert_eq!(g.set_real(&[VR_PIN_BASE], &[0.3]), fmi2Error);
    g.assert_error_contains("pin[0].x (value reference 2000) is not an input");
    // SAFETY: `g.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every pointer
    // argument is a local that outlives the call.
    unsafe { assert_eq!(fmi2Reset(g.c), fmi2OK) };
    enter(&g);
    assert_eq!(g.get_real(&force_vrs(0)), Ok(vec![0.0, 0.0]));
    // The XML declares the pin forces independent of every input.
    let xml = model_description(&s);
    assert!(xml.contains("name=\"pin[0].force.y\""));
    assert!(xml.contains("unit=\"N/m\""));
}

/// The test drives the input pin on a circle (h = 0.01 s, 50 substeps per
/// step): the FMU gives the bits of the library run with the same targets
/// (`set_pin_target_at` at each communication point), the pinned vertex
/// sits on `x_in + v_in (t - t_c)` exactly, and the pin force output is
/// the mean of the library's `-pin_reactions()` over the step's substeps.
#[test]
fn input_pin_driven_on_a_circle_gives_the_library_bits() {
    let s = pinned_scene("motion = \"input\"");
    let (c, r0, w) = (Vec2::new(0.35, 0.65), Vec2::new(-0.1, 0.0), 2.0);
    let path = |t: f64| {
        let (sn, cs) = (w * t).sin_cos();
        let r = Vec2::new(cs * r0.x - sn * r0.y, sn * r0.x + cs * r0.y);
        (c + r, Vec2::new(-r.y, r.x) * w)
    };
    let f = Fmu::initialized(&s);
    let mut sim = YarnSim::new(&s).unwrap();
    let mut worst_pin: f64 = 0.0;
    for k in 0..20 {
        let t = k as f64 * H;
        let (x, v) = path(t);
        assert_eq!(f.set_real(&pin_vrs(0), &[x.x, x.y, v.x, v.y]), fmi2OK);
        assert_eq!(f.do_step(t, H), fmi2OK, "{:?}", f.lines());
        sim.set_pin_target_at(0, x, v, t).unwrap();
        let mut sum = Vec2::zeros();
        for _ in 0..50 {
            sim.step().unwrap();
            sum -= sim.pin_reactions()[0];
        }
        let out = pin_outputs(&f);
        assert_eq!(
            bits(&out),
            bits(&library_outputs_with(&sim, sum / 50.0)),
            "step {k}"
        );
        // The pinned end: x_in + v_in (t_end - t_c), to round-off.
        let end = x + v * (sim.time() - t);
        worst_pin = worst_pin.max((Vec2::new(out[0], out[1]) - end).norm());
    }
    assert!(worst_pin < 1e-15, "{worst_pin}");
}

/// The FMU state of a driven scene under FLIP (pin targets, pin force
/// sums, the `transfer.scheme` parameter, no grid): get it, run on with
/// moving pin inputs, set it back and run the same inputs: identical bits
/// (outputs and pin forces after every step), in this instance and, from
/// the serialized bytes, in a fresh one.
#[test]
fn driven_pin_state_round_trip_gives_identical_bits() {
    let s = pinned_scene("motion = \"input\"");
    let drive = |f: &Fmu, k0: usize, n: usize| -> Vec<u64> {
        let mut out = Vec::new();
        for k in k0..k0 + n {
            let t = k as f64 * H;
            let x = [0.25 + 0.2 * t, 0.65 + 0.05 * (9.0 * t).sin()];
            let v = [0.2, 0.45 * (9.0 * t).cos()];
            assert_eq!(f.set_real(&pin_vrs(0), &[x[0], x[1], v[0], v[1]]), fmi2OK);
            assert_eq!(f.do_step(t, H), fmi2OK, "{:?}", f.lines());
            out.extend(bits(&pin_outputs(f)));
        }
        out
    };
    let f = Fmu::initialized_with(&s, VR_TRANSFER_SCHEME, "flip");
    drive(&f, 0, 4);
    let st = f.get_state();
    let bytes = f.serialize(st);
    let first = drive(&f, 4, 6);
    f.set_state(st);
    assert_eq!(drive(&f, 4, 6), first);
    f.free_state(st);

    let g = Fmu::initialized_from(&s, &bytes);
    assert_eq!(g.get_string(VR_TRANSFER_SCHEME), "flip");
    assert_eq!(drive(&g, 4, 6), first);
}

/// Inputs on the substep grid (h = dt) reproduce the scene-driven pins:
/// a `line` pin within round-off everywhere (both prescribe C = 0), and a
/// `circle` pin exactly at the pinned vertex but not in the rest of the
/// yarn: the circle pin also prescribes its rotation's velocity gradient
/// (C = omega J) to the pinned vertex's affine momentum, which an input pin
/// (a translation) does not; that difference is measured here.
#[test]
fn input_pin_on_the_substep_grid_reproduces_line_and_circle_pins() {
    let input = pinned_scene("motion = \"input\"");
    let dt = input.time.dt.fixed().unwrap();
    let steps = 250; // 0.05 s
    let run_fmu = |target: &dyn Fn(f64) -> (Vec2, Vec2)| {
        let f = Fmu::initialized(&input);
        let mut rows = Vec::new();
        for k in 0..steps {
            let t = k as f64 * dt;
            // Chosen so that x_in + v_in dt is the path at the substep's end.
            let (x1, v1) = target(t + dt);
            let x = x1 - v1 * dt;
            assert_eq!(f.set_real(&pin_vrs(0), &[x.x, x.y, v1.x, v1.y]), fmi2OK);
            assert_eq!(f.do_step(t, dt), fmi2OK, "{:?}", f.lines());
            rows.push(pin_outputs(&f));
        }
        rows
    };
    let run_lib = |s: &YarnScene| {
        let mut sim = YarnSim::new(s).unwrap();
        (0..steps)
            .map(|_| {
                sim.step().unwrap();
                library_outputs_with(&sim, -sim.pin_reactions()[0])
            })
            .collect::<Vec<_>>()
    };
    let diff = |a: &[Vec<f64>], b: &[Vec<f64>], cols: std::ops::Range<usize>| {
        a.iter()
            .zip(b)
            .flat_map(|(x, y)| cols.clone().map(move |i| (x[i] - y[i]).abs()))
            .fold(0.0, f64::max)
    };
    // line
    let vel = Vec2::new(0.3, -0.2);
    let x0 = Vec2::new(0.25, 0.65);
    let line = pinned_scene("motion = \"line\"\nvelocity = [0.3, -0.2]");
    let a = run_fmu(&|t| (x0 + vel * t, vel));
    let b = run_lib(&line);
    let ends = diff(&a, &b, 0..8);
    let pin = diff(&a, &b, 0..2);
    eprintln!("line: pinned vertex {pin:.2e} m, yarn ends {ends:.2e} m");
    assert!(pin < 1e-15 && ends < 1e-12, "{pin} {ends}");
    // circle
    let circle = pinned_scene("motion = \"circle\"\ncenter = [0.35, 0.65]\nangular_velocity = 2.0");
    let pinfo = YarnSim::new(&circle).unwrap().pins()[0].clone();
    let a = run_fmu(&|t| pinfo.target(0, t));
    let b = run_lib(&circle);
    let pin = diff(&a, &b, 0..2);
    let ends = diff(&a, &b, 0..8);
    let force = diff(&a, &b, 11..13);
    eprintln!(
        "circle: pinned vertex {pin:.2e} m, yarn ends {ends:.2e} m, pin force {force:.2e} N/m (C of the circle pin)"
    );
    assert!(pin < 1e-15, "{pin}");
    assert!(ends < 1e-3, "{ends}");
}

/// A yarn hanging from an input pin held at its start: the mean pin force
/// is the yarn's weight, pointing down.
#[test]
fn hanging_yarn_pulls_its_input_pin_with_its_weight() {
    // the hanging chain's material, grid and substep (k 2000, no
    // cross-section energy, 64^2, dt 1e-4), on a straight yarn 0.5 m long
    let g = CHAIN_GRAVITY;
    let mut s = YarnScene::from_toml_str(&hanging_chain_toml(50, 64, "1e-4")).unwrap();
    s.yarns[0] = YarnSpec {
        points: None,
        start: Some([0.5, 0.9]),
        end: Some([0.5, 0.4]),
        ..s.yarns[0].clone()
    };
    s.pins[0].motion = PinMotionKind::Input;
    s.validate().unwrap();
    let weight = YarnSim::new(&s).unwrap().diagnostics().total_mass * g;
    let f = Fmu::initialized(&s);
    let h = 0.01;
    let mut sum = Vec2::zeros();
    let mut n = 0;
    for k in 0..60 {
        let t = k as f64 * h;
        assert_eq!(f.set_real(&pin_vrs(0), &[0.5, 0.9, 0.0, 0.0]), fmi2OK);
        assert_eq!(f.do_step(t, h), fmi2OK, "{:?}", f.lines());
        let fo = f.get_real(&force_vrs(0)).unwrap();
        if k >= 20 {
            sum += Vec2::new(fo[0], fo[1]);
            n += 1;
        }
    }
    let mean = sum / n as f64;
    let err = (-mean.y - weight) / weight;
    eprintln!(
        "hanging yarn: mean pin force ({:.4e}, {:.4e}) N/m over 0.4 s, weight {weight:.4e} N/m, error {:+.2} %",
        mean.x,
        mean.y,
        100.0 * err
    );
    assert!(err.abs() < 0.03, "{err}");
    assert!(mean.x.abs() < 0.01 * weight, "{mean:?}");
}

/// The `scene` parameter must keep the bundled scene's pins: the pin
/// variables are fixed by the bundled scene.
#[test]
fn scene_parameter_must_keep_the_pins() {
    let s = pinned_scene("motion = \"input\"");
    let f = Fmu::new(&s);
    let fixed = pinned_scene("");
    std::fs::write(f.dir.join("fixed.toml"), fixed.to_toml_string()).unwrap();
    assert_eq!(f.set_string(VR_SCENE, "fixed.toml"), fmi2Error);
    assert!(f.last_error().contains("other pins"), "{}", f.last_error());
    // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every pointer
    // argument is a local that outlives the call.
    unsafe { assert_eq!(fmi2Reset(f.c), fmi2OK) };
    let mut moved = s.clone();
    moved.gravity = [0.0, -5.0];
    std::fs::write(f.dir.join("moved.toml"), moved.to_toml_string()).unwrap();
    assert_eq!(
        f.set_string(VR_SCENE, "moved.toml"),
        fmi2OK,
        "{:?}",
        f.lines()
    );
}

/// A yarn given by a preset (the nylon monofilament, `[material] preset`)
/// loads into the FMU with the converted parameters per metre of depth
/// (`k = EA / s`, `density = tex 1e-6 / s`, `s` = the diameter), and its
/// `pin[0].force.y` per metre of depth times the spacing is one yarn's
/// weight `mu g L`: communication steps of one axial period `4 L / c` each
/// average a whole period.
#[test]
fn a_preset_yarns_pin_force_times_the_spacing_is_one_yarns_weight() {
    let (len, g) = (
        yarnsim::testing::CHAIN_LENGTH,
        yarnsim::testing::CHAIN_GRAVITY,
    );
    let s = YarnScene::from_toml_str(&yarnsim::testing::hanging_preset_yarn_toml(
        "nylon66-mono-0.30mm",
    ))
    .unwrap();
    let p = yarnsim::scene::presets::preset("nylon66-mono-0.30mm").unwrap();
    let spacing = s.material.spacing().unwrap();
    assert_eq!(spacing, p.diameter);
    let f = Fmu::initialized(&s);
    // 1e-15 relative: the same quotient as the loader's
    let k = f.get_real(&[VR_K]).unwrap()[0];
    let density = f.get_real(&[VR_DENSITY]).unwrap()[0];
    assert!((k - p.ea / spacing).abs() <= 1e-15 * k, "{k}");
    assert!(
        (density - p.tex * 1e-6 / spacing).abs() <= 1e-15 * density,
        "{density}"
    );
    let period = 4.0 * len / (p.ea / (p.tex * 1e-6)).sqrt();
    let mut sum = 0.0;
    for k in 0..10 {
        assert_eq!(
            f.do_step(k as f64 * period, period),
            fmi2OK,
            "{:?}",
            f.lines()
        );
        sum += f.get_real(&force_vrs(0)).unwrap()[1];
    }
    let per_yarn = -sum / 10.0 * spacing;
    let weight = p.tex * 1e-6 * g * len;
    let err = (per_yarn - weight) / weight;
    eprintln!(
        "preset yarn in the FMU: pin force per yarn {per_yarn:.4e} N, mu g L {weight:.4e} N, error {:+.2} %",
        100.0 * err
    );
    // tolerance 2 %, as the library's test of the same yarn
    // (tests/yarn_materials.rs): whole continuum periods of an undamped
    // oscillation
    assert!(err.abs() < 0.02, "{err}");
}

/// A scene file with `transfer.flip_time` (a relaxation time; the
/// parameter of that name: `fmu/tests/axial.rs`) runs with the library's bits,
/// and `transfer.flip_ratio` reads 1; another ratio beside it is refused,
/// naming `transfer.flip_time`, and the FMU reports the error.
#[test]
fn a_scene_with_a_flip_time_runs_and_refuses_another_ratio() {
    let mut scene = small_scene();
    scene.transfer.flip_time = Some(0.004);
    let f = Fmu::initialized(&scene);
    assert_eq!(f.get_real(&[VR_FLIP_RATIO]), Ok(vec![1.0]));
    let out = fmu_run(&f);
    assert_eq!(bits(&out), bits(&library_run(&scene)));
    assert_ne!(bits(&out), bits(&library_run(&small_scene())));
    let g = Fmu::new(&scene);
    // a fixed parameter: set before initialization, checked with the scene
    // at its end
    assert_eq!(g.set_real(&[VR_FLIP_RATIO], &[0.9]), fmi2OK);
    assert_eq!(g.init_status(), fmi2Error);
    let e = g.last_error();
    assert!(
        e.contains("transfer.flip_time") && e.contains("flip_ratio is 0.9"),
        "{e}"
    );
}
