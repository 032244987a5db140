//! Kernel dispatch: every per-chunk kernel of the substep is compiled twice,
//! for AVX2 + FMA (run when the CPU has them) and as built, with the same
//! bits; plus the fixed chunking that keeps results independent of the
//! number of threads.

use std::sync::atomic::{AtomicBool, Ordering};

use super::grid::CHUNKS;

/// Particles per parallel task in the gathers.
pub(crate) const PAR_MIN: usize = 256;

/// Set to run the portable kernels even where AVX2 is available.
static PORTABLE_ONLY: AtomicBool = AtomicBool::new(false);

/// Makes every simulation in the process use the portable kernels (`true`)
/// or the AVX2 + FMA ones where the CPU has them (`false`, the default).
/// Results are bitwise the same; this exists to test exactly that.
pub fn set_portable_kernels(portable: bool) {
    PORTABLE_ONLY.store(portable, Ordering::Relaxed);
}

/// Whether the CPU runs the AVX2 + FMA versions of the kernels (detected
/// once by std, cached).
#[inline(always)]
pub(crate) fn wide_simd() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx2")
            && std::is_x86_feature_detected!("fma")
            && !PORTABLE_ONLY.load(Ordering::Relaxed)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// `multiversion! { fn name(args) -> R { body } }` defines `name`, whose body
/// (an `#[inline(always)]` inner function) is compiled twice: for AVX2 + FMA,
/// run when the CPU has them, and as built otherwise. Both give the same
/// bits: Rust never contracts `a * b + c` into an FMA by itself, so only the
/// register width differs.
macro_rules! multiversion {
    ($(#[$m:meta])* fn $name:ident$(<$(const $cn:ident: $ct:ty),*>)?($($a:ident: $t:ty),* $(,)?) $(-> $r:ty)? $body:block) => {
        $(#[$m])*
        fn $name$(<$(const $cn: $ct),*>)?($($a: $t),*) $(-> $r)? {
            #[inline(always)]
            fn imp$(<$(const $cn: $ct),*>)?($($a: $t),*) $(-> $r)? $body
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx2,fma")]
                unsafe fn wide$(<$(const $cn: $ct),*>)?($($a: $t),*) $(-> $r)? {
                    imp$(::<$($cn),*>)?($($a),*)
                }
                if $crate::mpm::simd::wide_simd() {
                    // SAFETY: the CPU has the features `wide` is compiled for.
                    return unsafe { wide$(::<$($cn),*>)?($($a),*) };
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

/// The scatter's chunks of `n` items (for tests).
#[doc(hidden)]
pub fn chunk_bounds(n: usize) -> Vec<std::ops::Range<usize>> {
    (0..CHUNKS).map(|k| chunk_range(n, k)).collect()
}
