//! What the user gives for a curve ([`CurveSpec`], its [`Widget`]s, junction
//! heights), the limits it must keep, and the check that turns a spec into
//! the smoothed, resampled polyline the constraint is built on.

use super::{LEFT, RIGHT, field, smooth};
use glam::DVec2;
use thiserror::Error;

/// A curve-located widget.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Widget {
    /// Position as a fraction of the curve's arc length, 0..=1.
    pub at: f64,
    /// Height of the curve here, metres.
    pub height_m: f64,
    /// Slope away from the curve on each side ([`LEFT`], [`RIGHT`]), degrees.
    pub slope_deg: [f64; 2],
    /// Area of effect on each side, output pixels.
    pub reach_px: [f64; 2],
}

/// A curve as the user describes it.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveSpec {
    /// The sketched polyline, output pixels (≥ 2 points, not all equal).
    pub points: Vec<DVec2>,
    /// At least one widget.
    pub widgets: Vec<Widget>,
    /// Chaikin iterations applied to the polyline (paper: "smoothed").
    pub smoothing: u32,
}

/// A junction's height set by the user: applies to the junction within
/// [`JUNCTION_SNAP`] pixels of `at`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JunctionHeight {
    pub at: DVec2,
    pub height_m: f64,
}

/// How far a [`JunctionHeight`] may be from the junction it sets, pixels.
pub const JUNCTION_SNAP: f64 = 4.0;

/// Curves that cannot be built.
#[non_exhaustive]
#[derive(Debug, Error, Clone, PartialEq)]
pub enum CurveError {
    #[error("curve {curve} has {count} point(s): expected at least 2")]
    TooFewPoints { curve: usize, count: usize },
    #[error("curve {curve} has zero length: its points must not all coincide")]
    ZeroLength { curve: usize },
    #[error("curve {curve} has no widget: expected at least 1 (height, slopes, reaches)")]
    NoWidget { curve: usize },
    #[error("curve {curve}: {what} {value} is invalid: expected {range}")]
    Value {
        curve: usize,
        what: &'static str,
        value: f64,
        range: &'static str,
    },
    #[error(
        "curve {curve} with reach {reach} px needs a distance field of more than {max} nodes: shorten it or reduce the reach",
        max = field::MAX_NODES
    )]
    TooLarge { curve: usize, reach: f64 },
    #[error(
        "curve {curve} is {length:.0} px long after smoothing ({points} points): at most {max} px and {max} smoothed points",
        max = MAX_LENGTH_PX
    )]
    TooLong {
        curve: usize,
        length: f64,
        points: usize,
    },
    #[error(
        "junction height at ({x}, {y}) matches no junction: the curves cross nowhere within {JUNCTION_SNAP} px of it"
    )]
    NoJunction { x: f64, y: f64 },
}

/// Longest curve, output pixels of arc length (and most points after
/// smoothing): its resampled form holds one point per pixel, so this bounds
/// the memory a hostile scene can ask for (64 MiB).
pub const MAX_LENGTH_PX: f64 = (1 << 22) as f64;

/// Largest reach, output pixels.
pub const MAX_REACH_PX: f64 = 4096.0;
/// Largest |slope|, degrees (steeper than this is a wall, not a slope).
pub const MAX_SLOPE_DEG: f64 = 85.0;

/// Smooths and resamples one spec's polyline, with its arc lengths.
pub(super) fn shape(curve: usize, spec: &CurveSpec) -> Result<(Vec<DVec2>, Vec<f64>), CurveError> {
    if spec.points.len() < 2 {
        return Err(CurveError::TooFewPoints {
            curve,
            count: spec.points.len(),
        });
    }
    for p in &spec.points {
        for v in [p.x, p.y] {
            if !v.is_finite() || v.abs() > 1e6 {
                return Err(CurveError::Value {
                    curve,
                    what: "point coordinate",
                    value: v,
                    range: "a finite value within ±1e6 px",
                });
            }
        }
    }
    if spec.widgets.is_empty() {
        return Err(CurveError::NoWidget { curve });
    }
    for w in &spec.widgets {
        let checks = [
            (
                "widget position",
                w.at,
                (0.0..=1.0).contains(&w.at),
                "0..=1 of the arc length",
            ),
            (
                "height",
                w.height_m,
                w.height_m.is_finite() && w.height_m.abs() <= 1e5,
                "-100000..=100000 m",
            ),
        ];
        for (what, value, ok, range) in checks {
            if !ok {
                return Err(CurveError::Value {
                    curve,
                    what,
                    value,
                    range,
                });
            }
        }
        for side in [LEFT, RIGHT] {
            let s = w.slope_deg[side];
            if s.is_nan() || s.abs() > MAX_SLOPE_DEG {
                return Err(CurveError::Value {
                    curve,
                    what: "slope",
                    value: s,
                    range: "-85..=85 degrees",
                });
            }
            let r = w.reach_px[side];
            if !(r > 0.0 && r <= MAX_REACH_PX) {
                return Err(CurveError::Value {
                    curve,
                    what: "reach",
                    value: r,
                    range: "0 < reach <= 4096 px",
                });
            }
        }
    }
    let iterations = spec.smoothing.min(8);
    let length: f64 = spec.points.windows(2).map(|w| w[0].distance(w[1])).sum();
    let smoothed_points = (spec.points.len() as f64) * f64::from(1u32 << iterations);
    if length > MAX_LENGTH_PX || smoothed_points > MAX_LENGTH_PX {
        return Err(CurveError::TooLong {
            curve,
            length,
            points: spec.points.len() << iterations,
        });
    }
    let smoothed = smooth::chaikin(&spec.points, iterations);
    let pts = smooth::resample(&smoothed).ok_or(CurveError::ZeroLength { curve })?;
    let cum = smooth::arc_lengths(&pts);
    Ok((pts, cum))
}
