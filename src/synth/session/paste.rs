//! The paste edit of a session: a paste's stored S and V written into the
//! previous frame at its target, frozen there, with a margin left free.
//!
//! Every loop runs over the lasso's bounds (at each level) or the written
//! pixels' bounds, not over the whole level: a paste touches a small part
//! of the map, and the whole-map scans (the lasso test of every pixel, the
//! margin's 17 × 17 search around every pixel) took ~300 ms of a 1024²
//! paste on 2 cores. Outside those bounds the scans found nothing, so the
//! result is the same.

use super::{PASTE_MARGIN, Session};
use crate::level::atlas::AtlasLevel;
use crate::level::fixed::Coord;
use crate::level::state::level_size;
use crate::stages::correct::W_FREE;
use crate::synth::control::{Lift, Paste, PasteSource, lasso_bounds, lift};
use crate::synth::union;

impl Session<'_> {
    /// Writes a paste's stored S and V (+δ) into the previous frame at the
    /// target, for every level and pass, freezes it there and leaves a
    /// margin around it unweighted in this step.
    pub(super) fn paste(&mut self, p: &Paste, weights0: &mut [u8]) {
        let db = self.synth.database();
        let frames = self.frames.as_mut().expect("a frame exists before a paste");
        let mut delta = (p.delta_m / db.quantization().scale_m).round() as i32;
        // Source mask at level 0, then dilated upwards (any child inside).
        let (mut sw, mut sh) = match p.source {
            PasteSource::Terrain => level_size(self.width, self.height, 0),
            PasteSource::Exemplar(e) => {
                let r = db.level(0).layout.rects[e];
                (r.width as usize, r.height as usize)
            }
        };
        // The source pixels the lasso can hold (see [`lasso_bounds`]).
        let mut b = lasso_bounds(&p.lasso, p.reach(), sw, sh);
        let mut mask = vec![false; sw * sh];
        for y in b[1]..b[3] {
            for x in b[0]..b[2] {
                mask[y * sw + x] = p.covers(x as f64 + 0.5, y as f64 + 0.5);
            }
        }
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
            let inner = |x: usize, y: usize| p.depth(0, x, y) > 0.0;
            let footprint = lift::footprint((b[0], b[1], b[2], b[3]), writes, inner);
            let target = |x: usize, y: usize| {
                let t = target_of(x, y).expect("a footprint pixel is written");
                (last.coords[t], last.offsets[t])
            };
            delta += lift::ground_offset(&AtlasLevel::new(db, 0), &footprint, source, target);
        }
        // Bounds of the level-0 pixels written (the margin's seeds).
        let mut written = None;
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
                // A pixel outside these bounds has no child in the child's.
                b = [b[0] / 2, b[1] / 2, b[2].div_ceil(2), b[3].div_ceil(2)];
                b = [b[0].min(sw), b[1].min(sh), b[2].min(sw), b[3].min(sh)];
                let child = std::mem::replace(&mut mask, vec![false; sw * sh]);
                for y in b[1]..b[3] {
                    for x in b[0]..b[2] {
                        mask[y * sw + x] =
                            [(0, 0), (1, 0), (0, 1), (1, 1)].iter().any(|&(dx, dy)| {
                                let (cx, cy) = (2 * x + dx, 2 * y + dy);
                                cx < cw && cy < ch && child[cy * cw + cx]
                            });
                    }
                }
            }
            let (tw, th) = level_size(self.width, self.height, level);
            let shift = |o: i64| o.div_euclid(1 << level);
            let (ox, oy) = (shift(p.offset.0), shift(p.offset.1));
            let atlas = AtlasLevel::new(db, level);
            // The pixels of the bounds no seam reaches (ground pastes):
            // every pixel within `lift::seam_reach` is written.
            let bw = b[2] - b[0];
            let clear = match p.lift {
                Lift::Ground => interior(&mask, sw, b, lift::seam_reach(level)),
                Lift::Source => Vec::new(),
            };
            // Read every source value first: source and target may overlap.
            let mut writes = Vec::new();
            let inner = (b[1]..b[3]).flat_map(|y| (b[0]..b[2]).map(move |x| y * sw + x));
            for k in inner.filter(|&k| mask[k]) {
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
                if p.lift == Lift::Ground && !clear[(y - b[1]) * bw + x - b[0]] {
                    let ground = passes.last().map(|r| (r.coords[t], r.offsets[t]));
                    if let Some(g) = ground {
                        lift::seam(&atlas, &mut values, g, p.depth(level, x, y));
                    }
                }
                writes.push((t, values));
            }
            let mut bounds = None;
            for (t, values) in writes {
                for (r, (c, v)) in passes.iter_mut().zip(values) {
                    r.coords[t] = c;
                    r.offsets[t] = v;
                }
                self.pasted[level][t] = true;
                self.fresh[level][t] = true;
                let (x, y) = (t % tw, t / tw);
                bounds = union(bounds, Some([x, y, x + 1, y + 1]));
            }
            // The level's kept final state repeats its last pass's results:
            // it takes the written pixels too (instead of being dropped and
            // rebuilt whole by the next frame, 12 MB at 1024² level 0).
            let state = frames.states.get(level).and_then(Option::as_ref);
            if let (Some(st), Some(b), Some(r)) = (state, bounds, passes.last()) {
                st.write_rect(b, &r.coords, &r.offsets);
            }
            if level == 0 {
                written = bounds;
            }
        }
        // Unweighted margin at level 0 (the frozen paste itself is set later).
        if let Some(written) = written {
            let (w0, h0) = level_size(self.width, self.height, 0);
            let near = near_fresh(&self.fresh[0], (w0, h0), written, PASTE_MARGIN as usize);
            for k in near.into_iter().filter(|&k| !self.pasted[0][k]) {
                weights0[k] = W_FREE;
            }
        }
    }
}

/// Per pixel of `b` (row-major, `b`'s width): whether every pixel within
/// `r` (Chebyshev) is set in `mask` (`sw` wide, set only inside `b`; a
/// pixel beyond the grid is not set), for all pixels at once: a square
/// search per pixel took ~5 ms of a 1024² paste with a 3-px seam.
/// Separable, like [`near_fresh`].
fn interior(mask: &[bool], sw: usize, b: [usize; 4], r: usize) -> Vec<bool> {
    let (bw, bh) = (b[2] - b[0], b[3] - b[1]);
    let mut rows = vec![false; bw * bh];
    for y in 0..bh {
        let row = &mask[(b[1] + y) * sw + b[0]..][..bw];
        for x in r..bw.saturating_sub(r) {
            rows[y * bw + x] = row[x - r..=x + r].iter().all(|&m| m);
        }
    }
    let mut out = vec![false; bw * bh];
    for y in r..bh.saturating_sub(r) {
        for x in 0..bw {
            out[y * bw + x] = (y - r..=y + r).all(|v| rows[v * bw + x]);
        }
    }
    out
}

/// The pixels (indices) of a `w × h` grid within `m` pixels (Chebyshev
/// distance) of a set pixel of `fresh`, whose set pixels lie in `bounds`
/// (none beyond `bounds` widened by `m` is near one). The square is
/// separable: a pass along the rows, then one down the columns of its
/// result.
fn near_fresh(fresh: &[bool], (w, h): (usize, usize), bounds: [usize; 4], m: usize) -> Vec<usize> {
    let [x0, y0] = [bounds[0].saturating_sub(m), bounds[1].saturating_sub(m)];
    let [x1, y1] = [(bounds[2] + m).min(w), (bounds[3] + m).min(h)];
    let bw = x1 - x0;
    // Per pixel of the widened bounds: a set pixel within m along its row.
    let mut rows = vec![false; bw * (y1 - y0)];
    for y in bounds[1]..bounds[3] {
        let row = &fresh[y * w + x0..y * w + x1];
        let out = &mut rows[(y - y0) * bw..(y - y0 + 1) * bw];
        for (x, o) in out.iter_mut().enumerate() {
            *o = row[x.saturating_sub(m)..(x + m + 1).min(bw)].contains(&true);
        }
    }
    let mut near = Vec::new();
    for y in y0..y1 {
        let (a, b) = (y.saturating_sub(m).max(y0), (y + m + 1).min(y1));
        for x in 0..bw {
            if (a..b).any(|v| rows[(v - y0) * bw + x]) {
                near.push(y * w + x0 + x);
            }
        }
    }
    near
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::control::inside;

    #[test]
    fn near_fresh_is_the_square_search_around_every_pixel() {
        let (w, h, m) = (23, 17, 3);
        let set = [(4, 5), (5, 5), (12, 9), (0, 16), (22, 0)];
        let mut fresh = vec![false; w * h];
        let mut bounds = None;
        for &(x, y) in &set {
            fresh[y * w + x] = true;
            bounds = union(bounds, Some([x, y, x + 1, y + 1]));
        }
        let got = near_fresh(&fresh, (w, h), bounds.unwrap(), m);
        let want: Vec<usize> = (0..w * h)
            .filter(|&k| {
                let (x, y) = ((k % w) as i64, (k / w) as i64);
                set.iter().any(|&(u, v)| {
                    (u as i64 - x).abs() <= m as i64 && (v as i64 - y).abs() <= m as i64
                })
            })
            .collect();
        assert_eq!(got, want);
    }

    #[test]
    fn interior_is_the_square_search_for_an_unset_pixel() {
        let lasso = [(3.2, 4.0), (20.7, 5.5), (11.0, 15.9), (6.5, 9.0)];
        let (sw, sh) = (24, 18);
        let b = lasso_bounds(&lasso, 0.0, sw, sh);
        let mask: Vec<bool> = (0..sw * sh)
            .map(|k| inside(&lasso, (k % sw) as f64 + 0.5, (k / sw) as f64 + 0.5))
            .collect();
        let in_mask = |u: i64, v: i64| {
            u >= 0 && v >= 0 && u < sw as i64 && v < sh as i64 && mask[v as usize * sw + u as usize]
        };
        for level in 0..3 {
            let inner = interior(&mask, sw, b, lift::seam_reach(level));
            for y in b[1]..b[3] {
                for x in b[0]..b[2] {
                    let got = !inner[(y - b[1]) * (b[2] - b[0]) + x - b[0]];
                    let r = lift::seam_reach(level) as i64;
                    let (x, y) = (x as i64, y as i64);
                    let want = (-r..=r).any(|dy| (-r..=r).any(|dx| !in_mask(x + dx, y + dy)));
                    assert_eq!(got, want, "({x}, {y})");
                }
            }
        }
    }
}
