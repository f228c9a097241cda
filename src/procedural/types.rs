//! Terrain-type masks derived from the terrain itself, for type painting
//! (seed 003 §5.2): each pixel gets one of [`TerrainType`], from slope and
//! topographic position, then a majority filter merges the classes into
//! contiguous regions.
//!
//! Files follow the layout of the shared DEMs' masks: `<name>_types.png`
//! (8-bit greyscale, one type index per pixel, same size as the DEM) and
//! `<name>_types.json` (`dem`, `types` index → name, `present`, `fractions`,
//! `method`).

use super::grid::sweep;
use crate::heightfield::Heightfield;
use crate::io::{IoError, write_atomic};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The terrain types of the procedural styles' masks; the discriminant is
/// the pixel value.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum TerrainType {
    /// Crests and spurs: clearly above the surrounding terrain.
    Ridge = 0,
    /// Hillsides: everything neither high, low, flat nor cliff.
    Slope = 1,
    /// Valley and canyon bottoms: clearly below the surroundings and not steep.
    ValleyFloor = 2,
    /// Flat ground that is not in a valley: mesa tops, benches, high flats.
    Plateau = 3,
    /// Walls steeper than 45°.
    Cliff = 4,
}

impl TerrainType {
    pub const ALL: [TerrainType; 5] = [
        TerrainType::Ridge,
        TerrainType::Slope,
        TerrainType::ValleyFloor,
        TerrainType::Plateau,
        TerrainType::Cliff,
    ];

    pub fn name(self) -> &'static str {
        match self {
            TerrainType::Ridge => "ridge",
            TerrainType::Slope => "slope",
            TerrainType::ValleyFloor => "valley floor",
            TerrainType::Plateau => "plateau",
            TerrainType::Cliff => "cliff",
        }
    }
}

/// Thresholds of [`TypeClassification::classify`]. Slopes are rise over run; the
/// topographic position `z` is the height above the mean of a disc-like
/// window of radius `window_m`, in units of the local relief (the standard
/// deviation of height in that window, at least `min_relief_m`).
const CLIFF_SLOPE: f64 = 1.0;
const FLAT_SLOPE: f64 = 0.1;
const VALLEY_SLOPE: f64 = 0.5;
const RIDGE_Z: f64 = 0.6;
const VALLEY_Z: f64 = -0.6;
const PLATEAU_MIN_Z: f64 = -0.5;
const WINDOW_M: f64 = 600.0;
const MIN_RELIEF_M: f64 = 15.0;
/// Majority filter: window radius in pixels and number of passes.
const MAJORITY_RADIUS: usize = 3;
const MAJORITY_PASSES: usize = 3;

/// A terrain classified from its own heights: one [`TerrainType`] per
/// pixel (the discriminant), what [`TypeClassification::classify`] finds.
/// It is written in the shared DEMs' mask layout, and reads back as the
/// general mask of any type indices and names, [`crate::io::TypeMask`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TypeClassification {
    width: usize,
    height: usize,
    data: Vec<u8>,
}

/// Box sums over a grid by a summed-area table (sequential, so exact order).
struct BoxSum {
    width: usize,
    height: usize,
    table: Vec<f64>,
}

impl BoxSum {
    fn new(values: &[f64], width: usize, height: usize) -> BoxSum {
        let stride = width + 1;
        let mut table = vec![0.0; stride * (height + 1)];
        for y in 0..height {
            let mut row = 0.0;
            for x in 0..width {
                row += values[y * width + x];
                table[(y + 1) * stride + x + 1] = table[y * stride + x + 1] + row;
            }
        }
        BoxSum {
            width,
            height,
            table,
        }
    }

    /// Mean over the window of radius `r` around (x, y), clipped to the grid.
    fn mean(&self, x: usize, y: usize, r: usize) -> f64 {
        let (x0, y0) = (x.saturating_sub(r), y.saturating_sub(r));
        let (x1, y1) = ((x + r + 1).min(self.width), (y + r + 1).min(self.height));
        let s = self.width + 1;
        let t = &self.table;
        let sum = t[y1 * s + x1] - t[y0 * s + x1] - t[y1 * s + x0] + t[y0 * s + x0];
        sum / ((x1 - x0) * (y1 - y0)) as f64
    }
}

impl TypeClassification {
    pub fn width(&self) -> usize {
        self.width
    }
    pub fn height(&self) -> usize {
        self.height
    }
    pub fn data(&self) -> &[u8] {
        &self.data
    }
    pub fn get(&self, x: usize, y: usize) -> TerrainType {
        TerrainType::ALL[self.data[y * self.width + x] as usize]
    }

    /// Classifies every pixel of a heightfield without nodata (nodata
    /// pixels count as slope). The rules, in order: slope ≥ 1 is cliff;
    /// slope < 0.1 with `z > −0.5` is plateau; `z < −0.6` with slope < 0.5
    /// is valley floor; `z > 0.6` is ridge; the rest is slope. Slope is taken
    /// from a 3×3 mean to ignore single-pixel roughness. Then three passes of
    /// a 7×7 majority filter turn the classes into regions.
    pub fn classify(hf: &Heightfield) -> TypeClassification {
        let (w, h) = (hf.width(), hf.height());
        let cell = hf.cell_size();
        let heights: Vec<f64> = hf
            .data()
            .iter()
            .map(|&v| if v.is_nan() { 0.0 } else { v as f64 })
            .collect();
        let squares: Vec<f64> = heights.iter().map(|v| v * v).collect();
        let sums = BoxSum::new(&heights, w, h);
        let sq_sums = BoxSum::new(&squares, w, h);
        let mut smooth = vec![0.0; w * h];
        sweep(&mut smooth, w, |x, y| sums.mean(x, y, 1));
        let radius = ((WINDOW_M / cell) as usize).max(2);
        let mut data = vec![0u8; w * h];
        sweep(&mut data, w, |x, y| {
            if hf.get(x, y).is_nan() {
                return TerrainType::Slope as u8;
            }
            let at = |dx: isize, dy: isize| {
                let xx = x.saturating_add_signed(dx).min(w - 1);
                let yy = y.saturating_add_signed(dy).min(h - 1);
                smooth[yy * w + xx]
            };
            let gx = (at(1, 0) - at(-1, 0)) / (2.0 * cell);
            let gy = (at(0, 1) - at(0, -1)) / (2.0 * cell);
            let slope = (gx * gx + gy * gy).sqrt();
            let mean = sums.mean(x, y, radius);
            let var = (sq_sums.mean(x, y, radius) - mean * mean).max(0.0);
            let z = (smooth[y * w + x] - mean) / var.sqrt().max(MIN_RELIEF_M);
            let t = if slope >= CLIFF_SLOPE {
                TerrainType::Cliff
            } else if slope < FLAT_SLOPE && z > PLATEAU_MIN_Z {
                TerrainType::Plateau
            } else if z < VALLEY_Z && slope < VALLEY_SLOPE {
                TerrainType::ValleyFloor
            } else if z > RIDGE_Z {
                TerrainType::Ridge
            } else {
                TerrainType::Slope
            };
            t as u8
        });
        let mut mask = TypeClassification {
            width: w,
            height: h,
            data,
        };
        for _ in 0..MAJORITY_PASSES {
            mask = mask.majority(MAJORITY_RADIUS);
        }
        mask
    }

    /// Each pixel takes the most frequent type in its (2r+1)² window; on a
    /// tie it keeps its own type if that is among the most frequent, else the
    /// lowest index.
    fn majority(&self, r: usize) -> TypeClassification {
        let (w, h) = (self.width, self.height);
        let mut data = vec![0u8; w * h];
        sweep(&mut data, w, |x, y| {
            let mut counts = [0u32; TerrainType::ALL.len()];
            for yy in y.saturating_sub(r)..(y + r + 1).min(h) {
                for &t in &self.data[yy * w + x.saturating_sub(r)..yy * w + (x + r + 1).min(w)] {
                    counts[t as usize] += 1;
                }
            }
            let own = self.data[y * w + x];
            let best = *counts.iter().max().expect("non-empty");
            if counts[own as usize] == best {
                own
            } else {
                counts.iter().position(|&c| c == best).expect("max exists") as u8
            }
        });
        TypeClassification {
            width: w,
            height: h,
            data,
        }
    }

    /// Number of pixels of each type, indexed by type.
    pub fn counts(&self) -> [usize; TerrainType::ALL.len()] {
        let mut c = [0; TerrainType::ALL.len()];
        for &t in &self.data {
            c[t as usize] += 1;
        }
        c
    }

    /// The mask as an 8-bit greyscale PNG.
    pub fn encode_png(&self) -> Vec<u8> {
        let mut out = Vec::new();
        let mut enc = png::Encoder::new(&mut out, self.width as u32, self.height as u32);
        enc.set_color(png::ColorType::Grayscale);
        enc.set_depth(png::BitDepth::Eight);
        let mut writer = enc
            .write_header()
            .expect("writing a PNG header to memory cannot fail");
        writer
            .write_image_data(&self.data)
            .expect("the buffer has exactly width × height bytes");
        drop(writer);
        out
    }

    /// The JSON description, in the layout of `../shared/dem/*_types.json`.
    pub fn encode_json(&self, dem_file: &str, method: &str) -> Vec<u8> {
        #[derive(Serialize)]
        struct Sidecar<'a> {
            dem: &'a str,
            types: BTreeMap<String, &'static str>,
            present: BTreeMap<String, &'static str>,
            fractions: BTreeMap<&'static str, f64>,
            method: &'a str,
        }
        let counts = self.counts();
        let total = self.data.len() as f64;
        let all = TerrainType::ALL
            .iter()
            .map(|t| (format!("{}", *t as u8), t.name()));
        let present = TerrainType::ALL.iter().filter(|t| counts[**t as usize] > 0);
        let sidecar = Sidecar {
            dem: dem_file,
            types: all.collect(),
            present: present
                .clone()
                .map(|t| (format!("{}", *t as u8), t.name()))
                .collect(),
            fractions: present
                .map(|t| {
                    (
                        t.name(),
                        (counts[*t as usize] as f64 * 1000.0 / total).round() / 1000.0,
                    )
                })
                .collect(),
            method,
        };
        let mut s = serde_json::to_vec_pretty(&sidecar).expect("plain data always serializes");
        s.push(b'\n');
        s
    }

    /// `<stem>_types.png` beside a DEM file; its JSON is the same with `.json`.
    pub fn path_for(dem: &Path) -> PathBuf {
        let stem = dem
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        dem.with_file_name(format!("{stem}_types.png"))
    }

    /// Writes `<stem>_types.png` and `<stem>_types.json` beside `dem` (atomically).
    pub fn write_beside(&self, dem: &Path, method: &str) -> Result<(), IoError> {
        let png_path = Self::path_for(dem);
        let dem_name = dem
            .file_name()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        write_atomic(
            &png_path.with_extension("json"),
            &self.encode_json(&dem_name, method),
        )?;
        write_atomic(&png_path, &self.encode_png())
    }
}
