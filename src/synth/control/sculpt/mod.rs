//! Sculpt brushes (issue 43 item 6, issue 41 item 4): raise, lower,
//! smooth, flatten and erode as a **low-frequency height target** that the
//! synthesis follows, like the paper's point and curve constraints (eq.
//! 8–9), so a sculpted hill is re-synthesized with the exemplar's texture
//! on top instead of being a smooth bump pasted over it.
//!
//! A stroke is a polyline with a radius and a grid of target heights
//! ([`TargetGrid`], baked once from the terrain it was painted on by
//! `scene::bake` and stored in the scene), so a scene reproduces its
//! sculpt without the live terrain. The strokes of a scene form one
//! [`SculptLayer`]: at a position the last stroke that covers it sets the
//! target (later strokes paint over earlier ones, as type paint does). The
//! layer is a [`Constraint`]: its targets enter the same overlap blend and
//! the same integer nudge as points and curves (host-side f64 here,
//! quantized once by the blend; no kernel changes).
//!
//! **How tightly.** Every covered pixel reports the same pseudo-distance
//! [`DISTANCE_PX`] with the tolerance slope [`S_SCULPT`]: the terrain may
//! leave the target by t = s·max(0, d − 2^(i−1))·cell at level i: 0.9 cell
//! of height at level 0, 0.5 at level 2 and none from level 3 up (held
//! hard, like a curve's own pixels). So the coarse levels take the target's
//! shape while the finest levels, whose errors below t are almost left
//! alone by φ_d, keep the detail the exemplar gives. The blend weight
//! b = 1/(1 + d) is 1/5 of a point's at its site, so a point or curve
//! placed on sculpted ground still wins there. Erode strokes are held
//! hard instead ([`SculptStroke::hard`]): their target is the filter's
//! own detailed terrain, and its changes are smaller than that tolerance.
//!
//! **Where a stroke acts.** An editing session frees (re-synthesizes
//! unweighted) only the pixels whose target a stroke changed
//! (`synth::session`'s sculpt edit); the synthesis's neighbourhoods carry
//! the change a few pixels further. Measured (`tests/synth/sculpt.rs`, radius 32,
//! Pyrenees; `tests/serve/sculpt.rs`, radius 16, the embedded database):
//! no pixel farther than the radius + 8 px from the stroke changes, bar a
//! handful by 0.01 m.

pub mod brush;

use super::{Constraint, Hold, Sample};
use crate::synth::control::curve::segments::closest_param;
use glam::DVec2;
use std::sync::Arc;

pub use brush::{Brush, BrushStroke};

/// The distance every sculpted pixel reports to the blend, output pixels.
pub const DISTANCE_PX: f64 = 4.0;
/// The tolerance slope of sculpt targets (the point's ¼ cone at
/// [`DISTANCE_PX`]).
pub const S_SCULPT: f64 = 0.25;
/// Side of the buckets that index which strokes reach where, output pixels.
const BUCKET: f64 = 32.0;

/// Target heights on a regular grid of nodes: node (i, j) lies at output
/// position (x0 + i·step, y0 + j·step); between nodes heights are
/// bilinear, and beyond the grid the edge nodes extend.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetGrid {
    pub x0: f64,
    pub y0: f64,
    pub step: f64,
    pub width: usize,
    pub height: usize,
    /// Row-major, metres.
    pub heights_m: Vec<f64>,
}

impl TargetGrid {
    /// The bilinear height at output position (x, y).
    pub fn at(&self, x: f64, y: f64) -> f64 {
        let coord = |v: f64, o: f64, n: usize| {
            let u = ((v - o) / self.step).clamp(0.0, (n - 1) as f64);
            let i = (u.floor() as usize).min(n.saturating_sub(2));
            (i, u - i as f64)
        };
        let (i, fx) = coord(x, self.x0, self.width);
        let (j, fy) = coord(y, self.y0, self.height);
        let h = |a: usize, b: usize| {
            let (a, b) = (a.min(self.width - 1), b.min(self.height - 1));
            self.heights_m[b * self.width + a]
        };
        let top = h(i, j) * (1.0 - fx) + h(i + 1, j) * fx;
        let bottom = h(i, j + 1) * (1.0 - fx) + h(i + 1, j + 1) * fx;
        top * (1.0 - fy) + bottom * fy
    }
}

/// One baked stroke: where it acts and what it asks there.
#[derive(Debug, Clone, PartialEq)]
pub struct SculptStroke {
    pub points: Vec<DVec2>,
    pub radius_px: f64,
    pub targets: TargetGrid,
    /// Held to its targets at every level (t = 0), not within the soft
    /// tolerance of [`S_SCULPT`]: the erode brush's targets are the
    /// filter's own detailed terrain, whose changes (~10 m) sit well
    /// inside that tolerance (0.5–0.9 cell of height: 46–83 m on 92.6 m
    /// cells), so a soft hold left them to chance.
    pub hard: bool,
}

impl SculptStroke {
    /// Bounds `[x0, y0, x1, y1]` of its capsule.
    pub fn bounds(&self) -> [f64; 4] {
        capsule_bounds(&self.points, self.radius_px)
    }

    /// Whether (x, y) lies strictly within its radius of its polyline.
    pub fn covers(&self, x: f64, y: f64) -> bool {
        polyline_distance(&self.points, DVec2::new(x, y)) < self.radius_px
    }
}

/// Bounds of the pixels within `r` of a polyline.
pub fn capsule_bounds(points: &[DVec2], r: f64) -> [f64; 4] {
    let lo = points.iter().fold(DVec2::INFINITY, |a, p| a.min(*p)) - DVec2::splat(r);
    let hi = points.iter().fold(DVec2::NEG_INFINITY, |a, p| a.max(*p)) + DVec2::splat(r);
    [lo.x, lo.y, hi.x, hi.y]
}

/// Distance from `p` to a polyline (a point when it has one vertex).
pub fn polyline_distance(points: &[DVec2], p: DVec2) -> f64 {
    if points.len() == 1 {
        return p.distance(points[0]);
    }
    points
        .windows(2)
        .map(|w| p.distance(w[0] + (w[1] - w[0]) * closest_param(p, w[0], w[1])))
        .fold(f64::INFINITY, f64::min)
}

/// The baked strokes of a scene, in order, as one constraint.
#[derive(Debug, Clone)]
pub struct SculptLayer {
    strokes: Vec<Arc<SculptStroke>>,
    bounds: [f64; 4],
    /// Per bucket (a square cell of `bounds`), the strokes whose capsule box
    /// reaches it (ascending), so a sample looks at a few strokes.
    buckets: Vec<Vec<u32>>,
    columns: usize,
    /// A bucket's side, output pixels ([`BUCKET`] or more).
    side: f64,
}

impl PartialEq for SculptLayer {
    fn eq(&self, other: &SculptLayer) -> bool {
        self.strokes == other.strokes
    }
}

impl SculptLayer {
    /// The layer of `strokes` (at least one).
    pub fn new(strokes: Vec<Arc<SculptStroke>>) -> SculptLayer {
        assert!(!strokes.is_empty(), "a sculpt layer has strokes");
        let bounds = strokes
            .iter()
            .map(|s| s.bounds())
            .reduce(union)
            .expect("non-empty");
        // At most ~256 buckets a side, whatever the extent.
        let side = BUCKET.max((bounds[2] - bounds[0]).max(bounds[3] - bounds[1]) / 256.0);
        let cells = |a: f64, b: f64| ((b - a) / side).floor() as usize + 1;
        let (columns, rows) = (cells(bounds[0], bounds[2]), cells(bounds[1], bounds[3]));
        let mut buckets = vec![Vec::new(); columns * rows];
        for (k, s) in strokes.iter().enumerate() {
            let b = s.bounds();
            let (c0, c1) = (cells(bounds[0], b[0]) - 1, cells(bounds[0], b[2]) - 1);
            let (r0, r1) = (cells(bounds[1], b[1]) - 1, cells(bounds[1], b[3]) - 1);
            for r in r0..=r1 {
                for c in c0..=c1 {
                    buckets[r * columns + c].push(k as u32);
                }
            }
        }
        SculptLayer {
            strokes,
            bounds,
            buckets,
            columns,
            side,
        }
    }

    pub fn strokes(&self) -> &[Arc<SculptStroke>] {
        &self.strokes
    }

    /// The target height at (x, y): the last stroke's that covers it.
    pub fn target(&self, x: f64, y: f64) -> Option<f64> {
        self.covering(x, y).map(|s| s.targets.at(x, y))
    }

    /// The last stroke that covers (x, y).
    fn covering(&self, x: f64, y: f64) -> Option<&SculptStroke> {
        let [bx0, by0, bx1, by1] = self.bounds;
        if !(x >= bx0 && y >= by0 && x <= bx1 && y <= by1) {
            return None;
        }
        let c = ((x - bx0) / self.side).floor() as usize;
        let r = ((y - by0) / self.side).floor() as usize;
        self.buckets[r * self.columns + c]
            .iter()
            .rev()
            .map(|&k| &*self.strokes[k as usize])
            .find(|s| s.covers(x, y))
    }

    /// Bounds within which layers `old` and `new` can differ (None: they
    /// are the same): the strokes after their common first ones.
    pub fn changed(old: Option<&SculptLayer>, new: Option<&SculptLayer>) -> Option<[f64; 4]> {
        let none: &[Arc<SculptStroke>] = &[];
        let a = old.map_or(none, |l| &l.strokes);
        let b = new.map_or(none, |l| &l.strokes);
        let same = a.iter().zip(b).take_while(|(x, y)| x == y).count();
        a[same..]
            .iter()
            .chain(&b[same..])
            .map(|s| s.bounds())
            .reduce(union)
    }
}

impl Constraint for SculptLayer {
    fn bounds(&self) -> [f64; 4] {
        self.bounds
    }

    fn sample(&self, x: f64, y: f64) -> Option<Sample> {
        self.covering(x, y).map(|s| Sample {
            target_m: s.targets.at(x, y),
            distance: if s.hard { 0.0 } else { DISTANCE_PX },
            reach: DISTANCE_PX,
        })
    }

    /// [`DISTANCE_PX`] plus the distance to the nearest stroke's capsule
    /// box: a covered position q is inside some box, so |p − q| is at
    /// least that distance.
    fn distance_bound(&self, x: f64, y: f64) -> f64 {
        let gap = self
            .strokes
            .iter()
            .map(|s| {
                let [x0, y0, x1, y1] = s.bounds();
                (x0 - x)
                    .max(x - x1)
                    .max(0.0)
                    .hypot((y0 - y).max(y - y1).max(0.0))
            })
            .fold(f64::INFINITY, f64::min);
        DISTANCE_PX + gap
    }

    fn hold(&self) -> Hold {
        Hold {
            tolerance_slope: S_SCULPT,
            level_cap: None,
            max_reach: DISTANCE_PX,
            keeps_detail: false,
        }
    }
}

/// A layer seen only within a rectangle: an editing session swaps an old
/// layer for a new one by subtracting and adding both only where they can
/// differ ([`SculptLayer::changed`]), which leaves the blend's integer
/// sums exactly as a swap of the whole layers would, at the cost of the
/// stroke, not of every stroke painted so far.
#[derive(Debug)]
pub struct Within<'a> {
    pub layer: &'a SculptLayer,
    pub rect: [f64; 4],
}

impl Constraint for Within<'_> {
    fn bounds(&self) -> [f64; 4] {
        let (a, b) = (self.layer.bounds, self.rect);
        [
            a[0].max(b[0]),
            a[1].max(b[1]),
            a[2].min(b[2]),
            a[3].min(b[3]),
        ]
    }

    fn sample(&self, x: f64, y: f64) -> Option<Sample> {
        let [x0, y0, x1, y1] = self.rect;
        (x >= x0 && y >= y0 && x <= x1 && y <= y1)
            .then(|| self.layer.sample(x, y))
            .flatten()
    }

    fn distance_bound(&self, x: f64, y: f64) -> f64 {
        self.layer.distance_bound(x, y)
    }

    fn hold(&self) -> Hold {
        self.layer.hold()
    }
}

/// The smallest box `[x0, y0, x1, y1]` holding boxes `a` and `b`.
fn union(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0].min(b[0]),
        a[1].min(b[1]),
        a[2].max(b[2]),
        a[3].max(b[3]),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stroke(x: f64, r: f64, h: f64) -> Arc<SculptStroke> {
        Arc::new(SculptStroke {
            points: vec![DVec2::new(x, 50.0)],
            radius_px: r,
            hard: false,
            targets: TargetGrid {
                x0: 0.0,
                y0: 0.0,
                step: 10.0,
                width: 2,
                height: 2,
                heights_m: vec![h, h + 10.0, h, h + 10.0],
            },
        })
    }

    #[test]
    fn later_strokes_paint_over_earlier_ones() {
        let l = SculptLayer::new(vec![stroke(50.0, 20.0, 100.0), stroke(60.0, 5.0, 500.0)]);
        assert_eq!(l.target(40.0, 50.0), Some(110.0), "edge node extends");
        assert_eq!(l.target(60.0, 50.0), Some(510.0));
        assert_eq!(l.target(90.0, 50.0), None);
        let grid = &l.strokes[0].targets;
        assert_eq!(grid.at(5.0, 3.0), 105.0, "bilinear between nodes");
        let one = SculptLayer::new(vec![stroke(50.0, 20.0, 100.0)]);
        assert_eq!(SculptLayer::changed(Some(&one), Some(&one)), None);
        assert_eq!(
            SculptLayer::changed(Some(&one), Some(&l)),
            Some([55.0, 45.0, 65.0, 55.0])
        );
        assert!(l.distance_bound(200.0, 50.0) >= DISTANCE_PX + 100.0);
    }
}
