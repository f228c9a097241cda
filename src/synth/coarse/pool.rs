//! Where the coarse start's pieces come from: every interior texel of the
//! start level, of one exemplar or of all, ranked by the altitude of its
//! surroundings; and the scale of landforms those exemplars show, which
//! the altitude guide lays out ([`Scale`]).

use super::guide::Scale;
use crate::database::layout::MARGIN;
use crate::level::atlas::AtlasLevel;
use crate::stages::common::texel_height;
use rayon::prelude::*;

/// Radius, in output pixels, of the surroundings whose mean altitude ranks
/// a texel (a square 224 px across).
///
/// Why the surroundings and not the texel: the guide sets the altitude of
/// regions, and a region of low ground holds valley floors *and* the
/// ridges between them. Ranked by their own height, the lowest ranks were
/// valley floors alone, and a low region of the guide came out as a flat
/// basin — a lake bed where the exemplar has valleys (pyrenees: realism
/// ratio 2.2, slope 80 %; ranked by a 100-px surrounding 1.2, 88 %).
pub const REGION_PX: i32 = 112;

/// Interior texels of a level ranked by the mean height around them.
pub struct Pool {
    /// (x, y) atlas coordinates, by ascending mean height of their
    /// surroundings, ties by position.
    ranked: Vec<(i32, i32)>,
    /// The guide's scale for these exemplars.
    scale: Scale,
}

impl Pool {
    /// The pool of exemplar `from` (or of every exemplar) at the level of
    /// `a`: every interior texel, ranked by the mean height of the interior
    /// texels within `REGION_PX` of it (a square; from summed-area tables,
    /// in integers); the guide's `Scale` from those exemplars' sizes.
    pub fn new(a: &AtlasLevel<'_>, from: Option<usize>) -> Pool {
        let radius = (REGION_PX >> a.level.index).max(1);
        let rects = &a.level.layout.rects;
        let rects = match from {
            Some(e) => &rects[e..=e],
            None => &rects[..],
        };
        let mut keyed: Vec<(i64, i32, i32)> = rects
            .par_iter()
            .flat_map_iter(|r| {
                let c = a.columns[r.x0 as usize];
                let (x0, y0) = (c.min_x, MARGIN as i32);
                let (nx, ny) = (c.max_x - x0 + 1, c.max_y - y0 + 1);
                let sat = Sat::new(nx, ny, |x, y| {
                    i64::from(texel_height(a.appearance(x0 + x, y0 + y)))
                });
                let mut keys = Vec::with_capacity((nx * ny) as usize);
                for y in 0..ny {
                    for x in 0..nx {
                        let (lx, ly) = ((x - radius).max(0), (y - radius).max(0));
                        let (hx, hy) = ((x + radius + 1).min(nx), (y + radius + 1).min(ny));
                        let (sum, n) = (sat.sum(lx, ly, hx, hy), i64::from((hx - lx) * (hy - ly)));
                        keys.push((sum.div_euclid(n), x0 + x, y0 + y));
                    }
                }
                keys
            })
            .collect();
        keyed.par_sort_unstable();
        // The median of the exemplars' shorter sides, in output pixels.
        let mut sides: Vec<usize> = rects
            .iter()
            .map(|r| (r.width.min(r.height) as usize) << a.level.index)
            .collect();
        sides.sort_unstable();
        Pool {
            ranked: keyed.into_iter().map(|(_, x, y)| (x, y)).collect(),
            scale: Scale::of_exemplars(sides.get(sides.len() / 2).copied().unwrap_or(0)),
        }
    }

    /// The altitude guide's scale for the pool's exemplars.
    pub fn scale(&self) -> Scale {
        self.scale
    }

    /// How many texels the pool holds.
    pub fn len(&self) -> u32 {
        self.ranked.len() as u32
    }

    pub fn is_empty(&self) -> bool {
        self.ranked.is_empty()
    }

    /// The texel of rank `r` (< [`Pool::len`]).
    pub fn at(&self, r: u32) -> (i32, i32) {
        self.ranked[r as usize]
    }

    /// The texels of `self` whose terrain type (at the level of `a`) is in
    /// the set `mask` (bit t = type t), in the same order: the pool of a
    /// place painted with those types.
    pub fn of_types(&self, a: &AtlasLevel<'_>, mask: u32) -> Pool {
        Pool {
            scale: self.scale,
            ranked: self
                .ranked
                .iter()
                .copied()
                .filter(|&(x, y)| mask >> a.level.types[a.index(x, y)] & 1 == 1)
                .collect(),
        }
    }
}

/// A summed-area table of an `nx × ny` grid.
struct Sat {
    nx: i32,
    s: Vec<i64>,
}

impl Sat {
    fn new(nx: i32, ny: i32, v: impl Fn(i32, i32) -> i64) -> Sat {
        let w = (nx + 1) as usize;
        let mut s = vec![0i64; w * (ny + 1) as usize];
        for y in 0..ny {
            let mut row = 0;
            for x in 0..nx {
                row += v(x, y);
                let i = (y + 1) as usize * w + (x + 1) as usize;
                s[i] = s[i - w] + row;
            }
        }
        Sat { nx, s }
    }

    /// The sum over `[x0, x1) × [y0, y1)`.
    fn sum(&self, x0: i32, y0: i32, x1: i32, y1: i32) -> i64 {
        let w = (self.nx + 1) as usize;
        let at = |x: i32, y: i32| self.s[y as usize * w + x as usize];
        at(x1, y1) - at(x0, y1) - at(x1, y0) + at(x0, y0)
    }
}
