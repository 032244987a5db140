//! Centre of mass of the built-in reference bundle (`yarn-reference`) at
//! t = 0.5 s and 1 s for a given substep, the measurement of the obstacle
//! contact's effect on the bundle (docs/obstacle-contact.md, "Under
//! impact"):
//!
//! ```text
//! cargo run --release -p yarnsim-evidence --example bundle_com -- DT [apic] [per-yarn]
//! ```
//!
//! `DT` is a number (s) or `auto`; `per-yarn`: `[contact] fields =
//! "per-yarn"` (a velocity field per yarn, `src/mpm/laws/fields.rs`).
//! Prints one line.

use std::time::Instant;

use yarnsim::scene::builtin::yarn_reference;
use yarnsim::scene::{FieldPartition, StepSize, TransferScheme};
use yarnsim::YarnSim;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let dt = args.get(1).map_or("4e-5", String::as_str);
    let mut s = yarn_reference();
    if dt == "auto" {
        s.time.dt = StepSize::Auto;
    } else {
        s.time.dt = StepSize::Fixed(dt.parse().expect("DT: a number or auto"));
    }
    let flag = |f: &str| args.iter().skip(2).any(|a| a == f);
    if flag("apic") {
        s.transfer.scheme = TransferScheme::Apic;
    }
    if flag("per-yarn") {
        s.contact.fields = FieldPartition::PerYarn;
    }
    let mut sim = YarnSim::new(&s).expect("scene");
    let start = Instant::now();
    let mut line = format!("dt {dt} {:?} {:?}:", s.transfer.scheme, s.contact.fields);
    for t in [0.5, 1.0] {
        sim.advance_to(t).expect("run");
        let c = sim.diagnostics().center_of_mass;
        line += &format!(" t {t}: ({:.3}, {:.3})", c.x, c.y);
    }
    line += &format!(
        "; {} substeps, {:.1} s wall",
        sim.steps(),
        start.elapsed().as_secs_f64()
    );
    println!("{line}");
}
