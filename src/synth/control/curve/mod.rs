//! Curve constraints (paper §3, §5.1): a sketched polyline, smoothed, whose
//! height, left/right slope and left/right reach are given by widgets along
//! it and interpolated with Hermite curves; junction widgets (height only)
//! placed automatically where curves cross each other or themselves; end
//! caps by angular interpolation of the left and right properties; closest
//! points from a distance field cached on the curve's shape; and an area of
//! effect whose boundary is smoothed as an isocurve (Fig. 5).
//!
//! Conventions (the paper leaves them open):
//! - Positions are output (finest-level) pixels, y down; pixel (i, j) has
//!   its centre at (i + ½, j + ½).
//! - *Left* is the left of someone walking along the curve from its first
//!   point to its last, as seen on the map (y down): for a curve heading
//!   east, left is north (smaller y).
//! - A widget sits at a fraction `at` of the smoothed curve's arc length, so
//!   it stays on the same part of the curve when the sketch is smoothed.
//! - Slope is an angle in degrees from the horizontal, positive when the
//!   terrain rises away from the curve: the target height at distance d is
//!   `height + tan(slope)·d·cell`. A canyon floor has positive slopes, a
//!   ridge negative ones, a cliff top one flat side and one steep negative.
//! - A junction's default height is the mean of the heights its curves'
//!   own widgets give there (so adding a crossing does not move either
//!   curve on average); a scene may set it. Near a widget (within half a
//!   pixel of arc length) the widget wins over a junction.

pub mod envelope;
pub mod field;
pub mod junction;
pub mod profile;
pub mod segments;
pub mod smooth;
mod spec;

use super::{Centres, Constraint, Hold, Sample};
use envelope::Envelope;
use field::DistanceField;
pub use field::FieldCache;
use glam::DVec2;
use profile::Track;
use segments::Hit;
use spec::shape;
pub use spec::{
    CurveError, CurveSpec, JUNCTION_SNAP, JunctionHeight, MAX_LENGTH_PX, MAX_REACH_PX,
    MAX_SLOPE_DEG, Widget,
};
use std::sync::{Arc, OnceLock};

/// Side indices of two-sided properties.
pub const LEFT: usize = 0;
pub const RIGHT: usize = 1;

/// A junction widget placed where curves cross.
#[derive(Debug, Clone, PartialEq)]
pub struct Junction {
    pub at: DVec2,
    pub height_m: f64,
    /// `(curve index, arc length)` of every curve through it.
    pub members: Vec<(usize, f64)>,
}

/// The properties the constraint asks for at one closest point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Props {
    /// Arc length of the closest point, pixels.
    pub s: f64,
    /// 0 = fully left-side properties, 1 = fully right (fractional in caps).
    pub right: f64,
    pub height_m: f64,
    pub slope_deg: f64,
    pub reach_px: f64,
}

/// One built curve constraint.
pub struct Curve {
    field: Arc<DistanceField>,
    /// Resampled points and arc length at each.
    points: Vec<DVec2>,
    cum: Vec<f64>,
    tracks: Tracks,
    cell_m: f64,
    /// The area of effect, shared with every curve of the same shape and
    /// reach (see [`FieldCache::envelope`]).
    env: Arc<Envelope>,
    /// Its samples at the finest level's pixel centres, taken on first use
    /// (see [`Centres`]).
    centres: OnceLock<Option<Centres>>,
}

/// A curve's height, left/right slope and left/right reach along its arc
/// length: from its widgets alone, then with the junctions' heights.
struct Tracks {
    height: Track,
    slope: [Track; 2],
    reach: [Track; 2],
}

impl std::fmt::Debug for Curve {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Curve")
            .field("points", &self.points.len())
            .field("length_px", &self.length())
            .field("field", &(self.field.width, self.field.height))
            .field("envelope_loops", &self.env.smoothed.len())
            .finish()
    }
}

/// Builds every curve of a scene together, so that junctions between them
/// are found; `junction_heights` override junction heights. Distance fields
/// come from `cache`.
pub fn build(
    specs: &[CurveSpec],
    junction_heights: &[JunctionHeight],
    cell_m: f64,
    cache: &FieldCache,
) -> Result<(Vec<Curve>, Vec<Junction>), CurveError> {
    let shapes: Vec<(Vec<DVec2>, Vec<f64>)> = specs
        .iter()
        .enumerate()
        .map(|(k, s)| shape(k, s))
        .collect::<Result<_, _>>()?;
    // Widget-only tracks, for junction defaults.
    let tracks: Vec<_> = specs
        .iter()
        .zip(&shapes)
        .map(|(spec, (_, cum))| widget_tracks(spec, *cum.last().expect("non-empty")))
        .collect();
    let refs: Vec<(&[DVec2], &[f64])> = shapes.iter().map(|(p, c)| (&p[..], &c[..])).collect();
    let mut junctions: Vec<Junction> = junction::find(&refs)
        .into_iter()
        .map(|c| {
            let mean = c
                .members
                .iter()
                .map(|&(k, s)| tracks[k].height.at(s))
                .sum::<f64>()
                / c.members.len() as f64;
            Junction {
                at: c.at,
                height_m: mean,
                members: c.members,
            }
        })
        .collect();
    for jh in junction_heights {
        let best = junctions
            .iter_mut()
            .map(|j| (j.at.distance(jh.at), j))
            .filter(|(d, _)| *d <= JUNCTION_SNAP)
            .min_by(|a, b| a.0.total_cmp(&b.0));
        match best {
            Some((_, j)) => j.height_m = jh.height_m,
            None => {
                return Err(CurveError::NoJunction {
                    x: jh.at.x,
                    y: jh.at.y,
                });
            }
        }
    }
    let curves = shapes
        .into_iter()
        .zip(tracks)
        .enumerate()
        .map(|(k, ((points, cum), tracks))| {
            let total = *cum.last().expect("non-empty");
            let mut keys: Vec<(f64, f64)> = specs[k]
                .widgets
                .iter()
                .map(|w| (w.at * total, w.height_m))
                .collect();
            for j in &junctions {
                keys.extend(
                    j.members
                        .iter()
                        .filter(|m| m.0 == k)
                        .map(|m| (m.1, j.height_m)),
                );
            }
            let tracks = Tracks {
                height: Track::new(&keys),
                ..tracks
            };
            Curve::new(k, points, cum, tracks, cell_m, cache)
        })
        .collect::<Result<_, _>>()?;
    Ok((curves, junctions))
}

/// Height, slope and reach tracks from a spec's widgets alone.
fn widget_tracks(spec: &CurveSpec, total: f64) -> Tracks {
    let keys = |f: &dyn Fn(&Widget) -> f64| -> Track {
        Track::new(
            &spec
                .widgets
                .iter()
                .map(|w| (w.at * total, f(w)))
                .collect::<Vec<_>>(),
        )
    };
    Tracks {
        height: keys(&|w| w.height_m),
        slope: [keys(&|w| w.slope_deg[LEFT]), keys(&|w| w.slope_deg[RIGHT])],
        reach: [keys(&|w| w.reach_px[LEFT]), keys(&|w| w.reach_px[RIGHT])],
    }
}

impl Curve {
    fn new(
        index: usize,
        points: Vec<DVec2>,
        cum: Vec<f64>,
        tracks: Tracks,
        cell_m: f64,
        cache: &FieldCache,
    ) -> Result<Curve, CurveError> {
        let reach = &tracks.reach;
        let max_reach = reach[LEFT].max().max(reach[RIGHT].max());
        let sigma = envelope::sigma(max_reach);
        // Smoothing may push the boundary outward by up to ~σ where it fills
        // a notch; the field must cover that.
        let margin = max_reach + sigma + 2.0;
        let field = cache.get(&points, margin).ok_or(CurveError::TooLarge {
            curve: index,
            reach: max_reach,
        })?;
        let mut curve = Curve {
            field,
            points,
            cum,
            tracks,
            cell_m,
            env: Arc::default(),
            centres: OnceLock::new(),
        };
        curve.env = cache.envelope(&curve.field, &curve.tracks.reach, || {
            Envelope::compute(&curve.field, sigma, |hit, p| curve.reach(hit, p))
        });
        Ok(curve)
    }

    /// Arc length of the smoothed curve, pixels.
    pub fn length(&self) -> f64 {
        *self.cum.last().expect("non-empty")
    }

    /// The smoothed, resampled curve, output pixels.
    pub fn points(&self) -> &[DVec2] {
        &self.points
    }

    /// The point at arc length `s`.
    pub fn point_at(&self, s: f64) -> DVec2 {
        let k = self
            .cum
            .partition_point(|&c| c <= s)
            .clamp(1, self.cum.len() - 1)
            - 1;
        let len = self.cum[k + 1] - self.cum[k];
        let u = if len > 0.0 {
            ((s - self.cum[k]) / len).clamp(0.0, 1.0)
        } else {
            0.0
        };
        self.points[k].lerp(self.points[k + 1], u)
    }

    /// Height at arc length `s`, metres (widgets and junctions).
    pub fn height_at(&self, s: f64) -> f64 {
        self.tracks.height.at(s)
    }

    /// The smoothed area-of-effect boundary (closed loops), output pixels.
    pub fn envelope(&self) -> &[Vec<DVec2>] {
        &self.env.smoothed
    }

    /// The boundary before isocurve smoothing, for comparison.
    pub fn raw_envelope(&self) -> &[Vec<DVec2>] {
        &self.env.raw
    }

    /// The shared distance field this curve uses.
    pub fn field(&self) -> &Arc<DistanceField> {
        &self.field
    }

    /// Effective reach at lattice node `(i, j)` of [`Curve::field`].
    pub fn reach_at_node(&self, i: usize, j: usize) -> f32 {
        self.env.reach_eff[j * self.field.width + i]
    }

    /// The raw (unsmoothed) reach the closest point asks for at node `(i, j)`.
    pub fn raw_reach_at_node(&self, i: usize, j: usize) -> Option<f64> {
        let f = &self.field;
        let s = f.node(i as i64, j as i64);
        (s != field::NONE).then(|| {
            let p = DVec2::new((f.x0 + i as i64) as f64, (f.y0 + j as i64) as f64);
            self.reach(f.segments.project(s, p), p)
        })
    }

    /// The properties for position `p` whose closest curve point is `hit`:
    /// the side's own slope and reach, or in an end cap the left and right
    /// values blended by the angle around the end point (see
    /// `Curve::side`).
    pub fn props(&self, hit: Hit, p: DVec2) -> Props {
        let (s, right) = self.side(hit, p);
        Props {
            s,
            right,
            height_m: self.tracks.height.at(s),
            slope_deg: mix(&self.tracks.slope, s, right),
            reach_px: mix(&self.tracks.reach, s, right),
        }
    }

    /// [`Props::reach_px`] alone (what the envelope is made of).
    fn reach(&self, hit: Hit, p: DVec2) -> f64 {
        let (s, right) = self.side(hit, p);
        mix(&self.tracks.reach, s, right)
    }

    /// Arc length of `hit` and how far `p` is on its right side: 0 or 1
    /// beside the curve, in an end cap a cubic Hermite step of the angle
    /// around the end point from the left normal, 0°, to the right
    /// normal, 180°.
    fn side(&self, hit: Hit, p: DVec2) -> (f64, f64) {
        let k = hit.seg as usize;
        let n = self.points.len() - 1;
        let s = self.cum[k] + hit.u * (self.cum[k + 1] - self.cum[k]);
        let dir = |k: usize| (self.points[k + 1] - self.points[k]).normalize_or_zero();
        let c = self.points[k].lerp(self.points[k + 1], hit.u);
        let v = p - c;
        let right = if (k == 0 && hit.u == 0.0) || (k == n - 1 && hit.u == 1.0) {
            let fwd = if k == 0 && hit.u == 0.0 {
                dir(0)
            } else {
                dir(n - 1)
            };
            let left_normal = DVec2::new(fwd.y, -fwd.x);
            let len = v.length();
            if len == 0.0 {
                0.0
            } else {
                let a = (left_normal.dot(v) / len).clamp(-1.0, 1.0).acos() / std::f64::consts::PI;
                a * a * (3.0 - 2.0 * a)
            }
        } else {
            let fwd = if hit.u == 0.0 {
                dir(k - 1) + dir(k)
            } else if hit.u == 1.0 {
                dir(k) + dir(k + 1)
            } else {
                dir(k)
            };
            if fwd.perp_dot(v) > 0.0 { 1.0 } else { 0.0 }
        };
        (s, right)
    }

    /// Effective reach at output position `p`, bilinear between nodes.
    fn reach_eff_at(&self, p: DVec2) -> f64 {
        let f = &self.field;
        let (fx, fy) = (p.x - f.x0 as f64, p.y - f.y0 as f64);
        let (i0, j0) = (fx.floor(), fy.floor());
        let (tx, ty) = (fx - i0, fy - j0);
        let at = |i: f64, j: f64| -> f64 {
            if i < 0.0 || j < 0.0 || i >= f.width as f64 || j >= f.height as f64 {
                return -1.0;
            }
            self.env.reach_eff[j as usize * f.width + i as usize] as f64
        };
        let top = at(i0, j0) * (1.0 - tx) + at(i0 + 1.0, j0) * tx;
        let bottom = at(i0, j0 + 1.0) * (1.0 - tx) + at(i0 + 1.0, j0 + 1.0) * tx;
        top * (1.0 - ty) + bottom * ty
    }
}

/// A two-sided property at arc length `s`, `right` of the way from its
/// left value to its right one.
fn mix(t: &[Track; 2], s: f64, right: f64) -> f64 {
    t[LEFT].at(s) * (1.0 - right) + t[RIGHT].at(s) * right
}

impl Constraint for Curve {
    /// A curve's profile (height, slopes, reaches) is the artist's explicit
    /// shape: held closely over its whole reach at every level (see
    /// [`super::blend::S_CURVE`]).
    fn hold(&self) -> Hold {
        Hold {
            tolerance_slope: super::blend::S_CURVE,
            level_cap: None,
            max_reach: self.field.margin,
            keeps_detail: true,
        }
    }

    fn bounds(&self) -> [f64; 4] {
        let f = &self.field;
        [
            f.x0 as f64,
            f.y0 as f64,
            (f.x0 + f.width as i64) as f64,
            (f.y0 + f.height as i64) as f64,
        ]
    }

    fn centres(&self) -> Option<&Centres> {
        self.centres.get_or_init(|| Centres::new(self)).as_ref()
    }

    fn bytes(&self) -> usize {
        let centres = self.centres.get().and_then(Option::as_ref);
        centres.map_or(0, Centres::bytes) + self.field.bytes() + self.env.bytes()
    }

    fn sample(&self, x: f64, y: f64) -> Option<Sample> {
        let p = DVec2::new(x, y);
        let hit = self.field.closest(p)?;
        let reach = self.reach_eff_at(p);
        if hit.dist > reach {
            return None;
        }
        // Height and slope only: the reach is the envelope's.
        let (s, right) = self.side(hit, p);
        let slope_deg = mix(&self.tracks.slope, s, right);
        Some(Sample {
            target_m: self.tracks.height.at(s)
                + slope_deg.to_radians().tan() * hit.dist * self.cell_m,
            distance: hit.dist,
            reach,
        })
    }

    /// From the lattice node n nearest to p (|p − n| ≤ √½): a sample's
    /// distance is to a point of the curve, so it is at least the true
    /// distance, which is 1-Lipschitz and at n is exactly the projection on
    /// n's stored segment, or more than the field's margin where n stores
    /// none (or lies off the lattice, which extends past the margin).
    fn distance_bound(&self, x: f64, y: f64) -> f64 {
        let f = &self.field;
        let (i, j) = ((x - f.x0 as f64).round(), (y - f.y0 as f64).round());
        let n = DVec2::new(f.x0 as f64 + i, f.y0 as f64 + j);
        let s = f.node(i as i64, j as i64);
        let at_node = if s == field::NONE {
            f.margin
        } else {
            f.segments.project(s, n).dist
        };
        at_node - n.distance(DVec2::new(x, y))
    }
}

#[cfg(test)]
mod tests;
