//! The dependency cone of a window: which pixels of each level a window of
//! the output depends on, so that windowed synthesis computes those and
//! nothing else (issue 17; Lefebvre & Hoppe 2005, §3.3).
//!
//! Every stage is local and every random choice hashes absolute
//! coordinates (DESIGN §5–§6), so a pixel's value is a function of a
//! bounded neighbourhood of the levels above it. Going down a level, a
//! window's dependencies are, per level i (absolute level-i pixels,
//! half-open):
//! - **level 0**: the window widened by `reconstruct::REACH` = 2
//!   (`reconstruct` blends 3×3 predictions, then repairs extrema among
//!   3×3 blends);
//! - **correction** (levels ≤ L): a subpass reads up to
//!   `REACH_PER_SUBPASS` = 2 pixels away, so what must be right after the
//!   level's `4 · passes` subpasses is computed over a region widened by
//!   `2 · 4 · passes` (16 with the default 2 passes; the start level of
//!   smooth exemplars takes more, `coarse::seams`). Pixels that near the
//!   region's edge read reflected neighbours where the real ones are
//!   missing, and are wrong — but only they, and nothing right depends on
//!   them. Where the region meets the world's edge, reflection *is* the
//!   world's rule, so those pixels are right;
//! - **upsampling and the height prior** read the level above at
//!   `⌊p / 2⌋` and its neighbour (`correct::parent_v`): the level above must
//!   be right over `[x0 / 2, ⌈x1 / 2⌉)` — to the level's edge when the
//!   region reaches the world's edge, so that the prior's clamping matches;
//! - region corners are rounded down to even coordinates so that a local
//!   parity class is the absolute one (`correct`'s subpasses) and a child
//!   buffer's parents start exactly at the parent view's corner.
//!
//! So per level the region is ≈ `window / 2^i` plus a margin that converges
//! to ~`2 · 16` pixels (16 from the level's own correction, half the margin
//! of the level below): a 1024² window computes a 1060² level 0 and ever
//! smaller levels above, whatever the world's size. The coarse start (level
//! L's hashed pieces, or the exemplar centre) is a pure function of
//! absolute position and is computed over the top region only.

use super::window::REACH_PER_SUBPASS;
use crate::level::state::{State, level_size};
use crate::stages::correct::SUBPASSES;
use crate::stages::reconstruct::REACH as RECONSTRUCT_REACH;

/// A half-open rectangle `[x0, x1) × [y0, y1)` of one level's pixels, in
/// absolute coordinates of that level.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Rect {
    pub x0: usize,
    pub y0: usize,
    pub x1: usize,
    pub y1: usize,
}

impl Rect {
    /// The `width × height` rectangle whose top-left pixel is (x, y).
    pub fn new(x: usize, y: usize, width: usize, height: usize) -> Rect {
        Rect {
            x0: x,
            y0: y,
            x1: x + width,
            y1: y + height,
        }
    }

    pub fn width(&self) -> usize {
        self.x1 - self.x0
    }

    pub fn height(&self) -> usize {
        self.y1 - self.y0
    }

    pub fn pixels(&self) -> usize {
        self.width() * self.height()
    }

    /// The smallest rectangle holding both.
    pub fn union(self, o: Rect) -> Rect {
        Rect {
            x0: self.x0.min(o.x0),
            y0: self.y0.min(o.y0),
            x1: self.x1.max(o.x1),
            y1: self.y1.max(o.y1),
        }
    }

    /// Whether `o` lies inside.
    pub fn contains(&self, o: &Rect) -> bool {
        self.x0 <= o.x0 && self.y0 <= o.y0 && o.x1 <= self.x1 && o.y1 <= self.y1
    }

    /// Grown by `by` on every side, clipped to a `w × h` level.
    pub fn widen(self, by: usize, (w, h): (usize, usize)) -> Rect {
        Rect {
            x0: self.x0.saturating_sub(by),
            y0: self.y0.saturating_sub(by),
            x1: (self.x1 + by).min(w),
            y1: (self.y1 + by).min(h),
        }
    }

    /// `self` in the coordinates of `outer`'s buffer (`outer` holds it).
    pub fn within(self, outer: Rect) -> Rect {
        debug_assert!(outer.contains(&self), "{self:?} outside {outer:?}");
        Rect {
            x0: self.x0 - outer.x0,
            y0: self.y0 - outer.y0,
            x1: self.x1 - outer.x0,
            y1: self.y1 - outer.y0,
        }
    }

    /// The corner moved down to even coordinates (see the module docs).
    pub(super) fn even(self) -> Rect {
        Rect {
            x0: self.x0 & !1,
            y0: self.y0 & !1,
            ..self
        }
    }
}

/// `data` (over `from`) cropped to `to` (inside `from`).
pub(crate) fn crop<T: Copy>(data: &[T], from: Rect, to: Rect) -> Vec<T> {
    let r = to.within(from);
    (r.y0..r.y1)
        .flat_map(|y| {
            data[y * from.width() + r.x0..y * from.width() + r.x1]
                .iter()
                .copied()
        })
        .collect()
}

/// The pixels of the level above a level-`i` region that its stages read
/// (module docs): `[x0 / 2, ⌈x1 / 2⌉)`, to the parent level's edge when the
/// region reaches the world's edge. `size` and `parent` are the two
/// levels' world sizes.
pub(super) fn parent_view(r: Rect, size: (usize, usize), parent: (usize, usize)) -> Rect {
    let end = |v: usize, n: usize, pn: usize| if v == n { pn } else { v.div_ceil(2) };
    Rect {
        x0: r.x0 / 2,
        y0: r.y0 / 2,
        x1: end(r.x1, size.0, parent.0),
        y1: end(r.y1, size.1, parent.1),
    }
}

/// What a synthesis computes at each level: the whole world, or a window's
/// cone. Built by [`Cone::plan`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Cone {
    world: (usize, usize),
    window: Rect,
    /// Index = level, 0..=top.
    regions: Vec<Rect>,
}

impl Cone {
    /// The cone of `window` (output pixels inside the `world`) for a
    /// synthesis whose coarsest level is `top` and whose levels ≤ `l` are
    /// corrected by `passes[level]` passes. `needs[i]`, when given, is one more
    /// rectangle of level i that must come out right (e.g. a paste's
    /// source): the cone covers it and what it depends on.
    pub fn plan(
        world: (usize, usize),
        window: Rect,
        (top, l, passes): (usize, usize, &[u32]),
        needs: &[Option<Rect>],
    ) -> Cone {
        let mut regions = Vec::with_capacity(top + 1);
        let mut from_below: Option<Rect> = None;
        for i in 0..=top {
            let size = level_size(world.0, world.1, i);
            let mut need = from_below.unwrap_or_else(|| window.widen(RECONSTRUCT_REACH, size));
            if let Some(r) = needs.get(i).copied().flatten() {
                need = need.union(r.widen(0, size));
            }
            let passes = passes.get(i).copied().unwrap_or(0) as usize;
            let r = if i <= l && passes > 0 {
                need.widen(REACH_PER_SUBPASS * SUBPASSES.len() * passes, size)
            } else {
                need
            }
            .even();
            regions.push(r);
            from_below = Some(parent_view(r, size, level_size(world.0, world.1, i + 1)));
        }
        Cone {
            world,
            window,
            regions,
        }
    }

    /// The world's size (output pixels).
    pub fn world(&self) -> (usize, usize) {
        self.world
    }

    /// The output window.
    pub fn window(&self) -> Rect {
        self.window
    }

    /// The coarsest level.
    pub fn top(&self) -> usize {
        self.regions.len() - 1
    }

    /// The pixels computed at `level`.
    pub fn region(&self, level: usize) -> Rect {
        self.regions[level]
    }

    /// The part of `level + 1`'s buffer that `level`'s stages read, in that
    /// buffer's coordinates, when it is not the whole buffer (the synthesis
    /// crops it out first so that a child buffer's parents start at its
    /// corner: `upsample_jitter` and `correct` index parents as `p / 2`).
    pub fn parent_crop(&self, level: usize) -> Option<Rect> {
        let (w, h) = self.world;
        let view = parent_view(
            self.regions[level],
            level_size(w, h, level),
            level_size(w, h, level + 1),
        );
        let above = self.regions[level + 1];
        (view != above).then(|| view.within(above))
    }

    /// Peak bytes of a synthesis over this cone: the largest level's state
    /// with the level above and its crop alive, then level 0's fixed-point
    /// heights and the output.
    pub fn bytes(&self) -> u64 {
        let state = (0..self.top())
            .map(|i| {
                let crop = self.parent_crop(i).map_or(0, |c| c.pixels());
                self.regions[i].pixels() + self.regions[i + 1].pixels() + crop
            })
            .chain([self.regions[self.top()].pixels()])
            .max()
            .unwrap_or(0);
        (state * State::BYTES_PER_PIXEL + self.regions[0].pixels() * 4 + self.window.pixels() * 4)
            as u64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_whole_world_is_its_own_cone() {
        let world = (777, 333);
        let c = Cone::plan(world, Rect::new(0, 0, 777, 333), (9, 5, &[2; 10]), &[]);
        for i in 0..=9 {
            let (w, h) = level_size(777, 333, i);
            assert_eq!(c.region(i), Rect::new(0, 0, w, h));
        }
        assert!((0..9).all(|i| c.parent_crop(i).is_none()));
    }

    #[test]
    fn a_window_widens_by_its_reach_and_halves_per_level() {
        let world = (65536, 65536);
        let c = Cone::plan(
            world,
            Rect::new(30001, 40000, 1024, 1024),
            (5, 5, &[2; 6]),
            &[],
        );
        // Level 0: the window ± 2 (reconstruct's reach), then ± 16, corner
        // made even.
        let r = c.region(0);
        assert_eq!((r.x0, r.x1), (30001 - 19, 30001 + 1024 + 18));
        assert_eq!((r.y0, r.y1), (40000 - 18, 40000 + 1024 + 18));
        for i in 0..5 {
            let (r, above) = (c.region(i), c.region(i + 1));
            assert_eq!(r.x0 % 2, 0);
            // Parents of every pixel, and their neighbours, are computed.
            assert!(above.x0 <= r.x0 / 2 && above.x1 >= r.x1.div_ceil(2));
            // The margin stays bounded.
            assert!(r.width() <= (1024 >> i) + 2 * 34, "level {i}: {r:?}");
        }
    }

    #[test]
    fn regions_at_the_world_edge_reach_the_level_edge() {
        let world = (300, 200);
        let c = Cone::plan(world, Rect::new(290, 0, 10, 7), (7, 5, &[2; 8]), &[]);
        for i in 0..=7 {
            let (w, _) = level_size(300, 200, i);
            assert_eq!(c.region(i).x1, w, "level {i}");
            assert_eq!(c.region(i).y0, 0);
        }
    }
}
