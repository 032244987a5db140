//! The limit: a roofline of the yarn substep on this machine.
//!
//! * Peaks, measured with simple kernels on one core: `f64` multiply-adds
//!   over 12 independent vector registers (intrinsics: SSE2 multiply and
//!   add, AVX2 FMA and AVX-512 FMA when the CPU has them), and a STREAM-like triad `a = b + s c` over
//!   arrays resident in L2, in L3 and larger than the last-level cache
//!   (DRAM). Median of the repeats.
//! * Counts per particle of each pass, from the kernels' source: the
//!   [`Term`] tables below (one term per line of work, with the file it is
//!   counted from). Adds, subtractions, multiplications, divisions, `sqrt`
//!   and `ln` count 1 flop each; comparisons, `abs`, `max`/`min`, sign
//!   flips of `perp` and integer index arithmetic count 0. Bytes are what
//!   the kernel loads and stores as written (each particle-array element or
//!   grid node accessed, once per access in the source), not the DRAM
//!   traffic: the working set of the reference scene (about 2 MB of
//!   particles, 5 MB of grid window) stays in the caches.
//! * The roofline: per pass, the measured time per substep of the
//!   `yarn-reference` scene on 1 thread ([`yarnsim::YarnSim::timings`]) against
//!   `min(peak flop/s, flop/byte x bandwidth)`, for the DRAM, L3 and L2
//!   bandwidth; and the 20x-Taichi goal against the same bound.
//!
//! When a kernel changes, update its [`Term`] table; `term_totals` (a unit

pub mod counts;
pub mod peaks;
pub mod report;

pub use counts::*;
pub use peaks::{measure_peaks, Isa, Peak, Peaks};
pub use report::{bound, run, PassPoint, RooflineOptions, RooflineReport};
