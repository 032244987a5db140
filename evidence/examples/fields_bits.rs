//! The final state of the built-in reference bundle (`yarn-reference`)
//! after a number of substeps, as the FNV-1a checksum of its saved state
//! (every particle's position, velocity, APIC matrix and frame, bit for
//! bit): the before/after comparison of a change that must keep the bits
//! of the velocity fields (`src/mpm/laws/fields.rs`):
//!
//! ```text
//! cargo run --release -p yarnsim-evidence --example fields_bits -- DT FIELDS SUBSTEPS
//! ```
//!
//! `DT` is a number (s) or `auto`, `FIELDS` is `per-yarn` or `held-free`.
//! Prints one line: the checksum, the substeps, the simulated time and the
//! grid memory at the end.

use yarnsim::mpm::driver::state::fnv1a;
use yarnsim::scene::builtin::yarn_reference;
use yarnsim::scene::{FieldPartition, StepSize};
use yarnsim::YarnSim;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let arg = |k: usize, default: &'static str| args.get(k).map_or(default, String::as_str);
    let (dt, fields) = (arg(1, "auto"), arg(2, "per-yarn"));
    let substeps: u64 = arg(3, "300").parse().expect("SUBSTEPS: a whole number");
    let mut s = yarn_reference();
    s.time.dt = match dt {
        "auto" => StepSize::Auto,
        x => StepSize::Fixed(x.parse().expect("DT: a number or auto")),
    };
    s.contact.fields = match fields {
        "per-yarn" => FieldPartition::PerYarn,
        "held-free" => FieldPartition::HeldFree,
        x => panic!("FIELDS: per-yarn or held-free, not {x}"),
    };
    let mut sim = YarnSim::new(&s).expect("scene");
    sim.steps_n(substeps).expect("run");
    println!(
        "{dt} {fields}: state {:016x} after {} substeps, t {:.6} s, grid {} bytes",
        fnv1a(&sim.save_state()),
        sim.steps(),
        sim.time(),
        sim.grid_memory_bytes()
    );
}
