//! Exact closest-segment queries on a polyline through a uniform bucket grid.
//!
//! Shared by the curve's distance field, the junction search and the
//! envelope's signed distance: segments are ~1 pixel long after resampling,
//! so a bucket of [`BUCKET`] pixels holds a handful, and a query visits
//! square rings of buckets outward only until no unvisited bucket can hold
//! anything closer. Ties break toward the lowest segment index, so results
//! never depend on visiting order.

use glam::DVec2;

/// Bucket side, output pixels.
pub const BUCKET: f64 = 8.0;

/// Slack taken off a candidate's distance bound
/// ([`Segments::tile_candidates`]) for the rounding of the two distances
/// it is made of (each exact to ~1e-13 pixels here).
const BOUND_SLACK: f64 = 1e-6;

/// The closest point of a segment list to a query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Segment index (segment k joins points k and k+1, or k and 0 for the
    /// closing segment of a loop).
    pub seg: u32,
    /// Parameter along the segment, 0..=1.
    pub u: f64,
    pub dist: f64,
}

/// The parameter (0..=1) of the point of segment `a`–`b` closest to `p`;
/// 0 when the segment is a single point.
#[inline]
pub fn closest_param(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let d = b - a;
    let len2 = d.length_squared();
    if len2 > 0.0 {
        ((p - a).dot(d) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// Segments bucketed on a grid.
#[derive(Debug, Clone)]
pub struct Segments {
    pub a: Vec<DVec2>,
    pub b: Vec<DVec2>,
    origin: DVec2,
    nx: usize,
    ny: usize,
    /// CSR: bucket k holds `items[start[k]..start[k + 1]]`.
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Segments {
    /// The segments of a polyline (`closed`: add the last→first segment).
    pub fn polyline(pts: &[DVec2], closed: bool) -> Segments {
        let mut a: Vec<DVec2> = pts.windows(2).map(|w| w[0]).collect();
        let mut b: Vec<DVec2> = pts.windows(2).map(|w| w[1]).collect();
        if closed && pts.len() > 2 {
            a.push(*pts.last().expect("non-empty"));
            b.push(pts[0]);
        }
        Segments::new(a, b)
    }

    /// Concatenated segments of several polylines.
    pub fn new(a: Vec<DVec2>, b: Vec<DVec2>) -> Segments {
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for p in a.iter().chain(&b) {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        if a.is_empty() {
            lo = DVec2::ZERO;
            hi = DVec2::ZERO;
        }
        let nx = ((hi.x - lo.x) / BUCKET).floor() as usize + 1;
        let ny = ((hi.y - lo.y) / BUCKET).floor() as usize + 1;
        let mut count = vec![0u32; nx * ny + 1];
        let cells = |k: usize| {
            let (p, q) = (a[k].min(b[k]), a[k].max(b[k]));
            let c0 = ((p - lo) / BUCKET).floor();
            let c1 = ((q - lo) / BUCKET).floor();
            (c0.x as usize, c0.y as usize, c1.x as usize, c1.y as usize)
        };
        for k in 0..a.len() {
            let (x0, y0, x1, y1) = cells(k);
            for y in y0..=y1.min(ny - 1) {
                for x in x0..=x1.min(nx - 1) {
                    count[y * nx + x + 1] += 1;
                }
            }
        }
        for k in 1..count.len() {
            count[k] += count[k - 1];
        }
        let start = count.clone();
        let mut fill = count;
        let mut items = vec![0u32; *start.last().expect("non-empty") as usize];
        for k in 0..a.len() {
            let (x0, y0, x1, y1) = cells(k);
            for y in y0..=y1.min(ny - 1) {
                for x in x0..=x1.min(nx - 1) {
                    let slot = &mut fill[y * nx + x];
                    items[*slot as usize] = k as u32;
                    *slot += 1;
                }
            }
        }
        Segments {
            a,
            b,
            origin: lo,
            nx,
            ny,
            start,
            items,
        }
    }

    pub fn len(&self) -> usize {
        self.a.len()
    }

    pub fn is_empty(&self) -> bool {
        self.a.is_empty()
    }

    /// The exact closest point of segment `k` to `p`.
    #[inline]
    pub fn project(&self, k: u32, p: DVec2) -> Hit {
        let (a, b) = (self.a[k as usize], self.b[k as usize]);
        let u = closest_param(p, a, b);
        Hit {
            seg: k,
            u,
            dist: p.distance(a + (b - a) * u),
        }
    }

    /// The closest segment within `max_dist` of `p`, if any.
    pub fn closest(&self, p: DVec2, max_dist: f64) -> Option<Hit> {
        if self.is_empty() {
            return None;
        }
        let c = (p - self.origin) / BUCKET;
        let (cx, cy) = (c.x.floor() as i64, c.y.floor() as i64);
        let mut best: Option<Hit> = None;
        let (nx, ny) = (self.nx as i64, self.ny as i64);
        // Rings beyond this cannot reach the grid at all.
        let far = (cx.abs().max(cy.abs()) + nx + ny) as f64;
        let mut r: i64 = 0;
        loop {
            // Every bucket of ring r lies at least (r − 1)·BUCKET from p.
            let ring_min = (r as f64 - 1.0).max(0.0) * BUCKET;
            if ring_min > max_dist || r as f64 > far {
                break;
            }
            if let Some(h) = best
                && h.dist <= ring_min
            {
                break;
            }
            for y in cy - r..=cy + r {
                if y < 0 || y >= ny {
                    continue;
                }
                let step = if y == cy - r || y == cy + r {
                    1
                } else {
                    (2 * r).max(1)
                };
                let mut x = cx - r;
                while x <= cx + r {
                    if x >= 0 && x < nx {
                        let k = (y * nx + x) as usize;
                        for &s in &self.items[self.start[k] as usize..self.start[k + 1] as usize] {
                            let h = self.project(s, p);
                            let better = match best {
                                None => true,
                                Some(b) => h.dist < b.dist || (h.dist == b.dist && h.seg < b.seg),
                            };
                            if better {
                                best = Some(h);
                            }
                        }
                    }
                    x += step;
                }
            }
            r += 1;
        }
        best.filter(|h| h.dist <= max_dist)
    }

    /// The segments that can be the closest, within `dist`, to any node of
    /// the `w × h` tile of lattice nodes whose first node is at `corner`,
    /// into `out`, each with a lower bound of its distance to every node of
    /// the tile (its distance to the tile's centre less the tile's
    /// half-diagonal), by ascending bound then index; false (and `out`
    /// empty) when every node of the tile lies farther than `dist` from
    /// every segment.
    ///
    /// Why: a node's own [`Segments::closest`] visits every bucket out to
    /// its distance, so nodes far from the curve were the costliest (89 %
    /// of building a 1024² curve's field). A node p within h (the tile's
    /// half-diagonal) of the centre c has its closest segment at most
    /// d(c) + h away, hence within d(c) + 2h of c: one query and one gather
    /// per tile, and each node compares only those — the same segment as
    /// its own query, ties included.
    pub fn tile_candidates(
        &self,
        corner: DVec2,
        (w, h): (usize, usize),
        dist: f64,
        out: &mut Vec<(f64, u32)>,
    ) -> bool {
        out.clear();
        let (a, b) = ((w - 1) as f64, (h - 1) as f64);
        let half = a.hypot(b) / 2.0;
        let centre = corner + DVec2::new(a, b) / 2.0;
        // A pixel of slack for rounding, in both bounds.
        let Some(near) = self.closest(centre, dist + half + 1.0) else {
            return false;
        };
        let r = near.dist + 2.0 * half + 1.0;
        // The buckets' segments, filtered before they are sorted: a segment
        // spans several buckets, and most of a box lies beyond r.
        self.for_box(centre - DVec2::splat(r), centre + DVec2::splat(r), |s| {
            let d = self.project(s, centre).dist;
            if d <= r {
                out.push((d - half - BOUND_SLACK, s));
            }
        });
        out.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        out.dedup_by_key(|c| c.1);
        true
    }

    /// The closest of `candidates` (from [`Segments::tile_candidates`]) to
    /// `p` within `max_dist`: ties toward the lowest index, as
    /// [`Segments::closest`].
    ///
    /// Why in order of the bound: a node near the curve has its closest
    /// segment among the first few, and the bound ends the scan there.
    #[inline]
    pub fn closest_among(&self, candidates: &[(f64, u32)], p: DVec2, max_dist: f64) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        for &(bound, s) in candidates {
            if bound > best.map_or(max_dist, |b| b.dist) {
                break;
            }
            let h = self.project(s, p);
            if best.is_none_or(|b| h.dist < b.dist || (h.dist == b.dist && s < b.seg)) {
                best = Some(h);
            }
        }
        best.filter(|h| h.dist <= max_dist)
    }

    /// Indices of segments whose bucket overlaps the box `[lo, hi]`.
    pub fn near_box(&self, lo: DVec2, hi: DVec2, out: &mut Vec<u32>) {
        out.clear();
        self.for_box(lo, hi, |s| out.push(s));
        out.sort_unstable();
        out.dedup();
    }

    /// Calls `f` on the segments of every bucket that overlaps the box
    /// `[lo, hi]` (a segment once per bucket it spans).
    fn for_box(&self, lo: DVec2, hi: DVec2, mut f: impl FnMut(u32)) {
        let c0 = ((lo - self.origin) / BUCKET).floor();
        let c1 = ((hi - self.origin) / BUCKET).floor();
        let x0 = (c0.x.max(0.0) as usize).min(self.nx);
        let y0 = (c0.y.max(0.0) as usize).min(self.ny);
        if c1.x < 0.0 || c1.y < 0.0 {
            return;
        }
        let x1 = (c1.x as usize).min(self.nx - 1);
        let y1 = (c1.y as usize).min(self.ny - 1);
        for y in y0..=y1 {
            for x in x0..=x1 {
                let k = y * self.nx + x;
                for &s in &self.items[self.start[k] as usize..self.start[k + 1] as usize] {
                    f(s);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn brute(s: &Segments, p: DVec2) -> Hit {
        (0..s.len() as u32)
            .map(|k| s.project(k, p))
            .min_by(|a, b| a.dist.total_cmp(&b.dist).then(a.seg.cmp(&b.seg)))
            .unwrap()
    }

    proptest! {
        #[test]
        fn bucketed_closest_equals_brute_force(
            pts in proptest::collection::vec((-40.0f64..40.0, -40.0f64..40.0), 2..30),
            q in (-80.0f64..80.0, -80.0f64..80.0),
        ) {
            let pts: Vec<DVec2> = pts.into_iter().map(|(x, y)| DVec2::new(x, y)).collect();
            let s = Segments::polyline(&pts, false);
            let p = DVec2::new(q.0, q.1);
            let h = s.closest(p, f64::INFINITY).unwrap();
            prop_assert_eq!(h, brute(&s, p));
            // A limit below the distance finds nothing.
            prop_assert!(s.closest(p, h.dist * 0.5 - 1e-9).is_none() || h.dist == 0.0);
        }

        /// Every node of a tile finds among its tile's candidates what its
        /// own query finds (and nothing where the tile has none), for
        /// tiles near, across and far from the polyline.
        #[test]
        fn tile_candidates_hold_every_nodes_closest_segment(
            pts in proptest::collection::vec((-40.0f64..40.0, -40.0f64..40.0), 2..30),
            corner in (-90i32..70, -90i32..70),
            size in (1usize..12, 1usize..12),
            dist in 0.5f64..60.0,
        ) {
            let pts: Vec<DVec2> = pts.into_iter().map(|(x, y)| DVec2::new(x, y)).collect();
            let s = Segments::polyline(&pts, false);
            let corner = DVec2::new(corner.0 as f64, corner.1 as f64);
            let mut c = Vec::new();
            let any = s.tile_candidates(corner, size, dist, &mut c);
            prop_assert_eq!(any, !c.is_empty());
            for j in 0..size.1 {
                for i in 0..size.0 {
                    let p = corner + DVec2::new(i as f64, j as f64);
                    prop_assert_eq!(s.closest_among(&c, p, dist), s.closest(p, dist), "node {}", p);
                }
            }
        }
    }
}
