//! Kernel dispatch: every per-chunk kernel of the substep is compiled three
//! times, for AVX-512 (F + VL, with AVX2 and FMA), for AVX2 + FMA, and as
//! built, and runs the widest the CPU has; all three give the same bits.
//! Plus the fixed chunking that keeps results independent of the number of
//! threads.

use std::sync::atomic::{AtomicU8, Ordering};

use crate::mpm::machinery::grid::CHUNKS;

/// Particles per parallel task in the gathers.
pub(crate) const PAR_MIN: usize = 256;

/// The kernel versions, narrowest first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Kernels {
    /// As built for the target (SSE2 on x86-64).
    Portable = 0,
    /// AVX2 + FMA.
    Avx2 = 1,
    /// AVX-512 F + VL (with AVX2 and FMA).
    Avx512 = 2,
}

/// The widest kernels a simulation may use (tests lower it); 255 until
/// first read, then the limit from `YARNSIM_KERNELS` or [`Kernels::Avx512`].
static WIDEST: AtomicU8 = AtomicU8::new(u8::MAX);

/// The limit the environment sets: `YARNSIM_KERNELS=portable|avx2|avx512`
/// (for benchmarks that compare kernel widths; unset means the widest).
fn widest_from_env() -> u8 {
    let k = match std::env::var("YARNSIM_KERNELS").as_deref() {
        Ok("portable") => Kernels::Portable,
        Ok("avx2") => Kernels::Avx2,
        _ => Kernels::Avx512,
    };
    k as u8
}

/// Limits every simulation in the process to kernels no wider than `k`
/// (default: [`Kernels::Avx512`], i.e. the widest the CPU has). Results are
/// bitwise the same for every choice; this exists to test exactly that.
#[cfg(feature = "testing")]
pub fn set_widest_kernels(k: Kernels) {
    WIDEST.store(k as u8, Ordering::Relaxed);
}

/// The kernels this CPU runs, within the limit of `set_widest_kernels`
/// (features detected once by std, cached).
#[inline(always)]
pub fn kernels() -> Kernels {
    let mut widest = WIDEST.load(Ordering::Relaxed);
    if widest == u8::MAX {
        widest = widest_from_env();
        // a concurrent `set_widest_kernels` wins
        let _ = WIDEST.compare_exchange(u8::MAX, widest, Ordering::Relaxed, Ordering::Relaxed);
    }
    #[cfg(target_arch = "x86_64")]
    {
        let avx2 = std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma");
        if avx2
            && widest >= Kernels::Avx512 as u8
            && std::is_x86_feature_detected!("avx512f")
            && std::is_x86_feature_detected!("avx512vl")
        {
            return Kernels::Avx512;
        }
        if avx2 && widest >= Kernels::Avx2 as u8 {
            return Kernels::Avx2;
        }
    }
    let _ = widest;
    Kernels::Portable
}

/// `multiversion! { fn name(args) -> R { body } }` defines `name`, whose body
/// (an `#[inline(always)]` inner function) is compiled three times: for
/// AVX-512 and for AVX2 + FMA, run when the CPU has them (see [`kernels`]),
/// and as built otherwise. All give the same bits: Rust never contracts
/// `a * b + c` into an FMA by itself, so only the register width differs.
macro_rules! multiversion {
    ($(#[$m:meta])* fn $name:ident$(<$(const $cn:ident: $ct:ty),*>)?($($a:ident: $t:ty),* $(,)?) $(-> $r:ty)? $body:block) => {
        $(#[$m])*
        fn $name$(<$(const $cn: $ct),*>)?($($a: $t),*) $(-> $r)? {
            #[inline(always)]
            fn imp$(<$(const $cn: $ct),*>)?($($a: $t),*) $(-> $r)? $body
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
                unsafe fn avx512$(<$(const $cn: $ct),*>)?($($a: $t),*) $(-> $r)? {
                    imp$(::<$($cn),*>)?($($a),*)
                }
                #[target_feature(enable = "avx2,fma")]
                unsafe fn wide$(<$(const $cn: $ct),*>)?($($a: $t),*) $(-> $r)? {
                    imp$(::<$($cn),*>)?($($a),*)
                }
                match $crate::mpm::machinery::simd::kernels() {
                    $crate::mpm::machinery::simd::Kernels::Avx512 => {
                        // SAFETY: `kernels()` reports AVX-512 F + VL, AVX2 and FMA.
                        return unsafe { avx512$(::<$($cn),*>)?($($a),*) };
                    }
                    $crate::mpm::machinery::simd::Kernels::Avx2 => {
                        // SAFETY: `kernels()` reports AVX2 and FMA.
                        return unsafe { wide$(::<$($cn),*>)?($($a),*) };
                    }
                    $crate::mpm::machinery::simd::Kernels::Portable => {}
                }
            }
            imp$(::<$($cn),*>)?($($a),*)
        }
    };
}
pub(crate) use multiversion;

/// Index range of chunk `k` of `n` items (the scatter's fixed chunking).
#[inline]
pub(crate) fn chunk_range(n: usize, k: usize) -> std::ops::Range<usize> {
    (n * k / CHUNKS)..(n * (k + 1) / CHUNKS)
}

/// The scatter's chunks of `n` items (for tests and the roofline counts).
pub fn chunk_bounds(n: usize) -> Vec<std::ops::Range<usize>> {
    (0..CHUNKS).map(|k| chunk_range(n, k)).collect()
}
