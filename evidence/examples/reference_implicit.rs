//! The reference bundle (`yarn-reference`) under backward Euler with a
//! fixed or adaptive substep, on one thread: every EVERY outer substeps a
//! line with the time, mean vertex height, kinetic energy and the implicit
//! solver's counts (cutbacks included), then the state at the end.
//!
//! ```text
//! cargo run --release -p yarnsim-evidence --example reference_implicit -- DT [fixed|auto] T [EVERY]
//! cargo run --release -p yarnsim-evidence --example reference_implicit -- 1e-3 fixed 1.0 50
//! ```
//! `auto`: `dt = "auto"` with `dt_max = DT`. `EXPLICIT=1` in the
//! environment runs the explicit integrator instead (for the comparison;
//! the reference dt is 4e-5). The figures of docs/yarn-model.md
//! ("Reference scene") come from these runs.

use std::time::Instant;

use yarnsim::math::Vec2;
use yarnsim::scene::builtin::yarn_reference;
use yarnsim::scene::{Integrator, StepSize};
use yarnsim::{SimError, YarnSim};

fn mean_height(sim: &YarnSim) -> f64 {
    let x = &sim.particles().vert.x;
    x.iter().map(|p| p.y).sum::<f64>() / x.len() as f64
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 3 {
        return Err("usage: reference_implicit DT [fixed|auto] T [EVERY]".into());
    }
    let dt: f64 = args[0].parse()?;
    let auto = match args[1].as_str() {
        "auto" => true,
        "fixed" => false,
        other => return Err(format!("expected fixed or auto, got {other}").into()),
    };
    let t_end: f64 = args[2].parse()?;
    let every: u64 = args.get(3).map_or(Ok(50), |s| s.parse())?.max(1);
    let mut s = yarn_reference();
    s.time.integrator = if std::env::var_os("EXPLICIT").is_some() {
        Integrator::Explicit
    } else {
        Integrator::Implicit
    };
    if auto {
        s.time.dt = StepSize::Auto;
        s.time.dt_max = Some(dt);
    } else {
        s.time.dt = StepSize::Fixed(dt);
    }
    let mut sim = YarnSim::new(&s)?;
    let t0 = Instant::now();
    let mut outer = 0u64;
    yarnsim::pool::on_pool(|| {
        while sim.time() < t_end - 1e-9 {
            if auto {
                sim.step_toward(t_end)?;
            } else {
                sim.step()?;
            }
            outer += 1;
            if outer.is_multiple_of(every) {
                let st = sim.implicit_stats();
                println!(
                    "t {:.3} s: mean height {:.4} m, kinetic energy {:.3e} J; {} substeps, \
                     {} cutbacks ({} undone, deepest {}), {} Newton, {} CG; wall {:.0} s",
                    sim.time(),
                    mean_height(&sim),
                    sim.diagnostics().kinetic_energy,
                    sim.steps(),
                    st.cutbacks,
                    st.undone,
                    st.deepest_cut,
                    st.newton,
                    st.cg,
                    t0.elapsed().as_secs_f64()
                );
            }
        }
        Ok::<(), SimError>(())
    })?;
    let x = &sim.particles().vert.x;
    let low = x.iter().map(|p| p.y).fold(f64::INFINITY, f64::min);
    let depth = x
        .iter()
        .flat_map(|p| {
            s.obstacles
                .iter()
                .map(move |o| o.radius - (p - Vec2::from(o.center)).norm())
        })
        .fold(f64::NEG_INFINITY, f64::max);
    let st = sim.implicit_stats();
    println!(
        "end t {:.4} s: mean height {:.4} m, lowest {:.4} m, deepest vertex {:+.2} dx, \
         largest speed {:.3} m/s, kinetic energy {:.4e} J; {} outer / {} substeps (mean {:.3e} \
         s), {st:?}; wall {:.1} s",
        sim.time(),
        mean_height(&sim),
        low,
        depth / s.dx(),
        sim.max_speed(),
        sim.diagnostics().kinetic_energy,
        outer,
        sim.steps(),
        sim.dt_stats().mean(),
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}
