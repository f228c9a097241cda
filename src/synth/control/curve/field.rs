//! The curve's distance field: for every integer lattice node around the
//! curve, its closest segment (paper §5.1: "closest-point queries are
//! accelerated using a distance field that is recomputed only when the
//! horizontal shape of the curve changes").
//!
//! Nodes sit at integer output coordinates, i.e. on output pixel corners.
//! That is where constraints are evaluated on every level but the finest:
//! a level-i pixel centre maps to ((x + ½)·2^i, (y + ½)·2^i), an integer
//! for every i ≥ 1. Storing the closest *segment* (not the distance) keeps
//! the distance exact there: a query projects onto the stored segment(s),
//! so at a node it equals the brute-force closest-point distance. Between
//! nodes (level-0 pixel centres) it takes the best of the four surrounding
//! nodes' segments, which is the true closest point except where those
//! nodes straddle a medial axis of the curve, and never closer than it.
//!
//! [`FieldCache`] keys fields on the resampled shape, so changing a widget's
//! height, slope or reach reuses the field; only a reach that outgrows the
//! computed margin (or a new shape) recomputes it. Beside each field it
//! keeps the last few envelopes built on it, keyed on the reach tracks, so
//! changing a height or slope reuses the envelope too.

use super::envelope::Envelope;
use super::profile::Track;
use super::segments::Segments;
use glam::DVec2;
use rayon::prelude::*;
use std::collections::HashMap;
use std::hash::{Hash, Hasher};
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// No segment within the field's margin.
pub const NONE: u32 = u32::MAX;

/// Most lattice nodes one field may hold (256 MiB of segment indices).
pub const MAX_NODES: usize = 1 << 26;

/// The resampled curve and its closest-segment lattice.
#[derive(Debug)]
pub struct DistanceField {
    pub segments: Segments,
    /// Lattice origin: node (0, 0) is at output position (x0, y0).
    pub x0: i64,
    pub y0: i64,
    pub width: usize,
    pub height: usize,
    /// How far from the curve nodes were searched, output pixels.
    pub margin: f64,
    /// Closest segment per node, row-major; [`NONE`] beyond the margin.
    pub seg: Vec<u32>,
}

impl DistanceField {
    /// Heap bytes held, about: the nodes and the segments (not the
    /// segments' grid index).
    pub fn bytes(&self) -> usize {
        self.seg.len() * 4 + self.segments.len() * size_of::<[DVec2; 2]>()
    }

    /// Computes the field around `points` (resampled) out to `margin` pixels,
    /// tile rows in parallel, each node comparing its tile's candidates
    /// ([`Segments::tile_candidates`]; none for tiles beyond the margin).
    /// `None` when the lattice would exceed [`MAX_NODES`].
    pub fn compute(points: &[DVec2], margin: f64) -> Option<DistanceField> {
        let segments = Segments::polyline(points, false);
        let (mut lo, mut hi) = (points[0], points[0]);
        for p in points {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        let x0 = (lo.x - margin).floor() as i64 - 1;
        let y0 = (lo.y - margin).floor() as i64 - 1;
        let x1 = (hi.x + margin).ceil() as i64 + 1;
        let y1 = (hi.y + margin).ceil() as i64 + 1;
        let (width, height) = ((x1 - x0 + 1) as usize, (y1 - y0 + 1) as usize);
        if width.checked_mul(height)? > MAX_NODES {
            return None;
        }
        let mut seg = vec![NONE; width * height];
        let node = |i: usize, j: usize| DVec2::new((x0 + i as i64) as f64, (y0 + j as i64) as f64);
        seg.par_chunks_mut(TILE * width)
            .enumerate()
            .for_each(|(t, rows)| {
                let j0 = t * TILE;
                let mut near = Vec::new();
                for (i0, i1) in tiles(width) {
                    let tile = (i1 - i0, rows.len() / width);
                    if !segments.tile_candidates(node(i0, j0), tile, margin, &mut near) {
                        continue;
                    }
                    for (j, row) in rows.chunks_mut(width).enumerate() {
                        for (i, slot) in row.iter_mut().enumerate().take(i1).skip(i0) {
                            if let Some(h) = segments.closest_among(&near, node(i, j0 + j), margin)
                            {
                                *slot = h.seg;
                            }
                        }
                    }
                }
            });
        Some(DistanceField {
            segments,
            x0,
            y0,
            width,
            height,
            margin,
            seg,
        })
    }

    /// The stored closest segment of node `(i, j)` (lattice indices).
    #[inline]
    pub fn node(&self, i: i64, j: i64) -> u32 {
        if i < 0 || j < 0 || i >= self.width as i64 || j >= self.height as i64 {
            return NONE;
        }
        self.seg[j as usize * self.width + i as usize]
    }

    /// Closest point to output position `p`, from the segments stored at
    /// the (up to four) lattice nodes around it; `None` beyond the margin.
    pub fn closest(&self, p: DVec2) -> Option<super::segments::Hit> {
        let (fx, fy) = (p.x - self.x0 as f64, p.y - self.y0 as f64);
        let (i0, j0) = (fx.floor() as i64, fy.floor() as i64);
        let (i1, j1) = (fx.ceil() as i64, fy.ceil() as i64);
        let mut best: Option<super::segments::Hit> = None;
        for (i, j) in [(i0, j0), (i1, j0), (i0, j1), (i1, j1)] {
            let s = self.node(i, j);
            if s == NONE {
                continue;
            }
            let h = self.segments.project(s, p);
            if best.is_none_or(|b| h.dist < b.dist || (h.dist == b.dist && h.seg < b.seg)) {
                best = Some(h);
            }
        }
        best
    }
}

/// Envelopes kept per field: an editor alternates between a few reaches
/// (undo, redo) while heights change freely.
const ENVELOPES_PER_FIELD: usize = 4;

/// Side of the tiles of lattice nodes that share their candidate segments
/// ([`Segments::tile_candidates`]).
pub const TILE: usize = 8;

/// Column ranges `[i0, i1)` of the tiles of a `width`-node row.
pub fn tiles(width: usize) -> impl Iterator<Item = (usize, usize)> {
    (0..width)
        .step_by(TILE)
        .map(move |i0| (i0, (i0 + TILE).min(width)))
}

/// Distance fields by shape, shared by the curves of a scene and across the
/// frames of an editing session.
///
/// Bounded: an editor session re-sketches curves for hours, and every shape
/// it ever drew stayed (a 1024² curve's field and envelopes are ~1–4 MB).
/// Past `FieldCache::budget` bytes the least recently used shapes are
/// dropped (a scene's own curves are used every edit, so they stay); a
/// dropped shape is computed again if it comes back.
#[derive(Debug)]
pub struct FieldCache {
    fields: Mutex<HashMap<u64, Entry>>,
    computed: AtomicUsize,
    /// Use counter: an entry's `used` is the count at its last use.
    clock: AtomicU64,
    budget: usize,
}

/// The default [`FieldCache`] budget.
const FIELD_CACHE_BYTES: usize = 256 << 20;

impl Default for FieldCache {
    fn default() -> FieldCache {
        FieldCache::with_budget(FIELD_CACHE_BYTES)
    }
}

/// A field and the envelopes last built on it, most recent first, with
/// the left and right reach tracks each was built from.
#[derive(Debug)]
struct Entry {
    field: Arc<DistanceField>,
    envelopes: Vec<([Track; 2], Arc<Envelope>)>,
    used: u64,
}

impl Entry {
    /// Heap bytes held, about: the field's and the envelopes'.
    fn bytes(&self) -> usize {
        self.field.bytes() + self.envelopes.iter().map(|(_, e)| e.bytes()).sum::<usize>()
    }
}

impl FieldCache {
    pub fn new() -> FieldCache {
        FieldCache::default()
    }

    /// A cache that keeps at most `budget` bytes of fields and envelopes
    /// (but always the shape last used).
    pub fn with_budget(budget: usize) -> FieldCache {
        FieldCache {
            fields: Mutex::default(),
            computed: AtomicUsize::new(0),
            clock: AtomicU64::new(0),
            budget,
        }
    }

    /// Bytes held now.
    pub fn bytes(&self) -> usize {
        let fields = self.fields.lock().expect("not poisoned");
        fields.values().map(Entry::bytes).sum()
    }

    fn tick(&self) -> u64 {
        self.clock.fetch_add(1, Ordering::Relaxed) + 1
    }

    /// Drops the least recently used entries until the rest fit the
    /// budget, keeping at least one.
    fn evict(&self, fields: &mut HashMap<u64, Entry>) {
        let mut total: usize = fields.values().map(Entry::bytes).sum();
        while total > self.budget && fields.len() > 1 {
            let (&oldest, e) = (fields.iter())
                .min_by_key(|(_, e)| e.used)
                .expect("more than one entry");
            total -= e.bytes();
            fields.remove(&oldest);
        }
    }

    /// How many fields were computed (cache misses) so far.
    pub fn computed(&self) -> usize {
        self.computed.load(Ordering::Relaxed)
    }

    /// The field of `points` with at least `margin`, reused when the same
    /// shape was seen with a margin at least as large.
    pub fn get(&self, points: &[DVec2], margin: f64) -> Option<Arc<DistanceField>> {
        let key = shape_key(points);
        if let Some(e) = self.fields.lock().expect("not poisoned").get_mut(&key)
            && e.field.margin >= margin
            && same_shape(&e.field.segments, points)
        {
            e.used = self.tick();
            return Some(e.field.clone());
        }
        let f = Arc::new(DistanceField::compute(points, margin)?);
        self.computed.fetch_add(1, Ordering::Relaxed);
        let entry = Entry {
            field: f.clone(),
            envelopes: Vec::new(),
            used: self.tick(),
        };
        let mut fields = self.fields.lock().expect("not poisoned");
        fields.insert(key, entry);
        self.evict(&mut fields);
        Some(f)
    }

    /// The envelope on `field` (one [`FieldCache::get`] gave) for these
    /// reach tracks: a kept one, else `compute`'s, kept. The envelope is a
    /// function of the field and the reach tracks only (the curve's points
    /// are the field's segments), so a kept one is the very same.
    pub fn envelope(
        &self,
        field: &Arc<DistanceField>,
        reach: &[Track; 2],
        compute: impl FnOnce() -> Envelope,
    ) -> Arc<Envelope> {
        let key = shape_key_of(&field.segments);
        fn kept<'a>(
            fields: &'a mut HashMap<u64, Entry>,
            key: u64,
            field: &Arc<DistanceField>,
        ) -> Option<&'a mut Entry> {
            fields
                .get_mut(&key)
                .filter(|e| Arc::ptr_eq(&e.field, field))
        }
        if let Some(e) = kept(&mut self.fields.lock().expect("not poisoned"), key, field)
            && let Some(k) = e.envelopes.iter().position(|(r, _)| r == reach)
        {
            let hit = e.envelopes.remove(k);
            e.envelopes.insert(0, hit.clone());
            e.used = self.tick();
            return hit.1;
        }
        // Computed unlocked: other curves of the scene build meanwhile.
        let env = Arc::new(compute());
        let mut fields = self.fields.lock().expect("not poisoned");
        if let Some(e) = kept(&mut fields, key, field) {
            e.envelopes.insert(0, (reach.clone(), env.clone()));
            e.envelopes.truncate(ENVELOPES_PER_FIELD);
            e.used = self.tick();
            self.evict(&mut fields);
        }
        env
    }
}

fn shape_key(points: &[DVec2]) -> u64 {
    shape_key_iter(points.iter().copied())
}

/// The key of the points a field's segments join.
fn shape_key_of(s: &Segments) -> u64 {
    shape_key_iter(s.a.iter().chain(s.b.last()).copied())
}

fn shape_key_iter(points: impl Iterator<Item = DVec2>) -> u64 {
    // DefaultHasher::new() has fixed keys: stable within and across runs.
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for p in points {
        p.x.to_bits().hash(&mut h);
        p.y.to_bits().hash(&mut h);
    }
    h.finish()
}

fn same_shape(s: &Segments, points: &[DVec2]) -> bool {
    s.len() + 1 == points.len()
        && s.a.iter().zip(points).all(|(a, p)| a == p)
        && s.b.last() == points.last()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wiggle() -> Vec<DVec2> {
        let raw: Vec<DVec2> = (0..40)
            .map(|k| {
                let t = k as f64 / 39.0;
                DVec2::new(5.0 + 50.0 * t, 20.0 + 12.0 * (t * 9.0).sin())
            })
            .collect();
        super::super::smooth::resample(&raw).unwrap()
    }

    #[test]
    fn field_distances_equal_brute_force_at_every_node() {
        let pts = wiggle();
        let f = DistanceField::compute(&pts, 12.0).unwrap();
        let mut inside = 0;
        for j in 0..f.height as i64 {
            for i in 0..f.width as i64 {
                let p = DVec2::new((f.x0 + i) as f64, (f.y0 + j) as f64);
                let brute = (0..f.segments.len() as u32)
                    .map(|k| f.segments.project(k, p).dist)
                    .fold(f64::INFINITY, f64::min);
                match f.closest(p) {
                    Some(h) => {
                        assert_eq!(h.dist, brute, "node ({i}, {j})");
                        inside += 1;
                    }
                    None => assert!(brute > 12.0, "node ({i}, {j}) at {brute} was missed"),
                }
            }
        }
        assert!(inside > 1000, "{inside}");
        // Between nodes the four-node lookup stays within a pixel of exact.
        for k in 0..500 {
            let p = DVec2::new(
                3.0 + (k as f64 * 0.618).fract() * 55.0,
                10.0 + (k as f64 * 0.377).fract() * 20.0,
            );
            let brute = (0..f.segments.len() as u32)
                .map(|s| f.segments.project(s, p).dist)
                .fold(f64::INFINITY, f64::min);
            if brute < 10.0 {
                let d = f.closest(p).unwrap().dist;
                assert!(d >= brute && d - brute < 0.1, "{p}: {d} vs {brute}");
            }
        }
    }

    #[test]
    fn tile_candidates_change_no_node() {
        let pts = wiggle();
        for margin in [3.0, 12.0, 40.0] {
            let f = DistanceField::compute(&pts, margin).unwrap();
            let mut skipped = 0;
            for j in 0..f.height {
                for i in 0..f.width {
                    let p = DVec2::new((f.x0 + i as i64) as f64, (f.y0 + j as i64) as f64);
                    let want = f.segments.closest(p, margin).map_or(NONE, |h| h.seg);
                    assert_eq!(f.seg[j * f.width + i], want, "margin {margin}, ({i}, {j})");
                    skipped += (want == NONE) as usize;
                }
            }
            assert!(skipped > 0, "margin {margin}");
        }
    }

    #[test]
    fn cache_recomputes_only_for_new_shapes_or_wider_margins() {
        let c = FieldCache::new();
        let pts = wiggle();
        let a = c.get(&pts, 10.0).unwrap();
        let b = c.get(&pts, 8.0).unwrap();
        assert!(Arc::ptr_eq(&a, &b));
        assert_eq!(c.computed(), 1);
        c.get(&pts, 20.0).unwrap();
        assert_eq!(c.computed(), 2);
        let mut moved = pts.clone();
        moved[3].x += 0.5;
        c.get(&moved, 10.0).unwrap();
        assert_eq!(c.computed(), 3);
    }

    #[test]
    fn cache_drops_the_least_recently_used_shapes_past_its_budget() {
        let shape = |k: usize| {
            let mut p = wiggle();
            p[3].x += k as f64;
            p
        };
        let one = {
            let c = FieldCache::new();
            c.get(&shape(0), 10.0).unwrap();
            c.bytes()
        };
        // Room for two shapes of about this size, not three.
        let c = FieldCache::with_budget(2 * one + one / 2);
        c.get(&shape(0), 10.0).unwrap();
        c.get(&shape(1), 10.0).unwrap();
        c.get(&shape(0), 10.0).unwrap(); // shape 1 is now the oldest
        c.get(&shape(2), 10.0).unwrap();
        assert_eq!(c.computed(), 3);
        assert!(c.bytes() <= 2 * one + one / 2, "{} bytes", c.bytes());
        c.get(&shape(0), 10.0).unwrap();
        c.get(&shape(2), 10.0).unwrap();
        assert_eq!(c.computed(), 3, "shapes 0 and 2 kept");
        c.get(&shape(1), 10.0).unwrap();
        assert_eq!(c.computed(), 4, "shape 1 dropped");
        // A single shape larger than the budget is still kept.
        let tiny = FieldCache::with_budget(1);
        tiny.get(&shape(0), 10.0).unwrap();
        tiny.get(&shape(0), 10.0).unwrap();
        assert_eq!(tiny.computed(), 1);
    }
}
