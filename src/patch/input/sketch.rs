//! Sketch input (issue 7 §1): where the user wants ridges and valleys.
//!
//! Two forms, one meaning — a signed "elevation-like" field in `[-1, 1]`:
//! - an **image** (8- or 16-bit grey PNG): mid-grey = no preference, white
//!   strokes = ridges, black strokes = valleys. A smooth grey-level
//!   elevation sketch as in Zhou et al. (seed 001 §3: "gray-scale values in
//!   the sketch map are treated as elevation values") means the same thing.
//! - **JSON polylines**:
//!   `{"width": W, "height": H, "strokes": [{"kind": "ridge"|"valley",
//!   "width": PX, "points": [[x, y], ...]}, ...]}` in the sketch's own pixel
//!   frame; each stroke is drawn as a cone of its width (crest on the
//!   centre line, so PPA finds the line itself and not a plateau).
//!
//! Either is resampled to the output size before feature extraction.

use serde::Deserialize;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Largest sketch side accepted (same bound as the CLI's `--size`).
pub const MAX_SIDE: usize = 65535;
/// Most points over all strokes of a JSON sketch.
pub const MAX_POINTS: usize = 1 << 20;

/// Why a sketch could not be read.
#[non_exhaustive]
#[derive(Debug, Error)]
pub enum SketchError {
    #[error("{path}: cannot read the sketch: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: not a sketch JSON: {message}")]
    Json { path: PathBuf, message: String },
    #[error("{path}: {field} = {value} is out of range: expected {allowed}")]
    Range {
        path: PathBuf,
        field: String,
        value: String,
        allowed: &'static str,
    },
    #[error("{path}: not a readable sketch image: {message}")]
    Image { path: PathBuf, message: String },
}

/// Ridge (high) or valley (low).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    Ridge,
    Valley,
}

/// One polyline stroke.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stroke {
    pub kind: Kind,
    /// Stroke width in sketch pixels.
    pub width: f32,
    pub points: Vec<[f32; 2]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonSketch {
    width: usize,
    height: usize,
    strokes: Vec<Stroke>,
}

/// A parsed sketch.
#[derive(Debug, Clone, PartialEq)]
pub enum Sketch {
    /// Polylines in a `width × height` frame.
    Strokes {
        width: usize,
        height: usize,
        strokes: Vec<Stroke>,
    },
    /// A grey image already mapped to `[-1, 1]` (0 = mid-grey).
    Image {
        width: usize,
        height: usize,
        values: Vec<f32>,
    },
}

impl Sketch {
    /// Reads a sketch: `.json` as polylines, anything else as an image.
    pub fn read(path: &Path) -> Result<Sketch, SketchError> {
        let bytes = std::fs::read(path).map_err(|source| SketchError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        let is_json = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"));
        if is_json {
            Sketch::from_json(&bytes, path)
        } else {
            Sketch::from_image(&bytes, path)
        }
    }

    /// Parses JSON polylines; `path` only names the input in errors.
    pub fn from_json(bytes: &[u8], path: &Path) -> Result<Sketch, SketchError> {
        let s: JsonSketch = serde_json::from_slice(bytes).map_err(|e| SketchError::Json {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        let range = |field: String, value: String, allowed| SketchError::Range {
            path: path.to_path_buf(),
            field,
            value,
            allowed,
        };
        for (f, v) in [("width", s.width), ("height", s.height)] {
            if !(1..=MAX_SIDE).contains(&v) {
                return Err(range(f.into(), v.to_string(), "1..=65535"));
            }
        }
        let total: usize = s.strokes.iter().map(|k| k.points.len()).sum();
        if total > MAX_POINTS {
            return Err(range(
                "strokes[*].points (total)".into(),
                total.to_string(),
                "at most 1048576 points",
            ));
        }
        let lim = 4.0 * s.width.max(s.height) as f32;
        for (i, k) in s.strokes.iter().enumerate() {
            if !(k.width.is_finite() && k.width > 0.0 && k.width <= lim) {
                return Err(range(
                    format!("strokes[{i}].width"),
                    k.width.to_string(),
                    "a finite width > 0 and at most 4x the sketch's larger side",
                ));
            }
            if k.points.is_empty() {
                return Err(range(
                    format!("strokes[{i}].points"),
                    "[]".into(),
                    "at least one point",
                ));
            }
            for (j, p) in k.points.iter().enumerate() {
                if !p.iter().all(|c| c.is_finite() && c.abs() <= lim) {
                    return Err(range(
                        format!("strokes[{i}].points[{j}]"),
                        format!("{p:?}"),
                        "finite coordinates within 4x the sketch's size",
                    ));
                }
            }
        }
        Ok(Sketch::Strokes {
            width: s.width,
            height: s.height,
            strokes: s.strokes,
        })
    }

    /// Decodes a grey (or colour, converted to luma) PNG; 8- and 16-bit.
    pub fn from_image(bytes: &[u8], path: &Path) -> Result<Sketch, SketchError> {
        let err = |message: String| SketchError::Image {
            path: path.to_path_buf(),
            message,
        };
        let reader = image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| err(e.to_string()))?;
        let (w, h) = reader.into_dimensions().map_err(|e| err(e.to_string()))?;
        let (w, h) = (w as usize, h as usize);
        if !(1..=MAX_SIDE).contains(&w) || !(1..=MAX_SIDE).contains(&h) || w * h > 1 << 28 {
            return Err(err(format!(
                "size {w}x{h}: expected each side in 1..=65535 and at most 2^28 pixels"
            )));
        }
        let img = image::load_from_memory(bytes).map_err(|e| err(e.to_string()))?;
        let grey = img.to_luma16();
        let values = grey
            .into_raw()
            .into_iter()
            .map(|v| (v as f32 / 65535.0) * 2.0 - 1.0)
            .collect();
        Ok(Sketch::Image {
            width: w,
            height: h,
            values,
        })
    }

    /// The sketch's own size.
    pub fn size(&self) -> (usize, usize) {
        match self {
            Sketch::Strokes { width, height, .. } | Sketch::Image { width, height, .. } => {
                (*width, *height)
            }
        }
    }

    /// The signed field at `w × h` (`+1` ridge crest, `-1` valley floor).
    pub fn raster(&self, w: usize, h: usize) -> Vec<f32> {
        match self {
            Sketch::Image {
                width,
                height,
                values,
            } => {
                if (*width, *height) == (w, h) {
                    return values.clone();
                }
                // Values are finite and the sizes valid (checked on reading).
                let hf = crate::Heightfield::from_vec(*width, *height, 1.0, values.clone())
                    .and_then(|hf| crate::resample::resample(&hf, w, h));
                hf.map(|hf| hf.into_vec())
                    .unwrap_or_else(|_| vec![0.0; w * h])
            }
            Sketch::Strokes { strokes, .. } => {
                let s = Scale::new(self.size(), (w, h));
                let scale = (s.sx * s.sy).sqrt();
                let mut hi = vec![0.0f32; w * h];
                let mut lo = vec![0.0f32; w * h];
                for k in strokes {
                    let pts = s.points(k);
                    let hw = (k.width * scale * 0.5).max(1.0);
                    let target = match k.kind {
                        Kind::Ridge => &mut hi,
                        Kind::Valley => &mut lo,
                    };
                    draw_cone(target, w, h, &pts, hw);
                }
                hi.iter().zip(&lo).map(|(a, b)| a - b).collect()
            }
        }
    }
}

/// From a stroke sketch's pixels to the output's, per axis.
struct Scale {
    sx: f32,
    sy: f32,
}

impl Scale {
    fn new((width, height): (usize, usize), (w, h): (usize, usize)) -> Scale {
        Scale {
            sx: w as f32 / width as f32,
            sy: h as f32 / height as f32,
        }
    }

    /// A stroke's points in output pixels.
    fn points(&self, k: &Stroke) -> Vec<[f32; 2]> {
        k.points
            .iter()
            .map(|p| [p[0] * self.sx, p[1] * self.sy])
            .collect()
    }
}

/// Draws `max(v, 1 − (d / hw)²)` around a polyline (d = distance to it).
fn draw_cone(out: &mut [f32], w: usize, h: usize, pts: &[[f32; 2]], hw: f32) {
    let segs: Vec<([f32; 2], [f32; 2])> = if pts.len() == 1 {
        vec![(pts[0], pts[0])]
    } else {
        pts.windows(2).map(|p| (p[0], p[1])).collect()
    };
    for (a, b) in segs {
        let x0 = (a[0].min(b[0]) - hw).floor().max(0.0) as usize;
        let x1 = ((a[0].max(b[0]) + hw).ceil().max(0.0) as usize).min(w);
        let y0 = (a[1].min(b[1]) - hw).floor().max(0.0) as usize;
        let y1 = ((a[1].max(b[1]) + hw).ceil().max(0.0) as usize).min(h);
        for y in y0..y1 {
            for x in x0..x1 {
                let p = [x as f32 + 0.5, y as f32 + 0.5];
                let d = seg_dist(p, a, b);
                let v = 1.0 - (d / hw) * (d / hw);
                let o = &mut out[y * w + x];
                if v > *o {
                    *o = v;
                }
            }
        }
    }
}

/// Distance from `p` to segment `ab`.
pub(crate) fn seg_dist(p: [f32; 2], a: [f32; 2], b: [f32; 2]) -> f32 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (ex, ey) = (a[0] + t * dx - p[0], a[1] + t * dy - p[1]);
    (ex * ex + ey * ey).sqrt()
}

/// Pixels within `radius` of a stroke of `kind`, at output size `w × h`
/// (for measuring feature adherence). Image sketches use the sign of the
/// field beyond ±0.25 instead.
pub fn stroke_mask(sketch: &Sketch, kind: Kind, w: usize, h: usize, radius: f32) -> Vec<bool> {
    match sketch {
        Sketch::Image { .. } => {
            let f = sketch.raster(w, h);
            f.iter()
                .map(|&v| match kind {
                    Kind::Ridge => v > 0.25,
                    Kind::Valley => v < -0.25,
                })
                .collect()
        }
        Sketch::Strokes { strokes, .. } => {
            let s = Scale::new(sketch.size(), (w, h));
            let mut m = vec![0.0f32; w * h];
            for k in strokes.iter().filter(|k| k.kind == kind) {
                draw_cone(&mut m, w, h, &s.points(k), radius.max(0.5));
            }
            m.iter().map(|&v| v > 0.0).collect()
        }
    }
}
