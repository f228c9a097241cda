//! Stage `upsample_jitter` (paper eq. 1–2): each pixel of level i+1 seeds
//! its 2×2 children at level i, `S(2p + c) = 2·S(p) + c + r·H(2p + c)`,
//! `V(2p + c) = V(p)`, with `H` a stateless hash in [−1, 1]² (DESIGN §6).
//!
//! (The paper writes children at `2p ± ½` in OpenCL's half-integer texel
//! convention; with texel centres at integers that is `2p + c`, c ∈ {0,1}²,
//! matching how the exemplar pyramid pairs texel x with children 2x, 2x+1.)
//!
//! Levels above the database's coarsest level L have no exemplar data; their
//! coordinates are kept in level-L units, where "doubling" is adding
//! `(c + r·H)·2^(i−L)` (the same map, expressed at level L). Entering level
//! L they wrap toroidally into the start exemplar's interior, so an output
//! larger than the exemplar starts from a jittered, tiled copy that the
//! correction at level L then rearranges. Below L, children are clamped into
//! the interior of their parent's exemplar, found from the child's position
//! before jitter: a jitter of up to 4 texels (the `--jitter` limit) can
//! carry a child past the 2-texel margin and gap, into another exemplar or
//! off the atlas (a crash at `--jitter 4` before this rule).

use crate::database::layout::MARGIN;
use crate::hash::hash4;
use crate::isa::Isa;
use crate::level::atlas::AtlasLevel;
use crate::level::fixed::{Coord, FRAC_BITS};
use crate::level::state::State;
use bytemuck::{Pod, Zeroable};
use rayon::prelude::*;
use std::sync::atomic::Ordering::Relaxed;

/// How children relate to parents at this step.
#[derive(Debug, Clone, Copy)]
pub enum Step {
    /// Both levels are at or below L: children are `2·S + c + j`, clamped
    /// into the interior of their exemplar at the child level.
    Pyramid,
    /// The child level is above L: coordinates stay in level-L units and
    /// move by `(c + j) << shift` (shift = child level − L).
    Virtual { shift: u32 },
    /// The child level is L itself and the parent is above it: as `Virtual`
    /// with shift 0, then wrap into the rectangle (inclusive texel bounds).
    Wrap {
        min_x: i32,
        max_x: i32,
        min_y: i32,
        max_y: i32,
    },
}

/// Parameters of one upsampling (the WGSL mirror takes the same numbers).
#[derive(Debug, Clone, Copy)]
pub struct UpsampleParams {
    pub seed: u32,
    /// The child level's index.
    pub level: u32,
    /// Jitter amplitude r in fixed point (r · 2^FRAC_BITS).
    pub jitter: i32,
    pub step: Step,
    /// Absolute position, in the child level, of the child buffer's pixel
    /// (0, 0): `[0, 0]` for a whole level, the window's corner for windowed
    /// synthesis. The jitter hashes absolute coordinates (DESIGN §6), so a
    /// window draws what the whole level draws there. Both components are
    /// even, so a pixel's child parity `c` is the same locally and
    /// absolutely, and the parent buffer starts at `origin / 2`.
    pub origin: [u32; 2],
}

/// The jitter offset of a child pixel: two values in [−r, r) (fixed point).
#[inline(always)]
pub fn jitter(seed: u32, level: u32, x: u32, y: u32, r: i32) -> (i32, i32) {
    let h = hash4(seed, level, x, y);
    let jx = (h & 0xFFFF) as i32 - 32768;
    let jy = (h >> 16) as i32 - 32768;
    // |j · r| ≤ 2^15 · 2^10 < 2^31; >> is an arithmetic (floor) shift.
    ((jx * r) >> 15, (jy * r) >> 15)
}

/// Fills `child` from `parent`. `atlas` is the child level's atlas (used by
/// [`Step::Pyramid`] to clamp); `isa` picks the jitter's copy (the same
/// bytes at every level).
pub fn upsample_jitter(
    parent: &State,
    child: &State,
    atlas: Option<&AtlasLevel<'_>>,
    p: &UpsampleParams,
    isa: Isa,
) {
    let rect = [0, 0, child.width, child.height];
    upsample_jitter_rect(parent, child, atlas, p, rect, isa);
}

/// [`upsample_jitter`] of the child pixels in `[x0, y0, x1, y1)` only (the
/// rest keep their state): an edit's restricted re-synthesis reads the
/// upsampled values only around the window it corrects.
pub fn upsample_jitter_rect(
    parent: &State,
    child: &State,
    atlas: Option<&AtlasLevel<'_>>,
    p: &UpsampleParams,
    [x0, y0, x1, y1]: [usize; 4],
    isa: Isa,
) {
    let [ox, oy] = p.origin;
    debug_assert!(ox % 2 == 0 && oy % 2 == 0, "odd origin {:?}", p.origin);
    let x1 = x1.min(child.width);
    (y0..y1.min(child.height)).into_par_iter().for_each(|y| {
        let mut jit = [(0, 0); ROW_CHUNK];
        for a in (x0..x1).step_by(ROW_CHUNK) {
            let b = x1.min(a + ROW_CHUNK);
            let jit = &mut jit[..b - a];
            jitter_row(p, ox + a as u32, oy + y as u32, jit, isa);
            let run = Run {
                parent,
                child,
                y,
                a,
            };
            // One loop per step kind: the step is the same for the level.
            match p.step {
                Step::Pyramid => {
                    let at = atlas.expect("pyramid steps have an atlas");
                    run.fill(jit, |s, cx, (dx, dy)| {
                        let c = Coord {
                            x: 2 * s.x + dx,
                            y: 2 * s.y + dy,
                        };
                        clamp(at, c, 2 * s.x + (cx << FRAC_BITS))
                    })
                }
                Step::Virtual { shift } => run.fill(jit, |s, _, (dx, dy)| Coord {
                    x: s.x + (dx << shift),
                    y: s.y + (dy << shift),
                }),
                Step::Wrap {
                    min_x,
                    max_x,
                    min_y,
                    max_y,
                } => run.fill(jit, |s, _, (dx, dy)| Coord {
                    x: wrap(s.x + dx, min_x, max_x),
                    y: wrap(s.y + dy, min_y, max_y),
                }),
            }
        }
    });
}

/// Child pixels per batch of jitter: the hashes of a batch are computed
/// in one loop over the row, which the compiler vectorises (AVX2: eight
/// pixels per instruction) where per-pixel hashing between the other
/// work was the stage's main cost.
const ROW_CHUNK: usize = 256;

/// [`jitter`] of the pixels (ax, ay), (ax + 1, ay), … into `out`, by
/// `isa`'s copy.
#[inline]
fn jitter_row(p: &UpsampleParams, ax: u32, ay: u32, out: &mut [(i32, i32)], isa: Isa) {
    #[cfg(target_arch = "x86_64")]
    if isa.avx2() {
        // SAFETY: the CPU supports AVX2 (`Isa::avx2` checks it), the one
        // feature the function enables.
        unsafe { jitter_row_avx2(p, ax, ay, out) };
        return;
    }
    jitter_row_any(p, ax, ay, out);
}

/// [`jitter_row_any`] compiled for AVX2 (per-lane shifts and 32-bit
/// multiplies: the hash vectorises).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn jitter_row_avx2(p: &UpsampleParams, ax: u32, ay: u32, out: &mut [(i32, i32)]) {
    jitter_row_any(p, ax, ay, out);
}

/// [`jitter_row`] for any instruction set.
#[inline(always)]
fn jitter_row_any(p: &UpsampleParams, ax: u32, ay: u32, out: &mut [(i32, i32)]) {
    for (k, o) in out.iter_mut().enumerate() {
        *o = jitter(p.seed, p.level, ax.wrapping_add(k as u32), ay, p.jitter);
    }
}

/// A run of child pixels, row `y` from column `a` on, and their parents.
struct Run<'s> {
    parent: &'s State,
    child: &'s State,
    y: usize,
    a: usize,
}

impl Run<'_> {
    /// Sets the run's pixels (one per element of `jit`, their jitter) to
    /// `step(S(parent), cx, offset)` and V(parent), where `cx` is the
    /// child's column parity and the offset `(c << FRAC_BITS) + j`.
    #[inline(always)]
    fn fill(&self, jit: &[(i32, i32)], step: impl Fn(Coord, i32, (i32, i32)) -> Coord) {
        let (parent, child, y, a) = (self.parent, self.child, self.y, self.a);
        let n = jit.len();
        let (pa, pb) = (a / 2, (a + n - 1) / 2 + 1);
        let (ps, pv) = parent.run((y / 2) * parent.width + pa, pb - pa);
        let (cs, cv) = child.run(y * child.width + a, n);
        let cy = (y & 1) as i32;
        for (x, ((s_out, v_out), &(jx, jy))) in (a..).zip(cs.iter().zip(cv).zip(jit)) {
            let pk = x / 2 - pa;
            let s = Coord::unpack(ps[pk].load(Relaxed));
            let cx = (x & 1) as i32;
            let off = ((cx << FRAC_BITS) + jx, (cy << FRAC_BITS) + jy);
            s_out.store(step(s, cx, off).pack(), Relaxed);
            v_out.store(pv[pk].load(Relaxed), Relaxed);
        }
    }
}

/// Clamps a fixed-point coordinate into the interior of the exemplar that
/// holds `home_x` (the child's x before jitter, inside its parent's
/// exemplar).
#[inline(always)]
fn clamp(a: &AtlasLevel<'_>, c: Coord, home_x: i32) -> Coord {
    let tx = crate::level::fixed::round(home_x);
    let col = &a.columns[tx as usize];
    Coord {
        x: c.x.clamp(col.min_x << FRAC_BITS, col.max_x << FRAC_BITS),
        y: c.y
            .clamp((MARGIN as i32) << FRAC_BITS, col.max_y << FRAC_BITS),
    }
}

/// Toroidal wrap of a fixed-point value into texels `[min, max]`.
#[inline(always)]
fn wrap(v: i32, min: i32, max: i32) -> i32 {
    let period = (max - min + 1) << FRAC_BITS;
    (min << FRAC_BITS) + (v - (min << FRAC_BITS)).rem_euclid(period)
}

/// [`Step`] as the kernel's `step` field.
pub const STEP_PYRAMID: u32 = 0;
pub const STEP_VIRTUAL: u32 = 1;
pub const STEP_WRAP: u32 = 2;

/// `UpsampleParams` of `kernels/upsample_jitter.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, Pod, Zeroable)]
pub struct UpsampleUniform {
    pub child_width: u32,
    pub child_height: u32,
    pub parent_width: u32,
    pub seed: u32,
    pub level: u32,
    pub jitter: i32,
    pub step: u32,
    pub shift: u32,
    pub min_x: i32,
    pub max_x: i32,
    pub min_y: i32,
    pub max_y: i32,
    /// `UpsampleParams::origin`.
    pub origin_x: u32,
    pub origin_y: u32,
    pub pad0: u32,
    pub pad1: u32,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jitter_stays_within_r_and_is_centred() {
        let r = (0.4 * (1 << FRAC_BITS) as f64).round() as i32;
        let (mut sx, mut n) = (0i64, 0i64);
        for y in 0..64 {
            for x in 0..64 {
                let (jx, jy) = jitter(7, 3, x, y, r);
                assert!((-r..r).contains(&jx) && (-r..r).contains(&jy));
                sx += jx as i64;
                n += 1;
            }
        }
        assert!((sx as f64 / n as f64).abs() < 2.0);
        assert_eq!(jitter(7, 3, 5, 5, 0), (0, 0));
    }

    #[test]
    fn wrap_is_periodic_inside_bounds() {
        let one = 1 << FRAC_BITS;
        assert_eq!(wrap(5 * one, 2, 9), 5 * one);
        assert_eq!(wrap(10 * one, 2, 9), 2 * one);
        assert_eq!(wrap(one + 3, 2, 9), 9 * one + 3);
    }
}
