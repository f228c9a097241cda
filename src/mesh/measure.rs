//! The vertical error of a triangulation against its heightfield,
//! measured by rasterising every triangle back over the samples it covers
//! (edges included) and comparing its plane with the height there. The
//! adaptive triangulation uses the same rasteriser for its split errors,
//! so what it promises is what this measures.

use super::Triangulation;
use crate::heightfield::Heightfield;

/// What [`max_vertical_error`] found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measured {
    /// Largest |surface − height| over the covered samples, metres.
    pub max_error: f32,
    /// Samples no triangle covers (0 for a triangulation of the grid).
    pub uncovered: usize,
    /// Triangles with no area (0 for a valid triangulation).
    pub degenerate: usize,
}

/// Twice the signed area of (a, b, c) in (column, row) coordinates:
/// negative for a triangle counter-clockwise seen from above (rows run
/// south, so the grid's plane is seen mirrored).
pub fn orient(a: [i64; 2], b: [i64; 2], c: [i64; 2]) -> i64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Calls `f(x, y, |plane − height|)` for every sample inside or on the
/// edge of triangle `t` (corners in samples, inside the grid); nothing for
/// a triangle with no area.
fn raster(hf: &Heightfield, t: [[i64; 2]; 3], mut f: impl FnMut(usize, usize, f64)) {
    let [a, b, c] = t;
    let area = orient(a, b, c);
    if area == 0 {
        return;
    }
    let h = |p: [i64; 2]| hf.get(p[0] as usize, p[1] as usize) as f64;
    let (ha, hb, hc) = (h(a), h(b), h(c));
    let (x0, x1) = (a[0].min(b[0]).min(c[0]), a[0].max(b[0]).max(c[0]));
    let (y0, y1) = (a[1].min(b[1]).min(c[1]), a[1].max(b[1]).max(c[1]));
    for y in y0..=y1 {
        for x in x0..=x1 {
            let p = [x, y];
            let (wa, wb, wc) = (orient(b, c, p), orient(c, a, p), orient(a, b, p));
            let inside = if area > 0 {
                wa >= 0 && wb >= 0 && wc >= 0
            } else {
                wa <= 0 && wb <= 0 && wc <= 0
            };
            if inside {
                let plane = (wa as f64 * ha + wb as f64 * hb + wc as f64 * hc) / area as f64;
                f(x as usize, y as usize, (plane - h(p)).abs());
            }
        }
    }
}

/// The largest vertical error of triangle `t` over the samples it covers.
pub(crate) fn triangle_error(hf: &Heightfield, t: [[i64; 2]; 3]) -> f32 {
    let mut e = 0.0f64;
    raster(hf, t, |_, _, d| e = e.max(d));
    e as f32
}

/// Measures `pieces` (the tiles of one level, or one whole triangulation)
/// against `hf`: the largest error, and the samples left uncovered.
pub fn max_vertical_error(hf: &Heightfield, pieces: &[Triangulation]) -> Measured {
    let (w, h) = (hf.width(), hf.height());
    let mut covered = vec![false; w * h];
    let mut m = Measured {
        max_error: 0.0,
        uncovered: 0,
        degenerate: 0,
    };
    let mut worst = 0.0f64;
    for p in pieces {
        for t in &p.triangles {
            let t = t.map(|i| {
                let [x, y] = p.vertices[i as usize];
                [x as i64, y as i64]
            });
            if orient(t[0], t[1], t[2]) == 0 {
                m.degenerate += 1;
            }
            raster(hf, t, |x, y, d| {
                covered[y * w + x] = true;
                worst = worst.max(d);
            });
        }
    }
    m.max_error = worst as f32;
    m.uncovered = covered.iter().filter(|c| !**c).count();
    m
}
