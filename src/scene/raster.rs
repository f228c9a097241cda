//! Type paint and freeze masks as per-pixel rasters of the scene's size,
//! from strokes or from images (checked against the scene and database).

use super::*;
use crate::io::maps::type_mask::{NO_TYPE, TypeMask};
use crate::synth::cone::Rect;
use rayon::prelude::*;

/// Pixels whose centre lies within a stroke's radius of its polyline.
pub fn stroke_mask(width: usize, height: usize, strokes: &[&Stroke]) -> Vec<bool> {
    let mut mask = vec![false; width * height];
    paint(
        Rect::new(0, 0, width, height),
        strokes.iter().map(|s| (*s, true)),
        &mut mask,
    );
    mask
}

/// Paints `value` of each stroke, in order, onto `out`, the pixels of
/// `rect` (the whole scene, or a window's footprint; rows in parallel):
/// a pixel takes the value of the last stroke whose polyline comes within
/// its radius of the pixel's centre. Each row visits only the segments
/// whose capsule (bounding box grown by the radius) crosses it, and only
/// the columns of that box, so an editor that repaints every stroke of a
/// scene on every edit pays for the strokes' area, not the image's.
fn paint<'a, T: Copy + Send + Sync>(
    rect: Rect,
    strokes: impl Iterator<Item = (&'a Stroke, T)>,
    out: &mut [T],
) {
    let width = rect.width();
    // Per segment (a one-point stroke is one degenerate segment): its ends,
    // the stroke's radius and value, and its capsule's bounds.
    struct Seg<T> {
        a: DVec2,
        b: DVec2,
        r: f64,
        value: T,
        lo: DVec2,
        hi: DVec2,
    }
    let segs: Vec<Seg<T>> = strokes
        .flat_map(|(s, value)| {
            let pairs: Vec<(DVec2, DVec2)> = if s.points.len() == 1 {
                vec![(s.points[0], s.points[0])]
            } else {
                s.points.windows(2).map(|w| (w[0], w[1])).collect()
            };
            let r = s.radius_px;
            pairs.into_iter().map(move |(a, b)| Seg {
                a,
                b,
                r,
                value,
                lo: a.min(b) - DVec2::splat(r),
                hi: a.max(b) + DVec2::splat(r),
            })
        })
        .collect();
    let (left, right) = (rect.x0 as f64, rect.x1 as f64);
    out.par_chunks_mut(width).enumerate().for_each(|(j, row)| {
        let y = (rect.y0 + j) as f64 + 0.5;
        for s in segs.iter().filter(|s| y >= s.lo.y && y <= s.hi.y) {
            // Pixel centres i + 0.5 in [lo.x, hi.x], inside the rectangle.
            let x0 = (s.lo.x - 0.5).ceil().clamp(left, right) as usize - rect.x0;
            let x1 = ((s.hi.x - 0.5).floor() + 1.0).clamp(left, right) as usize - rect.x0;
            for (i, slot) in row.iter_mut().enumerate().take(x1).skip(x0) {
                let x = (rect.x0 + i) as f64 + 0.5;
                if segment_distance(DVec2::new(x, y), s.a, s.b) <= s.r {
                    *slot = s.value;
                }
            }
        }
    });
}

/// The pixels of `rect` painted by `strokes` in order over `blank`.
pub(crate) fn paint_strokes<T: Copy + Send + Sync>(
    rect: Rect,
    strokes: &[(Stroke, T)],
    blank: T,
) -> Vec<T> {
    let mut out = vec![blank; rect.pixels()];
    paint(rect, strokes.iter().map(|(s, v)| (s, *v)), &mut out);
    out
}

/// Distance from `p` to the segment `a`–`b` (a point when they coincide).
fn segment_distance(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    p.distance(a + (b - a) * crate::synth::control::curve::segments::closest_param(p, a, b))
}

impl Scene {
    /// The painted type per pixel as database type indices
    /// ([`NO_TYPE`] = unconstrained), or `None` when nothing is painted.
    /// `type_names` are the database's, by index.
    pub fn type_raster(&self, type_names: &[String]) -> Result<Option<Vec<u8>>, SceneError> {
        let index_of = |name: &str, path: String| self.type_index(type_names, name, path);
        let (w, h) = (self.width, self.height);
        match &self.types {
            None => Ok(None),
            Some(TypePaint::Strokes(_)) => {
                let strokes = self.type_strokes(type_names)?.unwrap_or_default();
                Ok(Some(paint_strokes(
                    Rect::new(0, 0, w, h),
                    &strokes,
                    NO_TYPE,
                )))
            }
            Some(TypePaint::Image(path)) => {
                let mask = TypeMask::read(path).map_err(|e| self.err("types.image", e.into()))?;
                self.check_size("types.image", mask.width, mask.height)?;
                // The image's own index → the database's index, by name.
                let mut map = [NO_TYPE; 256];
                for i in mask.present() {
                    map[i as usize] = index_of(&mask.name_of(i), "types.image".to_string())?;
                }
                Ok(Some(
                    mask.indices.iter().map(|&i| map[i as usize]).collect(),
                ))
            }
        }
    }

    /// The database index of type `name` (`path` locates it in the scene).
    fn type_index(
        &self,
        type_names: &[String],
        name: &str,
        path: String,
    ) -> Result<u8, SceneError> {
        let known = match type_names.is_empty() {
            true => "no types".to_string(),
            false => type_names.join(", "),
        };
        (type_names.iter().position(|n| n == name))
            .map(|i| i as u8)
            .ok_or_else(|| {
                self.err(
                    path,
                    SceneErrorKind::UnknownType {
                        name: name.to_string(),
                        known,
                    },
                )
            })
    }

    /// Stroke-form type paint with database type indices ([`NO_TYPE`] for
    /// an eraser), or `None` when the paint is not strokes.
    pub(crate) fn type_strokes(
        &self,
        type_names: &[String],
    ) -> Result<Option<Vec<(Stroke, u8)>>, SceneError> {
        let Some(TypePaint::Strokes(strokes)) = &self.types else {
            return Ok(None);
        };
        let mut values = Vec::with_capacity(strokes.len());
        for (i, (name, s)) in strokes.iter().enumerate() {
            let value = match name {
                Some(name) => {
                    self.type_index(type_names, name, format!("types.strokes[{i}].type"))?
                }
                None => NO_TYPE,
            };
            values.push((s.clone(), value));
        }
        Ok(Some(values))
    }

    /// The frozen pixels, or `None` when nothing is frozen.
    pub fn freeze_raster(&self) -> Result<Option<Vec<bool>>, SceneError> {
        match &self.freeze {
            None => Ok(None),
            Some(Freeze::Strokes(s)) => {
                let mut out = vec![false; self.width * self.height];
                let all = Rect::new(0, 0, self.width, self.height);
                paint(all, s.iter().map(|(v, s)| (s, *v)), &mut out);
                Ok(Some(out))
            }
            Some(Freeze::Mask(path)) => {
                // An 8-bit greyscale PNG, like a type mask; any value ≠ 0 freezes.
                let mask = TypeMask::read(path).map_err(|e| self.err("freeze.mask", e.into()))?;
                self.check_size("freeze.mask", mask.width, mask.height)?;
                Ok(Some(mask.indices.iter().map(|&v| v != 0).collect()))
            }
        }
    }

    fn check_size(&self, path: &str, width: usize, height: usize) -> Result<(), SceneError> {
        if (width, height) != (self.width, self.height) {
            return Err(self.err(
                path,
                SceneErrorKind::MaskSize {
                    width,
                    height,
                    scene_width: self.width,
                    scene_height: self.height,
                },
            ));
        }
        Ok(())
    }
}
