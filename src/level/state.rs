//! Per-level synthesis state: exemplar coordinates S and height offsets V.
//!
//! The buffers are arrays of relaxed atomics. A correction subpass updates
//! its pixels in place while reading their neighbours (which belong to other
//! subpasses, DESIGN §5), exactly like a GPU kernel writing a storage buffer;
//! relaxed loads and stores compile to plain moves, and make that sharing
//! safe Rust without a copy of the state per subpass.

use super::fixed::Coord;
use rayon::prelude::*;
use std::sync::atomic::{AtomicI32, AtomicU64, Ordering::Relaxed};

/// Size of a synthesis level: `max(2, ⌈W / 2^i⌉)` per axis, so that every
/// level has the 2×2 neighbourhood the correction reflects at its borders.
pub fn level_size(width: usize, height: usize, level: usize) -> (usize, usize) {
    let f = |n: usize| n.div_ceil(1 << level).max(2);
    (f(width), f(height))
}

/// The coarsest synthesis level M: the first whose size is 2×2.
pub fn top_level(width: usize, height: usize) -> usize {
    let mut m = 0;
    while level_size(width, height, m) != (2, 2) {
        m += 1;
    }
    m
}

/// S and V of one level.
pub struct State {
    pub width: usize,
    pub height: usize,
    s: Vec<AtomicU64>,
    v: Vec<AtomicI32>,
}

/// `n` zeroed atomics from one zeroed allocation (`calloc`): pages fresh
/// from the OS come zeroed, so nothing is written here, and the first
/// stage to write a pixel (an upsampling, in parallel) pays for its page
/// (a huge one: [`crate::pages`]).
/// Zeroing them one by one was a serial pass over the level, half of
/// `upsample_jitter`'s time at level 0.
fn zeroed_u64(n: usize) -> Vec<AtomicU64> {
    const { assert!(align_of::<AtomicU64>() == align_of::<u64>()) };
    let mut v = std::mem::ManuallyDrop::new(vec![0u64; n]);
    crate::pages::advise_huge(&v);
    // SAFETY: AtomicU64 has the size and bit validity of u64 and (asserted
    // above) its alignment, so the allocation, handed over whole (pointer,
    // length, capacity), is a valid Vec<AtomicU64> of zeros.
    unsafe { Vec::from_raw_parts(v.as_mut_ptr().cast(), v.len(), v.capacity()) }
}

/// [`zeroed_u64`] for the offsets.
fn zeroed_i32(n: usize) -> Vec<AtomicI32> {
    const { assert!(align_of::<AtomicI32>() == align_of::<i32>()) };
    let mut v = std::mem::ManuallyDrop::new(vec![0i32; n]);
    crate::pages::advise_huge(&v);
    // SAFETY: as in `zeroed_u64`, for AtomicI32 and i32.
    unsafe { Vec::from_raw_parts(v.as_mut_ptr().cast(), v.len(), v.capacity()) }
}

impl State {
    pub fn new(width: usize, height: usize) -> State {
        let n = width * height;
        State {
            width,
            height,
            s: zeroed_u64(n),
            v: zeroed_i32(n),
        }
    }
    #[inline(always)]
    pub fn s(&self, i: usize) -> Coord {
        Coord::unpack(self.s[i].load(Relaxed))
    }
    #[inline(always)]
    pub fn v(&self, i: usize) -> i32 {
        self.v[i].load(Relaxed)
    }
    #[inline(always)]
    pub fn set(&self, i: usize, s: Coord, v: i32) {
        self.s[i].store(s.pack(), Relaxed);
        self.v[i].store(v, Relaxed);
    }
    /// The S and V of the `n` pixels from `i` on, for kernels that read a
    /// run of pixels (one bounds check per run, not two per pixel). Read
    /// them with [`Coord::unpack`] and relaxed loads.
    #[inline(always)]
    pub fn run(&self, i: usize, n: usize) -> (&[AtomicU64], &[AtomicI32]) {
        (&self.s[i..i + n], &self.v[i..i + n])
    }
    /// A copy of the coordinates, row-major.
    pub fn coords(&self) -> Vec<Coord> {
        self.s
            .iter()
            .map(|a| Coord::unpack(a.load(Relaxed)))
            .collect()
    }
    /// A copy of the offsets, row-major.
    pub fn offsets(&self) -> Vec<i32> {
        self.v.iter().map(|a| a.load(Relaxed)).collect()
    }
    /// A state holding `coords` and `offsets` (row-major, `width × height`):
    /// the inverse of [`State::coords`] and [`State::offsets`].
    pub fn from_parts(width: usize, height: usize, coords: &[Coord], offsets: &[i32]) -> State {
        assert_eq!(
            (coords.len(), offsets.len()),
            (width * height, width * height)
        );
        // Into zeroed buffers advised huge, in parallel: a restricted edit
        // builds a whole level's state this way (level 0: 12 MB at 1024²),
        // and collected into fresh 4 KiB pages one thread faulted ~3000
        // times per edit — more time than the edit's correction of level 1.
        let st = State::new(width, height);
        const RUN: usize = 1 << 14;
        st.s.par_chunks(RUN)
            .zip(coords.par_chunks(RUN))
            .for_each(|(s, c)| {
                s.iter()
                    .zip(c)
                    .for_each(|(s, c)| s.store(c.pack(), Relaxed))
            });
        st.v.par_chunks(RUN)
            .zip(offsets.par_chunks(RUN))
            .for_each(|(v, o)| v.iter().zip(o).for_each(|(v, &o)| v.store(o, Relaxed)));
        st
    }
    /// Overwrites the pixels `[x0, x1) × [y0, y1)` with those of
    /// `coords` and `offsets`, row-major rasters of this state's size.
    pub fn write_rect(&self, [x0, y0, x1, y1]: [usize; 4], coords: &[Coord], offsets: &[i32]) {
        let n = self.width * self.height;
        assert_eq!((coords.len(), offsets.len()), (n, n));
        for y in y0..y1 {
            let row = y * self.width + x0..y * self.width + x1;
            let (s, v) = self.run(row.start, row.len());
            s.iter()
                .zip(&coords[row.clone()])
                .for_each(|(s, c)| s.store(c.pack(), Relaxed));
            v.iter()
                .zip(&offsets[row])
                .for_each(|(v, &o)| v.store(o, Relaxed));
        }
    }
    /// A copy of the pixels `[x0, x1) × [y0, y1)`.
    pub fn crop(&self, [x0, y0, x1, y1]: [usize; 4]) -> State {
        let out = State::new(x1 - x0, y1 - y0);
        for (j, y) in (y0..y1).enumerate() {
            for (i, x) in (x0..x1).enumerate() {
                let k = y * self.width + x;
                out.set(j * out.width + i, self.s(k), self.v(k));
            }
        }
        out
    }
    /// Bytes held per pixel (for memory reports).
    pub const BYTES_PER_PIXEL: usize = 12;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn level_sizes_cover_any_output() {
        assert_eq!(level_size(1024, 1024, 0), (1024, 1024));
        assert_eq!(level_size(777, 333, 3), (98, 42));
        assert_eq!(level_size(1, 1, 0), (2, 2));
        assert_eq!(top_level(1024, 1024), 9);
        assert_eq!(top_level(1, 1), 0);
        assert_eq!(top_level(3, 2049), 11);
        for m in 0..12 {
            let (w, h) = level_size(3, 2049, m);
            let (cw, ch) = level_size(3, 2049, m + 1);
            assert!(2 * cw >= w && 2 * ch >= h, "children must cover level {m}");
        }
    }
}
