//! The paste edit of a session: a paste's stored S and V written into the
//! previous frame at its target, frozen there, with a margin left free.

use super::{PASTE_MARGIN, Session};
use crate::level::atlas::AtlasLevel;
use crate::level::fixed::Coord;
use crate::level::state::level_size;
use crate::stages::correct::W_FREE;
use crate::synth::control::{Lift, Paste, PasteSource, inside, lift};

impl Session<'_> {
    /// Writes a paste's stored S and V (+δ) into the previous frame at the
    /// target, for every level and pass, freezes it there and leaves a
    /// margin around it unweighted in this step.
    pub(super) fn paste(&mut self, p: &Paste, weights0: &mut [u8]) {
        let db = self.synth.database();
        let frames = self.frames.as_mut().expect("a frame exists before a paste");
        // The kept final states no longer match the results written here.
        frames.states.clear();
        let mut delta = (p.delta_m / db.quantization().scale_m).round() as i32;
        // Source mask at level 0, then dilated upwards (any child inside).
        let (mut sw, mut sh) = match p.source {
            PasteSource::Terrain => level_size(self.width, self.height, 0),
            PasteSource::Exemplar(e) => {
                let r = db.level(0).layout.rects[e];
                (r.width as usize, r.height as usize)
            }
        };
        let mut mask: Vec<bool> = (0..sw * sh)
            .map(|k| inside(&p.lasso, (k % sw) as f64 + 0.5, (k / sw) as f64 + 0.5))
            .collect();
        if let (Lift::Ground, Some(last)) = (p.lift, frames.levels[0].last()) {
            let (w0, h0) = level_size(self.width, self.height, 0);
            let r0 = &db.level(0).layout.rects;
            let source = |x: usize, y: usize| match p.source {
                PasteSource::Terrain => (last.coords[y * sw + x], last.offsets[y * sw + x]),
                PasteSource::Exemplar(e) => {
                    (Coord::from_texel(r0[e].x0 as i32 + x as i32, y as i32), 0)
                }
            };
            let target_of = |x: usize, y: usize| {
                let (tx, ty) = (x as i64 + p.offset.0, y as i64 + p.offset.1);
                (tx >= 0 && ty >= 0 && tx < w0 as i64 && ty < h0 as i64)
                    .then(|| ty as usize * w0 + tx as usize)
            };
            let margin = crate::database::layout::MARGIN as usize;
            let writes = |x: usize, y: usize| {
                x < sw
                    && y < sh
                    && mask[y * sw + x]
                    && target_of(x, y).is_some()
                    && match p.source {
                        PasteSource::Terrain => true,
                        PasteSource::Exemplar(_) => {
                            x >= margin && y >= margin && x + margin < sw && y + margin < sh
                        }
                    }
            };
            let rim = lift::rim((0, 0, sw, sh), writes);
            let target = |x: usize, y: usize| {
                let t = target_of(x, y).expect("a rim pixel is written");
                (last.coords[t], last.offsets[t])
            };
            delta += lift::ground_offset(&AtlasLevel::new(db, 0), &rim, source, target);
        }
        for (level, passes) in frames.levels.iter_mut().enumerate() {
            if level > 0 {
                let (cw, ch) = (sw, sh);
                (sw, sh) = match p.source {
                    PasteSource::Terrain => level_size(self.width, self.height, level),
                    PasteSource::Exemplar(e) => {
                        let r = db.level(level).layout.rects[e];
                        (r.width as usize, r.height as usize)
                    }
                };
                mask = (0..sw * sh)
                    .map(|k| {
                        let (x, y) = (k % sw, k / sw);
                        [(0, 0), (1, 0), (0, 1), (1, 1)].iter().any(|&(dx, dy)| {
                            let (cx, cy) = (2 * x + dx, 2 * y + dy);
                            cx < cw && cy < ch && mask[cy * cw + cx]
                        })
                    })
                    .collect();
            }
            let (tw, th) = level_size(self.width, self.height, level);
            let shift = |o: i64| o.div_euclid(1 << level);
            let (ox, oy) = (shift(p.offset.0), shift(p.offset.1));
            let atlas = AtlasLevel::new(db, level);
            let in_mask = |u: i64, v: i64| {
                u >= 0
                    && v >= 0
                    && u < sw as i64
                    && v < sh as i64
                    && mask[v as usize * sw + u as usize]
            };
            // Read every source value first: source and target may overlap.
            let mut writes = Vec::new();
            for k in (0..sw * sh).filter(|&k| mask[k]) {
                let (x, y) = ((k % sw) as i64, (k / sw) as i64);
                let (tx, ty) = (x + ox, y + oy);
                if tx < 0 || ty < 0 || tx >= tw as i64 || ty >= th as i64 {
                    continue;
                }
                let t = ty as usize * tw + tx as usize;
                let delta = p.delta_at(delta, level, x as usize, y as usize);
                let mut values: Vec<(Coord, i32)> = match p.source {
                    PasteSource::Terrain => passes
                        .iter()
                        .map(|r| (r.coords[k], r.offsets[k] + delta))
                        .collect(),
                    PasteSource::Exemplar(e) => {
                        let r = db.level(level).layout.rects[e];
                        let m = crate::database::layout::MARGIN as i64;
                        if x < m || y < m || x >= r.width as i64 - m || y >= r.height as i64 - m {
                            continue;
                        }
                        let c = Coord::from_texel(r.x0 as i32 + x as i32, y as i32);
                        vec![(c, delta); passes.len()]
                    }
                };
                let (x, y) = (x as usize, y as usize);
                if p.lift == Lift::Ground && lift::near_seam(level, x, y, in_mask) {
                    let ground = passes.last().map(|r| (r.coords[t], r.offsets[t]));
                    if let Some(g) = ground {
                        lift::seam(&atlas, &mut values, g, p.depth(level, x, y));
                    }
                }
                writes.push((t, values));
            }
            for (t, values) in writes {
                for (r, (c, v)) in passes.iter_mut().zip(values) {
                    r.coords[t] = c;
                    r.offsets[t] = v;
                }
                self.pasted[level][t] = true;
                self.fresh[level][t] = true;
            }
        }
        // Unweighted margin at level 0 (the frozen paste itself is set later).
        let (w0, h0) = level_size(self.width, self.height, 0);
        let m = PASTE_MARGIN as i64;
        let pasted = &self.pasted[0];
        let fresh = &self.fresh[0];
        for y in 0..h0 as i64 {
            for x in 0..w0 as i64 {
                let near = (-m..=m).any(|dy| {
                    (-m..=m).any(|dx| {
                        let (u, v) = (x + dx, y + dy);
                        u >= 0
                            && v >= 0
                            && u < w0 as i64
                            && v < h0 as i64
                            && fresh[(v * w0 as i64 + u) as usize]
                    })
                });
                if near && !pasted[(y * w0 as i64 + x) as usize] {
                    weights0[(y * w0 as i64 + x) as usize] = W_FREE;
                }
            }
        }
    }
}
