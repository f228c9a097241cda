//! The atlas: where every exemplar lives at every pyramid level.
//!
//! All exemplars of a level share one coordinate space (the *virtual atlas*):
//! exemplar `e` occupies columns `[x0_e >> i, (x0_e >> i) + w_e^i)` and rows
//! `[0, h_e^i)` at level `i`, with `w_e^i = ⌊w_e / 2^i⌋`. The level-0 offsets
//! `x0_e` are multiples of `2^L`, so an exemplar's offset at level `i` is
//! exactly `x0_e >> i` and upsampling a coordinate (`2·S + c`) stays inside
//! the same exemplar's columns — no per-exemplar translation in the hot loop.
//!
//! Storage is *not* that virtual rectangle: each exemplar's texels are stored
//! row-major and back to back, so differing exemplar sizes waste no bytes.
//! A texel at virtual (x, y) in exemplar `e` is at
//! `offset_e + y·w_e + (x − x0_e)`; `e` comes from a per-column table.
//! Coordinates pack into a u32 as `x | y << 16`, so a level's virtual atlas
//! must stay below 65536 in both directions (checked at build time).

use serde::{Deserialize, Serialize};

/// Columns of virtual atlas that belong to no exemplar map to this.
pub const NO_EXEMPLAR: u8 = u8::MAX;
/// Most exemplars in one database (exemplar ids are u8, [`NO_EXEMPLAR`] reserved).
pub const MAX_EXEMPLARS: usize = 254;
/// Largest virtual atlas side (coordinates pack into 16 bits each).
pub const MAX_ATLAS_SIDE: u32 = 1 << 16;
/// Synthesis coordinates and similarity entries stay this many texels away
/// from every exemplar edge, so that a candidate shifted by ±1 still has its
/// four diagonal neighbours inside the exemplar (paper §4: "cannot be on the
/// edge of an exemplar").
pub const MARGIN: u32 = 2;

/// One exemplar's rectangle at one level.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Rect {
    /// First virtual column.
    pub x0: u32,
    pub width: u32,
    pub height: u32,
    /// Index of its first texel in the level's arrays.
    pub offset: u64,
}

impl Rect {
    pub fn texels(&self) -> u64 {
        self.width as u64 * self.height as u64
    }
    /// Texel index of virtual (x, y); the caller guarantees it lies inside.
    #[inline(always)]
    pub fn index(&self, x: u32, y: u32) -> usize {
        (self.offset + y as u64 * self.width as u64 + (x - self.x0) as u64) as usize
    }
    /// Whether virtual (x, y) is at least [`MARGIN`] texels from every edge.
    #[inline(always)]
    pub fn is_interior(&self, x: u32, y: u32) -> bool {
        x >= self.x0 + MARGIN
            && x + MARGIN < self.x0 + self.width
            && y >= MARGIN
            && y + MARGIN < self.height
    }
    /// Virtual (x, y) of texel `k` of this rectangle.
    pub fn coords(&self, k: u64) -> (u32, u32) {
        let local = k - self.offset;
        (
            self.x0 + (local % self.width as u64) as u32,
            (local / self.width as u64) as u32,
        )
    }
}

/// Where every exemplar sits at one level.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct LevelLayout {
    pub rects: Vec<Rect>,
    /// Virtual atlas width (one past the last exemplar's last column).
    pub atlas_width: u32,
    /// Virtual atlas height (the tallest exemplar).
    pub atlas_height: u32,
}

impl LevelLayout {
    pub fn texels(&self) -> u64 {
        self.rects.iter().map(Rect::texels).sum()
    }

    /// Exemplar id of every virtual column ([`NO_EXEMPLAR`] in gaps).
    pub fn column_table(&self) -> Vec<u8> {
        let mut t = vec![NO_EXEMPLAR; self.atlas_width as usize];
        for (e, r) in self.rects.iter().enumerate() {
            t[r.x0 as usize..(r.x0 + r.width) as usize].fill(e as u8);
        }
        t
    }

    /// Exemplar containing virtual (x, y), if any.
    pub fn exemplar_at(&self, columns: &[u8], x: u32, y: u32) -> Option<usize> {
        let e = *columns.get(x as usize)?;
        (e != NO_EXEMPLAR && y < self.rects[e as usize].height).then_some(e as usize)
    }
}

/// Packs virtual coordinates (each < 65536) into one u32.
#[inline(always)]
pub fn pack(x: u32, y: u32) -> u32 {
    x | (y << 16)
}

/// Inverse of [`pack`].
#[inline(always)]
pub fn unpack(c: u32) -> (u32, u32) {
    (c & 0xFFFF, c >> 16)
}

/// Lays out exemplars of level-0 sizes `sizes` for levels `0..=levels`.
/// Returns `None` if the virtual atlas would exceed [`MAX_ATLAS_SIDE`] or a
/// level would hold more than `i32::MAX` texels.
pub fn plan(sizes: &[(u32, u32)], levels: usize) -> Option<Vec<LevelLayout>> {
    let align = 1u64 << levels;
    let mut x0s = Vec::with_capacity(sizes.len());
    let mut next = 0u64;
    for &(w, _) in sizes {
        x0s.push(next);
        next = (next + w as u64).div_ceil(align) * align;
    }
    let mut out = Vec::with_capacity(levels + 1);
    for i in 0..=levels {
        let mut rects = Vec::with_capacity(sizes.len());
        let mut offset = 0u64;
        let (mut aw, mut ah) = (0u64, 0u64);
        for (&(w, h), &x0) in sizes.iter().zip(&x0s) {
            let r = Rect {
                x0: (x0 >> i) as u32,
                width: w >> i,
                height: h >> i,
                offset,
            };
            offset += r.texels();
            aw = aw.max(r.x0 as u64 + r.width as u64);
            ah = ah.max(r.height as u64);
            rects.push(r);
        }
        // Texel indices must fit an i32 (synthesis and the GPU mirror
        // address with 32-bit signed arithmetic).
        if aw >= MAX_ATLAS_SIDE as u64 || ah >= MAX_ATLAS_SIDE as u64 || offset > i32::MAX as u64 {
            return None;
        }
        out.push(LevelLayout {
            rects,
            atlas_width: aw as u32,
            atlas_height: ah as u32,
        });
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offsets_halve_exactly_and_rects_never_overlap() {
        let sizes = [(900, 900), (733, 600), (1024, 1024)];
        let levels = plan(&sizes, 6).unwrap();
        for (i, l) in levels.iter().enumerate() {
            for (e, r) in l.rects.iter().enumerate() {
                assert_eq!(r.x0, levels[0].rects[e].x0 >> i);
                assert_eq!(r.width, sizes[e].0 >> i);
            }
            for w in l.rects.windows(2) {
                assert!(w[0].x0 + w[0].width <= w[1].x0);
                assert_eq!(w[0].offset + w[0].texels(), w[1].offset);
            }
            let cols = l.column_table();
            let r = l.rects[1];
            assert_eq!(l.exemplar_at(&cols, r.x0, r.height - 1), Some(1));
            assert_eq!(l.exemplar_at(&cols, r.x0, r.height), None);
            let k = r.offset + 5;
            let (x, y) = r.coords(k);
            assert_eq!(r.index(x, y) as u64, k);
        }
        assert!(plan(&[(60_000, 10), (10_000, 10)], 6).is_none());
        assert_eq!(unpack(pack(65_535, 1234)), (65_535, 1234));
    }
}
