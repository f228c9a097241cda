//! A feature candidate's geometry before scoring: the thin-plate-spline
//! warp onto a user patch, sampling the warped source, and the removal of
//! the tilt every patch brings from its source.

use crate::patch::merge::Window;
use crate::patch::place::candidates::{FeatureNode, PreparedSource};
use crate::patch::place::costs::{Tps, transform_angle};
use crate::resample::bilinear;

/// Builds the warp of a feature candidate onto a user patch: a TPS from
/// output coordinates (relative to the user centre, in units of r) to
/// source coordinates, through the centres, the matched control points and
/// one extra point at distance r perpendicular to the first control
/// direction (mirrored with the candidate), which keeps the three points of
/// a straight path from being collinear. Returns the spline and its cost
/// `bending energy + stretch`.
pub fn feature_warp(
    user: &FeatureNode,
    cand: &FeatureNode,
    t: usize,
    shift: usize,
    r: f32,
) -> Option<(Tps, f64)> {
    let d = user.cps.len();
    let mirrored = transform_angle(0, t).1;
    let order = |j: usize| if mirrored { d - 1 - j } else { j };
    let (uc, sc) = (user.centre, cand.centre);
    let rr = r as f64;
    let rel = |p: [f32; 2], c: [f32; 2]| [(p[0] - c[0]) as f64 / rr, (p[1] - c[1]) as f64 / rr];
    let mut src = vec![[0.0, 0.0]];
    let mut dst = vec![[0.0, 0.0]];
    for (i, cu) in user.cps.iter().enumerate() {
        let cs = &cand.cps[order((i + shift) % d)];
        src.push(rel(cu.pos, uc));
        dst.push(rel(cs.pos, sc));
    }
    let unit = |v: [f64; 2]| {
        let l = (v[0] * v[0] + v[1] * v[1]).sqrt().max(1e-9);
        [v[0] / l, v[1] / l]
    };
    let du = unit(src[1]);
    let ds = unit(dst[1]);
    let sign = if mirrored { -1.0 } else { 1.0 };
    src.push([-du[1], du[0]]);
    dst.push([-ds[1] * sign, ds[0] * sign]);
    let tps = Tps::fit(&src, &dst)?;
    let cost = tps.bending_energy() + tps.stretch();
    Some((tps, cost))
}

/// Samples the warped candidate over window `win` (heights in metres);
/// `None` if any sample falls outside the source. The spline is evaluated
/// on an 8-pixel lattice and interpolated bilinearly in between.
pub fn sample_warped(
    src: &PreparedSource,
    tps: &Tps,
    user_centre: [f32; 2],
    cand_centre: [f32; 2],
    r: f32,
    win: Window,
) -> Option<Vec<f32>> {
    let n = win.n;
    let step = 8;
    let m = n / step + 1;
    let mut lat = vec![[0.0f32; 2]; m * m];
    for ly in 0..m {
        for lx in 0..m {
            let p = [
                (win.x0 + lx * step) as f32 + 0.5,
                (win.y0 + ly * step) as f32 + 0.5,
            ];
            let q = tps.map([
                ((p[0] - user_centre[0]) / r) as f64,
                ((p[1] - user_centre[1]) / r) as f64,
            ]);
            lat[ly * m + lx] = [
                cand_centre[0] + (q[0] * r as f64) as f32,
                cand_centre[1] + (q[1] * r as f64) as f32,
            ];
        }
    }
    let (w, h) = (src.width as f32, src.height as f32);
    let mut out = vec![0.0f32; n * n];
    for y in 0..n {
        let (ly, ty) = ((y / step).min(m - 2), (y % step) as f32 / step as f32);
        let ty = if y / step > m - 2 { 1.0 } else { ty };
        for x in 0..n {
            let (lx, tx) = ((x / step).min(m - 2), (x % step) as f32 / step as f32);
            let tx = if x / step > m - 2 { 1.0 } else { tx };
            let l = |i: usize, j: usize| lat[j * m + i];
            let mix = |a: [f32; 2], b: [f32; 2], t: f32| {
                [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]
            };
            let top = mix(l(lx, ly), l(lx + 1, ly), tx);
            let bot = mix(l(lx, ly + 1), l(lx + 1, ly + 1), tx);
            let q = mix(top, bot, ty);
            if !(q[0] >= 0.5 && q[1] >= 0.5 && q[0] <= w - 0.5 && q[1] <= h - 0.5) {
                return None;
            }
            out[y * n + x] = bilinear(&src.heights, src.width, src.height, q);
        }
    }
    Some(out)
}

/// Removes the least-squares tilt (the `x` and `y` slopes of the best-fit
/// plane) from an `n × n` feature patch, keeping its mean. Gradient-domain
/// merging keeps every patch's slopes, so the regional tilt a ridge or
/// valley patch brings from its source (a ridge that runs downhill) would
/// add up along the sketched feature into a random walk of height; the
/// feature's broad shape is the sketch's to give ([`deform_by_sketch`]).
/// Fill patches are not detrended: removing a patch's tilt reverses every
/// channel that falls less steeply than it, which makes closed pits
/// ([`crate::patch::fill::hole_fill`] says how many).
///
/// [`deform_by_sketch`]: crate::patch::deform_by_sketch
pub fn detrend(patch: &mut [f32], n: usize) {
    let c = (n as f64 - 1.0) / 2.0;
    let (mut sx, mut sy, mut sxx) = (0.0f64, 0.0f64, 0.0f64);
    for y in 0..n {
        for x in 0..n {
            let v = patch[y * n + x] as f64;
            sx += (x as f64 - c) * v;
            sy += (y as f64 - c) * v;
        }
    }
    for x in 0..n {
        sxx += (x as f64 - c).powi(2);
    }
    sxx *= n as f64;
    let (bx, by) = (sx / sxx, sy / sxx);
    for y in 0..n {
        for x in 0..n {
            patch[y * n + x] -= (bx * (x as f64 - c) + by * (y as f64 - c)) as f32;
        }
    }
}
