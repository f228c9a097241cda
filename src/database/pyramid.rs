//! Exemplar pyramids E⁰..E^L (paper §4: a pyramid, not a Gaussian stack, so
//! memory is O(N)) and the one height quantization shared by the database.

use serde::{Deserialize, Serialize};

/// A plain float grid (one exemplar at one level), heights in metres.
#[derive(Debug, Clone)]
pub struct Grid {
    pub width: usize,
    pub height: usize,
    pub data: Vec<f32>,
}

impl Grid {
    #[inline(always)]
    pub fn get_clamped(&self, x: isize, y: isize) -> f32 {
        let x = x.clamp(0, self.width as isize - 1) as usize;
        let y = y.clamp(0, self.height as isize - 1) as usize;
        self.data[y * self.width + x]
    }

    /// E^{i+1}: each texel the mean of its 2×2 children; an odd last row or
    /// column is dropped (`w^{i+1} = ⌊w^i / 2⌋`), matching the layout's sizes.
    pub fn downsample(&self) -> Grid {
        let (w, h) = (self.width / 2, self.height / 2);
        let mut data = Vec::with_capacity(w * h);
        for y in 0..h {
            for x in 0..w {
                let i = 2 * y * self.width + 2 * x;
                let s = self.data[i] as f64
                    + self.data[i + 1] as f64
                    + self.data[i + self.width] as f64
                    + self.data[i + self.width + 1] as f64;
                data.push((s * 0.25) as f32);
            }
        }
        Grid {
            width: w,
            height: h,
            data,
        }
    }
}

/// Float pyramid of one exemplar, levels `0..=levels`.
pub fn pyramid(base: Grid, levels: usize) -> Vec<Grid> {
    let mut out = vec![base];
    for _ in 0..levels {
        let next = out.last().expect("non-empty").downsample();
        out.push(next);
    }
    out
}

/// The database's one height scale: `h_m = offset_m + scale_m · u`, with
/// `u` a 16-bit unit. Shared by every exemplar so that heights from different
/// sources compare directly, and by synthesis offsets V (which may leave
/// 0..65535: they are i32).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Quantization {
    pub offset_m: f64,
    pub scale_m: f64,
}

impl Quantization {
    /// Spreads `[min, max]` over the 16-bit range. A flat database gets a
    /// nominal 1 mm scale so that offsets still mean something.
    pub fn spanning(min: f64, max: f64) -> Quantization {
        let scale_m = if max > min {
            (max - min) / 65535.0
        } else {
            1e-3
        };
        Quantization {
            offset_m: min,
            scale_m,
        }
    }
    /// Metres → (fractional) units.
    #[inline(always)]
    pub fn units(&self, m: f64) -> f64 {
        (m - self.offset_m) / self.scale_m
    }
    /// Units → metres.
    #[inline(always)]
    pub fn metres(&self, u: f64) -> f64 {
        self.offset_m + self.scale_m * u
    }
    /// Metres → the nearest 16-bit unit.
    pub fn quantize(&self, m: f64) -> u16 {
        self.units(m).round().clamp(0.0, 65535.0) as u16
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn downsample_averages_blocks_and_drops_odd_edges() {
        let g = Grid {
            width: 5,
            height: 3,
            data: (0..15).map(|v| v as f32).collect(),
        };
        let d = g.downsample();
        assert_eq!((d.width, d.height), (2, 1));
        assert_eq!(d.data, vec![3.0, 5.0]);
        assert_eq!(pyramid(g, 1).len(), 2);
    }

    #[test]
    fn quantization_error_is_half_a_unit() {
        let q = Quantization::spanning(-17.0, 3564.0);
        for i in 0..1000 {
            let m = -17.0 + i as f64 * 3.581;
            let back = q.metres(q.quantize(m) as f64);
            assert!((back - m).abs() <= q.scale_m * 0.5 + 1e-9);
        }
    }
}
