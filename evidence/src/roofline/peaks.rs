//! Peaks of this machine, measured with simple kernels on one core:
//! multiply-adds over independent registers and a STREAM-like triad.

use std::hint::black_box;
use std::time::Instant;

/// Independent accumulator registers of the multiply-add kernels: 12,
/// enough chains to cover the latency (4 cycles) of 2 pipes, and few
/// enough to stay in registers.
const CHAINS: usize = 12;

/// `acc = acc m + a` on `CHAINS` scalar accumulators, `iters` times
/// (fallback off x86-64).
#[allow(dead_code)]
fn madd_generic(iters: u64, m: f64, a: f64) -> f64 {
    let mut acc = [0.0f64; CHAINS];
    for (i, x) in acc.iter_mut().enumerate() {
        *x = i as f64 * 1e-3;
    }
    for _ in 0..iters {
        for x in acc.iter_mut() {
            *x = *x * m + a;
        }
    }
    acc.iter().sum()
}

/// SSE2 (x86-64 baseline, what the portable kernels are built for):
/// `CHAINS` registers of 2 lanes, separate multiply and add.
#[cfg(target_arch = "x86_64")]
fn madd_sse2(iters: u64, m: f64, a: f64) -> f64 {
    use std::arch::x86_64::*;
    // SAFETY: SSE2 is part of the x86-64 baseline.
    unsafe {
        let (vm, va) = (_mm_set1_pd(m), _mm_set1_pd(a));
        let mut acc: [__m128d; CHAINS] = std::array::from_fn(|i| _mm_set1_pd(i as f64 * 1e-3));
        for _ in 0..iters {
            for x in acc.iter_mut() {
                *x = _mm_add_pd(_mm_mul_pd(*x, vm), va);
            }
        }
        let mut out = [0.0f64; 2];
        let s = acc.iter().fold(_mm_setzero_pd(), |s, &x| _mm_add_pd(s, x));
        _mm_storeu_pd(out.as_mut_ptr(), s);
        out.iter().sum()
    }
}

/// A multiply-add kernel of `CHAINS` registers of the vector type `$v`,
/// one FMA each, for the target features `$features`: `$set1`, `$fmadd`,
/// `$zero` and `$add` are that width's intrinsics, and `$reduce` sums the
/// lanes of the register `$s`. (A macro: the intrinsics differ by width,
/// and no generic function can name them.)
macro_rules! madd_fma {
    ($(#[$doc:meta])* $name:ident, $features:literal, $v:ty,
     $set1:ident, $fmadd:ident, $zero:ident, $add:ident, |$s:ident| $reduce:block) => {
        $(#[$doc])*
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $features)]
        fn $name(iters: u64, m: f64, a: f64) -> f64 {
            use std::arch::x86_64::*;
            let (vm, va) = ($set1(m), $set1(a));
            let mut acc: [$v; CHAINS] = std::array::from_fn(|i| $set1(i as f64 * 1e-3));
            for _ in 0..iters {
                for x in acc.iter_mut() {
                    *x = $fmadd(*x, vm, va);
                }
            }
            let $s = acc.iter().fold($zero(), |s, &x| $add(s, x));
            $reduce
        }
    };
}

madd_fma!(
    /// AVX2 + FMA: `CHAINS` registers of 4 lanes, one FMA each.
    madd_avx2, "avx2,fma", __m256d,
    _mm256_set1_pd, _mm256_fmadd_pd, _mm256_setzero_pd, _mm256_add_pd,
    |s| {
        let mut out = [0.0f64; 4];
        // SAFETY: `out` holds 4 f64.
        unsafe { _mm256_storeu_pd(out.as_mut_ptr(), s) };
        out.iter().sum()
    }
);

madd_fma!(
    /// AVX-512 F: `CHAINS` registers of 8 lanes, one FMA each.
    madd_avx512, "avx512f,avx512vl,avx2,fma", __m512d,
    _mm512_set1_pd, _mm512_fmadd_pd, _mm512_setzero_pd, _mm512_add_pd,
    |s| { _mm512_reduce_add_pd(s) }
);

#[inline(always)]
fn triad_body(a: &mut [f64], b: &[f64], c: &[f64], s: f64) {
    for ((x, y), z) in a.iter_mut().zip(b).zip(c) {
        *x = y + s * z;
    }
}

fn triad_portable(a: &mut [f64], b: &[f64], c: &[f64], s: f64) {
    triad_body(a, b, c, s)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn triad_avx2(a: &mut [f64], b: &[f64], c: &[f64], s: f64) {
    triad_body(a, b, c, s)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
fn triad_avx512(a: &mut [f64], b: &[f64], c: &[f64], s: f64) {
    triad_body(a, b, c, s)
}

/// Instruction sets of the peak kernels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    /// The x86-64 baseline the portable kernels are built for: SSE2, 2
    /// lanes, separate multiply and add.
    Portable,
    Avx2Fma,
    Avx512,
}

impl Isa {
    pub fn name(self) -> &'static str {
        match self {
            Isa::Portable => "SSE2 (x86-64 baseline)",
            Isa::Avx2Fma => "AVX2 + FMA",
            Isa::Avx512 => "AVX-512 F + FMA",
        }
    }
    /// The instruction sets this CPU runs, narrowest first.
    pub fn available() -> Vec<Isa> {
        let mut v = vec![Isa::Portable];
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
                v.push(Isa::Avx2Fma);
                if std::is_x86_feature_detected!("avx512f")
                    && std::is_x86_feature_detected!("avx512vl")
                {
                    v.push(Isa::Avx512);
                }
            }
        }
        v
    }
    /// Runs the multiply-add kernel; returns its result and the number of
    /// accumulators (f64 lanes).
    fn madd(self, iters: u64, m: f64, a: f64) -> (f64, usize) {
        match self {
            #[cfg(target_arch = "x86_64")]
            Isa::Portable => (madd_sse2(iters, m, a), 2 * CHAINS),
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2Fma => {
                // SAFETY: `available` listed this instruction set only where the CPU has it.
                (unsafe { madd_avx2(iters, m, a) }, 4 * CHAINS)
            }
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => {
                // SAFETY: as for AVX2 above.
                (unsafe { madd_avx512(iters, m, a) }, 8 * CHAINS)
            }
            #[cfg(not(target_arch = "x86_64"))]
            _ => (madd_generic(iters, m, a), CHAINS),
        }
    }
    fn triad(self, a: &mut [f64], b: &[f64], c: &[f64], s: f64) {
        match self {
            Isa::Portable => triad_portable(a, b, c, s),
            #[cfg(target_arch = "x86_64")]
            // SAFETY: as in `madd`.
            Isa::Avx2Fma => unsafe { triad_avx2(a, b, c, s) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: as in `madd`.
            Isa::Avx512 => unsafe { triad_avx512(a, b, c, s) },
            #[cfg(not(target_arch = "x86_64"))]
            _ => triad_portable(a, b, c, s),
        }
    }
}

/// One measured peak.
#[derive(Clone, Debug, PartialEq)]
pub struct Peak {
    pub kernel: String,
    pub detail: String,
    /// flop/s or byte/s.
    pub value: f64,
    pub unit: &'static str,
    pub repeats: usize,
}

/// The peaks of one core.
#[derive(Clone, Debug, PartialEq)]
pub struct Peaks {
    pub flops: Vec<Peak>,
    /// Triad bandwidth: L2, L3, DRAM.
    pub bandwidth: Vec<Peak>,
}

impl Peaks {
    /// The compute roof: the fastest multiply-add kernel.
    pub fn peak_flops(&self) -> f64 {
        self.flops.iter().map(|p| p.value).fold(0.0, f64::max)
    }
    fn bw(&self, level: &str) -> f64 {
        self.bandwidth
            .iter()
            .find(|p| p.kernel.contains(level))
            .map_or(f64::NAN, |p| p.value)
    }
    pub fn dram(&self) -> f64 {
        self.bw("DRAM")
    }
    pub fn l3(&self) -> f64 {
        self.bw("L3")
    }
    pub fn l2(&self) -> f64 {
        self.bw("L2")
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Measures the peaks on the calling thread, median of `repeats`.
pub fn measure_peaks(repeats: usize) -> Peaks {
    let repeats = repeats.max(1);
    let mut flops = Vec::new();
    // about 2e8 flops per timing
    let work = 200_000_000u64;
    let isas = Isa::available();
    for &isa in &isas {
        let (_, n) = isa.madd(1, 1.0, 0.0);
        let iters = work / (2 * n as u64);
        let _ = isa.madd(iters / 10, black_box(0.999_999), black_box(1e-6)); // warm up clocks
        let rates: Vec<f64> = (0..repeats)
            .map(|_| {
                let t0 = Instant::now();
                let r = isa.madd(iters, black_box(0.999_999), black_box(1e-6));
                let s = t0.elapsed().as_secs_f64();
                black_box(r);
                (2 * n as u64 * iters) as f64 / s
            })
            .collect();
        flops.push(Peak {
            kernel: format!("f64 multiply-add, {}", isa.name()),
            detail: format!(
                "{CHAINS} registers, {n} f64 accumulators, {} (2 flop each)",
                if isa == Isa::Portable {
                    "mul + add"
                } else {
                    "fma"
                }
            ),
            value: median(rates),
            unit: "flop/s",
            repeats,
        });
    }
    let widest = *isas.last().unwrap_or(&Isa::Portable);
    let mut bandwidth = Vec::new();
    // (level, elements per array, passes per timing)
    for (level, n, passes) in [
        ("L2", 32 * 1024, 2000usize),
        ("L3", 256 * 1024, 200),
        ("DRAM", 8 * 1024 * 1024, 4),
    ] {
        let mut a = vec![0.0f64; n];
        let b = vec![1.0f64; n];
        let c = vec![2.0f64; n];
        isa_triad_passes(widest, &mut a, &b, &c, passes.div_ceil(4));
        let rates: Vec<f64> = (0..repeats)
            .map(|_| {
                let t0 = Instant::now();
                isa_triad_passes(widest, &mut a, &b, &c, passes);
                let s = t0.elapsed().as_secs_f64();
                (24 * n * passes) as f64 / s
            })
            .collect();
        bandwidth.push(Peak {
            kernel: format!("triad a = b + s c, {level}"),
            detail: format!(
                "3 arrays of {} KiB ({}), 24 byte per element (no write-allocate)",
                8 * n / 1024,
                widest.name()
            ),
            value: median(rates),
            unit: "byte/s",
            repeats,
        });
    }
    Peaks { flops, bandwidth }
}

fn isa_triad_passes(isa: Isa, a: &mut [f64], b: &[f64], c: &[f64], passes: usize) {
    for _ in 0..passes {
        isa.triad(a, b, c, black_box(3.0));
        black_box(&mut *a);
    }
}

// ---------------------------------------------------------------- study

#[cfg(test)]
mod tests {
    use super::*;

    /// Every multiply-add kernel this CPU runs computes the scalar
    /// recurrence `x = x m + a` of each chain (start `i 1e-3`), summed over
    /// the chains and lanes: relative error at most 1e-14 (FMA against
    /// separate multiply and add, and the lanes' summation order).
    #[test]
    fn madd_kernels_compute_the_scalar_recurrence() {
        let (iters, m, a) = (50, 0.9, 0.01);
        let chains: f64 = (0..CHAINS)
            .map(|i| (0..iters).fold(i as f64 * 1e-3, |x, _| x * m + a))
            .sum();
        for isa in Isa::available() {
            let (sum, lanes) = isa.madd(iters, m, a);
            let expect = chains * (lanes / CHAINS) as f64;
            let err = ((sum - expect) / expect).abs();
            assert!(
                err <= 1e-14,
                "{}: {sum} against {expect} ({err:.1e})",
                isa.name()
            );
        }
    }

    #[test]
    fn median_of_odd_and_even() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(vec![4.0, 1.0, 2.0, 3.0]), 2.5);
    }
}
