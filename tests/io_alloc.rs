//! No reader allocates more than its input justifies.
//!
//! A counting global allocator records the peak of live heap bytes while
//! each malformed file, fuzz seed and regression case is decoded. The bound
//! is the decoded size the file's length can justify — `len × R` samples
//! of 4 bytes, with R the format's best compression ratio (1 for raw
//! formats, 1032 deflate, 1376 EXR PXR24, 3641 TIFF LZW, 1 for ESRI ASCII
//! whose numbers take ≥ 2 bytes each) — times a small factor for the
//! decoder's working copies, plus a fixed allowance for codec state.
//! A 40-byte file claiming 100000×100000 samples would need 40 GB; the
//! absurd-size cases are also held to the fixed allowance alone.
//!
//! One test function only: the counters are process-wide.

#[path = "common/replay.rs"]
mod replay;

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};
use terrasynth::io::Format;

struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards to the system allocator; only adds bookkeeping.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let now = LIVE.fetch_add(layout.size(), Relaxed) + layout.size();
            PEAK.fetch_max(now, Relaxed);
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        LIVE.fetch_sub(layout.size(), Relaxed);
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            let now = LIVE.fetch_add(new_size, Relaxed) + new_size;
            PEAK.fetch_max(now, Relaxed);
            LIVE.fetch_sub(layout.size(), Relaxed);
        }
        p
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Peak heap growth while `f` runs.
fn peak_during<T>(f: impl FnOnce() -> T) -> (T, usize) {
    let base = LIVE.load(Relaxed);
    PEAK.store(base, Relaxed);
    let r = f();
    (r, PEAK.load(Relaxed).saturating_sub(base))
}

/// Fixed allowance for codec state (inflate windows, EXR/TIFF tables).
const FIXED: usize = 256 * 1024;
/// Working copies beyond the f32 output (integer buffer, conversion, ...).
const COPIES: usize = 4;

fn ratio(format: Option<Format>) -> usize {
    match format {
        Some(Format::Png16 | Format::Png8) => 1032,
        Some(Format::Exr) => 1376,
        Some(Format::Tiff) => 3641,
        _ => 1,
    }
}

#[test]
fn readers_allocate_only_what_the_file_justifies() {
    let mut report = Vec::new();
    let mut worst = (0.0f64, String::new());
    for (path, format) in replay::cases() {
        let data = std::fs::read(&path).unwrap();
        let (_, peak) = peak_during(|| replay::run_target(format, &data));
        let justified = FIXED + COPIES * 4 * data.len() * ratio(format);
        let name = path
            .strip_prefix(replay::root())
            .unwrap()
            .display()
            .to_string();
        assert!(
            peak <= justified,
            "{name}: peak {peak} B > {justified} B justified by {} B",
            data.len()
        );
        if name.contains("huge") || name.contains("not_justified") {
            assert!(
                peak <= FIXED,
                "{name}: an absurd declared size allocated {peak} B"
            );
        }
        let share = peak as f64 / justified as f64;
        if share > worst.0 {
            worst = (share, name.clone());
        }
        report.push(format!("{peak:>9} B  {name}"));
    }
    println!(
        "{}\nclosest to its bound: {} ({:.1}%)",
        report.join("\n"),
        worst.1,
        worst.0 * 100.0
    );
}
