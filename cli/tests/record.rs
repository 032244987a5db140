//! `yarnsim record` end to end: run the binary, decode the `.rrd` with
//! Rerun's own decoder, and check entity paths, timelines, frame count and
//! that the logged positions are the library's state at each frame.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::process::Command;

use rerun::components::{Position2D, Position3D};
use rerun::external::re_log_types::LogMsg;
use rerun::log::Chunk;
use rerun::{Points2D, Points3D, StoreKind, TimelineName};
use yarnsim::massspring::{scenes, Integrator, IntegratorOptions, Simulation};
use yarnsim::scene::Scene;
use yarnsim::YarnSim;

/// A small yarn scene: 2 yarns of 30 vertices on a 64^2 grid, a frame every
/// 10 substeps, with walls, an obstacle and an active attractor.
const SCENE: &str = include_str!("data/small.toml");

mod common;

use common::rrd::{all_values, decode_store};
use common::{fresh_tmp, record_ok, tmp, yarnsim_ok as yarnsim};

/// The recording's data chunks (blueprint store left out), by entity path.
fn decode(path: &Path) -> BTreeMap<String, Vec<Chunk>> {
    decode_store(path, StoreKind::Recording)
}

/// Every `(frame, values)` of one component of an entity, sorted by frame.
fn by_frame<C: rerun::Component + Clone>(
    chunks: &[Chunk],
    component: rerun::ComponentIdentifier,
) -> Vec<(i64, Vec<C>)> {
    let mut rows = Vec::new();
    for c in chunks {
        let frames = c.iter_component_indices(TimelineName::from_static_str("frame"), component);
        for ((t, _), values) in frames.zip(c.iter_component::<C>(component)) {
            rows.push((t.as_i64(), values.to_vec()));
        }
    }
    rows.sort_by_key(|(f, _)| *f);
    rows
}

fn timelines(chunks: &BTreeMap<String, Vec<Chunk>>) -> BTreeSet<String> {
    chunks
        .values()
        .flatten()
        .flat_map(|c| c.timelines().keys().map(|k| k.to_string()))
        .collect()
}

#[test]
fn yarn_recording_holds_the_library_state_at_every_frame() {
    let scene_file = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/small.toml");
    let rrd = fresh_tmp("record-test.rrd");
    // 2 ms = 50 substeps of 40 us = 5 frames of 10 substeps, plus frame 0.
    let out = record_ok(&scene_file, "2ms", &rrd);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("recorded 6 frames (50 substeps"),
        "{stdout}"
    );

    let chunks = decode(&rrd);
    let entities: BTreeSet<&str> = chunks.keys().map(String::as_str).collect();
    for e in [
        "legend",
        "world/vertices",
        "world/quadrature",
        "world/yarns",
        "world/domain",
        "world/walls",
        "world/obstacles",
        "world/attractor",
        "plots/energy/kinetic",
        "plots/energy/elastic",
        "plots/momentum/x",
        "plots/momentum/y",
        "plots/angular_momentum",
        "plots/stretch/max",
        "timing/step_time",
    ] {
        assert!(
            entities.contains(e),
            "missing entity {e}; have {entities:?}"
        );
    }
    // Reproducible: only the two simulation timelines, no wall clock.
    let tl = timelines(&chunks);
    assert_eq!(
        tl,
        BTreeSet::from(["frame".to_string(), "sim_time".to_string()])
    );

    let Scene::Yarn(y) = Scene::from_toml_str(SCENE).unwrap() else {
        panic!("yarn scene expected")
    };
    let mut sim = YarnSim::new(&y).unwrap();
    let verts = by_frame::<Position2D>(
        &chunks["world/vertices"],
        Points2D::descriptor_positions().component,
    );
    let quads = by_frame::<Position2D>(
        &chunks["world/quadrature"],
        Points2D::descriptor_positions().component,
    );
    assert_eq!(
        verts.iter().map(|(f, _)| *f).collect::<Vec<_>>(),
        (0..=5).collect::<Vec<_>>()
    );
    assert_eq!(quads.len(), 6);
    for ((frame, v), (_, q)) in verts.iter().zip(&quads) {
        let target = 10 * *frame as u64;
        sim.steps_n(target - sim.steps()).unwrap();
        let p = sim.particles();
        assert_eq!(v.len(), p.vert.x.len());
        assert_eq!(q.len(), p.quad.x.len());
        // Stored as (x, size - y): Rerun's 2D view is y-down.
        let size = y.grid.size;
        for (logged, x) in v.iter().zip(&p.vert.x) {
            assert_eq!(
                logged.0 .0,
                [x.x as f32, (size - x.y) as f32],
                "frame {frame}"
            );
        }
        for (logged, x) in q.iter().zip(&p.quad.x) {
            assert_eq!(
                logged.0 .0,
                [x.x as f32, (size - x.y) as f32],
                "frame {frame}"
            );
        }
    }
    // The bundle moved (the test would be weak on a state at rest).
    assert_ne!(verts[0].1, verts[5].1);
}

#[test]
fn massspring_recording_holds_the_library_state_at_every_frame() {
    let rrd = fresh_tmp("record-wire.rrd");
    // 0.15 s = 3 frames of 0.05 s.
    yarnsim(&[
        "record",
        "wire",
        "--duration",
        "0.15",
        "--integrator",
        "backward-euler",
        "-o",
        rrd.to_str().unwrap(),
    ]);
    let chunks = decode(&rrd);
    for e in [
        "world/particles",
        "world/springs",
        "plots/energy/kinetic",
        "plots/energy/gravity",
        "plots/momentum/z",
        "plots/angular_momentum/y",
        "plots/strain/max",
        "timing/step_time",
    ] {
        assert!(chunks.contains_key(e), "missing entity {e}");
    }
    assert_eq!(
        timelines(&chunks),
        BTreeSet::from(["frame".to_string(), "sim_time".to_string()])
    );
    let pos = by_frame::<Position3D>(
        &chunks["world/particles"],
        Points3D::descriptor_positions().component,
    );
    assert_eq!(pos.len(), 4);
    let mut sim = Simulation::new(
        &scenes::wire(),
        Integrator::BackwardEuler,
        IntegratorOptions::default(),
    )
    .unwrap();
    for (frame, logged) in &pos {
        while (sim.frame() as i64) < *frame {
            sim.step_frame().unwrap();
        }
        let want: Vec<[f32; 3]> = sim
            .positions()
            .iter()
            .map(|x| [x.x as f32, x.y as f32, x.z as f32])
            .collect();
        let got: Vec<[f32; 3]> = logged.iter().map(|p| p.0 .0).collect();
        assert_eq!(got, want, "frame {frame}");
    }
    assert_ne!(pos[0].1, pos[3].1);
}

/// Starts a long recording, sends `signal` once the file has grown, and
/// checks exit code 130 and a decodable file with contiguous frames.
#[cfg(unix)]
fn signal_finishes_the_recording_cleanly(signal: &str) {
    let rrd = fresh_tmp(&format!("record-interrupted-{signal}.rrd"));
    let scene_file = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/small.toml");
    let child = Command::new(env!("CARGO_BIN_EXE_yarnsim"))
        .args(["record", scene_file.to_str().unwrap(), "--duration", "1000"])
        .arg("-o")
        .arg(&rrd)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("start yarnsim");
    // Let it record a few frames, then interrupt it like Ctrl-C does.
    let start = std::time::Instant::now();
    while std::fs::metadata(&rrd).map_or(0, |m| m.len()) < 20_000 {
        assert!(start.elapsed().as_secs() < 60, "no recording after 60 s");
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    let kill = Command::new("kill")
        .args([&format!("-{signal}"), &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let out = child.wait_with_output().unwrap();
    assert_eq!(
        out.status.code(),
        Some(130),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("interrupted"));
    // Every message decodes, and the frames logged are 0, 1, 2, ... without gaps.
    let chunks = decode(&rrd);
    let frames: Vec<i64> = by_frame::<Position2D>(
        &chunks["world/vertices"],
        Points2D::descriptor_positions().component,
    )
    .iter()
    .map(|(f, _)| *f)
    .collect();
    assert!(frames.len() >= 2, "{frames:?}");
    assert_eq!(frames, (0..frames.len() as i64).collect::<Vec<_>>());
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains(&format!("recorded {} frames", frames.len())),
        "{stdout}"
    );
}

#[cfg(unix)]
#[test]
fn ctrl_c_finishes_the_recording_cleanly() {
    signal_finishes_the_recording_cleanly("INT");
}

#[cfg(unix)]
#[test]
fn sigterm_finishes_the_recording_like_ctrl_c() {
    signal_finishes_the_recording_cleanly("TERM");
}

fn small_scene() -> String {
    common::small_scene().to_str().unwrap().to_string()
}

/// Frames at which `world/vertices` was logged.
fn vertex_frames(chunks: &BTreeMap<String, Vec<Chunk>>) -> Vec<i64> {
    by_frame::<Position2D>(
        &chunks["world/vertices"],
        Points2D::descriptor_positions().component,
    )
    .iter()
    .map(|(f, _)| *f)
    .collect()
}

#[test]
fn dash_o_dash_writes_the_recording_to_stdout() {
    // `yarnsim record -o - | rerun -`: the bytes on stdout are the recording,
    // the closing message goes to stderr.
    let out = yarnsim(&["record", &small_scene(), "--duration", "2ms", "-o", "-"]);
    let piped = tmp("record-stdout.rrd");
    std::fs::write(&piped, &out.stdout).unwrap();
    assert_eq!(vertex_frames(&decode(&piped)), (0..=5).collect::<Vec<_>>());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("recorded 6 frames"), "{stderr}");
    assert!(stderr.contains("to standard output"), "{stderr}");
    assert!(!Path::new("-").exists(), "wrote a file named -");
}

#[test]
fn save_is_an_alias_of_output() {
    let rrd = fresh_tmp("record-save.rrd");
    yarnsim(&[
        "record",
        &small_scene(),
        "-d",
        "1ms",
        "--save",
        rrd.to_str().unwrap(),
    ]);
    assert_eq!(vertex_frames(&decode(&rrd)), (0..=3).collect::<Vec<_>>());
}

#[test]
fn every_n_logs_every_nth_frame_and_the_last() {
    let rrd = fresh_tmp("record-every.rrd");
    let out = yarnsim(&[
        "record",
        &small_scene(),
        "--duration",
        "2ms",
        "--every",
        "2",
        "-o",
        rrd.to_str().unwrap(),
    ]);
    assert_eq!(vertex_frames(&decode(&rrd)), vec![0, 2, 4, 5]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("recorded 4 frames (1 in 2 of 6 frames)"),
        "{stdout}"
    );
}

fn fails(args: &[&str], env: &[(&str, &str)]) -> (i32, String) {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_yarnsim"));
    cmd.args(args);
    for (k, v) in env {
        cmd.env(k, v);
    }
    let out = cmd.output().expect("run yarnsim");
    assert!(out.stdout.is_empty(), "{args:?} printed to stdout");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// [`fails`] with the exit code `code` and `what` in its standard error.
fn fails_with(args: &[&str], env: &[(&str, &str)], code: i32, what: &str) {
    let (got, err) = fails(args, env);
    assert_eq!(got, code, "{args:?}: {err}");
    assert!(err.contains(what), "{args:?}: {what:?} not in {err}");
}

#[test]
fn sinks_refuse_clearly() {
    let small = small_scene();
    // Not an .rrd name: refused before anything runs.
    fails_with(
        &["record", &small, "-d", "1ms", "-o", "x.txt"],
        &[],
        2,
        "`x.txt` does not end in .rrd",
    );
    assert!(!Path::new("x.txt").exists());
    // --serve goes with --save FILE, not with standard output.
    fails_with(
        &["record", &small, "--serve", "-o", "-"],
        &[],
        2,
        "--serve does not write to standard output",
    );
    // One sink at a time (--serve goes with --save FILE, not with another
    // live sink); the server options need --serve, and a limit Rerun
    // understands: usage errors.
    let usage: [&[&str]; 4] = [
        &["--spawn", "-o", "a.rrd"],
        &["--serve", "--spawn"],
        &["--port", "9000"],
        &["--serve", "--server-memory-limit", "lots"],
    ];
    for extra in usage {
        let args: Vec<&str> = ["record", &small]
            .into_iter()
            .chain(extra.iter().copied())
            .collect();
        let (code, err) = fails(&args, &[]);
        assert_eq!(code, 2, "{args:?}: {err}");
    }
    // A port in use (e.g. by a viewer): refused before anything runs.
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = taken.local_addr().unwrap().port().to_string();
    let serve = [
        "record",
        &small,
        "-d",
        "1ms",
        "--serve",
        "--bind",
        "127.0.0.1",
        "--port",
        &port,
    ];
    fails_with(&serve, &[], 4, &format!("cannot serve on 127.0.0.1:{port}"));
    // --spawn without a viewer on PATH.
    fails_with(
        &["record", &small, "-d", "1ms", "--spawn"],
        &[("PATH", "/nonexistent")],
        4,
        "cannot start a Rerun viewer",
    );
    // A bad --connect URL; no viewer listening: Rerun gives up after 5 s,
    // and the run says so.
    for (url, what) in [
        (
            "ftp://nowhere",
            "cannot stream to the viewer at ftp://nowhere",
        ),
        (
            "127.0.0.1:1",
            "cannot stream to the viewer at rerun+http://127.0.0.1:1/proxy",
        ),
    ] {
        fails_with(
            &["record", &small, "-d", "1ms", "--connect", url],
            &[],
            4,
            what,
        );
    }
}

#[test]
fn recordings_read_at_a_glance() {
    use rerun::blueprint::components::PanelState;
    use rerun::components::{Color, Scalar, Text, ViewCoordinates};

    // Yarn scene: one line strip per yarn, each in its own colour; the
    // quadrature points coloured by their stretch; a legend stating the
    // scale; every plot's series in distinct colours; total energy, mean
    // stretch and centre of mass logged.
    let rrd = fresh_tmp("record-look.rrd");
    record_ok(&common::small_scene(), "2ms", &rrd);
    let chunks = decode(&rrd);
    let strips = by_frame::<rerun::components::LineStrip2D>(
        &chunks["world/yarns"],
        rerun::LineStrips2D::descriptor_strips().component,
    );
    assert_eq!(strips.last().unwrap().1.len(), 2, "one strip per yarn");
    let strip_colors = by_frame::<Color>(
        &chunks["world/yarns"],
        rerun::LineStrips2D::descriptor_colors().component,
    );
    let c = &strip_colors.last().unwrap().1;
    assert_ne!(c[0], c[1], "yarns share a colour");
    let quad_colors = by_frame::<Color>(
        &chunks["world/quadrature"],
        Points2D::descriptor_colors().component,
    );
    let stretch = by_frame::<Scalar>(
        &chunks["world/quadrature"],
        rerun::ComponentIdentifier::from("stretch"),
    );
    let (frame, colors) = quad_colors.last().unwrap();
    let values = &stretch.iter().find(|(f, _)| f == frame).unwrap().1;
    for (c, s) in colors.iter().zip(values) {
        assert_eq!(*c, yarnsim_cli::record::stretch_color(s.0 .0));
    }
    let legend = all_values::<Text>(&chunks["legend"]);
    assert!(legend[0].as_str().contains("blue = 0.9"), "{:?}", legend);
    for e in [
        "plots/energy/total",
        "plots/stretch/mean",
        "plots/center_of_mass/x",
    ] {
        assert!(chunks.contains_key(e), "missing {e}");
    }
    let energy_colors: BTreeSet<[u8; 4]> = [
        "plots/energy/kinetic",
        "plots/energy/elastic",
        "plots/energy/potential",
        "plots/energy/total",
    ]
    .iter()
    .map(|e| all_values::<Color>(&chunks[*e])[0].to_array())
    .collect();
    assert_eq!(energy_colors.len(), 4, "energy series share colours");
    // Blueprint, selection and time panels start collapsed.
    let bp = decode_store(&rrd, StoreKind::Blueprint);
    for panel in ["blueprint_panel", "selection_panel", "time_panel"] {
        let states = all_values::<PanelState>(&bp[panel]);
        assert_eq!(states, vec![PanelState::Collapsed], "{panel}");
    }
    // The views: the scene, the colour scales and one plot per unit (its
    // title then names its series, see `cli/tests/blueprint.rs`).
    let views = view_names(&bp);
    let has_view = |views: &BTreeSet<String>, v: &str| {
        views
            .iter()
            .any(|n| n == v || n.starts_with(&format!("{v}: ")))
    };
    for v in [
        "scene",
        "colours",
        "energy [J]",
        "momentum [kg m/s]",
        "angular momentum [kg m^2/s]",
        "stretch l/l0",
        "centre of mass [m]",
        "wall time per substep [s]",
    ] {
        assert!(has_view(&views, v), "no view {v:?} in {views:?}");
    }

    // Labels at their objects: the obstacle's label is drawn at its centre
    // (no transform anywhere in a 2D recording, so nothing can mirror it),
    // and the boxes carry no labels that would cover it.
    let Scene::Yarn(y) = Scene::from_toml_str(SCENE).unwrap() else {
        unreachable!()
    };
    let centers = all_values::<Position2D>(&chunks["world/obstacles"]);
    let labels = all_values::<Text>(&chunks["world/obstacles"]);
    let o = &y.obstacles[0];
    let want = [o.center[0] as f32, (y.grid.size - o.center[1]) as f32];
    assert_eq!(
        centers.iter().map(|c| c.0 .0).collect::<Vec<_>>(),
        vec![want]
    );
    assert_eq!(labels.len(), 1);
    assert!(labels[0].as_str().contains("friction 0.3"));
    assert!(!chunks.contains_key("world"), "a transform on world");
    for boxes in ["world/domain", "world/walls"] {
        assert!(all_values::<Text>(&chunks[boxes]).is_empty(), "{boxes}");
    }
    assert!(legend[0].as_str().contains("grid 64x64"), "{:?}", legend);

    // Mass-spring scene: Y-up view coordinates at the 3D view's origin.
    let rrd = fresh_tmp("record-look-wire.rrd");
    yarnsim(&["record", "wire", "-d", "0.1", "-o", rrd.to_str().unwrap()]);
    let chunks = decode(&rrd);
    let vc = all_values::<ViewCoordinates>(&chunks["world"]);
    assert_eq!(vc, vec![rerun::components::ViewCoordinates::RUB]);
    let views = view_names(&decode_store(&rrd, StoreKind::Blueprint));
    for v in ["scene", "colours", "strain |l/l0 - 1|", "CG iterations"] {
        assert!(has_view(&views, v), "no view {v:?} in {views:?}");
    }
}

/// The display names in a blueprint store (views and containers).
fn view_names(bp: &BTreeMap<String, Vec<Chunk>>) -> BTreeSet<String> {
    bp.values()
        .flat_map(|chunks| all_values::<rerun::components::Name>(chunks))
        .map(|n| n.as_str().to_string())
        .collect()
}

/// Reads the data chunks a `--serve` server sends, the way a viewer started
/// with `rerun --connect URL` does (Rerun's gRPC client), until `done`
/// holds for them; fails after 60 s or when the connection fails.
#[cfg(unix)]
fn read_server(
    url: &str,
    done: impl Fn(&BTreeMap<String, Vec<Chunk>>) -> bool,
) -> BTreeMap<String, Vec<Chunk>> {
    use re_log_channel::{DataSourceMessage, SmartMessagePayload};
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .enable_all()
        .build()
        .unwrap();
    let handle = re_async::AsyncRuntimeHandle::new_native(runtime.handle().clone());
    let rx = rerun::external::re_grpc_client::stream(&handle, url.parse().expect("proxy URL"));
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
    let mut chunks: BTreeMap<String, Vec<Chunk>> = BTreeMap::new();
    while !done(&chunks) {
        let left = deadline.saturating_duration_since(std::time::Instant::now());
        let msg = rx
            .recv_timeout(left)
            .unwrap_or_else(|e| panic!("no more data from {url} ({e}); got {:?}", chunks.keys()));
        match msg.payload {
            SmartMessagePayload::Msg(DataSourceMessage::LogMsg(LogMsg::ArrowMsg(store, arrow)))
                if store.kind() == StoreKind::Recording =>
            {
                let chunk = Chunk::from_arrow_msg(&arrow).expect("chunk");
                let path = chunk.entity_path().to_string();
                chunks
                    .entry(path.trim_start_matches('/').to_string())
                    .or_default()
                    .push(chunk);
            }
            SmartMessagePayload::Quit(err) => panic!("connection to {url} ended: {err:?}"),
            _ => {}
        }
    }
    chunks
}

/// `record --serve --save FILE`: the server serves the whole recording to a
/// viewer that connects after the run, the file is complete while it still
/// serves, and SIGTERM ends the serving with exit code 0.
#[cfg(unix)]
#[test]
fn serve_serves_the_recording_until_sigterm() {
    use std::io::BufRead;
    let rrd = fresh_tmp("record-serve.rrd");
    let port = {
        let free = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        free.local_addr().unwrap().port().to_string()
    };
    let mut child = Command::new(env!("CARGO_BIN_EXE_yarnsim"))
        .args(["record", &small_scene(), "-d", "2ms", "--serve"])
        .args(["--bind", "127.0.0.1", "--port", &port, "--save"])
        .arg(&rrd)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("start yarnsim");
    let url = format!("rerun+http://127.0.0.1:{port}/proxy");
    // Kill the child whatever happens below, so a failure leaves no server.
    struct Reap(std::process::Child);
    impl Drop for Reap {
        fn drop(&mut self) {
            let _ = self.0.kill();
            let _ = self.0.wait();
        }
    }
    let mut lines = std::io::BufReader::new(child.stdout.take().unwrap()).lines();
    let mut child = Reap(child);
    let mut stdout = String::new();
    // The URL comes first, before the run; "still serving" once it is done.
    while !stdout.contains("still serving") {
        let Some(Ok(line)) = lines.next() else {
            let mut err = String::new();
            std::io::Read::read_to_string(child.0.stderr.as_mut().unwrap(), &mut err).unwrap();
            panic!("yarnsim stopped before serving:\n{stdout}{err}");
        };
        stdout += &line;
        stdout += "\n";
    }
    assert!(
        stdout.starts_with(&format!(
            "serving at {url}; view it live with: rerun --connect {url}\n"
        )),
        "{stdout}"
    );
    assert!(
        stdout.contains(&format!(
            "recorded 6 frames (50 substeps, 118 particles) to the server at {url} and {}",
            rrd.display()
        )),
        "{stdout}"
    );
    // The saved copy is complete while the server still runs.
    let saved = decode(&rrd);
    assert_eq!(vertex_frames(&saved), (0..=5).collect::<Vec<_>>());
    // A viewer connecting now gets all of it: every entity, every frame.
    let served = read_server(&url, |c| {
        c.get("world/vertices").is_some_and(|v| {
            by_frame::<Position2D>(v, Points2D::descriptor_positions().component).len() == 6
        }) && saved.keys().all(|k| c.contains_key(k))
    });
    assert_eq!(
        served.keys().collect::<Vec<_>>(),
        saved.keys().collect::<Vec<_>>()
    );
    assert_eq!(vertex_frames(&served), (0..=5).collect::<Vec<_>>());
    let positions = |c: &BTreeMap<String, Vec<Chunk>>| {
        by_frame::<Position2D>(
            &c["world/vertices"],
            Points2D::descriptor_positions().component,
        )
    };
    assert_eq!(positions(&served), positions(&saved));
    // SIGTERM (like Ctrl-C) ends the serving: exit code 0, the run was complete.
    let kill = Command::new("kill")
        .args(["-TERM", &child.0.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let status = child.0.wait().unwrap();
    let rest: Vec<String> = lines.map(Result::unwrap).collect();
    assert_eq!(status.code(), Some(0), "{rest:?}");
    assert_eq!(rest, ["stopped serving"]);
}
