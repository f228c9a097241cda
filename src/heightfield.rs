//! The `Heightfield`: a regular grid of elevations in metres.
//!
//! Nodata has exactly one representation: a NaN sample. Readers turn every
//! format's void marker (SRTM −32768, GDAL_NODATA, ESRI `NODATA_value`, NaN in
//! EXR) into NaN, so a missing sample can never be silently used as a height:
//! any arithmetic that touches it yields NaN, and [`Heightfield::stats`] and the
//! writers see it. Infinite samples are refused at construction for the same
//! reason. The mask view ([`Heightfield::nodata_mask`]) is derived, not stored,
//! so it cannot disagree with the data.

use crate::georef::Georef;
use crate::size::{SizeError, check_dims};

/// Summary statistics over the valid (non-nodata) samples.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stats {
    pub min: f32,
    pub max: f32,
    pub mean: f64,
    /// Number of valid samples.
    pub valid: usize,
    /// Number of nodata samples.
    pub nodata: usize,
}

/// [`Heightfield::extent`]: the range of the valid samples and how many
/// are nodata.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Extent {
    /// (min, max) of the valid samples; `None` when there are none.
    pub range: Option<(f32, f32)>,
    pub nodata: usize,
}

/// [`Heightfield::first_nodata`]: where the first missing sample is (row
/// order) and how many are missing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FirstNodata {
    pub count: usize,
    pub x: usize,
    pub y: usize,
}

/// A row-major grid of heights in metres; row 0 is north, column 0 is west.
#[derive(Debug, Clone, PartialEq)]
pub struct Heightfield {
    width: usize,
    height: usize,
    cell_size: f64,
    data: Vec<f32>,
    georef: Option<Georef>,
}

impl Heightfield {
    /// A flat grid at 0 m.
    pub fn new(width: usize, height: usize, cell_size: f64) -> Result<Self, SizeError> {
        check_dims(width, height)?;
        check_cell_size(cell_size)?;
        let data = vec![0.0; width * height];
        crate::pages::advise_huge(&data);
        Ok(Self::wrap(width, height, cell_size, data))
    }

    /// The grid of checked dimensions and samples, without a georeference.
    fn wrap(width: usize, height: usize, cell_size: f64, data: Vec<f32>) -> Self {
        Self {
            width,
            height,
            cell_size,
            data,
            georef: None,
        }
    }

    /// Wraps row-major samples. NaN marks nodata; ±∞ is refused because no
    /// format can mean it and it would poison every statistic.
    pub fn from_vec(
        width: usize,
        height: usize,
        cell_size: f64,
        data: Vec<f32>,
    ) -> Result<Self, SizeError> {
        check_dims(width, height)?;
        check_cell_size(cell_size)?;
        if data.len() != width * height {
            return Err(SizeError::Length {
                expected: width * height,
                found: data.len(),
            });
        }
        if let Some(i) = data.iter().position(|v| v.is_infinite()) {
            return Err(SizeError::Infinite {
                x: i % width,
                y: i / width,
            });
        }
        Ok(Self::wrap(width, height, cell_size, data))
    }

    /// Builds a grid from a function of (x, y), evaluated in parallel by row.
    pub fn from_fn(
        width: usize,
        height: usize,
        cell_size: f64,
        f: impl Fn(usize, usize) -> f32 + Sync,
    ) -> Result<Self, SizeError> {
        Self::from_rows(width, height, cell_size, |y, row| {
            for (x, v) in row.iter_mut().enumerate() {
                *v = f(x, y);
            }
        })
    }

    /// Builds a grid row by row, in parallel: `f(y, row)` fills row `y`.
    /// Non-finite values become NaN (no data). For callers that can fill a
    /// row as a slice map, which the compiler vectorizes where a call per
    /// pixel with its own index arithmetic was not (an edit converts the
    /// whole level to metres: ~6 % of its CPU time at 1024² before).
    pub fn from_rows(
        width: usize,
        height: usize,
        cell_size: f64,
        f: impl Fn(usize, &mut [f32]) + Sync,
    ) -> Result<Self, SizeError> {
        use rayon::prelude::*;
        let mut hf = Self::new(width, height, cell_size)?;
        hf.data
            .par_chunks_mut(width)
            .enumerate()
            .for_each(|(y, row)| {
                f(y, row);
                for v in row.iter_mut() {
                    *v = if v.is_finite() { *v } else { f32::NAN };
                }
            });
        Ok(hf)
    }

    pub fn width(&self) -> usize {
        self.width
    }
    pub fn height(&self) -> usize {
        self.height
    }
    /// Cell size (sample spacing) in metres.
    pub fn cell_size(&self) -> f64 {
        self.cell_size
    }
    pub fn set_cell_size(&mut self, cell_size: f64) -> Result<(), SizeError> {
        check_cell_size(cell_size)?;
        self.cell_size = cell_size;
        Ok(())
    }
    /// Where the grid lies on a map, when its file said so (see [`Georef`]).
    pub fn georef(&self) -> Option<&Georef> {
        self.georef.as_ref()
    }
    pub fn set_georef(&mut self, georef: Option<Georef>) {
        self.georef = georef;
    }
    pub fn len(&self) -> usize {
        self.data.len()
    }
    /// Never true: a heightfield has at least one sample.
    pub fn is_empty(&self) -> bool {
        false
    }
    pub fn data(&self) -> &[f32] {
        &self.data
    }
    /// Mutable samples. Writing ±∞ breaks the invariant; use NaN for nodata.
    pub fn data_mut(&mut self) -> &mut [f32] {
        &mut self.data
    }
    pub fn into_vec(self) -> Vec<f32> {
        self.data
    }
    pub fn row(&self, y: usize) -> &[f32] {
        &self.data[y * self.width..(y + 1) * self.width]
    }
    pub fn get(&self, x: usize, y: usize) -> f32 {
        self.data[y * self.width + x]
    }
    pub fn set(&mut self, x: usize, y: usize, v: f32) {
        self.data[y * self.width + x] = v;
    }
    /// Sample with coordinates clamped to the grid (edge replication).
    pub fn get_clamped(&self, x: isize, y: isize) -> f32 {
        let x = x.clamp(0, self.width as isize - 1) as usize;
        let y = y.clamp(0, self.height as isize - 1) as usize;
        self.data[y * self.width + x]
    }

    pub fn is_nodata(&self, x: usize, y: usize) -> bool {
        self.get(x, y).is_nan()
    }
    pub fn nodata_count(&self) -> usize {
        self.extent().nodata
    }
    /// The first missing sample and the count, `None` when none is missing:
    /// what every tool that refuses nodata (eval, water, mesh, erode, the
    /// procedural filters) names in its error, found in one place.
    pub fn first_nodata(&self) -> Option<FirstNodata> {
        let i = self.data.iter().position(|v| v.is_nan())?;
        Some(FirstNodata {
            count: self.nodata_count(),
            x: i % self.width,
            y: i / self.width,
        })
    }
    /// `Some(mask)` (true = nodata) when any sample is missing, else `None`.
    pub fn nodata_mask(&self) -> Option<Vec<bool>> {
        let mask: Vec<bool> = self.data.iter().map(|v| v.is_nan()).collect();
        mask.iter().any(|&m| m).then_some(mask)
    }

    /// The smallest and largest valid heights (`None` when every sample is
    /// nodata) and the nodata count, in one parallel pass. What writers
    /// need before they quantize: [`Heightfield::stats`]' mean is a serial
    /// sum (its rounding depends on the order), and at 1024² its pass,
    /// run on one core after a synthesis that used all of them, was a
    /// visible part of a `synth` process. Min and max do not depend on the
    /// order, so these equal `stats()`'s.
    pub fn extent(&self) -> Extent {
        use rayon::prelude::*;
        let fold = |(mut lo, mut hi, mut nodata): (f32, f32, usize), &v: &f32| {
            if v.is_nan() {
                nodata += 1;
            } else {
                lo = lo.min(v);
                hi = hi.max(v);
            }
            (lo, hi, nodata)
        };
        let empty = (f32::INFINITY, f32::NEG_INFINITY, 0);
        let (lo, hi, nodata) = self
            .data
            .par_chunks(1 << 16)
            .map(|c| c.iter().fold(empty, fold))
            .reduce(|| empty, |a, b| (a.0.min(b.0), a.1.max(b.1), a.2 + b.2));
        Extent {
            range: (nodata < self.data.len()).then_some((lo, hi)),
            nodata,
        }
    }

    /// Min, max and mean over valid samples; `None` when every sample is nodata.
    /// The range and count come from [`Heightfield::extent`]; the mean is
    /// summed in sample order, so its rounding is the same on every run.
    pub fn stats(&self) -> Option<Stats> {
        let Extent { range, nodata } = self.extent();
        let (min, max) = range?;
        let sum: f64 = self
            .data
            .iter()
            .filter(|v| !v.is_nan())
            .map(|&v| v as f64)
            .sum();
        let valid = self.data.len() - nodata;
        Some(Stats {
            min,
            max,
            mean: sum / valid as f64,
            valid,
            nodata,
        })
    }

    /// A borrowed window; fails if it does not lie inside the grid.
    pub fn view(&self, x: usize, y: usize, w: usize, h: usize) -> Result<View<'_>, SizeError> {
        self.check_window(x, y, w, h)?;
        Ok(View {
            hf: self,
            x0: x,
            y0: y,
            width: w,
            height: h,
        })
    }

    /// An owned copy of a window (cell size and shifted georeference kept).
    pub fn crop(&self, x: usize, y: usize, w: usize, h: usize) -> Result<Heightfield, SizeError> {
        self.view(x, y, w, h).map(|v| v.to_heightfield())
    }

    fn check_window(&self, x: usize, y: usize, w: usize, h: usize) -> Result<(), SizeError> {
        crate::size::check_window(x, y, w, h, self.width, self.height)
    }
}

fn check_cell_size(cell_size: f64) -> Result<(), SizeError> {
    if cell_size.is_finite() && cell_size > 0.0 {
        Ok(())
    } else {
        Err(SizeError::CellSize(cell_size))
    }
}

/// A rectangular window of a [`Heightfield`], without copying.
#[derive(Debug, Clone, Copy)]
pub struct View<'a> {
    hf: &'a Heightfield,
    x0: usize,
    y0: usize,
    width: usize,
    height: usize,
}

impl<'a> View<'a> {
    pub fn width(&self) -> usize {
        self.width
    }
    pub fn height(&self) -> usize {
        self.height
    }
    pub fn get(&self, x: usize, y: usize) -> f32 {
        debug_assert!(x < self.width && y < self.height);
        self.hf.get(self.x0 + x, self.y0 + y)
    }
    pub fn row(&self, y: usize) -> &'a [f32] {
        let start = (self.y0 + y) * self.hf.width + self.x0;
        &self.hf.data[start..start + self.width]
    }
    pub fn to_heightfield(&self) -> Heightfield {
        let mut data = Vec::with_capacity(self.width * self.height);
        for y in 0..self.height {
            data.extend_from_slice(self.row(y));
        }
        let georef = self.hf.georef.as_ref().map(|g| g.shifted(self.x0, self.y0));
        Heightfield {
            width: self.width,
            height: self.height,
            cell_size: self.hf.cell_size,
            data,
            georef,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stats_ignore_nodata() {
        let hf = Heightfield::from_vec(2, 2, 1.0, vec![1.0, f32::NAN, 3.0, 5.0]).unwrap();
        let s = hf.stats().unwrap();
        assert_eq!((s.min, s.max, s.valid, s.nodata), (1.0, 5.0, 3, 1));
        assert!((s.mean - 3.0).abs() < 1e-12);
        assert_eq!(hf.nodata_mask().unwrap(), vec![false, true, false, false]);
    }

    #[test]
    fn extent_is_the_range_and_nodata_count_of_stats() {
        // Several parallel chunks (2^16 samples each), nodata in some, the
        // extremes in the last: a chunk left out or misfolded changes it.
        let (w, h) = (700, 300);
        let mut hf = Heightfield::from_fn(w, h, 1.0, |x, y| {
            ((x * 7919 + y * 104_729) % 1000) as f32 * 0.5 - 100.0
        })
        .unwrap();
        for (x, y) in [(3, 0), (699, 150), (10, 299)] {
            hf.set(x, y, f32::NAN);
        }
        hf.set(650, 299, -1234.5);
        hf.set(651, 299, 4321.25);
        let s = hf.stats().unwrap();
        let e = hf.extent();
        assert_eq!(e.range, Some((s.min, s.max)));
        assert_eq!(e.range, Some((-1234.5, 4321.25)));
        assert_eq!(e.nodata, 3);
        let none = Heightfield::from_vec(1, 2, 1.0, vec![f32::NAN; 2]).unwrap();
        assert_eq!(
            none.extent(),
            Extent {
                range: None,
                nodata: 2
            }
        );
    }

    #[test]
    fn all_nodata_has_no_stats() {
        let hf = Heightfield::from_vec(1, 2, 1.0, vec![f32::NAN; 2]).unwrap();
        assert!(hf.stats().is_none());
    }

    #[test]
    fn refuses_bad_sizes_and_values() {
        assert!(matches!(
            Heightfield::new(0, 5, 1.0),
            Err(SizeError::Empty { .. })
        ));
        assert!(matches!(
            Heightfield::new(100_000, 100_000, 1.0),
            Err(SizeError::TooLarge { .. })
        ));
        assert!(matches!(
            Heightfield::from_vec(2, 2, 1.0, vec![0.0; 3]),
            Err(SizeError::Length { .. })
        ));
        assert!(matches!(
            Heightfield::from_vec(2, 1, 1.0, vec![0.0, f32::INFINITY]),
            Err(SizeError::Infinite { x: 1, y: 0 })
        ));
        assert!(matches!(
            Heightfield::new(1, 1, -1.0),
            Err(SizeError::CellSize(_))
        ));
    }

    #[test]
    fn crop_copies_window_and_shifts_georef() {
        let mut hf = Heightfield::from_fn(4, 3, 2.0, |x, y| (x + 10 * y) as f32).unwrap();
        let mut g = Georef::local(3, 2.0);
        (g.origin_x, g.origin_y) = (100.0, 50.0);
        hf.set_georef(Some(g));
        let c = hf.crop(1, 1, 2, 2).unwrap();
        assert_eq!(c.data(), &[11.0, 12.0, 21.0, 22.0]);
        let g = c.georef().unwrap();
        assert_eq!((g.origin_x, g.origin_y), (102.0, 48.0));
        assert!(hf.crop(3, 0, 2, 1).is_err());
        assert_eq!(
            hf.view(0, 2, 4, 1).unwrap().row(0),
            &[20.0, 21.0, 22.0, 23.0]
        );
    }
}
