//! yarnsim's entry of the rod benchmark against MuJoCo and PyElastica
//! (`tools/bench/peers/bench.py`): the oracle scenes of `tests/yarn_oracles.rs`
//! run through the library, timing the stepping loop only, one JSON line
//! on stdout per run.
//!
//! ```text
//! cargo run --release -p yarnsim-evidence --example peers_chain -- chain VERTICES GRID DT [INTEGRATOR [K]]
//! cargo run --release -p yarnsim-evidence --example peers_chain -- chain-preset PRESET VERTICES GRID DT [INTEGRATOR]
//! cargo run --release -p yarnsim-evidence --example peers_chain -- cantilever VERTICES [INTEGRATOR [DT]]
//! cargo run --release -p yarnsim-evidence --example peers_chain -- capstan R L1 L2 MU [INTEGRATOR [DT]]
//! cargo run --release -p yarnsim-evidence --example peers_chain -- capstan-preset PRESET SCALE MU INTEGRATOR [DT]
//! cargo run --release -p yarnsim-evidence --example peers_chain -- bundle DURATION [INTEGRATOR [DT [OPTION...]]]
//! ```
//!
//! `INTEGRATOR` is `explicit` (the default) or `implicit` (the scene's
//! `[time] integrator`). A scene the implicit integrator refuses prints
//! `{"ok": false, "refused": "<the scene error>"}` and exits 0, so the
//! driver records the refusal instead of failing.
//!
//! * `chain`: the hanging chain of the oracle test (L = 0.8 m pinned at the
//!   top, k = 2000, no bending, started in the first mode shape
//!   `u = A J0(j01 sqrt(z / L))`, A = 0.02 m), run for 3.4 s; the period is
//!   twice the mean spacing of the free end's zero crossings (interpolated
//!   within the substep). `DT` is a TOML value (`1e-4` or `"auto"`); `K`
//!   replaces the fibre stiffness (e.g. `2e5`: a nearly inextensible
//!   rope, strain at the top 0.004 %).
//! * `chain-preset`: the same chain as one yarn of `[material] preset =
//!   PRESET` (its EA, EI, mass and cross-section), APIC, `[time] axial =
//!   "implicit"`; `period` is to be compared with the hanging beam's.
//!   With `INTEGRATOR` `implicit-vertices` or `midpoint-vertices` the
//!   yarn steps on its vertices without the grid (`GRID` then only sizes
//!   the domain): the preset's EA, EI and mass, its cross-section
//!   energies off (`gamma = youngs_modulus = 0`: they live on the grid
//!   and act only where yarns touch, which one hanging yarn does not).
//! * `cantilever`: the Euler-Bernoulli cantilever of the oracle test
//!   (L = 0.5 m, B = 1, rho = 1, 64^2, dt 5e-5, two vertices pinned), the tip
//!   deflection averaged over two measured periods of the first mode;
//!   `DT` replaces the substep.
//! * `capstan`: the bending-free yarn over a half circle (128^2, dt 1e-4,
//!   g = 2) loaded for 0.2 s, then up to 1 s more: slid if a free end moved
//!   vertically by more than 0.5 % of its hanging length; `DT` replaces
//!   the substep.
//! * `capstan-preset`: the capstan above (R 0.1, L1 0.1, L2 0.3 m) as one
//!   yarn of `PRESET`, its lengths (and the domain) times `SCALE` and its
//!   load and hold times `sqrt(SCALE)` (the same motion in units of the
//!   hanging lengths; the slip threshold does not depend on the scale),
//!   on the yarn's vertices without the grid (`INTEGRATOR`
//!   `implicit-vertices` or `midpoint-vertices`; the preset's
//!   cross-section energies off, as in `chain-preset`). A real yarn's
//!   bending is not negligible on the 0.1 m drum (the heavy-rope oracle
//!   neglects it); `SCALE` makes it so.
//! * `bundle`: the built-in `yarn-reference` scene for `DURATION` s; prints
//!   every yarn's vertex positions for the driver's common metrics and the
//!   wall time of two windows (`windows`: `[start, end, wall]` for the fall
//!   and landing up to 0.2 s, then the rest) and the seconds spent in each
//!   pass of the substep (`passes`, from `YarnSim::timings`); `DT`
//!   replaces the substep (4e-5): a number or `auto`. `frames`: every
//!   yarn's vertices every 0.1 s (not timed). `OPTION`s: `preset=NAME`
//!   (the `[material]` table replaced by `preset = NAME`, return mapping
//!   on), `apic`, `per-yarn` (`[contact] fields`), `axial-implicit`
//!   (`[time] axial = "implicit"`), and any scene field as `KEY=VALUE`,
//!   as `yarnsim run --set` takes it (for example
//!   `transfer.flip_time=0.002` or `time.safety=0.3`).
//!
//! Threads: set `RAYON_NUM_THREADS=1` for one thread. The whole run steps
//! on one rayon worker (`yarnsim::pool::on_pool`), as a program's own
//! stepping loop should: calling `YarnSim::step` from a thread outside the
//! pool hands each substep over and back (a thread wake-up per substep,
//! which doubled the chain's wall time here).

use std::time::Instant;

use yarnsim::scene::overrides::{apply_to_text, parse_all};
use yarnsim::scene::{
    builtin_toml, Axial, FieldPartition, Integrator, Scene, StepSize, TransferScheme, YarnScene,
};
use yarnsim::testing::{
    cantilever_setup, cantilever_toml, capstan_preset_scene, capstan_toml, hanging_chain_period,
    hanging_chain_toml, two_periods_about_mean, with_material_table, ZeroCrossings,
    CAPSTAN_PURE_STRING,
};
use yarnsim::YarnSim;

fn scene(text: &str) -> YarnScene {
    YarnScene::from_toml_str(text).unwrap_or_else(|e| {
        eprintln!("scene: {e}");
        std::process::exit(3)
    })
}

/// A JSON string literal of `s`.
fn json_str(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            c if (c as u32) < 0x20 => out.push_str(&format!("\\u{:04x}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// The simulation of `s` under `integrator`; a scene it refuses prints the
/// refusal as the run's JSON line and ends the process (status 0).
fn sim_with(mut s: YarnScene, integrator: Integrator) -> YarnSim {
    s.time.integrator = integrator;
    YarnSim::new(&s).unwrap_or_else(|e| {
        println!(
            "{{\"ok\": false, \"refused\": {}}}",
            json_str(&e.to_string())
        );
        std::process::exit(0)
    })
}

/// The optional trailing `INTEGRATOR` argument at `i`.
fn integrator(args: &[String], i: usize) -> Integrator {
    match args.get(i).map(String::as_str) {
        None | Some("explicit") => Integrator::Explicit,
        Some("implicit") => Integrator::Implicit,
        Some("implicit-vertices") => Integrator::ImplicitVertices,
        Some("midpoint-vertices") => Integrator::MidpointVertices,
        Some(x) => {
            eprintln!("INTEGRATOR must be explicit, implicit, implicit-vertices or midpoint-vertices, got {x:?}");
            std::process::exit(2)
        }
    }
}

/// The optional argument at `i` (absent: `None`).
fn opt<T: std::str::FromStr>(args: &[String], i: usize, name: &str) -> Option<T> {
    args.get(i).map(|_| arg(args, i, name))
}

fn arg<T: std::str::FromStr>(args: &[String], i: usize, name: &str) -> T {
    args.get(i).and_then(|s| s.parse().ok()).unwrap_or_else(|| {
        eprintln!("missing or invalid argument {name}");
        std::process::exit(2)
    })
}

fn chain(vertices: u32, grid: u32, dt: &str, integ: Integrator, k: Option<f64>) -> String {
    let mut s = scene(&hanging_chain_toml(vertices, grid, dt));
    if let Some(k) = k {
        s.material.k = k;
    }
    chain_run(s, integ)
}

/// The hanging chain of [`chain`] as one real yarn: the `[material]` lines
/// replaced by `preset = NAME` (its EA, EI, mass and cross-section, no
/// return mapping), APIC and `[time] axial = "implicit"`. The `error` is
/// against the string's oracle; the driver compares `period` with the
/// hanging beam's (the bending shortens it).
fn chain_preset(preset: &str, vertices: u32, grid: u32, dt: &str, integ: Integrator) -> String {
    let text = hanging_chain_toml(vertices, grid, dt);
    let material = "k = 2000.0\ngamma = 0.0\nyoungs_modulus = 0.0\nfriction = 0.0\nbending = 0.0\n";
    assert!(text.contains(material), "the chain's [material] lines");
    let mut lines = format!("preset = {}\n", json_str(preset));
    if integ.is_gridless() {
        lines.push_str("gamma = 0.0\nyoungs_modulus = 0.0\n");
    }
    let mut s = scene(&text.replace(material, &lines));
    if integ.is_gridless() {
        return chain_run(s, integ);
    }
    s.transfer.scheme = TransferScheme::Apic;
    s.time.axial = Axial::Implicit;
    chain_run(s, Integrator::Explicit)
}

/// The chain's run: the period from the free end's zero crossings.
fn chain_run(s: YarnScene, integ: Integrator) -> String {
    let mut sim = sim_with(s, integ);
    let duration = 3.4;
    let mut crossings = ZeroCrossings::new(sim.yarn_endpoints(0).1.x - 0.5);
    let mut ok = true;
    let t0 = Instant::now();
    while sim.time() < duration {
        let before = sim.time();
        if let Err(e) = sim.step() {
            eprintln!("{e}");
            ok = false;
            break;
        }
        let h = sim.time() - before;
        crossings.push(sim.time(), h, sim.yarn_endpoints(0).1.x - 0.5);
    }
    let wall = t0.elapsed().as_secs_f64();
    let period = crossings.period();
    let oracle = hanging_chain_period();
    format!(
        "{{\"ok\": {ok}, \"period\": {period}, \"oracle\": {oracle}, \"error\": {}, \"crossings\": {}, \
         \"wall_s\": {wall}, \"sim_s\": {}, \"steps\": {}, \"newton\": {}}}",
        (period - oracle) / oracle,
        crossings.times.len(),
        sim.time(),
        sim.steps(),
        sim.implicit_stats().newton
    )
}

fn cantilever(vertices: u32, integ: Integrator, dt: Option<f64>) -> String {
    let (len, b, rho, g) = cantilever_setup();
    let mut s = scene(&cantilever_toml(vertices));
    if let Some(dt) = dt {
        s.time.dt = StepSize::Fixed(dt);
    }
    let mut sim = sim_with(s, integ);
    let free = len - 0.5 * len / (vertices - 1) as f64;
    let oracle = rho * g * free.powi(4) / (8.0 * b);
    let omega1 = 1.8751f64.powi(2) * (b / (rho * free.powi(4))).sqrt();
    let steps = (2.5 * 2.0 * std::f64::consts::PI / omega1 / sim.dt()).round() as u64;
    let y0 = sim.yarn_endpoints(0).1.y;
    let mut d = Vec::with_capacity(steps as usize);
    let mut ok = true;
    let t0 = Instant::now();
    for _ in 0..steps {
        if sim.step().is_err() {
            ok = false;
            break;
        }
        d.push(y0 - sim.yarn_endpoints(0).1.y);
    }
    let wall = t0.elapsed().as_secs_f64();
    let tip = match two_periods_about_mean(&d) {
        Some((a, e)) => d[a..e].iter().sum::<f64>() / (e - a) as f64,
        None => f64::NAN,
    };
    format!(
        "{{\"ok\": {ok}, \"tip\": {tip}, \"oracle\": {oracle}, \"error\": {}, \"wall_s\": {wall}, \
         \"sim_s\": {}, \"steps\": {}}}",
        (tip - oracle) / oracle,
        sim.time(),
        sim.steps()
    )
}

fn capstan(r: f64, l1: f64, l2: f64, mu: f64, integ: Integrator, dt: Option<f64>) -> String {
    let mut c = CAPSTAN_PURE_STRING;
    if let Some(dt) = dt {
        c.dt = dt;
    }
    let s = scene(&capstan_toml(r, l1, l2, mu, &c));
    capstan_run(s, integ, (l1, l2), (0.2, 1.0))
}

/// The capstan of `capstan` (R 0.1, L1 0.1, L2 0.3 m) as one yarn of
/// `preset` on its vertices, every length times `scale`, the load and
/// hold times `sqrt(scale)`.
fn capstan_preset(preset: &str, scale: f64, mu: f64, integ: Integrator, dt: Option<f64>) -> String {
    if !integ.is_gridless() {
        eprintln!("capstan-preset: INTEGRATOR must be implicit-vertices or midpoint-vertices");
        std::process::exit(2)
    }
    let mut c = CAPSTAN_PURE_STRING;
    if let Some(dt) = dt {
        c.dt = dt;
    }
    let (s, l1, l2) = capstan_preset_scene(preset, scale, mu, &c);
    let t = scale.sqrt();
    capstan_run(s, integ, (l1, l2), (0.2 * t, 1.0 * t))
}

/// One capstan run: loaded for `load` s, then held `hold` s; slid if a
/// free end moved vertically by more than 0.5 % of its hanging length
/// (`l1` on the left, `l2` on the right).
fn capstan_run(
    s: YarnScene,
    integ: Integrator,
    (l1, l2): (f64, f64),
    (load, hold): (f64, f64),
) -> String {
    let vertices = s.yarns[0].vertices;
    let mut sim = sim_with(s, integ);
    let t0 = Instant::now();
    let mut ok = match sim.advance(load) {
        Ok(_) => true,
        Err(e) => {
            eprintln!("{e}");
            false
        }
    };
    let (a0, b0) = sim.yarn_endpoints(0);
    let steps = (hold / sim.dt()).round() as u64;
    let (mut worst, mut slid) = (0.0f64, false);
    for k in 0..steps {
        if !ok {
            break;
        }
        if let Err(e) = sim.step() {
            eprintln!("{e}");
            ok = false;
            break;
        }
        if k % 50 == 49 || k + 1 == steps {
            let (a, b) = sim.yarn_endpoints(0);
            let rel = ((a.y - a0.y).abs() / l1).max((b.y - b0.y).abs() / l2);
            worst = worst.max(rel);
            if rel > 0.005 {
                slid = true;
                break;
            }
        }
    }
    let wall = t0.elapsed().as_secs_f64();
    format!(
        "{{\"ok\": {ok}, \"slid\": {slid}, \"moved\": {worst}, \"wall_s\": {wall}, \"sim_s\": {}, \
         \"steps\": {}, \"vertices\": {vertices}}}",
        sim.time(),
        sim.steps()
    )
}

/// The end of the bundle's first timed window (s): it falls, lands on the
/// top circle at about 0.1 s and settles into the drape by then
/// (`BUNDLE["landed"]` in `tools/bench/peers/oracles.py`).
const BUNDLE_LANDED: f64 = 0.2;

/// Every yarn's vertex positions as a JSON array of `[x, y]` arrays.
fn yarn_positions(sim: &YarnSim) -> String {
    let p = sim.particles();
    let r = &p.yarn_vertices;
    (0..sim.num_yarns())
        .map(|y| {
            let xs = p.vert.x[r[y]..r[y + 1]]
                .iter()
                .map(|x| format!("[{:.6}, {:.6}]", x.x, x.y))
                .collect::<Vec<_>>()
                .join(", ");
            format!("[{xs}]")
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// The reference bundle's scene with the trailing `OPTION`s of `bundle`:
/// `preset=NAME` replaces the `[material]` table by the preset (return
/// mapping on, as in the reference), `apic` the transfer, `per-yarn` the
/// contact fields, `axial-implicit` the fibre stretch solve.
fn bundle_scene(options: &[String]) -> YarnScene {
    let mut text = builtin_toml("yarn-reference")
        .expect("built-in yarn-reference")
        .to_string();
    for o in options {
        if let Some(name) = o.strip_prefix("preset=") {
            text = with_material_table(
                &text,
                &format!("preset = {}\nplasticity = true\n", json_str(name)),
            );
        }
    }
    let sets: Vec<String> = options.iter().filter(|o| is_set(o)).cloned().collect();
    let mut s = match parse_all(&sets).and_then(|o| apply_to_text(&text, &o)) {
        Ok(Scene::Yarn(s)) => s,
        Ok(_) => unreachable!("yarn-reference is a yarn scene"),
        Err(e) => {
            eprintln!("scene: {e}");
            std::process::exit(3)
        }
    };
    for o in options {
        match o.as_str() {
            "apic" => s.transfer.scheme = TransferScheme::Apic,
            "per-yarn" => s.contact.fields = FieldPartition::PerYarn,
            "axial-implicit" => s.time.axial = Axial::Implicit,
            x if x.starts_with("preset=") || is_set(x) => {}
            x => {
                eprintln!(
                    "OPTION must be preset=NAME, apic, per-yarn, axial-implicit or a scene \
                     field KEY=VALUE, got {x:?}"
                );
                std::process::exit(2)
            }
        }
    }
    s
}

/// A bundle `OPTION` that sets a scene field: `KEY=VALUE` other than
/// `preset=NAME` (`time.safety=0.3`, `gravity=[0.0, -9.8]`), as `yarnsim
/// run --set` takes it.
fn is_set(option: &str) -> bool {
    option.contains('=') && !option.starts_with("preset=")
}

/// Seconds between the bundle's recorded frames (every yarn's vertices).
const BUNDLE_FRAME: f64 = 0.1;

fn bundle(duration: f64, integ: Integrator, dt: Option<&str>, options: &[String]) -> String {
    let mut s = bundle_scene(options);
    match dt {
        None => {}
        Some("auto") => s.time.dt = StepSize::Auto,
        Some(x) => match x.parse::<f64>() {
            Ok(dt) => s.time.dt = StepSize::Fixed(dt),
            Err(_) => {
                eprintln!("DT must be a number or auto, got {x:?}");
                std::process::exit(2)
            }
        },
    }
    let mut sim = sim_with(s, integ);
    // wall time per window: the fall and landing (to 0.2 s), then the rest
    let mut windows = Vec::new();
    let mut frames = vec![format!("[{}, [{}]]", sim.time(), yarn_positions(&sim))];
    let mut untimed = 0.0;
    let t0 = Instant::now();
    let mut ok = true;
    for end in [BUNDLE_LANDED.min(duration), duration] {
        if end <= sim.time() {
            continue;
        }
        let w0 = Instant::now();
        let start = sim.time();
        // to each recorded frame in turn (the frames are not timed)
        let mut frame_wall = 0.0;
        while ok && sim.time() < end - 1e-12 {
            let next = ((sim.time() / BUNDLE_FRAME + 1e-6).floor() + 1.0) * BUNDLE_FRAME;
            let before = sim.time();
            ok = sim.advance(next.min(end) - before).is_ok();
            if sim.time() <= before {
                // a fixed step rounds the rest (under half a step) to none
                break;
            }
            let f0 = Instant::now();
            frames.push(format!("[{}, [{}]]", sim.time(), yarn_positions(&sim)));
            frame_wall += f0.elapsed().as_secs_f64();
        }
        windows.push(format!(
            "[{start}, {}, {}]",
            sim.time(),
            w0.elapsed().as_secs_f64() - frame_wall
        ));
        untimed += frame_wall;
        if !ok {
            break;
        }
    }
    let wall = t0.elapsed().as_secs_f64() - untimed;
    let yarns = yarn_positions(&sim);
    let d = sim.diagnostics();
    // where a substep's time goes (the passes of `YarnSim::timings`)
    let passes = sim
        .timings()
        .entries()
        .iter()
        .map(|(name, t)| format!("[{}, {t}]", json_str(name)))
        .collect::<Vec<_>>()
        .join(", ");
    format!(
        "{{\"ok\": {ok}, \"wall_s\": {wall}, \"sim_s\": {}, \"steps\": {}, \"min_stretch\": {}, \
         \"max_stretch\": {}, \"windows\": [{}], \"passes\": [{passes}], \"yarns\": [{yarns}], \
         \"frames\": [{}]}}",
        sim.time(),
        sim.steps(),
        d.min_stretch,
        d.max_stretch,
        windows.join(", "),
        frames.join(", ")
    )
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    // the whole run on one rayon worker: one hand-off, not one per substep
    let out = yarnsim::pool::on_pool(|| match args.first().map(String::as_str) {
        Some("chain") => chain(
            arg(&args, 1, "VERTICES"),
            arg(&args, 2, "GRID"),
            &arg::<String>(&args, 3, "DT"),
            integrator(&args, 4),
            opt(&args, 5, "K"),
        ),
        Some("chain-preset") => chain_preset(
            &arg::<String>(&args, 1, "PRESET"),
            arg(&args, 2, "VERTICES"),
            arg(&args, 3, "GRID"),
            &arg::<String>(&args, 4, "DT"),
            integrator(&args, 5),
        ),
        Some("cantilever") => cantilever(
            arg(&args, 1, "VERTICES"),
            integrator(&args, 2),
            opt(&args, 3, "DT"),
        ),
        Some("capstan") => capstan(
            arg(&args, 1, "R"),
            arg(&args, 2, "L1"),
            arg(&args, 3, "L2"),
            arg(&args, 4, "MU"),
            integrator(&args, 5),
            opt(&args, 6, "DT"),
        ),
        Some("capstan-preset") => capstan_preset(
            &arg::<String>(&args, 1, "PRESET"),
            arg(&args, 2, "SCALE"),
            arg(&args, 3, "MU"),
            integrator(&args, 4),
            opt(&args, 5, "DT"),
        ),
        Some("bundle") => bundle(
            arg(&args, 1, "DURATION"),
            integrator(&args, 2),
            args.get(3).map(String::as_str),
            args.get(4..).unwrap_or(&[]),
        ),
        _ => {
            eprintln!("usage: peers_chain chain|cantilever|capstan|bundle ARGS (see the source)");
            std::process::exit(2)
        }
    });
    println!("{out}");
}
