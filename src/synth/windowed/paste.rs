//! Pastes in a window (the windowed mirror of `Session::paste`): where a
//! paste writes at each level, which pixels of the previous frame a window
//! needs because a paste copies them into it, and the writes themselves —
//! all over rectangles, never the world.
//!
//! A paste is **global**: its source may lie anywhere in the world (or in
//! an exemplar), and pastes apply in order, so a later paste may copy what
//! an earlier one wrote. Its support is bounded, though: the lasso's
//! bounding box at every level. A window therefore also synthesizes the
//! first frame over the sources of every terrain paste whose target reaches
//! its cone — transitively, walking the pastes backwards ([`needs`]) —
//! and, for a paste that lands on the ground ([`Lift::Ground`]), its whole
//! source and target at level 0, whose rim sets its lift.

use crate::database::Database;
use crate::database::layout::MARGIN;
use crate::level::atlas::AtlasLevel;
use crate::level::fixed::Coord;
use crate::level::state::level_size;
use crate::synth::cone::Rect;
use crate::synth::control::{Lift, Paste, PasteSource, lasso_bounds, lift};
use crate::synth::{Frames, PassResult};

/// One paste at one level.
struct Level {
    /// Bounding box of the source mask, source-level pixels.
    bbox: Rect,
    /// The source mask over `bbox`, row-major.
    mask: Vec<bool>,
    /// Target = source + `off` (the paste's offset at this level).
    off: (i64, i64),
    /// The world level's size: targets outside it are dropped.
    world: (usize, usize),
    /// An exemplar source: its atlas column and size at this level (its
    /// texels within the margin are not pasted).
    exemplar: Option<(u32, u32, u32)>,
}

/// One paste, levels `0..=last`.
pub(super) struct PasteGeometry {
    levels: Vec<Level>,
    terrain: bool,
    /// δ in database units.
    delta: i32,
    /// The paste (its feather: [`Paste::delta_at`]).
    paste: Paste,
}

impl PasteGeometry {
    /// The geometry of `p` in a `world` (output pixels), levels 0..=last.
    /// Its masks are computed over the lasso's bounding box only.
    pub(super) fn new(p: &Paste, db: &Database, world: (usize, usize), last: usize) -> Self {
        let src_size = |i: usize| match p.source {
            PasteSource::Terrain => level_size(world.0, world.1, i),
            PasteSource::Exemplar(e) => {
                let r = db.level(i).layout.rects[e];
                (r.width as usize, r.height as usize)
            }
        };
        // Pixel centres i + 0.5 the paste covers lie in these bounds.
        let (sw, sh) = src_size(0);
        let [x0, y0, x1, y1] = lasso_bounds(&p.lasso, p.reach(), sw, sh);
        let mut bbox = Rect { x0, y0, x1, y1 };
        let mut mask: Vec<bool> = (bbox.y0..bbox.y1)
            .flat_map(|y| (bbox.x0..bbox.x1).map(move |x| (x, y)))
            .map(|(x, y)| p.covers(x as f64 + 0.5, y as f64 + 0.5))
            .collect();
        let mut levels = Vec::with_capacity(last + 1);
        for i in 0..=last {
            let (sw, sh) = src_size(i);
            if i > 0 {
                // Dilated upwards: a pixel is in if any child is.
                let (child, cbox) = (mask, bbox);
                bbox = Rect {
                    x0: cbox.x0 / 2,
                    y0: cbox.y0 / 2,
                    x1: cbox.x1.div_ceil(2).min(sw),
                    y1: cbox.y1.div_ceil(2).min(sh),
                };
                let at = |x: usize, y: usize| {
                    (cbox.x0..cbox.x1).contains(&x)
                        && (cbox.y0..cbox.y1).contains(&y)
                        && child[(y - cbox.y0) * cbox.width() + x - cbox.x0]
                };
                mask = (bbox.y0..bbox.y1)
                    .flat_map(|y| (bbox.x0..bbox.x1).map(move |x| (x, y)))
                    .map(|(x, y)| {
                        [(0, 0), (1, 0), (0, 1), (1, 1)]
                            .iter()
                            .any(|&(dx, dy)| at(2 * x + dx, 2 * y + dy))
                    })
                    .collect();
            }
            let shift = |o: i64| o.div_euclid(1 << i);
            let exemplar = match p.source {
                PasteSource::Terrain => None,
                PasteSource::Exemplar(e) => {
                    let r = db.level(i).layout.rects[e];
                    Some((r.x0, r.width, r.height))
                }
            };
            levels.push(Level {
                bbox,
                mask: mask.clone(),
                off: (shift(p.offset.0), shift(p.offset.1)),
                world: level_size(world.0, world.1, i),
                exemplar,
            });
        }
        PasteGeometry {
            levels,
            terrain: p.source == PasteSource::Terrain,
            delta: (p.delta_m / db.quantization().scale_m).round() as i32,
            paste: p.clone(),
        }
    }

    /// The source pixel that level-`i` pixel (x, y) receives, if the paste
    /// writes there (the rule of `Session::paste`).
    fn source_of(&self, i: usize, x: usize, y: usize) -> Option<(usize, usize)> {
        let l = &self.levels[i];
        if x >= l.world.0 || y >= l.world.1 {
            return None;
        }
        let (sx, sy) = (x as i64 - l.off.0, y as i64 - l.off.1);
        let b = l.bbox;
        if sx < b.x0 as i64 || sy < b.y0 as i64 || sx >= b.x1 as i64 || sy >= b.y1 as i64 {
            return None;
        }
        let (sx, sy) = (sx as usize, sy as usize);
        if !l.mask[(sy - b.y0) * b.width() + sx - b.x0] {
            return None;
        }
        if let Some((_, w, h)) = l.exemplar {
            let m = MARGIN as usize;
            if sx < m || sy < m || sx >= w as usize - m || sy >= h as usize - m {
                return None;
            }
        }
        Some((sx, sy))
    }

    /// The lift of a [`Lift::Ground`] paste ([`lift::ground_offset`]),
    /// from a first frame's last pass at level 0 over `region`; `None` when
    /// the rim (its targets, a terrain source's pixels) is not all inside.
    /// That happens only where the paste writes nothing the window reads:
    /// [`needs`] puts the whole of every paste that reaches it there.
    fn ground_offset(
        &self,
        atlas: &AtlasLevel<'_>,
        last: &PassResult,
        region: Rect,
    ) -> Option<i32> {
        let at = |x: i64, y: i64| {
            let inside = (region.x0 as i64..region.x1 as i64).contains(&x)
                && (region.y0 as i64..region.y1 as i64).contains(&y);
            inside.then(|| {
                let k = (y as usize - region.y0) * region.width() + x as usize - region.x0;
                (last.coords[k], last.offsets[k])
            })
        };
        let l = &self.levels[0];
        let b = l.bbox;
        let writes = |x: usize, y: usize| {
            let (tx, ty) = (x as i64 + l.off.0, y as i64 + l.off.1);
            tx >= 0 && ty >= 0 && self.source_of(0, tx as usize, ty as usize).is_some()
        };
        let inner = |x: usize, y: usize| self.paste.depth(0, x, y) > 0.0;
        let footprint = lift::footprint((b.x0, b.y0, b.x1, b.y1), writes, inner);
        let whole = (footprint.inner.iter().chain(&footprint.rim)).all(|&(x, y)| {
            at(x as i64 + l.off.0, y as i64 + l.off.1).is_some()
                && (l.exemplar.is_some() || at(x as i64, y as i64).is_some())
        });
        if !whole {
            return None;
        }
        let source = |x: usize, y: usize| match l.exemplar {
            Some((x0, _, _)) => (Coord::from_texel(x0 as i32 + x as i32, y as i32), 0),
            None => at(x as i64, y as i64).expect("checked"),
        };
        let target =
            |x: usize, y: usize| at(x as i64 + l.off.0, y as i64 + l.off.1).expect("checked");
        Some(lift::ground_offset(atlas, &footprint, source, target))
    }

    /// Bounding box of the level-`i` pixels the paste writes, if any.
    fn targets(&self, i: usize) -> Option<Rect> {
        let l = &self.levels[i];
        let shift = |v: usize, o: i64, n: usize| (v as i64 + o).clamp(0, n as i64) as usize;
        let r = Rect {
            x0: shift(l.bbox.x0, l.off.0, l.world.0),
            y0: shift(l.bbox.y0, l.off.1, l.world.1),
            x1: shift(l.bbox.x1, l.off.0, l.world.0),
            y1: shift(l.bbox.y1, l.off.1, l.world.1),
        };
        (r.x0 < r.x1 && r.y0 < r.y1).then_some(r)
    }
}

/// Intersection of two rectangles, if not empty.
fn meet(a: Rect, b: Rect) -> Option<Rect> {
    let r = Rect {
        x0: a.x0.max(b.x0),
        y0: a.y0.max(b.y0),
        x1: a.x1.min(b.x1),
        y1: a.y1.min(b.y1),
    };
    (r.x0 < r.x1 && r.y0 < r.y1).then_some(r)
}

/// Per level, the pixels of the first frame that must be right so that,
/// after the pastes, `regions` are: the regions themselves and, walking the
/// pastes from the last, the sources of every terrain paste's targets in
/// what is needed so far (bounding boxes).
pub(super) fn needs(pastes: &[PasteGeometry], regions: &[Rect]) -> Vec<Option<Rect>> {
    let mut need: Vec<Rect> = regions.to_vec();
    for p in pastes.iter().rev() {
        let reaches = (need.iter().enumerate().take(p.levels.len()))
            .any(|(i, n)| p.targets(i).and_then(|t| meet(t, *n)).is_some());
        if p.paste.lift == Lift::Ground && reaches {
            // Its lift reads the whole rim: every target at level 0 (and,
            // below, a terrain source's pixels for them).
            if let Some(t) = p.targets(0) {
                need[0] = need[0].union(t);
            }
        }
        if !p.terrain {
            continue;
        }
        for (i, n) in need.iter_mut().enumerate().take(p.levels.len()) {
            if let Some(t) = p.targets(i).and_then(|t| meet(t, *n)) {
                let l = &p.levels[i];
                let back = |v: usize, o: i64| (v as i64 - o).max(0) as usize;
                let src = Rect {
                    x0: back(t.x0, l.off.0),
                    y0: back(t.y0, l.off.1),
                    x1: back(t.x1, l.off.0),
                    y1: back(t.y1, l.off.1),
                };
                *n = n.union(src);
            }
        }
    }
    need.into_iter().map(Some).collect()
}

/// Level-`i` pixels of `rect` that some paste writes (they stay frozen).
pub(super) fn pasted(pastes: &[PasteGeometry], i: usize, rect: Rect) -> Vec<bool> {
    let mut out = vec![false; rect.pixels()];
    for p in pastes {
        let Some(t) = p.targets(i).and_then(|t| meet(t, rect)) else {
            continue;
        };
        for y in t.y0..t.y1 {
            for x in t.x0..t.x1 {
                if p.source_of(i, x, y).is_some() {
                    out[(y - rect.y0) * rect.width() + x - rect.x0] = true;
                }
            }
        }
    }
    out
}

/// Writes the pastes, in order, into a first frame's per-pass results over
/// `regions` (index = level): each target takes its source's S and V + δ
/// (a terrain source read from the frame itself, every source read before
/// any write of that paste and level). Targets whose source lies outside
/// the region are left alone: they lie outside what [`needs`] asked for.
pub(super) fn write(
    pastes: &[PasteGeometry],
    db: &Database,
    frames: &mut Frames,
    regions: &[Rect],
) {
    // The kept final states no longer match the results written here.
    frames.states.clear();
    let atlas0 = AtlasLevel::new(db, 0);
    for p in pastes {
        let delta = match (p.paste.lift, frames.levels[0].last()) {
            (Lift::Ground, Some(last)) => {
                p.delta + p.ground_offset(&atlas0, last, regions[0]).unwrap_or(0)
            }
            _ => p.delta,
        };
        for (i, passes) in frames.levels.iter_mut().enumerate() {
            let r = regions[i];
            let Some(t) = p.targets(i).and_then(|t| meet(t, r)) else {
                continue;
            };
            let atlas = AtlasLevel::new(db, i);
            let index = |x: usize, y: usize| (y - r.y0) * r.width() + x - r.x0;
            let mut writes = Vec::new();
            for y in t.y0..t.y1 {
                for x in t.x0..t.x1 {
                    let Some((sx, sy)) = p.source_of(i, x, y) else {
                        continue;
                    };
                    let delta = p.paste.delta_at(delta, i, sx, sy);
                    let mut values: Vec<(Coord, i32)> = match p.levels[i].exemplar {
                        None => {
                            if !(r.x0..r.x1).contains(&sx) || !(r.y0..r.y1).contains(&sy) {
                                continue;
                            }
                            let k = index(sx, sy);
                            passes
                                .iter()
                                .map(|q| (q.coords[k], q.offsets[k] + delta))
                                .collect()
                        }
                        Some((x0, _, _)) => {
                            let c = Coord::from_texel(x0 as i32 + sx as i32, sy as i32);
                            vec![(c, delta); passes.len()]
                        }
                    };
                    // The seam is where the depth is negative (`lift::seam`
                    // leaves the rest): one distance to the lasso per pixel,
                    // where a square search for an unwritten pixel took
                    // (2·17 + 1)² reads with a 16-px seam.
                    if p.paste.lift == Lift::Ground {
                        let k = index(x, y);
                        let ground = passes.last().map(|q| (q.coords[k], q.offsets[k]));
                        if let Some(g) = ground {
                            lift::seam(&atlas, &mut values, g, p.paste.depth(i, sx, sy));
                        }
                    }
                    writes.push((index(x, y), values));
                }
            }
            for (k, values) in writes {
                for (q, (c, v)) in passes.iter_mut().zip(values) {
                    let q: &mut PassResult = q;
                    q.coords[k] = c;
                    q.offsets[k] = v;
                }
            }
        }
    }
}
