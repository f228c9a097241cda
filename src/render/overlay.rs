//! Drawing on a finished preview: points, polylines, filled or outlined
//! polygons and cell regions, and text-free markers — for showing
//! constraints, frozen regions and sketches over the terrain.
//!
//! CPU-only and applied after `shade`: overlays are vector data of a few
//! hundred primitives, not a per-pixel stage, and need no GPU mirror.
//! Coordinates are heightfield cells (cell `(i, j)` covers `[i, i+1) ×
//! [j, j+1)`, its centre is `(i + 0.5, j + 0.5)`), so callers need not know
//! how the preview was resized; sizes are in preview pixels. Edges are
//! anti-aliased by exact distance (lines, discs) or 4×4 supersampling
//! (polygon fills); colours are sRGB with alpha as opacity, blended over.

use image::{Rgba, RgbaImage};

/// Marker shapes; `size` is the marker's full width in pixels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Marker {
    /// ×
    Cross,
    /// +
    Plus,
    /// Outlined square.
    Square,
    /// Filled diamond.
    Diamond,
    /// Filled triangle, apex up.
    Triangle,
    /// Outlined circle.
    Ring,
}

/// Draws in heightfield cell coordinates onto a preview image.
pub struct Canvas<'a> {
    img: &'a mut RgbaImage,
    sx: f64,
    sy: f64,
}

impl<'a> Canvas<'a> {
    /// `px_per_cell_*`: preview pixels per heightfield cell along each axis
    /// (see `RenderInfo`).
    pub fn new(img: &'a mut RgbaImage, px_per_cell_x: f64, px_per_cell_y: f64) -> Canvas<'a> {
        Canvas {
            img,
            sx: px_per_cell_x,
            sy: px_per_cell_y,
        }
    }

    fn px(&self, p: (f64, f64)) -> (f64, f64) {
        (p.0 * self.sx, p.1 * self.sy)
    }

    /// A filled disc of `radius` pixels.
    pub fn point(&mut self, at: (f64, f64), radius: f64, colour: Rgba<u8>) {
        let c = self.px(at);
        let mut cov = Coverage::around(self.img, &[c], radius + 1.0);
        cov.each(|x, y| {
            let d = ((x - c.0).powi(2) + (y - c.1).powi(2)).sqrt();
            radius + 0.5 - d
        });
        cov.blend(self.img, colour);
    }

    /// Connected segments, `width` pixels wide, with round joins and caps.
    pub fn polyline(&mut self, points: &[(f64, f64)], width: f64, colour: Rgba<u8>) {
        let pts: Vec<(f64, f64)> = points.iter().map(|&p| self.px(p)).collect();
        self.stroke_px(&pts, width, colour);
    }

    /// A polygon (closed automatically): filled with `fill` by the even-odd
    /// rule, and/or outlined `(colour, width)`.
    pub fn polygon(
        &mut self,
        points: &[(f64, f64)],
        fill: Option<Rgba<u8>>,
        outline: Option<(Rgba<u8>, f64)>,
    ) {
        let pts: Vec<(f64, f64)> = points.iter().map(|&p| self.px(p)).collect();
        if let Some(colour) = fill {
            self.fill_px(&pts, colour);
        }
        if let (Some((colour, width)), Some(&first)) = (outline, pts.first()) {
            let mut closed = pts.clone();
            closed.push(first);
            self.stroke_px(&closed, width, colour);
        }
    }

    /// A region given per cell (`mask[j * width + i]`, `width × height`
    /// cells, the heightfield's size): filled with `fill` and/or outlined
    /// with a 1-pixel `outline` along its inner edge.
    pub fn region(
        &mut self,
        mask: &[bool],
        width: usize,
        height: usize,
        fill: Option<Rgba<u8>>,
        outline: Option<Rgba<u8>>,
    ) {
        if mask.len() != width * height {
            return;
        }
        let (w, h) = self.img.dimensions();
        let cell = |x: i64, y: i64| -> bool {
            if x < 0 || y < 0 || x >= w as i64 || y >= h as i64 {
                return false;
            }
            let i = (((x as f64 + 0.5) / self.sx) as usize).min(width - 1);
            let j = (((y as f64 + 0.5) / self.sy) as usize).min(height - 1);
            mask[j * width + i]
        };
        let inside: Vec<bool> = (0..h as i64)
            .flat_map(|y| (0..w as i64).map(move |x| (x, y)))
            .map(|(x, y)| cell(x, y))
            .collect();
        let at = |x: i64, y: i64| {
            x >= 0 && y >= 0 && x < w as i64 && y < h as i64 && inside[(y * w as i64 + x) as usize]
        };
        for y in 0..h as i64 {
            for x in 0..w as i64 {
                if !at(x, y) {
                    continue;
                }
                let edge = !(at(x - 1, y) && at(x + 1, y) && at(x, y - 1) && at(x, y + 1));
                let colour = match (edge, outline, fill) {
                    (true, Some(c), _) => c,
                    (_, _, Some(c)) => c,
                    _ => continue,
                };
                blend_px(self.img.get_pixel_mut(x as u32, y as u32), colour, 1.0);
            }
        }
    }

    /// A marker centred on `at`, `size` pixels across.
    pub fn marker(&mut self, at: (f64, f64), shape: Marker, size: f64, colour: Rgba<u8>) {
        let (cx, cy) = self.px(at);
        let r = size / 2.0;
        let stroke = (size / 6.0).max(1.0);
        let off = |dx: f64, dy: f64| (cx + dx * r, cy + dy * r);
        match shape {
            Marker::Cross => {
                self.stroke_px(&[off(-1.0, -1.0), off(1.0, 1.0)], stroke, colour);
                self.stroke_px(&[off(-1.0, 1.0), off(1.0, -1.0)], stroke, colour);
            }
            Marker::Plus => {
                self.stroke_px(&[off(-1.0, 0.0), off(1.0, 0.0)], stroke, colour);
                self.stroke_px(&[off(0.0, -1.0), off(0.0, 1.0)], stroke, colour);
            }
            Marker::Square => {
                let sq = [
                    off(-1., -1.),
                    off(1., -1.),
                    off(1., 1.),
                    off(-1., 1.),
                    off(-1., -1.),
                ];
                self.stroke_px(&sq, stroke, colour);
            }
            Marker::Diamond => self.fill_px(
                &[off(0., -1.), off(1., 0.), off(0., 1.), off(-1., 0.)],
                colour,
            ),
            Marker::Triangle => {
                let h = 3f64.sqrt() / 2.0;
                self.fill_px(&[off(0., -1.), off(h, 0.5), off(-h, 0.5)], colour)
            }
            Marker::Ring => {
                let rr = (r - stroke / 2.0).max(0.5);
                let mut cov = Coverage::around(self.img, &[(cx, cy)], r + 1.0);
                cov.each(|x, y| {
                    let d = ((x - cx).powi(2) + (y - cy).powi(2)).sqrt();
                    stroke / 2.0 + 0.5 - (d - rr).abs()
                });
                cov.blend(self.img, colour);
            }
        }
    }

    fn stroke_px(&mut self, pts: &[(f64, f64)], width: f64, colour: Rgba<u8>) {
        let hw = width / 2.0;
        let mut cov = Coverage::around(self.img, pts, hw + 1.0);
        if pts.len() == 1 {
            let c = pts[0];
            cov.each(|x, y| hw + 0.5 - ((x - c.0).powi(2) + (y - c.1).powi(2)).sqrt());
        }
        for seg in pts.windows(2) {
            let (a, b) = (seg[0], seg[1]);
            cov.each_in(&[a, b], hw + 1.0, |x, y| {
                hw + 0.5 - segment_distance((x, y), a, b)
            });
        }
        cov.blend(self.img, colour);
    }

    fn fill_px(&mut self, pts: &[(f64, f64)], colour: Rgba<u8>) {
        if pts.len() < 3 {
            return;
        }
        const N: usize = 4; // samples per axis
        let mut cov = Coverage::around(self.img, pts, 0.0);
        for py in cov.y0..cov.y1 {
            for sub in 0..N {
                let y = py as f64 + (sub as f64 + 0.5) / N as f64;
                let mut xs: Vec<f64> = Vec::new();
                for k in 0..pts.len() {
                    let (a, b) = (pts[k], pts[(k + 1) % pts.len()]);
                    if (a.1 <= y) != (b.1 <= y) {
                        xs.push(a.0 + (y - a.1) / (b.1 - a.1) * (b.0 - a.0));
                    }
                }
                xs.sort_by(f64::total_cmp);
                for span in xs.chunks_exact(2) {
                    // Samples at x = px + (s + 0.5)/N inside [span0, span1).
                    let first = ((span[0] * N as f64 - 0.5).ceil().max(0.0)) as i64;
                    let last = (span[1] * N as f64 - 0.5).ceil() as i64; // exclusive
                    for s in first..last {
                        let px = s.div_euclid(N as i64);
                        cov.add(px, py, 1.0 / (N * N) as f64);
                    }
                }
            }
        }
        cov.blend(self.img, colour);
    }
}

/// Per-pixel coverage over a clipped bounding box; combined by maximum so
/// overlapping segments of one stroke do not darken their joins.
struct Coverage {
    x0: i64,
    y0: i64,
    x1: i64,
    y1: i64,
    data: Vec<f64>,
}

impl Coverage {
    fn around(img: &RgbaImage, pts: &[(f64, f64)], pad: f64) -> Coverage {
        let (w, h) = (img.width() as i64, img.height() as i64);
        let fold = |f: fn(f64, f64) -> f64, init: f64, k: usize| {
            pts.iter()
                .map(|p| if k == 0 { p.0 } else { p.1 })
                .fold(init, f)
        };
        let clampi = |v: f64, hi: i64| -> i64 {
            if v.is_nan() {
                0
            } else {
                (v.clamp(-1.0, hi as f64 + 1.0)) as i64
            }
            .clamp(0, hi)
        };
        let x0 = clampi((fold(f64::min, f64::INFINITY, 0) - pad).floor(), w);
        let x1 = clampi((fold(f64::max, f64::NEG_INFINITY, 0) + pad).ceil() + 1.0, w);
        let y0 = clampi((fold(f64::min, f64::INFINITY, 1) - pad).floor(), h);
        let y1 = clampi((fold(f64::max, f64::NEG_INFINITY, 1) + pad).ceil() + 1.0, h);
        let (x1, y1) = (x1.max(x0), y1.max(y0));
        Coverage {
            x0,
            y0,
            x1,
            y1,
            data: vec![0.0; ((x1 - x0) * (y1 - y0)) as usize],
        }
    }

    /// Coverage of every pixel centre in the box from `f` (clamped to 0..1).
    fn each(&mut self, f: impl Fn(f64, f64) -> f64) {
        let (x0, y0, x1, y1) = (self.x0, self.y0, self.x1, self.y1);
        self.each_box(x0, y0, x1, y1, f);
    }

    /// Like [`Self::each`], limited to the box around `pts` padded by `pad`.
    fn each_in(&mut self, pts: &[(f64, f64)], pad: f64, f: impl Fn(f64, f64) -> f64) {
        let lo = |k: usize| {
            pts.iter()
                .map(|p| if k == 0 { p.0 } else { p.1 })
                .fold(f64::INFINITY, f64::min)
        };
        let hi = |k: usize| {
            pts.iter()
                .map(|p| if k == 0 { p.0 } else { p.1 })
                .fold(f64::NEG_INFINITY, f64::max)
        };
        let cl = |v: f64, a: i64, b: i64| {
            if v.is_nan() {
                a
            } else {
                (v.clamp(a as f64, b as f64)) as i64
            }
        };
        let x0 = cl((lo(0) - pad).floor(), self.x0, self.x1);
        let x1 = cl((hi(0) + pad).ceil() + 1.0, self.x0, self.x1);
        let y0 = cl((lo(1) - pad).floor(), self.y0, self.y1);
        let y1 = cl((hi(1) + pad).ceil() + 1.0, self.y0, self.y1);
        self.each_box(x0, y0, x1, y1, f);
    }

    fn each_box(&mut self, x0: i64, y0: i64, x1: i64, y1: i64, f: impl Fn(f64, f64) -> f64) {
        let w = self.x1 - self.x0;
        for y in y0..y1 {
            for x in x0..x1 {
                let c = f(x as f64 + 0.5, y as f64 + 0.5).clamp(0.0, 1.0);
                let slot = &mut self.data[((y - self.y0) * w + (x - self.x0)) as usize];
                *slot = slot.max(c);
            }
        }
    }

    fn add(&mut self, x: i64, y: i64, c: f64) {
        if (self.x0..self.x1).contains(&x) && (self.y0..self.y1).contains(&y) {
            let w = self.x1 - self.x0;
            let slot = &mut self.data[((y - self.y0) * w + (x - self.x0)) as usize];
            *slot = (*slot + c).min(1.0);
        }
    }

    fn blend(&self, img: &mut RgbaImage, colour: Rgba<u8>) {
        let w = self.x1 - self.x0;
        for (k, &c) in self.data.iter().enumerate() {
            if c > 0.0 {
                let (x, y) = (self.x0 + k as i64 % w, self.y0 + k as i64 / w);
                blend_px(img.get_pixel_mut(x as u32, y as u32), colour, c);
            }
        }
    }
}

/// Source-over with the colour's alpha times `coverage`.
fn blend_px(dst: &mut Rgba<u8>, src: Rgba<u8>, coverage: f64) {
    let a = src[3] as f64 / 255.0 * coverage;
    for c in 0..3 {
        dst[c] = (dst[c] as f64 + (src[c] as f64 - dst[c] as f64) * a).round() as u8;
    }
    dst[3] = (dst[3] as f64 + (255.0 - dst[3] as f64) * a).round() as u8;
}

fn segment_distance(p: (f64, f64), a: (f64, f64), b: (f64, f64)) -> f64 {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (qx, qy) = (a.0 + t * dx, a.1 + t * dy);
    ((p.0 - qx).powi(2) + (p.1 - qy).powi(2)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    const RED: Rgba<u8> = Rgba([255, 0, 0, 255]);

    fn blank(w: u32, h: u32) -> RgbaImage {
        RgbaImage::from_pixel(w, h, Rgba([0, 0, 0, 255]))
    }

    #[test]
    fn point_covers_its_disc_only() {
        let mut img = blank(20, 20);
        Canvas::new(&mut img, 2.0, 2.0).point((5.0, 5.0), 3.0, RED);
        assert_eq!(img.get_pixel(10, 10)[0], 255);
        assert_eq!(img.get_pixel(10, 11)[0], 255);
        assert_eq!(img.get_pixel(10, 16)[0], 0);
        assert_eq!(img.get_pixel(0, 0)[0], 0);
    }

    #[test]
    fn polygon_fill_is_area_exact_on_pixel_edges() {
        let mut img = blank(10, 10);
        let sq = [(2.0, 2.0), (6.0, 2.0), (6.0, 6.0), (2.0, 6.0)];
        Canvas::new(&mut img, 1.0, 1.0).polygon(&sq, Some(RED), None);
        let red: usize = img.pixels().filter(|p| p[0] == 255).count();
        let any: usize = img.pixels().filter(|p| p[0] > 0).count();
        assert_eq!((red, any), (16, 16));
    }

    #[test]
    fn polyline_joins_do_not_double_blend() {
        let mut img = blank(30, 10);
        let half = Rgba([255, 0, 0, 128]);
        Canvas::new(&mut img, 1.0, 1.0).polyline(
            &[(2.0, 5.5), (15.0, 5.5), (28.0, 5.5)],
            1.0,
            half,
        );
        assert_eq!(img.get_pixel(15, 5)[0], img.get_pixel(8, 5)[0]);
        assert!(img.get_pixel(15, 5)[0] > 100);
        assert_eq!(img.get_pixel(15, 8)[0], 0);
    }

    #[test]
    fn region_fill_and_outline() {
        let mut img = blank(8, 8);
        let mut mask = vec![false; 16];
        for j in 1..3 {
            for i in 1..3 {
                mask[j * 4 + i] = true;
            }
        }
        let blue = Rgba([0, 0, 255, 255]);
        Canvas::new(&mut img, 2.0, 2.0).region(&mask, 4, 4, Some(RED), Some(blue));
        assert_eq!(img.get_pixel(2, 2)[2], 255); // edge
        assert_eq!(img.get_pixel(3, 3)[0], 255); // interior
        assert_eq!(img.get_pixel(0, 0).0, [0, 0, 0, 255]);
    }

    #[test]
    fn markers_and_degenerate_input_stay_in_bounds() {
        let mut img = blank(16, 16);
        let mut c = Canvas::new(&mut img, 1.0, 1.0);
        for m in [
            Marker::Cross,
            Marker::Plus,
            Marker::Square,
            Marker::Diamond,
            Marker::Triangle,
            Marker::Ring,
        ] {
            c.marker((8.0, 8.0), m, 9.0, RED);
            c.marker((-50.0, 1e9), m, 9.0, RED);
        }
        c.polyline(&[], 2.0, RED);
        c.polyline(&[(f64::NAN, 1.0), (3.0, f64::INFINITY)], 2.0, RED);
        c.polygon(&[(1.0, 1.0)], Some(RED), Some((RED, 1.0)));
        assert_eq!(img.get_pixel(8, 8)[0], 255);
    }
}
