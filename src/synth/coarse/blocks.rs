//! The blocks of the coarse start: where they lie, what they draw, how
//! their edges wander.

use super::fit;
use super::{Source, interiors};
use crate::hash::{below, hash4};
use crate::synth::atlas::AtlasLevel;
use crate::synth::cone::Rect;
use crate::synth::fixed::{Coord, FRAC_BITS};
use crate::synth::stages::upsample_jitter;
use crate::synth::state::State;
use rayon::prelude::*;

/// Hash salt of the block positions (kept apart from the jitter's
/// `hash4(seed, level, x, y)`, whose level is always < 2^16).
const COARSE_SALT: u32 = 0xC0A5_0000;

/// Level L of an output over `region` (absolute level-L pixels: the whole
/// level, or a window's cone): each pixel belongs to the 2^bits × 2^bits
/// block under its `warp`ed position; each block picks one exemplar
/// texel (`block_draw`: a hash of the seed, the block's position and its
/// group's layout, which `fit.rs` chooses) uniformly over every interior
/// texel of exemplar `from` (or of every exemplar), and its pixels copy the
/// exemplar around that texel, mirrored
/// at the interior's edges; each pixel gets the level's jitter (`jitter`,
/// fixed point, the same hash as `upsample_jitter`).
///
/// Why centred and mirrored: blocks that must fit the interior start only
/// at the first `side − 2^bits + 1` texels of each axis, so a texel near an
/// exemplar edge is covered by one origin where a central one is covered by
/// 2^bits — measured on the shared DEMs (blocks of 32 in a 43-texel
/// interior), the output drew 12× more from the exemplar's centre than from
/// its edges, and real DEMs are not alike across their extent (thuringia:
/// median slope 6.2° in its centre, 5.0° over all). A block centred on a
/// uniform texel and mirrored at the edges covers every interior texel
/// equally (2^bits + 1 times near an edge, 2^bits inside), like the
/// toroidal wrap this replaced, but the wrap put the exemplar's far side
/// next to its near side along a straight line — on the coastal DEMs a
/// straight coast 64 texels long wherever a block wrapped from sea to
/// mountains. A mirror line keeps heights continuous; what shows is a
/// symmetric landform, which correction and jitter then break up.
///
/// The block grid is shifted so that the world's centre is the centre of
/// a 2 × 2 group ([`grid_shift`]).
pub fn blocks(
    src: Source<'_>,
    (region, world): (Rect, (usize, usize)),
    (l, bits): (usize, usize),
    seed: u32,
    jitter: i32,
) -> State {
    let draws = Draws::new(src.atlas, src.from, bits);
    let (w, h) = (region.width(), region.height());
    let shift = (grid_shift(world.0, bits), grid_shift(world.1, bits));
    // The block of every pixel: the one under its warped position on the
    // shifted grid; it copies that block's exemplar from its own place
    // relative to the block's corner. Row by row in parallel: the warp
    // hashes ~20 times a pixel, and this start is serial work ahead of
    // every level (3 of the GPU path's 11 ms at 1024² on an H100).
    let row_y = |r: usize| (region.y0 + r) as i32 + shift.1;
    let row_x = move |c: usize| (region.x0 + c) as i32 + shift.0;
    let mut at = vec![(0, 0); w * h];
    at.par_chunks_mut(w).enumerate().for_each(|(r, row)| {
        let y = row_y(r);
        for (c, b) in row.iter_mut().enumerate() {
            *b = block_of(seed, row_x(c), y, bits);
        }
    });
    let layouts = fit::layouts(
        src.profile,
        &draws,
        (world, shift),
        seed,
        at.iter().copied(),
    );
    let st = State::new(w, h);
    at.par_chunks(w).enumerate().for_each(|(j, row)| {
        let y = row_y(j);
        // Neighbouring pixels mostly share a block: its origin is drawn once.
        let mut last: Option<((i32, i32), Texel)> = None;
        for (c, &block) in row.iter().enumerate() {
            let x = row_x(c);
            let origin = match last {
                Some((b, o)) if b == block => o,
                _ => {
                    let o = draws.origin(seed, layouts[&(block.0 >> 1, block.1 >> 1)], block);
                    last = Some((block, o));
                    o
                }
            };
            let (r, lx, ly) = draws.texel(origin, block, (x, y));
            let (x0, y0, nx, ny) = draws.ranges[r];
            let (ax, ay) = (x - shift.0, y - shift.1);
            let (jx, jy) = upsample_jitter::jitter(seed, l as u32, ax as u32, ay as u32, jitter);
            let s = Coord {
                x: inside(((x0 + lx) << FRAC_BITS) + jx, x0, nx),
                y: inside(((y0 + ly) << FRAC_BITS) + jy, y0, ny),
            };
            st.set(j * w + c, s, 0);
        }
    });
    st
}

/// An interior texel: the exemplar's range in [`Draws`] and its position
/// in that interior.
pub(super) type Texel = (usize, i32, i32);

/// The interiors blocks draw from, and where a drawn block's pixels copy
/// their texels.
pub(super) struct Draws {
    /// Interior origin and size (x0, y0, nx, ny) per exemplar.
    pub ranges: Vec<(i32, i32, i32, i32)>,
    /// [`z_order`] of the interior texels.
    order: Vec<u32>,
    total: u32,
    pub bits: usize,
}

impl Draws {
    pub fn new(a: &AtlasLevel<'_>, from: Option<usize>, bits: usize) -> Draws {
        let ranges = ranges(a, from);
        let total = ranges.iter().map(|r| (r.2 * r.3) as u32).sum();
        let order = z_order(&ranges);
        Draws {
            ranges,
            order,
            total,
            bits,
        }
    }

    /// The interior texel `(range, ox, oy)` block (bx, by) is centred on
    /// when its group takes its `layout`-th draw.
    pub fn origin(&self, seed: u32, layout: u32, (bx, by): (i32, i32)) -> Texel {
        let mut k = self.order[block_draw(seed, layout, bx as u32, by as u32, self.total) as usize];
        for (r, &(_, _, nx, ny)) in self.ranges.iter().enumerate() {
            let n = (nx * ny) as u32;
            if k < n {
                return (r, (k % nx as u32) as i32, (k / nx as u32) as i32);
            }
            k -= n;
        }
        unreachable!("block_draw stays below the interior texel count")
    }

    /// The interior texel `(range, lx, ly)` that pixel (x, y) of the
    /// shifted grid copies when it belongs to block (bx, by), centred on
    /// `origin` ([`Draws::origin`]): the block is mirrored at the
    /// interior's edges.
    #[inline]
    pub fn texel(&self, (r, ox, oy): Texel, (bx, by): (i32, i32), (x, y): (i32, i32)) -> Texel {
        let (_, _, nx, ny) = self.ranges[r];
        let half = 1 << (self.bits - 1);
        let lx = mirror(ox - half + x - (bx << self.bits), nx);
        let ly = mirror(oy - half + y - (by << self.bits), ny);
        (r, lx, ly)
    }
}

/// Interior origin and size (x0, y0, nx, ny) of exemplar `from`, or of
/// every exemplar, at level L.
pub(super) fn ranges(a: &AtlasLevel<'_>, from: Option<usize>) -> Vec<(i32, i32, i32, i32)> {
    interiors(a, from)
        .map(|(x0, x1, y0, y1)| (x0, y0, x1 - x0 + 1, y1 - y0 + 1))
        .collect()
}

/// The interior texels (as row-major indices over every exemplar's
/// interior in turn, the numbering `blocks` decodes) in Z order: each
/// exemplar's texels by the Morton code of their position, exemplar after
/// exemplar. A quarter of this order is a compact region — one exemplar's
/// quadrant, or whole exemplars — where a quarter of the row-major order
/// was a band of rows.
///
/// Why: the four blocks of a 2 × 2 group draw from the four quarters
/// ([`block_draw`]). Over bands of rows an exemplar's west and east were
/// one lottery — olympic's sea lies west — so an output the exemplar's size
/// held 5–35 % sea (exemplar 25 %); over quadrants each group takes two
/// texels from each half both ways. Measured over 18 seeds (11–19, 21–29)
/// on the 8 shared DEMs, targets met 53 → 57 of 64; north German plain
/// ratio 1.60 → 1.17 and 1.48 → 1.30.
///
/// Built by walking the Morton codes of the enclosing power-of-two square
/// and keeping those inside (no sort: at most 4× the texels).
fn z_order(ranges: &[(i32, i32, i32, i32)]) -> Vec<u32> {
    let total: usize = ranges.iter().map(|r| (r.2 * r.3) as usize).sum();
    let mut order = Vec::with_capacity(total);
    let mut base = 0u32;
    for &(_, _, nx, ny) in ranges {
        let side = (nx.max(ny) as u32).next_power_of_two();
        for code in 0..u64::from(side) * u64::from(side) {
            let (x, y) = (compact(code), compact(code >> 1));
            if x < nx as u32 && y < ny as u32 {
                order.push(base + y * nx as u32 + x);
            }
        }
        base += (nx * ny) as u32;
    }
    order
}

/// The even bits of a Morton code (x of an interleaved x, y).
fn compact(code: u64) -> u32 {
    let mut v = code & 0x5555_5555_5555_5555;
    v = (v | (v >> 1)) & 0x3333_3333_3333_3333;
    v = (v | (v >> 2)) & 0x0F0F_0F0F_0F0F_0F0F;
    v = (v | (v >> 4)) & 0x00FF_00FF_00FF_00FF;
    v = (v | (v >> 8)) & 0x0000_FFFF_0000_FFFF;
    v = (v | (v >> 16)) & 0x0000_0000_FFFF_FFFF;
    v as u32
}

/// How far the block grid is shifted along an axis of `n` level-L pixels:
/// the axis' centre falls on the border between the two blocks of a 2 × 2
/// group (block index 1 | 2 of the shifted grid's first group pair).
///
/// Why: with the grid at the origin, an output the size of its exemplar
/// lay mostly in one block — blocks are as large as the exemplars allow,
/// and the 600² riviera DEM's 512-pixel blocks gave 73 % of the output to
/// the block at the origin — so its make-up was one draw: its sea share ran
/// 11–74 % over 9 seeds (exemplar 39 %), its relief kept 75 %, its
/// realism ratio 1.32. Centred, the four blocks of one stratified group
/// share the output (20–52 % sea, relief 91 %, ratio 0.67); north German
/// plain relief 82 → 85 %. At 1024² from the shared DEMs the shift is 0.
fn grid_shift(n: usize, bits: usize) -> i32 {
    ((1i32 << bits) - (n / 2) as i32).rem_euclid(1 << (bits + 1))
}

/// The block (on the shifted grid) that pixel (x, y) of the shifted grid
/// belongs to: the one under its warped position.
fn block_of(seed: u32, x: i32, y: i32, bits: usize) -> (i32, i32) {
    let (wx, wy) = warp(seed, x, y, bits);
    ((x + wx) >> bits, (y + wy) >> bits)
}

/// The rank (below `total`, in [`z_order`]) of the interior texel that
/// block `(bx, by)` starts from: stratified over each aligned 2 × 2 group
/// of blocks, whose four blocks draw one from each quarter of `0..total`
/// in a hashed order, uniformly inside it.
///
/// Why stratify: an output holds few blocks (four at 1024² from the shared
/// DEMs), and independent draws made its make-up a lottery — measured on
/// the 8-DEM typed database at 1024², 43 % of one seed's output came from
/// the north German plain (10 % of the exemplars), "flat" took 20–44 % of
/// the output where it is 18 % of the exemplars. Quarters of the area
/// spread each group over the exemplars (and over the quadrants of one
/// exemplar), while groups stay independent, so like still meets like
/// across group borders. A pure function of the seed and the block's
/// position, as every choice of the start (windows need no neighbours).
fn block_draw(seed: u32, layout: u32, bx: u32, by: u32, total: u32) -> u32 {
    let salt = COARSE_SALT | layout << 8;
    let group = hash4(seed, salt | 1, bx >> 1, by >> 1);
    // The group's order of quarters: each slot's rank among four hashed
    // bytes (ties by slot), so every order of the quarters can occur.
    let key = |slot: u32| ((group >> (8 * slot)) & 0xFF, slot);
    let slot = (bx & 1) | (by & 1) << 1;
    let quarter = (0..4).filter(|&t| key(t) < key(slot)).count() as u64;
    let within = below(hash4(seed, salt, bx, by), total);
    ((quarter * u64::from(total) + u64::from(within)) / 4) as u32
}

/// How far pixel (x, y) of level L looks for its block: two octaves of
/// value noise (lattices of 2^(bits−1) and 2^(bits−2) texels, amplitudes
/// 2^(bits−2) and 2^(bits−3)), in level-L texels, x and y apart.
///
/// Why: square blocks left their edges in the output wherever unlike
/// blocks met — straight coastlines where a land block met a sea block,
/// a massif cut off along a grid line — because correction joins blocks
/// only over a few texels of each level. Warped edges wander like the
/// borders of real landforms; within a block the copy stays verbatim.
/// No warp for blocks under 8 texels (nothing to wander in).
fn warp(seed: u32, x: i32, y: i32, bits: usize) -> (i32, i32) {
    if bits < 3 {
        return (0, 0);
    }
    let octave = |salt: u32, g: usize, a: usize| {
        (value_noise(seed, COARSE_SALT | salt, x, y, g) * (1 << a)) >> 15
    };
    (
        octave(2, bits - 1, bits - 2) + octave(3, bits - 2, bits - 3),
        octave(4, bits - 1, bits - 2) + octave(5, bits - 2, bits - 3),
    )
}

/// Value noise in `[−2^15, 2^15)` at (x, y): hashed values on a lattice of
/// 2^g texels, interpolated bilinearly in integers.
fn value_noise(seed: u32, salt: u32, x: i32, y: i32, g: usize) -> i32 {
    let (cx, cy, fx, fy) = (x >> g, y >> g, x & ((1 << g) - 1), y & ((1 << g) - 1));
    let v = |dx: i32, dy: i32| {
        let h = hash4(seed, salt, (cx + dx) as u32, (cy + dy) as u32);
        i64::from((h >> 16) as i32 - (1 << 15))
    };
    let (fx, fy, n) = (i64::from(fx), i64::from(fy), 1i64 << g);
    let top = v(0, 0) * (n - fx) + v(1, 0) * fx;
    let bottom = v(0, 1) * (n - fx) + v(1, 1) * fx;
    ((top * (n - fy) + bottom * fy) >> (2 * g)) as i32
}

/// Texel `t` of an axis of `n` interior texels, mirrored at both ends
/// (…, 1, 0 | 0, 1, …, n − 1 | n − 1, n − 2, …).
fn mirror(t: i32, n: i32) -> i32 {
    let r = t.rem_euclid(2 * n);
    if r < n { r } else { 2 * n - 1 - r }
}

/// Fixed-point `v` clamped to `[min − ½, min + n − ½)` texels, so that it
/// rounds (half up) to one of the `n` interior texels from `min` (jitter may
/// carry a mirrored edge texel half a texel out).
fn inside(v: i32, min: i32, n: i32) -> i32 {
    let half = 1 << (FRAC_BITS - 1);
    v.clamp(
        (min << FRAC_BITS) - half,
        ((min + n) << FRAC_BITS) - half - 1,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_group_of_four_blocks_draws_from_the_four_quarters() {
        let total = 5_003;
        for seed in 0..50 {
            for (gx, gy) in [(0u32, 0u32), (7, 3), (u32::MAX >> 1, 2)] {
                let mut quarters: Vec<u32> = (0..4)
                    .map(|s| block_draw(seed, 0, 2 * gx + (s & 1), 2 * gy + (s >> 1), total))
                    .map(|k| {
                        assert!(k < total);
                        k * 4 / total
                    })
                    .collect();
                quarters.sort();
                assert_eq!(quarters, [0, 1, 2, 3], "seed {seed}, group ({gx}, {gy})");
            }
        }
    }

    #[test]
    fn z_order_quarters_are_quadrants_and_every_texel_appears_once() {
        // A 64² interior: its quarters are its four quadrants.
        let order = z_order(&[(0, 0, 64, 64)]);
        for (q, chunk) in order.chunks(1024).enumerate() {
            for &k in chunk {
                let (x, y) = (k % 64, k / 64);
                assert_eq!((x / 32 + 2 * (y / 32)) as usize, q, "texel ({x}, {y})");
            }
        }
        // Rectangles of any size, exemplar after exemplar: a permutation.
        let ranges = [(0, 0, 37, 23), (0, 0, 5, 71), (0, 0, 1, 1)];
        let mut order = z_order(&ranges);
        assert!(order[..37 * 23].iter().all(|&k| k < 37 * 23));
        order.sort_unstable();
        assert!(order.iter().enumerate().all(|(i, &k)| i as u32 == k));
    }

    #[test]
    fn an_output_the_size_of_its_exemplar_shares_four_blocks() {
        // Riviera at level 3: 75 × 75 pixels, blocks of 64.
        let (n, bits) = (75, 6);
        for seed in 0..20 {
            let shift = grid_shift(n, bits);
            let mut count = std::collections::HashMap::new();
            for y in 0..n as i32 {
                for x in 0..n as i32 {
                    let b = block_of(seed, x + shift, y + shift, bits);
                    *count.entry(b).or_insert(0usize) += 1;
                }
            }
            let largest = *count.values().max().unwrap() as f64 / (n * n) as f64;
            assert!(largest < 0.4, "seed {seed}: one block holds {largest:.2}");
            let (c, s) = (n as i32 / 2 + shift, 1 << bits);
            assert_eq!(c % (2 * s), s, "the centre is a group's centre");
        }
        assert_eq!(grid_shift(128, 6), 0, "1024² from level 3: no shift");
    }

    #[test]
    fn warp_stays_within_three_eighths_of_a_block_and_moves() {
        let bits = 6;
        let mut moved = 0;
        for y in (-200..200).step_by(7) {
            for x in (-200..200).step_by(5) {
                let (wx, wy) = warp(3, x, y, bits);
                let bound = 3 << (bits - 3);
                assert!(
                    wx.abs() <= bound && wy.abs() <= bound,
                    "({x},{y}): {wx},{wy}"
                );
                moved += usize::from(wx != 0 || wy != 0);
            }
        }
        assert!(moved > 3000, "{moved}");
        assert_eq!(warp(3, 10, 10, 2), (0, 0), "no warp under 8 texels");
    }
}
