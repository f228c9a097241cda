//! Turning the user's polyline into the curve the constraint follows.
//!
//! A sketched polyline has corners where the pen changed direction; the
//! closest-point parametrisation of a cornered curve jumps on the convex side
//! of every corner, and its side normal flips. Chaikin corner cutting rounds
//! the corners while keeping the end points where the user put them (the
//! paper only says the input is "smoothed"; Chaikin is the simplest scheme
//! that converges to a C¹ quadratic B-spline and never overshoots the
//! control polygon). The result is then resampled at uniform arc-length
//! spacing of at most [`SPACING`] output pixels, so that every later step
//! (distance field, junction search, isocurve extraction) sees short,
//! evenly sized segments.

use glam::DVec2;

/// Largest segment length of the resampled curve, output pixels.
pub const SPACING: f64 = 1.0;

/// Chaikin corner cutting, `iterations` times, end points kept.
pub fn chaikin(points: &[DVec2], iterations: u32) -> Vec<DVec2> {
    let mut pts = points.to_vec();
    for _ in 0..iterations {
        if pts.len() < 3 {
            break;
        }
        let mut next = Vec::with_capacity(pts.len() * 2);
        next.push(pts[0]);
        for w in pts.windows(2) {
            let (a, b) = (w[0], w[1]);
            next.push(a * 0.75 + b * 0.25);
            next.push(a * 0.25 + b * 0.75);
        }
        next.push(*pts.last().expect("at least 3 points"));
        pts = next;
    }
    pts
}

/// Cumulative arc length at each vertex (first = 0).
pub fn arc_lengths(points: &[DVec2]) -> Vec<f64> {
    let mut cum = Vec::with_capacity(points.len());
    let mut s = 0.0;
    cum.push(0.0);
    for w in points.windows(2) {
        s += w[0].distance(w[1]);
        cum.push(s);
    }
    cum
}

/// Resamples a polyline at uniform arc length, ≤ [`SPACING`] apart, with the
/// first and last points kept exactly; the new points lie on the input
/// polyline. Returns `None` for a polyline of zero length.
pub fn resample(points: &[DVec2]) -> Option<Vec<DVec2>> {
    let cum = arc_lengths(points);
    let total = *cum.last()?;
    if total.is_nan() || total <= 0.0 || !total.is_finite() {
        return None;
    }
    let n = (total / SPACING).ceil().max(1.0) as usize;
    let mut out = Vec::with_capacity(n + 1);
    let mut k = 0;
    for i in 0..=n {
        let s = total * i as f64 / n as f64;
        while k + 2 < cum.len() && cum[k + 1] < s {
            k += 1;
        }
        let len = cum[k + 1] - cum[k];
        let u = if len > 0.0 {
            ((s - cum[k]) / len).clamp(0.0, 1.0)
        } else {
            0.0
        };
        out.push(points[k].lerp(points[k + 1], u));
    }
    out[0] = points[0];
    out[n] = *points.last().expect("non-empty");
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chaikin_keeps_ends_and_rounds_corners() {
        let p = [
            DVec2::new(0., 0.),
            DVec2::new(10., 0.),
            DVec2::new(10., 10.),
        ];
        let s = chaikin(&p, 3);
        assert_eq!(s[0], p[0]);
        assert_eq!(*s.last().unwrap(), p[2]);
        // The corner (10, 0) is cut: no point of the smoothed curve is on it.
        assert!(s.iter().all(|q| q.distance(p[1]) > 1.0));
    }

    #[test]
    fn resampled_spacing_is_uniform_and_bounded() {
        let p = [
            DVec2::new(0., 0.),
            DVec2::new(7.3, 0.),
            DVec2::new(7.3, 4.1),
        ];
        let r = resample(&p).unwrap();
        let d: Vec<f64> = r.windows(2).map(|w| w[0].distance(w[1])).collect();
        assert!(d.iter().all(|&x| x <= SPACING + 1e-9));
        assert_eq!(r[0], p[0]);
        assert_eq!(*r.last().unwrap(), p[2]);
        // Arc length is preserved: the points stay on the polyline.
        let total: f64 = d.iter().sum();
        assert!(total <= 11.4 + 1e-9 && total > 11.4 - 0.6, "{total}");
        assert!(resample(&[p[0], p[0]]).is_none());
    }
}
