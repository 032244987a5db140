//! Helpers for tests and the measurement programs, not part of the
//! simulator: the reference material, the oracle scenes (hanging chain,
//! capstan, cantilever, implicit landing) and their measurements. Built only
//! with the cargo feature `testing` (the crate's own tests switch it on
//! through a dev-dependency on the crate itself, and so do the tests and
//! examples of `yarnsim-fmu` and `yarnsim-evidence`); the CLI's release
//! build leaves it out. The analytic oracles (`J0`, the extensible chain)
//! are re-exported from `yarnsim-oracles`, which the evidence studies use
//! without this feature; the small yarn scene of the studies and tests is
//! `yarnsim_evidence::small_yarn_scene`.

pub use yarnsim_oracles::{bessel_j0, extensible_chain_omega, J0_FIRST_ZERO};

use proptest::prelude::Rng as _;
use proptest::test_runner::{RngAlgorithm, TestRng};

use crate::math::Vec2;

use crate::scene::builtin::yarn_reference;
use crate::scene::{Integrator, Material, Obstacle, StepSize, YarnScene, YarnSpec};

/// The grid, substep and material lines of the small yarn test scenes, as
/// a string literal for `concat!`: a 64^2 grid, dt 1e-4, k 1000, gamma
/// 500, E 1000, friction 0.05, every other field of these tables
/// defaulted. Nine lines: `tests/scene_errors.rs` counts them in the line
/// numbers it asserts.
#[macro_export]
macro_rules! small_yarn_tables {
    () => {
        "[grid]
resolution = 64
[time]
dt = 1e-4
[material]
k = 1000.0
gamma = 500.0
youngs_modulus = 1000.0
friction = 0.05
"
    };
}

/// The smallest complete yarn scene file: [`small_yarn_tables`] (every
/// other field defaulted) and one straight yarn of 20 vertices from
/// (0.2, 0.5) along +x, 0.5 m long.
pub const MINIMAL_TOML: &str = concat!(
    "\nname = \"t\"\n",
    small_yarn_tables!(),
    "[[yarns]]
start = [0.2, 0.5]
direction = [1.0, 0.0]
length = 0.5
vertices = 20
"
);

/// The one seeded generator of the tests (the library's unit tests and
/// the integration tests): proptest's ChaCha [`TestRng`], whose draws are
/// the same on every system and proptest 1 version, seeded with `seed`.
pub struct Rng(TestRng);

impl Rng {
    /// The generator seeded with `seed` (its little-endian bytes, then zeros).
    pub fn new(seed: u64) -> Self {
        let mut bytes = [0u8; 32];
        bytes[..8].copy_from_slice(&seed.to_le_bytes());
        Rng(TestRng::from_seed(RngAlgorithm::ChaCha, &bytes))
    }
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0.next_u64()
    }
    /// Uniform in [0, 1) (53 bits).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
    /// Uniform in [-s/2, s/2).
    pub fn sym(&mut self, s: f64) -> f64 {
        s * (self.unit() - 0.5)
    }
    /// `n` vectors of components uniform in [-s/2, s/2).
    pub fn vec(&mut self, n: usize, s: f64) -> Vec<Vec2> {
        (0..n)
            .map(|_| Vec2::new(self.sym(s), self.sym(s)))
            .collect()
    }
}

/// Asserts that the error message `m` names every one of `parts` (a
/// field, its line, the bound it breaks); the failure prints `m`.
pub fn assert_mentions(m: &str, parts: &[&str]) {
    for part in parts {
        assert!(m.contains(part), "no {part:?} in the message: {m}");
    }
}

/// The material of the reference scene (`yarn-reference`).
pub fn reference_material() -> Material {
    yarn_reference().material
}

/// The grid implicit integrator's landing scene: a small bundle (3 yarns
/// of 0.3 m, 75 vertices each, 1 cm apart) of the built-in material with
/// fibre stiffness `k`, released 6.5 cm above one circle of the reference
/// scene (R 0.08 at (0.5, 0.6), obstacle friction `mu`, 256^2), under
/// `integrator = "implicit"` at `dt = "auto"`; it lands at about 1.1 m/s
/// at t = 0.111 s, as the reference bundle does.
pub fn implicit_landing_scene(k: f64, mu: f64) -> YarnScene {
    let mut s = yarn_reference();
    s.material.k = k;
    s.time.integrator = Integrator::Implicit;
    s.time.dt = StepSize::Auto;
    s.obstacles = vec![Obstacle {
        center: [0.5, 0.6],
        radius: 0.08,
        friction: mu,
    }];
    s.yarns = vec![YarnSpec {
        start: Some([0.35, 0.745]),
        direction: Some([1.0, 0.0]),
        length: Some(0.3),
        vertices: 75,
        count: 3,
        spacing: [0.0, 0.01],
        ..Default::default()
    }];
    s.validate().unwrap();
    s
}

/// The reference bundle's lowest `yarns` yarns (of 12: 0.8 m, 200
/// vertices, 1 cm apart, released at y 0.75 m over the three circles,
/// 256^2) of the built-in material with fibre stiffness `k`, under
/// `integrator = "implicit"` at `dt = "auto"`: they land on the left
/// circle at about 1.1 m/s at t = 0.114 s and pile up on one another.
pub fn implicit_pile_scene(k: f64, yarns: u32) -> YarnScene {
    let mut s = yarn_reference();
    s.material.k = k;
    s.time.integrator = Integrator::Implicit;
    s.time.dt = StepSize::Auto;
    s.yarns[0].count = yarns;
    s.validate().unwrap();
    s
}

/// The hanging chain's length (m) and gravity (m/s^2).
pub const CHAIN_LENGTH: f64 = 0.8;
/// The hanging chain's gravity (m/s^2).
pub const CHAIN_GRAVITY: f64 = 9.8;

/// A straight yarn of the material `preset` (`[material] preset`, see
/// `yarnsim materials`), L = `CHAIN_LENGTH` hanging at rest from a pin at
/// its top (0.5, 0.9), no return mapping, no walls, 100 vertices on a 64^2
/// grid at `dt = "auto"`, gravity `CHAIN_GRAVITY`: the scene of the checks
/// that a preset's pin force per metre of depth times the sheet spacing is
/// one yarn's weight.
pub fn hanging_preset_yarn_toml(preset: &str) -> String {
    let (len, g) = (CHAIN_LENGTH, CHAIN_GRAVITY);
    let yarn = format!(
        "start = [0.5, 0.9]\nend = [0.5, {}]\nvertices = 100\n",
        0.9 - len
    );
    one_pinned_yarn_toml(
        g,
        64,
        "\"auto\"",
        &format!("preset = \"{preset}\"\n"),
        &yarn,
        "end = \"start\"\n",
    )
}

/// A scene of one yarn with its first pin on yarn 0 and no walls, the text
/// the oracles' one-yarn scenes share: `material` and `yarn` are the lines
/// of those tables before `plasticity = false` / after `[[yarns]]`, `pin`
/// the first pin's lines after `yarn = 0` (and any further tables).
fn one_pinned_yarn_toml(
    g: f64,
    resolution: u32,
    dt: &str,
    material: &str,
    yarn: &str,
    pin: &str,
) -> String {
    format!(
        "\ngravity = [0.0, -{g}]\n[grid]\nresolution = {resolution}\n[time]\ndt = {dt}\n\
         [material]\n{material}plasticity = false\n[walls]\nmode = \"none\"\n\
         [[yarns]]\n{yarn}[[pins]]\nyarn = 0\n{pin}"
    )
}

/// The hanging chain of the yarn oracles as scene TOML: L = 0.8 m pinned at
/// (0.5, 0.9), bending 0, k = 2000 (static strain at the top g L rho / k =
/// 0.4 %), no cross-section energy, default FLIP, started in the first mode
/// shape `u = A J0(j01 sqrt(z / L))` with A = 0.02 m (200 polyline
/// segments, resampled to `vertices`), on a `resolution`^2 grid with the
/// substep `dt` (a TOML value: `1e-4` or `"auto"`).
pub fn hanging_chain_toml(vertices: u32, resolution: u32, dt: &str) -> String {
    let (len, g, amp, n) = (CHAIN_LENGTH, CHAIN_GRAVITY, 0.02, 200);
    let points = (0..=n)
        .map(|i| {
            let z = len * (n - i) as f64 / n as f64; // from the top down
            let u = amp * bessel_j0(J0_FIRST_ZERO * (z / len).sqrt());
            format!("[{:.12}, {:.12}]", 0.5 + u, 0.1 + z)
        })
        .collect::<Vec<_>>()
        .join(", ");
    one_pinned_yarn_toml(
        g,
        resolution,
        dt,
        "k = 2000.0\ngamma = 0.0\nyoungs_modulus = 0.0\nfriction = 0.0\nbending = 0.0\n",
        &format!("points = [{points}]\nvertices = {vertices}\n"),
        "end = \"start\"\n",
    )
}

/// The hanging chain's first-mode period, `2 pi / omega_1` with
/// `omega_1 = (j01 / 2) sqrt(g / L)` (Daniel Bernoulli's hanging chain,
/// whose modes are `J0(j sqrt(z / L))`).
pub fn hanging_chain_period() -> f64 {
    let omega = J0_FIRST_ZERO / 2.0 * (CHAIN_GRAVITY / CHAIN_LENGTH).sqrt();
    2.0 * std::f64::consts::PI / omega
}

/// The hanging chain's first-mode period (s) as the linearised discrete
/// extensible chain gives it ([`extensible_chain_omega`]): `segments` equal
/// segments of [`CHAIN_LENGTH`], fiber stiffness `k`, line density
/// `density`, gravity [`CHAIN_GRAVITY`]. Against [`hanging_chain_period`]
/// (the inextensible continuum) it is the model's own bias: the stretch
/// under the chain's weight and the segment count, not a scheme's error.
pub fn hanging_chain_floor_period(segments: usize, k: f64, density: f64) -> f64 {
    2.0 * std::f64::consts::PI
        / extensible_chain_omega(segments, CHAIN_LENGTH, density, k, CHAIN_GRAVITY)
}

/// The zero crossings of a sampled signal, each time interpolated linearly
/// within the step that crossed.
#[derive(Clone, Debug)]
pub struct ZeroCrossings {
    prev: f64,
    /// The crossing times, in order.
    pub times: Vec<f64>,
}

impl ZeroCrossings {
    /// Starts from the signal's first sample `u0`.
    pub fn new(u0: f64) -> Self {
        Self {
            prev: u0,
            times: Vec::new(),
        }
    }

    /// Takes the sample `u` at the time `t`, a step `h` after the previous
    /// one; returns whether the signal crossed zero in that step.
    pub fn push(&mut self, t: f64, h: f64, u: f64) -> bool {
        let crossed = self.prev * u < 0.0;
        if crossed {
            self.times.push(t - h * u / (u - self.prev));
        }
        self.prev = u;
        crossed
    }

    /// The period of an oscillation, twice the mean spacing of the
    /// crossings (NaN with fewer than two).
    pub fn period(&self) -> f64 {
        let c = &self.times;
        if c.len() < 2 {
            return f64::NAN;
        }
        2.0 * (c[c.len() - 1] - c[0]) / (c.len() - 1) as f64
    }
}

/// The Euler-Bernoulli cantilever of the yarn oracles: length (m), bending
/// stiffness B (N m), line density (kg/m), and the gravity `0.08 B / (rho
/// L^3)` that sags the tip by about 1 % of L.
pub fn cantilever_setup() -> (f64, f64, f64, f64) {
    let (len, b, rho): (f64, f64, f64) = (0.5, 1.0, 1.0);
    (len, b, rho, 0.08 * b / (rho * len * len * len))
}

/// The cantilever of [`cantilever_setup`] as scene TOML: from (0.25, 0.5)
/// along +x with `vertices` vertices, the first two pinned, k = 1e4, no
/// cross-section energy, 64^2 grid, dt 5e-5 s.
pub fn cantilever_toml(vertices: u32) -> String {
    let (len, b, rho, g) = cantilever_setup();
    one_pinned_yarn_toml(
        g,
        64,
        "5e-5",
        &format!(
            "k = 1e4\ngamma = 0.0\nyoungs_modulus = 0.0\nfriction = 0.0\n\
             bending = {b}\ndensity = {rho}\n"
        ),
        &format!(
            "start = [0.25, 0.5]\nend = [{}, 0.5]\nvertices = {vertices}\n",
            0.25 + len
        ),
        "end = \"start\"\ncount = 2\n",
    )
}

/// Resolution, time step, gravity and material of a capstan scene (a yarn
/// over a half circle).
#[derive(Clone, Copy, Debug)]
pub struct Capstan {
    /// Grid resolution (cells per side).
    pub res: u32,
    /// Substep in s.
    pub dt: f64,
    /// Gravity (the capstan's slip threshold does not depend on it).
    pub g: f64,
    /// Fibre shear stiffness in N/m.
    pub gamma: f64,
    /// Young's modulus of the cross-section in N/m.
    pub youngs_modulus: f64,
    /// Mohr-Coulomb friction coefficient between fibres.
    pub friction: f64,
    /// Bending stiffness in N m.
    pub bending: f64,
    /// Whether the Mohr-Coulomb return mapping is on.
    pub plasticity: bool,
}

/// Material: a pure string at 128^2, dt 1e-4. Bending 0 (all the
/// resistance is friction), k = 1000 (strain below 0.1 %), plasticity off,
/// and no cross-section energy (gamma = 0, E = 0); a small gravity keeps the
/// elastic stretch small.
pub const CAPSTAN_PURE_STRING: Capstan = Capstan {
    res: 128,
    dt: 1e-4,
    g: 2.0,
    gamma: 0.0,
    youngs_modulus: 0.0,
    friction: 0.0,
    bending: 0.0,
    plasticity: false,
};

/// The vertices of the capstan yarn (hanging `l1` and `l2` over a half
/// circle of radius `r`) on a `res`^2 grid: a vertex spacing of about dx / 2.
pub fn capstan_vertices(r: f64, l1: f64, l2: f64, res: u32) -> u32 {
    let length = l1 + l2 + std::f64::consts::PI * r;
    let dx = 1.0 / res as f64;
    (length / (0.5 * dx)).round() as u32 + 1
}

/// Scene TOML `text` with its `[material]` table, up to the next table,
/// replaced by one of the lines `material` (each ending in a newline), as
/// a scene gives a preset instead of the model's parameters.
pub fn with_material_table(text: &str, material: &str) -> String {
    let start = text.find("[material]").expect("a [material] table");
    let end = text[start..]
        .find("\n[")
        .map_or(text.len(), |e| start + e + 1);
    format!("{}[material]\n{material}{}", &text[..start], &text[end..])
}

/// The capstan of [`capstan_toml`] (R 0.1, L1 0.1, L2 0.3 m, the grid and
/// step of `c`) as one yarn of `[material] preset = preset` on its
/// vertices (the preset's cross-section energies off: a gridless
/// integrator has none), every length and the domain times `scale`. A
/// real yarn's bending is not negligible on the 0.1 m drum (the
/// heavy-rope threshold neglects it: the nylon monofilament's EI / R is
/// twice the hanging strand's moment); ten times longer it is 1/500 of
/// it, while the threshold, which depends on the ratios of the lengths
/// only, stays. Returns the scene and the hanging lengths `(l1, l2)` in
/// m. The scene's integrator is the explicit default: set a gridless one.
pub fn capstan_preset_scene(
    preset: &str,
    scale: f64,
    mu: f64,
    c: &Capstan,
) -> (YarnScene, f64, f64) {
    let (r, l1, l2) = (0.1, 0.1, 0.3);
    let text = with_material_table(
        &capstan_toml(r, l1, l2, mu, c),
        &format!("preset = {preset:?}\ngamma = 0.0\nyoungs_modulus = 0.0\n"),
    );
    let mut s = YarnScene::from_toml_str(&text).expect("the capstan with a preset");
    s.grid.size *= scale;
    s.attractor.position = s.attractor.position.map(|x| x * scale);
    for o in &mut s.obstacles {
        o.center = o.center.map(|x| x * scale);
        o.radius *= scale;
    }
    for p in s
        .yarns
        .iter_mut()
        .flat_map(|y| y.points.iter_mut().flatten())
    {
        *p = p.map(|x| x * scale);
    }
    (s, l1 * scale, l2 * scale)
}

/// A yarn over a half circle of radius `r` centred at (0.5, 0.75), hanging
/// `l1` on the left and `l2` on the right, on a circle with friction `mu`,
/// as scene TOML: k = 1000, no walls, the rest from `c`.
pub fn capstan_toml(r: f64, l1: f64, l2: f64, mu: f64, c: &Capstan) -> String {
    capstan_drop_toml(r, l1, l2, mu, 0.0, c)
}

/// [`capstan_toml`] with the yarn released `drop` (m) away from the
/// circle: every point moved out by `drop`, radially on the arc (radius
/// `r + drop`) and sideways on the two strands, which keep their hanging
/// lengths; the vertex spacing stays about dx / 2. `drop = 0` is
/// [`capstan_toml`] itself.
pub fn capstan_drop_toml(r: f64, l1: f64, l2: f64, mu: f64, drop: f64, c: &Capstan) -> String {
    let (cx, cy) = (0.5, 0.75);
    let ra = r + drop;
    let mut pts = vec![[cx - ra, cy - l1]];
    let arc = 64;
    for i in 0..=arc {
        let psi = std::f64::consts::PI * (1.0 - i as f64 / arc as f64);
        pts.push([cx + ra * psi.cos(), cy + ra * psi.sin()]);
    }
    pts.push([cx + ra, cy - l2]);
    let vertices = capstan_vertices(ra, l1, l2, c.res);
    let points = pts
        .iter()
        .map(|p| format!("[{:.12}, {:.12}]", p[0], p[1]))
        .collect::<Vec<_>>()
        .join(", ");
    format!(
        r#"
gravity = [0.0, -{}]
[grid]
resolution = {}
[time]
dt = {}
[material]
k = 1000.0
gamma = {}
youngs_modulus = {}
friction = {}
bending = {}
plasticity = {}
[walls]
mode = "none"
[[obstacles]]
center = [{cx}, {cy}]
radius = {r}
friction = {mu}
[[yarns]]
points = [{points}]
vertices = {vertices}
"#,
        c.g, c.res, c.dt, c.gamma, c.youngs_modulus, c.friction, c.bending, c.plasticity
    )
}

/// The window of two whole periods of an oscillation about its mean: the
/// indices of the first and third upward crossings of `d` through its
/// mean, or `None` with fewer than three.
pub fn two_periods_about_mean(d: &[f64]) -> Option<(usize, usize)> {
    let m0 = d.iter().sum::<f64>() / d.len() as f64;
    let up: Vec<usize> = (1..d.len())
        .filter(|&k| d[k - 1] < m0 && d[k] >= m0)
        .collect();
    (up.len() >= 3).then(|| (up[0], up[2]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn oracle_scenes_are_valid() {
        YarnScene::from_toml_str(&hanging_chain_toml(100, 64, "1e-4"))
            .unwrap()
            .validate()
            .unwrap();
        YarnScene::from_toml_str(&capstan_toml(0.1, 0.2, 0.3, 0.5, &CAPSTAN_PURE_STRING))
            .unwrap()
            .validate()
            .unwrap();
        YarnScene::from_toml_str(&cantilever_toml(100))
            .unwrap()
            .validate()
            .unwrap();
    }

    #[test]
    fn crossings_of_a_sine_give_its_period() {
        let (period, h) = (0.5, 1e-3);
        let f = |t: f64| (2.0 * std::f64::consts::PI * t / period + 0.3).sin();
        let mut c = ZeroCrossings::new(f(0.0));
        for k in 1..=2000 {
            let t = k as f64 * h;
            c.push(t, h, f(t));
        }
        assert_eq!(c.times.len(), 8);
        // linear interpolation within a step of 1e-3 of a 0.5 s sine
        assert!((c.period() - period).abs() < 1e-6, "{}", c.period());
        let d: Vec<f64> = (0..2000).map(|k| f(k as f64 * h)).collect();
        let (a, e) = two_periods_about_mean(&d).unwrap();
        assert!(((e - a) as f64 * h - 2.0 * period).abs() < 2.0 * h);
    }
}

/// Mutable particles of `sim`, to set up initial conditions in tests and
/// studies (not part of the simulator's API); the cached frame
/// factorisations are recomputed at the next step.
pub fn particles_mut(sim: &mut crate::YarnSim) -> &mut crate::mpm::machinery::particles::Particles {
    sim.particles_mut()
}

/// The solver's grid machinery and passes that the physics tests and the
/// roofline counts drive directly (not part of the simulator's API): the
/// grid, its node layouts and buffers, the kernel dispatch, the scatter and
/// the quadrature particles' stress pass.
pub mod internals {
    pub use crate::mpm::explicit::grid_to_particle::quad_stress;
    pub use crate::mpm::explicit::particle_to_grid::scatter;
    pub use crate::mpm::machinery::grid::{Grid, Node, P2gNode, BLOCK, M, P2G_LANES, PX, PY};
    pub use crate::mpm::machinery::simd::{chunk_bounds, kernels, set_widest_kernels, Kernels};
}

/// Highest point of a [`tilted_bundle`] at the start: 3 cells below the
/// top of the built-in scene's domain.
pub const BUNDLE_TOP: f64 = 1.0 - 3.0 / 256.0;

/// The built-in scene with its 12 yarns `length` long (`vertices`
/// vertices) tilted `angle` degrees down from +x, `spacing` m apart along
/// their normal, centred in x, its highest point `lower` m below
/// [`BUNDLE_TOP`] (the drop height onto the circles follows: a bundle that
/// starts within a cell of a circle is refused by [`clear_of_circles`]).
/// The bundles of `tests/bundle_property.rs` and
/// `evidence/examples/crush_probe.rs`.
pub fn tilted_bundle(
    angle: f64,
    spacing: f64,
    lower: f64,
    length: f64,
    vertices: u32,
) -> YarnScene {
    let mut s = yarn_reference();
    let a = angle.to_radians();
    let dir = [a.cos(), -a.sin()];
    let normal = [a.sin(), a.cos()];
    let width = 11.0 * spacing;
    // half extents of the bundle's bounding box in y
    let half_y = 0.5 * (length * a.sin() + width * a.cos());
    let (cx, cy) = (0.5, BUNDLE_TOP - lower - half_y);
    let start = [
        cx - dir[0] * length / 2.0 - normal[0] * width / 2.0,
        cy - dir[1] * length / 2.0 - normal[1] * width / 2.0,
    ];
    s.yarns = vec![YarnSpec {
        start: Some(start),
        direction: Some(dir),
        length: Some(length),
        vertices,
        count: 12,
        spacing: [normal[0] * spacing, normal[1] * spacing],
        ..Default::default()
    }];
    s
}

/// Whether every vertex of `s` starts more than a cell away from every circle.
pub fn clear_of_circles(s: &YarnScene) -> bool {
    let sim = crate::YarnSim::new(s).unwrap();
    let dx = s.dx();
    sim.particles().vert.x.iter().all(|x| {
        s.obstacles.iter().all(|o| {
            let d = ((x.x - o.center[0]).powi(2) + (x.y - o.center[1]).powi(2)).sqrt();
            d > o.radius + dx
        })
    })
}
