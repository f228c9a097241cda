//! Huge pages for large, freshly allocated buffers.
//!
//! A level-sized buffer (S and V, the fixed-point heights, the output
//! heightfield) comes zeroed from the OS and is paid for page by page, on
//! first write, by the stage that fills it. With 4 KiB pages that is one
//! fault per 4 KiB — at 1024² half of `upsample_jitter`'s time at level 0,
//! which wrote S and V at ~2.9 ms/level into buffers already mapped and
//! took ~8 ms into fresh ones. Linux backs a range advised
//! `MADV_HUGEPAGE` with 2 MiB pages (this machine's transparent huge pages
//! are `madvise`-only), 512× fewer faults.

/// Advises the kernel to back the 2 MiB-aligned part of `v` with huge
/// pages. Only a hint: it changes no contents, and elsewhere (or where the
/// kernel declines) nothing happens.
pub fn advise_huge<T>(v: &[T]) {
    #[cfg(target_os = "linux")]
    {
        const HUGE: usize = 2 << 20;
        let start = v.as_ptr() as usize;
        let end = start + std::mem::size_of_val(v);
        let (a, b) = (start.next_multiple_of(HUGE), end / HUGE * HUGE);
        if b > a {
            // SAFETY: [a, b) lies inside `v`'s allocation, which stays
            // mapped for the call; MADV_HUGEPAGE only changes how the
            // range is backed, never its contents. A refusal is ignored:
            // the advice is optional.
            unsafe { libc::madvise(a as *mut libc::c_void, b - a, libc::MADV_HUGEPAGE) };
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = v;
}
