//! Shared helpers of the integration tests.
#![allow(dead_code)]

use yarnsim::massspring::{Integrator as MassSpringIntegrator, IntegratorOptions};
use yarnsim::math::{perp, Mat2, Vec2};
use yarnsim::scene::{
    AttractorSpec, GridSpec, Integrator, Material, Obstacle, PinMotionKind, PinSpec, StepSize,
    TimeSpec, TransferScheme, TransferSpec, WallMode, Walls, YarnEnd, YarnMaterial, YarnScene,
    YarnSpec,
};
use yarnsim::testing::Capstan;
use yarnsim::YarnSim;

/// The seeded generator of the tests (proptest's ChaCha `TestRng`).
#[allow(unused_imports)] // not every test uses it
pub use yarnsim::testing::Rng;

/// The scale of momentum errors: `sum m |v|` over every particle.
pub fn momentum_scale(sim: &YarnSim) -> f64 {
    let p = sim.particles();
    p.vert
        .v
        .iter()
        .zip(&p.vert.m)
        .chain(p.quad.v.iter().zip(&p.quad.m))
        .map(|(v, m)| m * v.norm())
        .sum()
}

/// Runs `steps` substeps of `sim` and returns the worst momentum balance
/// of one substep: the change of momentum less the impulse of gravity and
/// of the pins' reactions, `(g M + sum R) dt`, relative to
/// [`momentum_scale`] plus that impulse.
pub fn worst_momentum_balance(sim: &mut YarnSim, steps: u32) -> f64 {
    let (dt, g) = (sim.dt(), sim.gravity());
    let mut worst: f64 = 0.0;
    for _ in 0..steps {
        let d0 = sim.diagnostics();
        sim.step().unwrap();
        let d1 = sim.diagnostics();
        let pins: Vec2 = sim.pin_reactions().iter().sum();
        let expect = (g * d0.total_mass + pins) * dt;
        let scale = momentum_scale(sim) + expect.norm();
        worst = worst.max((d1.momentum - d0.momentum - expect).norm() / scale);
    }
    worst
}

/// Runs `f` on a rayon pool of `threads` threads (for the bit-identity
/// checks across thread counts).
pub fn on_threads<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

/// `run` on 1 and on 2 threads (each with its own pool): asserts the
/// same result (states compared with `==`, no dump of their bytes) and
/// returns it.
pub fn same_on_one_and_two_threads<S: PartialEq + Send, T: PartialEq + std::fmt::Debug + Send>(
    run: impl Fn() -> (S, T) + Sync,
) -> T {
    let (a, sa) = on_threads(1, &run);
    let (b, sb) = on_threads(2, &run);
    assert_eq!(sa, sb);
    assert!(a == b, "states differ");
    sa
}

/// Runs `steps` substeps of `scene` on 1 and on 2 threads and asserts the
/// same saved state and implicit-solve counts; returns the counts.
pub fn same_bits_on_one_and_two_threads(
    scene: &YarnScene,
    steps: u64,
) -> yarnsim::mpm::driver::ImplicitStats {
    same_on_one_and_two_threads(|| {
        let mut sim = YarnSim::new(scene).unwrap();
        sim.steps_n(steps).unwrap();
        (sim.save_state(), sim.implicit_stats())
    })
}

/// A yarn scene from TOML text; panics with the loader's message on error.
pub fn scene(text: &str) -> YarnScene {
    YarnScene::from_toml_str(text).unwrap_or_else(|e| panic!("{e}"))
}

/// The bare test scene of [`SceneBuilder::bare`] with its `[[yarns]]` given
/// as TOML text, read by the scene loader (`yarns` holds `[[yarns]]` tables
/// only: the scene's other tables are already in the text).
pub fn bare_scene(yarns: &str) -> YarnScene {
    let text = SceneBuilder::bare()
        .yarn(straight([0.3, 0.5], [0.7, 0.5], 10))
        .build()
        .to_toml_string();
    let head = &text[..text.find("[[yarns]]").expect("the scene has a yarn")];
    scene(&format!("{head}{yarns}"))
}

/// A straight yarn from `start` to `end` with `vertices` vertices.
pub fn straight(start: [f64; 2], end: [f64; 2], vertices: u32) -> YarnSpec {
    YarnSpec::straight(start, end, vertices)
}

/// A yarn along the polyline `points`, resampled to `vertices` vertices.
pub fn polyline(points: &[[f64; 2]], vertices: u32) -> YarnSpec {
    YarnSpec {
        points: Some(points.to_vec()),
        vertices,
        count: 1,
        ..YarnSpec::default()
    }
}

/// `count` parallel copies of a straight yarn, each `spacing` from the last.
pub fn bundle(
    start: [f64; 2],
    end: [f64; 2],
    vertices: u32,
    count: u32,
    spacing: [f64; 2],
) -> YarnSpec {
    YarnSpec {
        count,
        spacing,
        ..straight(start, end, vertices)
    }
}

/// `[[yarns]]` and `[[pins]]` tables as scene-file text (the scene
/// loader's own spelling), for test scenes written as TOML text.
pub fn yarns_and_pins_toml(yarns: &[YarnSpec], pins: &[PinSpec]) -> String {
    #[derive(serde::Serialize)]
    struct Tables<'a> {
        yarns: &'a [YarnSpec],
        pins: &'a [PinSpec],
    }
    toml::to_string(&Tables { yarns, pins }).expect("yarns and pins serialize")
}

/// A fixed pin of `count` vertices of yarn `yarn` from its `end`.
pub fn pin_end(yarn: u32, end: YarnEnd, count: u32) -> PinSpec {
    PinSpec {
        yarn,
        end: Some(end),
        vertex: None,
        count,
        motion: PinMotionKind::Fixed,
        velocity: None,
        center: None,
        angular_velocity: None,
    }
}

/// A fixed pin of `count` vertices of yarn `yarn` from index `vertex` on.
pub fn pin_vertex(yarn: u32, vertex: u32, count: u32) -> PinSpec {
    PinSpec {
        end: None,
        vertex: Some(vertex),
        ..pin_end(yarn, YarnEnd::Start, count)
    }
}

/// A simulation of the bare scene ([`SceneBuilder::bare`]) with one
/// straight yarn.
pub fn straight_yarn_sim(start: [f64; 2], end: [f64; 2], vertices: u32) -> YarnSim {
    YarnSim::new(
        &SceneBuilder::bare()
            .yarn(straight(start, end, vertices))
            .build(),
    )
    .unwrap()
}

/// Test scenes without TOML text: [`SceneBuilder::bare`] and the settings
/// tests vary; [`SceneBuilder::build`] validates like the scene loader.
#[derive(Clone, Debug)]
pub struct SceneBuilder(YarnScene);

impl SceneBuilder {
    /// A 64^2 grid over 1 m without gravity, walls, obstacles or
    /// plasticity: dt 1e-4, k 1000, gamma 500, E 1000, friction 0.05,
    /// bending 1e-4, density 1, FLIP (the default transfer); no
    /// yarns yet.
    pub fn bare() -> Self {
        SceneBuilder(YarnScene {
            kind: "yarn".into(),
            name: String::new(),
            description: String::new(),
            grid: GridSpec {
                resolution: 64,
                size: 1.0,
            },
            time: TimeSpec {
                dt: StepSize::Fixed(1e-4),
                safety: None,
                dt_max: None,
                frame_dt: 1.0 / 60.0,
                integrator: Integrator::Explicit,
                axial: Default::default(),
            },
            material: Material {
                k: 1000.0,
                gamma: 500.0,
                youngs_modulus: 1000.0,
                friction: 0.05,
                bending: 1e-4,
                density: 1.0,
                plasticity: false,
                yarn: None,
            },
            gravity: [0.0, 0.0],
            attractor: AttractorSpec::default(),
            walls: Walls {
                mode: WallMode::None,
                ..Walls::default()
            },
            obstacles: Vec::new(),
            transfer: TransferSpec::default(),
            contact: Default::default(),
            yarns: Vec::new(),
            pins: Vec::new(),
        })
    }

    /// `n`^2 grid cells.
    pub fn resolution(mut self, n: u32) -> Self {
        self.0.grid.resolution = n;
        self
    }

    /// The substep: a size in s or [`StepSize::Auto`].
    pub fn dt(mut self, dt: impl Into<StepSize>) -> Self {
        self.0.time.dt = dt.into();
        self
    }

    /// Output frame interval in s.
    pub fn frame_dt(mut self, frame_dt: f64) -> Self {
        self.0.time.frame_dt = frame_dt;
        self
    }

    /// Gravity `[gx, gy]` in m/s^2.
    pub fn gravity(mut self, g: [f64; 2]) -> Self {
        self.0.gravity = g;
        self
    }

    /// Changes the material.
    pub fn material(mut self, edit: impl FnOnce(&mut Material)) -> Self {
        edit(&mut self.0.material);
        self
    }

    /// The boundary condition at the domain edges.
    pub fn walls(mut self, mode: WallMode) -> Self {
        self.0.walls.mode = mode;
        self
    }

    /// The transfer scheme (APIC or FLIP).
    pub fn scheme(mut self, scheme: TransferScheme) -> Self {
        self.0.transfer.scheme = scheme;
        self
    }

    /// Adds a circular obstacle.
    pub fn obstacle(mut self, center: [f64; 2], radius: f64, friction: f64) -> Self {
        self.0.obstacles.push(Obstacle {
            center,
            radius,
            friction,
        });
        self
    }

    /// Adds a `[[yarns]]` entry.
    pub fn yarn(mut self, yarn: YarnSpec) -> Self {
        self.0.yarns.push(yarn);
        self
    }

    /// Adds a `[[pins]]` entry.
    pub fn pin(mut self, pin: PinSpec) -> Self {
        self.0.pins.push(pin);
        self
    }

    /// The scene, validated; panics with the validator's message.
    pub fn build(self) -> YarnScene {
        self.0.validate().unwrap_or_else(|e| panic!("{e}"));
        self.0
    }
}

/// Free fall of the grid scheme from rest after `n` substeps of `dt` under
/// `g` (symplectic or backward Euler on the grid, no elastic force): the
/// centre of mass `c0 + dt^2 g n (n + 1) / 2` and the velocity `n dt g`.
pub fn grid_free_fall(c0: Vec2, g: Vec2, dt: f64, n: u64) -> (Vec2, Vec2) {
    (
        c0 + g * (dt * dt * (n * (n + 1)) as f64 / 2.0),
        g * (n as f64 * dt),
    )
}

/// A bundle of 3 + 1 crossing yarns on the bare scene (64^2, without
/// gravity, walls or obstacles), turned rigidly at `omega` about its centre
/// of mass (v = omega perp(x - c), C = [[0, -omega], [omega, 0]]) plus a
/// drift `drift`.
pub fn spinning_bundle(omega: f64, drift: Vec2) -> YarnSim {
    let s = SceneBuilder::bare()
        .yarn(bundle([0.3, 0.5], [0.7, 0.52], 80, 3, [0.0, 0.012]))
        .yarn(straight([0.48, 0.3], [0.52, 0.7], 80))
        .build();
    let mut sim = YarnSim::new(&s).unwrap();
    let c = sim.diagnostics().center_of_mass;
    let spin = Mat2::new(0.0, -omega, omega, 0.0);
    let p = yarnsim::testing::particles_mut(&mut sim);
    for k in 0..p.vert.x.len() {
        p.vert.v[k] = perp(p.vert.x[k] - c) * omega + drift;
        p.vert.c[k] = spin;
    }
    for k in 0..p.quad.x.len() {
        p.quad.v[k] = perp(p.quad.x[k] - c) * omega + drift;
        p.quad.c[k] = spin;
    }
    sim
}

/// Steps `sim`, at rest, `n` substeps of `dt` under `g` and asserts the
/// grid scheme's free fall ([`grid_free_fall`]) to round-off: the centre of
/// mass within 1e-12 m, the mean velocity within 1e-11 m/s, and with
/// `stretch_tol` every stretch within it of 1.
pub fn assert_grid_free_fall(
    sim: &mut YarnSim,
    g: Vec2,
    dt: f64,
    n: u64,
    stretch_tol: Option<f64>,
) {
    let c0 = sim.diagnostics().center_of_mass;
    sim.steps_n(n).unwrap();
    let (expected, v) = grid_free_fall(c0, g, dt, n);
    let d = sim.diagnostics();
    let err = (d.center_of_mass - expected).norm();
    assert!(err < 1e-12, "centre of mass off by {err:.3e} m");
    assert!((d.momentum / d.total_mass - v).norm() < 1e-11);
    if let Some(tol) = stretch_tol {
        for st in sim.stretches() {
            assert!((st - 1.0).abs() < tol, "stretch {st}");
        }
    }
}

/// Heavy-rope capstan: tension at the heavy end of the wrapped half circle
/// for friction `mu`, from dT/ds = mu T / R + w (mu sin psi - cos psi),
/// psi = pi - s / R, T(0) = w l1 (RK4 in 2000 steps).
pub fn capstan_tension(mu: f64, r: f64, w: f64, l1: f64) -> f64 {
    let f = |s: f64, t: f64| {
        let psi = std::f64::consts::PI - s / r;
        mu * t / r + w * (mu * psi.sin() - psi.cos())
    };
    let n = 2000;
    let h = std::f64::consts::PI * r / n as f64;
    let mut t = w * l1;
    for i in 0..n {
        let s = i as f64 * h;
        let k1 = f(s, t);
        let k2 = f(s + h / 2.0, t + h / 2.0 * k1);
        let k3 = f(s + h / 2.0, t + h / 2.0 * k2);
        let k4 = f(s + h, t + h * k3);
        t += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    }
    t
}

/// The friction coefficient at which the heavy-rope capstan just holds
/// hanging lengths `l1` and `l2` over a half circle of radius `r`
/// (bisection on `T(pi R) = w l2`; independent of `w`).
pub fn capstan_threshold(r: f64, l1: f64, l2: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 5.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if capstan_tension(mid, r, 1.0, l1) < l2 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The capstan oracles' material, that of every built-in scene
/// (`reference_material`) without its bending: k = 1000, gamma = 500,
/// E = 1000, fibre friction 0.05, plasticity on; at the test resolution
/// 128^2, dt 1e-4, and g = 2 m/s^2 as for the string: the elastic stretch
/// of the wrapped arc under g = 9.8 (T pi R / k = 9e-4 m at l2 = 0.3) is
/// 0.9 % of l1, and its undamped oscillation alone reads as a slip
/// (measured: R 0.1, l2 / l1 = 2 then crosses at +18 %, the other five
/// cases at +9.4 %).
pub const CAPSTAN_BUILTIN: Capstan = Capstan {
    res: 128,
    dt: 1e-4,
    g: 2.0,
    gamma: 500.0,
    youngs_modulus: 1000.0,
    friction: 0.05,
    bending: 0.0,
    plasticity: true,
};

/// [`CAPSTAN_BUILTIN`] at the resolution of the built-in scenes, 256^2,
/// dt 4e-5.
pub const CAPSTAN_BUILTIN_256: Capstan = Capstan {
    res: 256,
    dt: 4e-5,
    ..CAPSTAN_BUILTIN
};

/// The heavy-rope capstan of [`yarnsim::testing::capstan_drop_toml`]
/// (R `r`, l1 0.1, l2 0.3, the circle's friction `factor` times the
/// threshold mu*, [`CAPSTAN_BUILTIN`]'s grid and g) with the yarn of the
/// preset `name` (`EI = 0`: the oracle's rope is flexible; plasticity on)
/// at `dt = "auto"`, its centre line `d / 2 + drop` from the circle: on
/// the circle that contact sees, grown by half the preset's diameter `d`,
/// or `drop` above it. Laid on the bare circle instead, the yarn starts
/// inside the grown one, and its first step out of it stretches the
/// wrapped arc by `d / (2 R)`, at a real `EA` a tension thousands of times
/// the strands' weight (`docs/performance/softened.md`).
pub fn preset_capstan_toml(name: &str, r: f64, drop: f64, factor: f64) -> String {
    let (l1, l2) = (0.1, 0.3);
    let mu = factor * capstan_threshold(r, l1, l2);
    let lay = 0.5 * yarnsim::scene::presets::preset(name).unwrap().diameter;
    let text = yarnsim::testing::capstan_drop_toml(r, l1, l2, mu, lay + drop, &CAPSTAN_BUILTIN);
    let (a, b) = (
        text.find("[material]\n").unwrap(),
        text.find("[walls]").unwrap(),
    );
    format!(
        "{}[material]\npreset = \"{name}\"\nEI = 0.0\nplasticity = true\n{}",
        &text[..a],
        &text[b..]
    )
    .replace("dt = 0.0001\n", "dt = \"auto\"\n")
}

/// The `[[yarns]]` and `[[pins]]` of the incline of `yarn_friction.rs` on
/// `res`^2: a bed yarn of 0.8 m along x at y = 0.4, all vertices pinned,
/// and a free yarn of 0.3 m one cell above it, both at dx / 2 spacing.
pub fn incline_yarns_toml(res: u32) -> String {
    let dx = 1.0 / res as f64;
    let bed_n = (0.8 / (0.5 * dx)).round() as u32 + 1;
    let top_n = (0.3 / (0.5 * dx)).round() as u32 + 1;
    let y = 0.4 + dx;
    yarns_and_pins_toml(
        &[
            straight([0.1, 0.4], [0.9, 0.4], bed_n),
            straight([0.3, y], [0.6, y], top_n),
        ],
        &[pin_end(0, YarnEnd::Start, bed_n)],
    )
}

/// Time the capstan runs load before the slip is measured: the yarn starts
/// unstretched at rest, and until the tension wave has loaded it (a few
/// 0.01 s) the friction that needs that tension is missing and it slips
/// by up to about 1e-3 m even far above the threshold.
pub const CAPSTAN_LOAD: f64 = 0.2;

/// Runs a capstan scene's `sim` for [`CAPSTAN_LOAD`] and then up to 1 s
/// more; returns whether it slid in that second (a free end of hanging
/// length `l1` or `l2` moved vertically by more than 0.5 % of it; the
/// lateral pendulum swing of the hanging strands that the loading excites
/// is not a slip) and the largest relative vertical end displacement.
/// Stops as soon as it slid. Every 5 ms (and at the end) `at_check` sees
/// the simulation, before the slip test.
pub fn capstan_slip(
    sim: &mut YarnSim,
    l1: f64,
    l2: f64,
    mut at_check: impl FnMut(&YarnSim),
) -> (bool, f64) {
    sim.advance(CAPSTAN_LOAD).unwrap();
    let (a0, b0) = sim.yarn_endpoints(0);
    let steps = (1.0 / sim.dt()).round() as u64;
    let check = (5e-3 / sim.dt()).round().max(1.0) as u64;
    let mut worst: f64 = 0.0;
    for k in 0..steps {
        sim.step().unwrap();
        if k % check == check - 1 || k + 1 == steps {
            let (a, b) = sim.yarn_endpoints(0);
            let rel = ((a.y - a0.y).abs() / l1).max((b.y - b0.y).abs() / l2);
            worst = worst.max(rel);
            at_check(sim);
            if rel > 0.005 {
                return (true, rel);
            }
        }
    }
    (false, worst)
}

/// Mass-spring integrator options that solve each step to `cg_tolerance`
/// at the fixed step `h`; Chebyshev-Jacobi gets `chebyshev_iterations`
/// iterations at rho 0.9, so that its minimisation converges too.
pub fn solved_options(
    integ: MassSpringIntegrator,
    h: f64,
    cg_tolerance: f64,
    chebyshev_iterations: usize,
) -> IntegratorOptions {
    let mut o = IntegratorOptions {
        dt: Some(h),
        cg_tolerance,
        ..Default::default()
    };
    if integ == MassSpringIntegrator::ChebyshevJacobi {
        o.iterations = chebyshev_iterations;
        o.rho = 0.9;
    }
    o
}

/// `s` with the yarn diameter `d` (m, `material.diameter`) added to its
/// material given per metre of depth (`None`: `s` as it is).
pub fn with_diameter(mut s: YarnScene, d: Option<f64>) -> YarnScene {
    if let Some(d) = d {
        s.material.yarn = Some(YarnMaterial {
            diameter: Some(d),
            ..YarnMaterial::default()
        });
    }
    s
}

/// A scene of the built-in material (k 1000, gamma 500, E 1000) with
/// fibre friction `c_f`, no bending, plasticity on, no walls, on `res`^2,
/// gravity `gravity`, the `[time]` lines `time`, and the `[[yarns]]`,
/// `[[pins]]` and `[[obstacles]]` of `yarns` (the friction oracles:
/// `yarn_friction.rs`, `yarn_on_yarn.rs`).
pub fn friction_scene(
    gravity: [f64; 2],
    res: u32,
    scheme: TransferScheme,
    c_f: f64,
    yarns: &str,
    time: &str,
) -> YarnScene {
    let scheme = scheme.name();
    scene(&format!(
        r#"
gravity = [{}, {}]
[grid]
resolution = {res}
[time]
{time}
[transfer]
scheme = "{scheme}"
[material]
k = 1000.0
gamma = 500.0
youngs_modulus = 1000.0
friction = {c_f}
bending = 0.0
plasticity = true
[walls]
mode = "none"
{yarns}"#,
        gravity[0], gravity[1]
    ))
}
