//! Analytic oracles of the mass-spring integrators: the hanging chain at
//! rest, the single oscillator's amplification and period per step, and
//! forward Euler's computed CFL bound.

use yarnsim::massspring::{scenes, Integrator, IntegratorOptions, MassSpringScene, Simulation, V3};

const G: f64 = 9.81;

/// The course lecture notes' wire with the top particle pinned instead of driven.
fn hanging_wire() -> MassSpringScene {
    let mut l = scenes::wire();
    l.driven.clear();
    l.pinned = vec![0];
    l
}

/// Spring lengths of the chain, top first.
fn lengths(sim: &Simulation) -> Vec<f64> {
    let x = sim.positions();
    sim.system()
        .springs
        .iter()
        .map(|s| (x[s.b] - x[s.a]).norm())
        .collect()
}

/// `l0 + T_j / k` with `T_j = (N - j + 1) m g`, j = 1..N, N free masses.
fn chain_oracle(sim: &Simulation) -> Vec<f64> {
    let sys = sim.system();
    let n = sys.len() - 1;
    let m = sys.masses[1];
    sys.springs
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let j = i + 1;
            s.rest_length + (n - j + 1) as f64 * m * G / s.k
        })
        .collect()
}

#[test]
fn hanging_chain_rests_at_the_analytic_lengths_for_every_stable_integrator() {
    let layout = hanging_wire();
    for integ in [
        Integrator::ForwardEuler,
        Integrator::SymplecticEuler,
        Integrator::BackwardEuler,
        Integrator::Trapezoidal,
        Integrator::ChebyshevJacobi,
    ] {
        let mut sim = Simulation::new(&layout, integ, IntegratorOptions::default()).unwrap();
        let start_err = lengths(&sim)
            .iter()
            .zip(chain_oracle(&sim))
            .map(|(l, o)| (l - o).abs())
            .fold(0.0, f64::max);
        sim.run_to(2.5).unwrap();
        let oracle = chain_oracle(&sim);
        let got = lengths(&sim);
        let err = got
            .iter()
            .zip(&oracle)
            .map(|(l, o)| (l - o).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "{integ}: dt {:.3e}, max length error {err:.2e} (start {start_err:.2e})",
            sim.dt()
        );
        assert!(start_err > 1e-3, "the chain must start away from rest");
        assert!(err < 1e-9, "{integ}: lengths {got:?} vs {oracle:?}");
        // Bottom position: -(N l0 + m g N (N+1) / (2k)).
        let sys = sim.system();
        let (n, l0, k, m) = (10.0, 0.1, sys.springs[0].k, sys.masses[1]);
        let bottom = -(n * l0 + m * G * n * (n + 1.0) / (2.0 * k));
        assert!((sim.positions()[10].y - bottom).abs() < 1e-8, "{integ}");
        // At rest.
        assert!(sim.velocities().iter().all(|v| v.norm() < 1e-8), "{integ}");
    }
}

/// One particle of mass `m` on a spring `k` to a pinned particle, moving along
/// the spring only; no gravity, no damping.
fn oscillator(k: f64, m: f64, q0: f64, v0: f64) -> MassSpringScene {
    let text = format!(
        r#"
kind = "mass-spring"
gravity = [0.0, 0.0, 0.0]
pinned = [0]
[time]
frame_time = 1.0
frames = 1
[[particles]]
position = [0.0, 0.0, 0.0]
mass = 1.0
[[particles]]
position = [0.0, {y}, 0.0]
velocity = [0.0, {vy}, 0.0]
mass = {m}
[[springs]]
particles = [0, 1]
stiffness = {k}
rest_length = 1.0
"#,
        y = -(1.0 + q0),
        vy = -v0
    );
    MassSpringScene::from_toml_str(&text).unwrap()
}

/// The observed one-step map of `(q, v)` for the oscillator.
fn one_step_map(integ: Integrator, k: f64, m: f64, h: f64) -> [[f64; 2]; 2] {
    let mut cols = [[0.0; 2]; 2];
    for (c, (q0, v0)) in [(0.1, 0.0), (0.0, 0.1)].into_iter().enumerate() {
        let opts = IntegratorOptions {
            dt: Some(h),
            cg_tolerance: 1e-14,
            ..Default::default()
        };
        let mut sim = Simulation::new(&oscillator(k, m, q0, v0), integ, opts).unwrap();
        sim.step(h).unwrap();
        let q = -sim.positions()[1].y - 1.0;
        let v = -sim.velocities()[1].y;
        cols[c] = [q / 0.1, v / 0.1];
        // Motion stays on the spring's line.
        assert_eq!(sim.positions()[1].x, 0.0);
        assert_eq!(sim.positions()[1].z, 0.0);
    }
    [[cols[0][0], cols[1][0]], [cols[0][1], cols[1][1]]]
}

/// Modulus and argument of the eigenvalues of a real 2x2 matrix with complex
/// eigenvalues.
fn complex_eig(t: [[f64; 2]; 2]) -> (f64, f64) {
    let tr = t[0][0] + t[1][1];
    let det = t[0][0] * t[1][1] - t[0][1] * t[1][0];
    let disc = det - tr * tr / 4.0;
    assert!(disc > 0.0, "eigenvalues must be complex: {t:?}");
    (det.sqrt(), disc.sqrt().atan2(tr / 2.0))
}

#[test]
fn single_oscillator_amplification_and_period_match_the_formulas() {
    let (k, m): (f64, f64) = (100.0, 1.0);
    let w = (k / m).sqrt();
    for h in [0.02, 0.05, 0.15] {
        let hw = h * w;
        let cases = [
            (
                Integrator::ForwardEuler,
                (1.0 + hw * hw).sqrt(),
                hw / hw.atan(),
            ),
            (
                Integrator::BackwardEuler,
                1.0 / (1.0 + hw * hw).sqrt(),
                hw / hw.atan(),
            ),
            (Integrator::Trapezoidal, 1.0, (hw / 2.0) / (hw / 2.0).atan()),
            (
                Integrator::SymplecticEuler,
                1.0,
                hw / (2.0 * (hw / 2.0).asin()),
            ),
        ];
        for (integ, amp, period) in cases {
            let (modulus, angle) = complex_eig(one_step_map(integ, k, m, h));
            let ratio = hw / angle;
            eprintln!(
                "{integ} h w = {hw}: |lambda| {modulus:.12} (formula {amp:.12}), period ratio {ratio:.12} (formula {period:.12})"
            );
            assert!((modulus - amp).abs() < 1e-9, "{integ} h={h}");
            assert!((ratio - period).abs() < 1e-9, "{integ} h={h}");
        }
    }
}

#[test]
fn forward_and_backward_euler_amplitude_over_many_steps() {
    // In the scaled norm sqrt(q^2 + (v/w)^2) the FE and BE maps are normal,
    // so the amplitude changes by exactly |lambda| every step.
    let (k, m, h) = (100.0, 1.0, 0.01);
    let w: f64 = 10.0;
    let hw = h * w;
    for (integ, amp) in [
        (Integrator::ForwardEuler, (1.0 + hw * hw).sqrt()),
        (Integrator::BackwardEuler, 1.0 / (1.0 + hw * hw).sqrt()),
        (Integrator::Trapezoidal, 1.0),
    ] {
        let opts = IntegratorOptions {
            dt: Some(h),
            cg_tolerance: 1e-14,
            ..Default::default()
        };
        let mut sim = Simulation::new(&oscillator(k, m, 0.1, 0.0), integ, opts).unwrap();
        let steps = 200;
        for _ in 0..steps {
            sim.step(h).unwrap();
        }
        let q = -sim.positions()[1].y - 1.0;
        let v = -sim.velocities()[1].y;
        let a = (q * q + (v / w).powi(2)).sqrt() / 0.1;
        let expect = amp.powi(steps);
        assert!((a / expect - 1.0).abs() < 1e-8, "{integ}: {a} vs {expect}");
    }
}

/// Largest distance of any particle from the analytic rest position.
fn deviation(sim: &Simulation, rest: &[V3]) -> f64 {
    sim.positions()
        .iter()
        .zip(rest)
        .map(|(p, r)| (p - r).norm())
        .fold(0.0, f64::max)
}

#[test]
fn forward_euler_is_stable_below_the_computed_cfl_bound_and_grows_above() {
    let layout = hanging_wire();
    let sim0 = Simulation::new(
        &layout,
        Integrator::ForwardEuler,
        IntegratorOptions::default(),
    )
    .unwrap();
    let st = sim0.stability().unwrap();
    let bound = st.forward_euler;
    eprintln!(
        "wire: w_max^2 = {:.6e}, tau = {:?}, FE bound {bound:.6e} s, SE bound {:.6e} s, driver dt {:.6e} s",
        st.omega_max_sq, st.damping_ratio, st.symplectic_euler, sim0.dt()
    );
    // Analytic rest positions from the chain oracle.
    let oracle = chain_oracle(&sim0);
    let mut rest = vec![sim0.positions()[0]];
    for l in &oracle {
        let last = *rest.last().unwrap();
        rest.push(last - V3::new(0.0, *l, 0.0));
    }
    let steps = 1500;
    for factor in [0.9, 0.99, 1.01, 1.1, 1.5, 2.0] {
        let dt = factor * bound;
        let opts = IntegratorOptions {
            dt: Some(dt),
            ..Default::default()
        };
        let mut sim = Simulation::new(&layout, Integrator::ForwardEuler, opts).unwrap();
        let d0 = deviation(&sim, &rest);
        let mut diverged = false;
        let mut max_dev: f64 = 0.0;
        for _ in 0..steps {
            if sim.step(dt).is_err() {
                diverged = true;
                break;
            }
            max_dev = max_dev.max(deviation(&sim, &rest));
        }
        let d1 = if diverged {
            f64::INFINITY
        } else {
            deviation(&sim, &rest)
        };
        eprintln!("FE at {factor} x bound: deviation {d0:.3e} -> {d1:.3e} (max {max_dev:.3e})");
        if factor < 1.0 {
            assert!(!diverged && d1 < 0.5 * d0 && max_dev < 2.0 * d0, "{factor}");
        } else if factor >= 1.1 {
            assert!(diverged || d1 > 1e3 * d0, "{factor}: {d1}");
        }
    }
    // Forward Euler refuses a scene whose springs have no damping.
    let err = Simulation::new(
        &scenes::cloth(),
        Integrator::ForwardEuler,
        IntegratorOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("forward-euler") && err.contains("damping"),
        "{err}"
    );
}
