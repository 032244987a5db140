//! Probes the cross-section collapse of the seeded bundle draw that
//! diverges at the built-in fixed dt (4e-5): seed 7's ninth accepted draw
//! of `tests/bundle_property.rs`'s generator (12 yarns of 0.4 m, 100
//! vertices, 16.4 degrees, 1.18 cells apart, 91.3 mm lower), the case of
//! `docs/obstacle-contact.md`, "Known gaps".
//!
//! ```text
//! cargo run --release -p yarnsim-evidence --example crush_probe -- DT FROM [UNTIL]
//! cargo run --release -p yarnsim-evidence --example crush_probe -- sweep [DT]
//! ```
//!
//! `sweep` runs all 16 draws for 1 s at `DT` (default 4e-5) and prints
//! each one's stretch range, every 0.05 s, or its divergence.
//!
//! `DT` is a step (`4e-5`) or `auto`. Runs to `FROM` s, then prints every
//! substep up to `UNTIL` s (default 1) or the divergence: the quadrature
//! particle with the smallest `r22`, its `r11 r12 r22`, the cross-section
//! stress `normal ln r22`, its distance from the nearest circle's surface
//! (cells), the velocity gradient `C` in the fiber frame (`t` along d1,
//! `n` across it: `Cnn = n.Cn`, `Cnt = n.Ct` the change of the normal
//! velocity along the yarn, `Ctn = t.Cn` the shear), 1/s, and the rate of
//! `r22` that `d2 += dt C d2` gives with d1 held, `r22 Cnn + r12 Cnt`, the
//! normal velocities (outward from that circle's centre)
//! of its two vertices, how many other vertices lie in its stencil (1.5
//! cells in x and y) and their mean normal velocity, and the stable dt at that `r22` (the crushed
//! bound); then a summary line every 1 ms before `FROM`. `TRACK=K` in
//! the environment follows quadrature particle `K` instead. Each verbose
//! line is followed by the particle's nine stencil nodes after the last
//! grid update: distance from the circle's surface (cells, negative
//! inside), normal velocity and its change over that substep.

use yarnsim::scene::{StepSize, YarnScene};
use yarnsim::testing::{clear_of_circles, tilted_bundle, Rng};
use yarnsim::YarnSim;

/// The bundle of `tests/bundle_property.rs`: 12 yarns of 0.4 m, 100
/// vertices.
fn bundle(angle: f64, spacing: f64, lower: f64) -> YarnScene {
    tilted_bundle(angle, spacing, lower, 0.4, 100)
}

/// The first `n` draws of seed 7 that start clear of the circles.
fn draws(n: usize) -> Vec<(f64, f64, f64)> {
    let dx = 1.0 / 256.0;
    let mut rng = Rng::new(7);
    let mut out = Vec::new();
    while out.len() < n {
        let angle = rng.uniform(0.0, 90.0);
        let spacing = rng.uniform(0.5, 3.0) * dx;
        let lower = rng.uniform(0.0, 0.1);
        if clear_of_circles(&bundle(angle, spacing, lower)) {
            out.push((angle, spacing, lower));
        }
    }
    out
}

/// The ninth draw, the one that diverged at 4e-5.
fn draw() -> (f64, f64, f64) {
    draws(9)[8]
}

/// Runs all 16 draws for 1 s at `dt`: the error if one diverges, else the
/// stretch range sampled every 0.05 s (as `tests/bundle_property.rs`).
fn sweep(dt: StepSize) {
    for (angle, spacing, lower) in draws(16) {
        let mut s = bundle(angle, spacing, lower);
        s.time.dt = dt;
        let mut sim = YarnSim::new(&s).unwrap();
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        let mut r = Ok(());
        for k in 1..=20 {
            if let Err(e) = sim.advance_to(0.05 * k as f64) {
                r = Err(e);
                break;
            }
            for st in sim.stretches() {
                lo = lo.min(st);
                hi = hi.max(st);
            }
        }
        let out = match r {
            Ok(()) if (0.8..=1.25).contains(&lo) && hi <= 1.25 => {
                format!("stretch [{lo:.4}, {hi:.4}]")
            }
            Ok(()) => format!("OUT OF BAND: stretch [{lo:.4}, {hi:.4}]"),
            Err(e) => format!("DIVERGED: {e}"),
        };
        println!(
            "{angle:.1} deg, spacing {:.2} cells, lower {:.1} mm, dt {dt:?}: {out}",
            spacing * 256.0,
            lower * 1e3
        );
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("sweep") {
        let dt = match args.get(1).map(String::as_str) {
            Some("auto") => StepSize::Auto,
            v => StepSize::Fixed(v.unwrap_or("4e-5").parse().expect("DT")),
        };
        sweep(dt);
        return;
    }
    let dt = match args.first().map(String::as_str) {
        Some("auto") => StepSize::Auto,
        Some(v) => StepSize::Fixed(v.parse().expect("DT")),
        None => panic!("usage: crush_probe DT FROM [UNTIL]"),
    };
    let from: f64 = args.get(1).map_or(0.38, |v| v.parse().expect("FROM"));
    let until: f64 = args.get(2).map_or(1.0, |v| v.parse().expect("UNTIL"));
    let track: Option<usize> = std::env::var("TRACK")
        .ok()
        .map(|v| v.parse().expect("TRACK"));
    let (angle, spacing, lower) = draw();
    let dx = 1.0 / 256.0;
    println!(
        "draw: {angle:.3} deg, spacing {:.3} cells, lower {:.2} mm, dt {dt:?}",
        spacing / dx,
        lower * 1e3
    );
    let mut s = bundle(angle, spacing, lower);
    s.time.dt = dt;
    let normal = yarnsim::mpm::laws::constitutive::YarnEnergy::from_material(&s.material).normal;
    let obstacles = s.obstacles.clone();
    let mut sim = YarnSim::new(&s).unwrap();
    let mut next_ms = 0.001;
    while sim.time() < until {
        let t = sim.time();
        let verbose = t >= from;
        if !verbose && t < next_ms {
            if let Err(e) = sim.step() {
                println!("{e}");
                return;
            }
            continue;
        }
        next_ms += 0.001;
        let p = sim.particles();
        let q = &p.quad;
        let (mut k, mut r22) = (0, f64::INFINITY);
        for i in 0..q.d.len() {
            let r = q.frame[i].r22;
            if r < r22 {
                (k, r22) = (i, r);
            }
        }
        if let Some(fixed) = track {
            (k, r22) = (fixed, q.frame[fixed].r22);
        }
        let f = q.frame[k];
        let x = q.x[k];
        let (o, gap) = obstacles
            .iter()
            .map(|o| {
                let c = yarnsim::math::Vec2::new(o.center[0], o.center[1]);
                (o, ((x - c).norm() - o.radius) / dx)
            })
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap();
        let c = yarnsim::math::Vec2::new(o.center[0], o.center[1]);
        // the fiber frame: t along d1, n across it
        let t1 = q.d[k].column(0).into_owned().normalize();
        let n1 = yarnsim::math::Vec2::new(-t1.y, t1.x);
        let cm = q.c[k];
        let (cnn, cnt, ctn) = (n1.dot(&(cm * n1)), n1.dot(&(cm * t1)), t1.dot(&(cm * n1)));
        // d r22 / dt from the grid alone, d1 held: n . C d2 / l0
        let rate = f.r22 * cnn + f.r12 * cnt;
        let l = q.left[k] as usize;
        let vn = |i: usize| {
            let n = (p.vert.x[i] - c).normalize();
            p.vert.v[i].dot(&n)
        };
        // the other vertices in the particle's stencil (within 1.5 cells
        // in x and y), outside its own segment's neighbours: how many, and
        // their mean normal velocity (outward from the circle's centre)
        let (mut near, mut near_vn) = (0usize, 0.0);
        for i in 0..p.vert.x.len() {
            let r = p.vert.x[i] - x;
            if i.abs_diff(l) > 3 && r.x.abs() < 1.5 * dx && r.y.abs() < 1.5 * dx {
                near += 1;
                near_vn += vn(i);
            }
        }
        let near_vn = near_vn / near.max(1) as f64;
        let bound = yarnsim::mpm::driver::timestep::explicit_stable_dt(
            &s.material,
            s.time.axial,
            dx,
            sim.max_speed(),
            r22,
        );
        println!(
            "t {t:.6} q {k} r11 {:.4} r12 {:+.4} r22 {r22:.4} sigma {:+.2} gap {gap:+.3} \
             Cnn {cnn:+.1} Cnt {cnt:+.1} Ctn {ctn:+.1} dr22/dt {rate:+.1} C [{:+.1} {:+.1}; {:+.1} {:+.1}] vn {:+.3} {:+.3} |v| {:.3} {:.3} others {near} vn {near_vn:+.3} bound {bound:.2e} vmax {:.2}",
            f.r11,
            f.r12,
            normal * r22.ln(),
            q.c[k][(0, 0)],
            q.c[k][(0, 1)],
            q.c[k][(1, 0)],
            q.c[k][(1, 1)],
            vn(l),
            vn(l + 1),
            p.vert.v[l].norm(),
            p.vert.v[l + 1].norm(),
            sim.max_speed()
        );
        let st = q.stencil[k];
        let d_before = q.d[k];
        if let Err(e) = sim.step() {
            println!("{e}");
            return;
        }
        if verbose {
            // the stencil this substep scattered to and gathered from, its
            // nodes after the grid update: distance from the circle's
            // surface (cells, negative inside), normal velocity and its
            // change over the substep (m/s); the grid velocity gradient
            // `grad v = sum w_i v_i (x_i - x_p)^T 4 / dx^2` that advected d2
            // (the quadratic B-spline's, Jiang et al. 2016 eq. 11), its
            // `n.grad v n`, and the change of r22 it predicts against the
            // change that happened
            let p = sim.particles();
            let q = &p.quad;
            let mut line = String::from("  nodes:");
            let mut gv = yarnsim::math::Mat2::zeros();
            for a in 0..3 {
                for b in 0..3 {
                    let (i, j) = ((st.base[0] + a) as usize, (st.base[1] + b) as usize);
                    let xi = yarnsim::math::Vec2::new(i as f64 * dx, j as f64 * dx);
                    let n = (xi - c).normalize();
                    let h = ((xi - c).norm() - o.radius) / dx;
                    let nd = sim.grid_node(i, j).expect("a stencil node in the window");
                    let v = yarnsim::math::Vec2::new(nd[0], nd[1]);
                    let dv = yarnsim::math::Vec2::new(nd[2], nd[3]);
                    line += &format!(" [{h:+.2} vn {:+.3} dvn {:+.3}]", v.dot(&n), dv.dot(&n));
                    let w = st.w[0][a as usize] * st.w[1][b as usize];
                    let off =
                        yarnsim::math::Vec2::new(a as f64 - st.fx[0], b as f64 - st.fx[1]) * dx;
                    gv += v * off.transpose() * (w * 4.0 / (dx * dx));
                }
            }
            let t1 = d_before.column(0).into_owned().normalize();
            let n1 = yarnsim::math::Vec2::new(-t1.y, t1.x);
            let l0 = q.l0[k];
            let d2 = d_before.column(1).into_owned();
            let pred = n1.dot(&(gv * d2)) * sim.dt() / l0;
            println!(
                "{line}\n  grad v [{:+.1} {:+.1}; {:+.1} {:+.1}] n.grad v n {:+.1} predicted dr22 {pred:+.5} actual {:+.5}",
                gv[(0, 0)],
                gv[(0, 1)],
                gv[(1, 0)],
                gv[(1, 1)],
                n1.dot(&(gv * n1)),
                q.frame[k].r22 - r22
            );
        }
    }
}
