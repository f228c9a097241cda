//! Which instruction set the run-time-dispatched CPU stages use, and the
//! cache hint (`prefetch`) the latency-bound ones share.
//!
//! `correct` and `upsample_jitter` compile their hot loops twice — for the
//! build's baseline (SSE2 on x86-64) and for AVX2 — and pick AVX2 where the
//! CPU has it. Both must give the same bytes as the scalar oracle, but on
//! an AVX2 machine the baseline copy would never run: setting
//! `TERRASYNTH_PORTABLE_SIMD` (to anything) makes every dispatch take it,
//! so the tests check both copies on one machine (`.ci/run` runs the stage
//! tests with and without it).

use std::sync::OnceLock;

/// Whether the stages run their AVX2 copies: the CPU has AVX2 and the
/// scalar extensions that come with it on every AVX2 CPU (BMI1, BMI2,
/// LZCNT, POPCNT: x86-64-v3's integer set, which `correct`'s copy also
/// compiles for), and `TERRASYNTH_PORTABLE_SIMD` is unset (read once per
/// process).
#[inline]
pub fn avx2() -> bool {
    static AVX2: OnceLock<bool> = OnceLock::new();
    *AVX2.get_or_init(|| {
        #[cfg(target_arch = "x86_64")]
        let has = std::is_x86_feature_detected!("avx2")
            && std::is_x86_feature_detected!("bmi1")
            && std::is_x86_feature_detected!("bmi2")
            && std::is_x86_feature_detected!("lzcnt")
            && std::is_x86_feature_detected!("popcnt");
        #[cfg(not(target_arch = "x86_64"))]
        let has = false;
        has && std::env::var_os("TERRASYNTH_PORTABLE_SIMD").is_none()
    })
}

/// Asks the cache for the line holding `table[i]` (a hint: no effect on
/// results). The address is only formed, never read, so it needs no bounds
/// check: prefetching cannot fault.
#[inline(always)]
pub fn prefetch<T>(table: &[T], i: i32) {
    let t = table.as_ptr().wrapping_offset(i as isize);
    #[cfg(target_arch = "x86_64")]
    // SAFETY: `prefetch` only hints the cache; it cannot fault or change
    // memory, and SSE is part of the x86_64 baseline.
    unsafe {
        use core::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        _mm_prefetch::<_MM_HINT_T0>(t.cast());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = t;
}
