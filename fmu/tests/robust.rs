//! Bounded work and resources: the substep budget of one
//! `fmi2DoStep`, the stability warning at initialization, the instance's own
//! thread pool, and the limits on the `scene` parameter.

mod common;

use std::ffi::{c_int, CString};
use std::time::Instant;

use common::*;
use yarnsim::massspring::scenes::wire;
use yarnsim_fmu::fmi2::*;
use yarnsim_fmu::model_description::*;
use yarnsim_fmu::models::yarn::variables::*;

const H: f64 = 0.01;

fn set_int(f: &Fmu, vr: u32, v: c_int) -> fmi2Status {
    // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every pointer
    // argument is a local that outlives the call.
    unsafe { fmi2SetInteger(f.c, &vr, 1, &v) }
}

fn get_int(f: &Fmu, vr: u32) -> c_int {
    let mut v = -1;
    // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every pointer
    // argument is a local that outlives the call.
    assert_eq!(unsafe { fmi2GetInteger(f.c, &vr, 1, &mut v) }, fmi2OK);
    v
}

fn set_scene(f: &Fmu, path: &str) -> fmi2Status {
    let v = CString::new(path).unwrap();
    let p = v.as_ptr();
    // SAFETY: `f.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every pointer
    // argument is a local that outlives the call.
    unsafe { fmi2SetString(f.c, &VR_SCENE, 1, &p) }
}

/// dt = 1e-9 s with h = 1 s asks for 1e9 substeps: refused at once with
/// fmi2Error and a log line naming the count, before any substep runs.
#[test]
fn a_step_beyond_the_substep_budget_is_refused_before_it_runs() {
    let scene = small_scene();
    let f = Fmu::new(&scene);
    assert_eq!(f.set_real(&[VR_DT], &[1e-9]), fmi2OK);
    // 1e-9 s is far inside the stability bound: no warning.
    assert_eq!(f.init_status(), fmi2OK, "{:?}", f.lines());
    assert_eq!(get_int(&f, VR_MAX_SUBSTEPS), DEFAULT_MAX_SUBSTEPS as c_int);
    let t0 = Instant::now();
    assert_eq!(f.do_step(0.0, 1.0), fmi2Error);
    assert!(t0.elapsed().as_secs_f64() < 0.5, "{:?}", t0.elapsed());
    let msg = f.last_error();
    assert!(
        msg.contains("needs 1000000000 substeps") && msg.contains("max_substeps_per_step = 10000"),
        "{msg}"
    );
    assert!(f
        .lines()
        .iter()
        .any(|l| l.0 == fmi2Error && l.1 == "logStatusError" && l.2.contains("1000000000")));

    // The budget is a parameter: exactly the budget runs, one more is refused.
    let g = Fmu::new(&scene);
    assert_eq!(set_int(&g, VR_MAX_SUBSTEPS, 50), fmi2OK);
    g.init();
    assert_eq!(get_int(&g, VR_MAX_SUBSTEPS), 50);
    assert_eq!(g.do_step(0.0, 50.0 * 2e-4), fmi2OK);
    assert_eq!(g.substeps(), 50);
    assert_eq!(g.do_step(50.0 * 2e-4, 51.0 * 2e-4), fmi2Error);
    g.assert_error_contains("needs 51 substeps");
    // Fixed after initialization, at least 1, Integer only.
    let k = Fmu::new(&scene);
    assert_eq!(set_int(&k, VR_MAX_SUBSTEPS, 0), fmi2Error);
    let k = Fmu::initialized(&scene);
    assert_eq!(set_int(&k, VR_MAX_SUBSTEPS, 100), fmi2Error);
    k.assert_error_contains("max_substeps_per_step is a fixed parameter");
    let k = Fmu::new(&scene);
    assert_eq!(set_int(&k, VR_SUBSTEPS, 1), fmi2Error);

    // The same on the MassSpring FMU.
    let m = Fmu::mass_spring(&wire());
    assert_eq!(
        m.set_real(&[yarnsim_fmu::models::massspring::VR_DT], &[1e-9]),
        fmi2OK
    );
    assert_eq!(m.init_status(), fmi2OK, "{:?}", m.lines());
    assert_eq!(m.do_step(0.0, 1.0), fmi2Error);
    m.assert_error_contains("needs 1000000000 substeps");
}

/// fmi2ExitInitializationMode warns (fmi2Warning, a log line in
/// logStatusWarning) when dt exceeds the model's stability bound, the
/// library's: `YarnSim::stable_dt` and `Simulation::stable_dt`.
#[test]
fn a_substep_beyond_the_stability_bound_gives_a_warning() {
    let scene = small_scene();
    let sim = yarnsim::YarnSim::new(&scene).unwrap();
    let bound = sim.stable_dt();
    let dt = scene.time.dt.fixed().unwrap();
    assert!(dt < bound, "{dt} vs {bound}");
    let f = Fmu::new(&scene);
    assert_eq!(f.init_status(), fmi2OK);
    assert!(!f.lines().iter().any(|l| l.0 == fmi2Warning));

    let f = Fmu::new(&scene);
    assert_eq!(f.set_real(&[VR_DT], &[2.0 * bound]), fmi2OK);
    assert_eq!(f.init_status(), fmi2Warning);
    let line = warning_line(&f);
    assert!(line.contains("stability bound"), "{}", line);
    assert!(line.contains(&format!("{bound:.6e}")), "{} {bound}", line);
    // A warning is not an error: the instance steps.
    assert_eq!(f.do_step(0.0, 4.0 * bound), fmi2OK);

    // Mass-spring: symplectic Euler beyond its bound warns; backward Euler
    // (A-stable) never does.
    use yarnsim_fmu::models::massspring::{VR_DT as MS_DT, VR_INTEGRATOR};
    let layout = wire();
    let lib = yarnsim::massspring::Simulation::new(
        &layout,
        yarnsim::massspring::Integrator::SymplecticEuler,
        Default::default(),
    )
    .unwrap();
    let ms_bound = lib.stable_dt().unwrap();
    let integrator = CString::new("symplectic-euler").unwrap();
    let p = integrator.as_ptr();
    let m = Fmu::mass_spring(&layout);
    // SAFETY: `m.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every pointer
    // argument is a local that outlives the call.
    assert_eq!(unsafe { fmi2SetString(m.c, &VR_INTEGRATOR, 1, &p) }, fmi2OK);
    // Its default step (cfl_number times the bound) is inside.
    assert_eq!(m.init_status(), fmi2OK, "{:?}", m.lines());
    let m = Fmu::mass_spring(&layout);
    // SAFETY: `m.c` came from `fmi2Instantiate` and lives until its `Fmu` drops; every pointer
    // argument is a local that outlives the call.
    assert_eq!(unsafe { fmi2SetString(m.c, &VR_INTEGRATOR, 1, &p) }, fmi2OK);
    assert_eq!(m.set_real(&[MS_DT], &[1.5 * ms_bound]), fmi2OK);
    assert_eq!(m.init_status(), fmi2Warning);
    assert!(m
        .lines()
        .iter()
        .any(|l| l.0 == fmi2Warning && l.2.contains("stability bound")));
    let m = Fmu::mass_spring(&layout);
    assert_eq!(m.set_real(&[MS_DT], &[0.5]), fmi2OK);
    assert_eq!(m.init_status(), fmi2OK);
}

fn threaded_run(threads: c_int, scene: &yarnsim::scene::YarnScene) -> Vec<u64> {
    let f = Fmu::new(scene);
    assert_eq!(set_int(&f, VR_THREADS, threads), fmi2OK);
    f.init();
    assert_eq!(get_int(&f, VR_THREADS), threads);
    assert_eq!(f.set_real(&[VR_GRAVITY_X], &[3.0]), fmi2OK);
    f.output_bits(0..8, H)
}

/// `threads` = 1, 2 and 0 (the global pool) give the same bits, on the
/// yarn bundle (whose passes run in parallel) and on the cloth.
#[test]
fn threads_parameter_gives_identical_bits() {
    let mut scene = small_scene();
    // More vertices than one parallel chunk, so the pool splits the work.
    for y in &mut scene.yarns {
        y.vertices = 600;
    }
    let one = threaded_run(1, &scene);
    assert_eq!(threaded_run(2, &scene), one);
    assert_eq!(threaded_run(0, &scene), one);
    assert_eq!(threaded_run(3, &scene), one);

    let layout = yarnsim::massspring::scenes::cloth();
    let run = |threads: c_int| {
        let m = Fmu::mass_spring(&layout);
        assert_eq!(set_int(&m, VR_THREADS, threads), fmi2OK);
        m.init();
        for k in 0..3 {
            assert_eq!(m.do_step(k as f64 / 30.0, 1.0 / 30.0), fmi2OK);
        }
        let vrs: Vec<u32> = (0..3 * m.yarns as u32)
            .map(|k| yarnsim_fmu::models::massspring::VR_PARTICLE_BASE + k)
            .collect();
        m.get_real(&vrs).unwrap()
    };
    let a = run(1);
    assert_eq!(run(2), a);
    assert_eq!(run(0), a);

    // Out of range, fixed after initialization.
    let f = Fmu::new(&small_scene());
    assert_eq!(set_int(&f, VR_THREADS, -1), fmi2Error);
    let f = Fmu::new(&small_scene());
    assert_eq!(set_int(&f, VR_THREADS, 100_000), fmi2Error);
    let f = Fmu::initialized(&small_scene());
    assert_eq!(set_int(&f, VR_THREADS, 2), fmi2Error);
}

/// The `scene` parameter reads regular files of at most 1 MiB only.
#[test]
fn scene_parameter_refuses_devices_directories_and_huge_files() {
    let scene = small_scene();
    let cases: [(&str, &str); 3] = [
        ("/dev/zero", "not a regular file"),
        ("/tmp", "is a directory"),
        ("big.toml", "more than the limit of 1048576"),
    ];
    for (path, why) in cases {
        let f = Fmu::new(&scene);
        if path == "big.toml" {
            let mut text = scene.to_toml_string();
            text.push_str(&"# padding\n".repeat(110_000));
            std::fs::write(f.dir.join(path), text).unwrap();
        }
        let t0 = Instant::now();
        assert_eq!(set_scene(&f, path), fmi2Error, "{path}");
        assert!(t0.elapsed().as_secs_f64() < 1.0);
        let msg = f.last_error();
        assert!(msg.contains(why), "{path}: {msg}");
    }
    // A file just under the limit is read.
    let f = Fmu::new(&scene);
    let mut text = scene.to_toml_string();
    text.push_str(&"# padding\n".repeat(100_000));
    assert!((text.len() as u64) < MAX_SCENE_BYTES);
    std::fs::write(f.dir.join("padded.toml"), text).unwrap();
    assert_eq!(set_scene(&f, "padded.toml"), fmi2OK, "{:?}", f.lines());
    // A missing file names the path.
    let f = Fmu::new(&scene);
    assert_eq!(set_scene(&f, "missing.toml"), fmi2Error);
    f.assert_error_contains("missing.toml");
}

/// The first warning `f` logged (category `logStatusWarning`).
fn warning_line(f: &Fmu) -> String {
    let line = f
        .lines()
        .into_iter()
        .find(|l| l.0 == fmi2Warning)
        .expect("a warning line");
    assert_eq!(line.1, "logStatusWarning");
    line.2
}

/// A yarn of the `nylon66-mono-0.30mm` preset (d 0.3 mm) laid on a circle
/// of radius 0.1 m at `radius` from its center (a half circle of 41
/// vertices), no bending, dt "auto".
fn laid_nylon(radius: f64) -> yarnsim::scene::YarnScene {
    let points: Vec<String> = (0..=40)
        .map(|k| {
            let a = std::f64::consts::PI * k as f64 / 40.0;
            format!("[{}, {}]", 0.5 + radius * a.cos(), 0.5 + radius * a.sin())
        })
        .collect();
    let text = format!(
        "kind = \"yarn\"\ngravity = [0.0, -9.8]\n[grid]\nresolution = 64\n[time]\n\
         dt = \"auto\"\naxial = \"implicit\"\n[transfer]\nscheme = \"apic\"\n\
         [material]\npreset = \"nylon66-mono-0.30mm\"\nEI = 0.0\n\
         [[obstacles]]\ncenter = [0.5, 0.5]\nradius = 0.1\n\
         [[yarns]]\npoints = [{}]\nvertices = 41\n",
        points.join(", ")
    );
    yarnsim::scene::YarnScene::from_toml_str(&text).unwrap()
}

/// fmi2ExitInitializationMode warns when a yarn starts closer to an
/// obstacle than half its diameter (contact keeps the centre line d / 2
/// off the surface and its first substep would push the yarn out,
/// stretching it): the line names the obstacle, `material.diameter` and
/// the radius to lay it at; laid at R + d / 2 it does not warn.
#[test]
fn a_yarn_laid_inside_its_diameter_warns_at_initialization() {
    let d = 0.3e-3;
    let f = Fmu::new(&laid_nylon(0.1));
    assert_eq!(f.init_warned(), fmi2Warning);
    let line = warning_line(&f);
    for what in [
        "fmi2ExitInitializationMode",
        "obstacle 0",
        "material.diameter / 2 = 0.00015 m",
        "half of",
        "radius 0.10015 m",
    ] {
        assert!(line.contains(what), "{what}: {}", line);
    }
    // a warning is not an error: the instance steps
    assert_eq!(f.do_step(0.0, 1e-3), fmi2OK);

    let f = Fmu::new(&laid_nylon(0.1 + 0.5 * d));
    assert_eq!(f.init_warned(), fmi2OK, "{:?}", f.lines());
    assert!(!f.lines().iter().any(|l| l.0 == fmi2Warning));
}
