//! Type paint and freeze masks as per-pixel rasters of the scene's size,
//! from strokes or from images (checked against the scene and database).

use super::*;
use crate::io::type_mask::{NO_TYPE, TypeMask};
use rayon::prelude::*;

/// Pixels whose centre lies within a stroke's radius of its polyline.
pub fn stroke_mask(width: usize, height: usize, strokes: &[&Stroke]) -> Vec<bool> {
    let mut mask = vec![false; width * height];
    paint(width, strokes.iter().map(|s| (*s, true)), &mut mask);
    mask
}

/// Paints `value` of each stroke, in order, onto `out` (rows in parallel).
fn paint<'a, T: Copy + Send + Sync>(
    width: usize,
    strokes: impl Iterator<Item = (&'a Stroke, T)>,
    out: &mut [T],
) {
    let strokes: Vec<(&Stroke, T)> = strokes.collect();
    out.par_chunks_mut(width).enumerate().for_each(|(j, row)| {
        let y = j as f64 + 0.5;
        for (s, value) in &strokes {
            let (lo, hi) = s
                .points
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                    (a.min(p.y), b.max(p.y))
                });
            if y < lo - s.radius_px || y > hi + s.radius_px {
                continue;
            }
            for (i, slot) in row.iter_mut().enumerate() {
                let p = DVec2::new(i as f64 + 0.5, y);
                if distance_to_polyline(p, &s.points) <= s.radius_px {
                    *slot = *value;
                }
            }
        }
    });
}

fn distance_to_polyline(p: DVec2, pts: &[DVec2]) -> f64 {
    if pts.len() == 1 {
        return p.distance(pts[0]);
    }
    pts.windows(2)
        .map(|w| {
            let d = w[1] - w[0];
            let len2 = d.length_squared();
            let u = if len2 > 0.0 {
                ((p - w[0]).dot(d) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            p.distance(w[0] + d * u)
        })
        .fold(f64::INFINITY, f64::min)
}

impl Scene {
    /// The painted type per pixel as database type indices
    /// ([`NO_TYPE`] = unconstrained), or `None` when nothing is painted.
    /// `type_names` are the database's, by index.
    pub fn type_raster(&self, type_names: &[String]) -> Result<Option<Vec<u8>>, SceneError> {
        let known = || {
            if type_names.is_empty() {
                "no types".to_string()
            } else {
                type_names.join(", ")
            }
        };
        let index_of = |name: &str, path: String| -> Result<u8, SceneError> {
            type_names
                .iter()
                .position(|n| n == name)
                .map(|i| i as u8)
                .ok_or_else(|| {
                    self.err(
                        path,
                        SceneErrorKind::UnknownType {
                            name: name.to_string(),
                            known: known(),
                        },
                    )
                })
        };
        let (w, h) = (self.width, self.height);
        match &self.types {
            None => Ok(None),
            Some(TypePaint::Strokes(strokes)) => {
                let mut values = Vec::with_capacity(strokes.len());
                for (i, (name, s)) in strokes.iter().enumerate() {
                    values.push((s, index_of(name, format!("types.strokes[{i}].type"))?));
                }
                let mut out = vec![NO_TYPE; w * h];
                paint(w, values.into_iter(), &mut out);
                Ok(Some(out))
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

    /// The frozen pixels, or `None` when nothing is frozen.
    pub fn freeze_raster(&self) -> Result<Option<Vec<bool>>, SceneError> {
        match &self.freeze {
            None => Ok(None),
            Some(Freeze::Strokes(s)) => Ok(Some(stroke_mask(
                self.width,
                self.height,
                &s.iter().collect::<Vec<_>>(),
            ))),
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
