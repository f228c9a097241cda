//! Which instruction set the run-time-dispatched CPU stages use, and the
//! cache hint (`prefetch`) the latency-bound ones share.
//!
//! `correct` and `upsample_jitter` compile their hot loops twice — for the
//! build's baseline (SSE2 on x86-64) and for AVX2 — and run the copy of
//! the [`Isa`] they are handed (the CPU backend's, `backend::cpu::Cpu`).
//! Every copy must give the same bytes as the scalar oracle; since the
//! level is a value rather than a property of the process, one test run
//! checks every level this CPU has ([`Isa::all`],
//! `tests/common/variants.rs`).
//!
//! [`Isa::default`] is the best level the CPU has; setting
//! `TERRASYNTH_PORTABLE_SIMD` (to anything) lowers that default to
//! [`Isa::Portable`], for users who want to compare the two copies or
//! avoid AVX2's clock drop.

/// An instruction-set level of the CPU stages, lowest first (rav1e's
/// `CpuFeatureLevel`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Isa {
    /// The build's baseline (SSE2 on x86-64): runs on every CPU.
    Portable,
    /// AVX2 and the scalar extensions that come with it on every AVX2 CPU
    /// (BMI1, BMI2, LZCNT, POPCNT: x86-64-v3's integer set, which
    /// `correct`'s copy also compiles for).
    Avx2,
}

impl Isa {
    /// The levels this CPU runs, lowest first.
    pub fn all() -> &'static [Isa] {
        if has_avx2() {
            &[Isa::Portable, Isa::Avx2]
        } else {
            &[Isa::Portable]
        }
    }

    /// The level's name in reports and test variants: `portable`, `avx2`.
    pub fn name(self) -> &'static str {
        match self {
            Isa::Portable => "portable",
            Isa::Avx2 => "avx2",
        }
    }

    /// Whether a stage handed this level runs its AVX2 copy: the level asks
    /// for it and the CPU has it. A level the CPU lacks runs the portable
    /// copy, so no value of [`Isa`] can make a stage execute instructions
    /// the CPU does not have.
    #[inline]
    pub fn avx2(self) -> bool {
        self >= Isa::Avx2 && has_avx2()
    }
}

impl Default for Isa {
    /// The best level of [`Isa::all`], or [`Isa::Portable`] when
    /// `TERRASYNTH_PORTABLE_SIMD` is set.
    fn default() -> Isa {
        match std::env::var_os("TERRASYNTH_PORTABLE_SIMD") {
            Some(_) => Isa::Portable,
            None => *Isa::all().last().expect("Portable is always there"),
        }
    }
}

/// Whether the CPU has [`Isa::Avx2`]'s features (`std` caches the
/// detection: a load and a test per call).
#[inline]
fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx2")
            && std::is_x86_feature_detected!("bmi1")
            && std::is_x86_feature_detected!("bmi2")
            && std::is_x86_feature_detected!("lzcnt")
            && std::is_x86_feature_detected!("popcnt")
    }
    #[cfg(not(target_arch = "x86_64"))]
    false
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
