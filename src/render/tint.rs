//! Hypsometric tint: colour by elevation, quantized once into the look-up
//! table the `shade` kernel indexes.
//!
//! The natural palette follows the printed-atlas convention (lowland greens,
//! then yellow-tans and browns, rock greys, snow). It is stretched over the
//! terrain's relief but never over less than [`MIN_SPAN_M`], so a 300 m
//! plain stays green instead of being painted up to snow: the colours keep a
//! rough sense of absolute scale, which the paper (§3) names as the hard
//! part of judging isolated terrain.

/// The smallest height span the land palette is stretched over, in metres.
pub const MIN_SPAN_M: f64 = 1500.0;
/// Entries in the tint table. At 1500–3000 m spans one entry is 1.5–3 m, far
/// below what the eye can tell apart after shading.
pub const LUT_LEN: usize = 1024;
/// Water at sea level and at depth (sRGB).
pub const WATER_SHALLOW: [u8; 3] = [168, 204, 228];
pub const WATER_DEEP: [u8; 3] = [70, 120, 176];
/// The depth at which water reaches [`WATER_DEEP`] is the data's own depth,
/// but at least this (so a few metres of SRTM ringing stay shallow).
pub const MIN_WATER_DEPTH_M: f64 = 200.0;

/// Colour stops over `t` in `[0, 1]`, interpolated linearly in sRGB.
#[derive(Debug, Clone, PartialEq)]
pub struct Palette {
    stops: Vec<(f64, [u8; 3])>,
}

impl Palette {
    /// Stops must be sorted by `t`, start at 0 and end at 1.
    pub fn new(stops: Vec<(f64, [u8; 3])>) -> Option<Palette> {
        let ok = stops.len() >= 2
            && stops.first()?.0 == 0.0
            && stops.last()?.0 == 1.0
            && stops.windows(2).all(|w| w[0].0 < w[1].0);
        ok.then_some(Palette { stops })
    }

    /// Lowland green → yellow-tan → brown → rock grey → snow.
    pub fn natural() -> Palette {
        Palette {
            stops: vec![
                (0.00, [104, 150, 92]),
                (0.08, [128, 168, 102]),
                (0.20, [172, 190, 122]),
                (0.32, [214, 206, 150]),
                (0.45, [206, 176, 128]),
                (0.58, [178, 140, 104]),
                (0.70, [156, 126, 106]),
                (0.80, [150, 144, 140]),
                (0.90, [196, 194, 192]),
                (1.00, [248, 248, 250]),
            ],
        }
    }

    /// The palette moved toward grey by `amount` (0 = unchanged, 1 = grey
    /// of the same lightness): under a type overlay, so that type colours
    /// read as themselves instead of mixing with the elevation colours
    /// (the interference seed 003 §3 notes between tints and type colouring).
    pub fn muted(&self, amount: f64) -> Palette {
        let stops = self
            .stops
            .iter()
            .map(|&(t, c)| {
                let grey = 0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64;
                let m = |v: u8| {
                    (v as f64 + (grey - v as f64) * amount)
                        .round()
                        .clamp(0.0, 255.0) as u8
                };
                (t, [m(c[0]), m(c[1]), m(c[2])])
            })
            .collect();
        Palette { stops }
    }

    /// The colour at `t` (clamped to `[0, 1]`).
    pub fn sample(&self, t: f64) -> [u8; 3] {
        let t = t.clamp(0.0, 1.0);
        let i = self
            .stops
            .windows(2)
            .position(|w| t <= w[1].0)
            .unwrap_or(self.stops.len() - 2);
        let ((t0, a), (t1, b)) = (self.stops[i], self.stops[i + 1]);
        let f = (t - t0) / (t1 - t0);
        std::array::from_fn(|c| (a[c] as f64 + (b[c] as f64 - a[c] as f64) * f).round() as u8)
    }
}

/// Packs sRGB + opacity as the kernel's `r | g<<8 | b<<16 | a<<24`.
pub fn pack(rgb: [u8; 3], alpha: u8) -> u32 {
    u32::from_le_bytes([rgb[0], rgb[1], rgb[2], alpha])
}

/// The tint table for heights `lo_units ..= lo_units + span_units`:
/// returns `(shift, table)` with entry `k` coloured at the centre of
/// `[lo + k·2^shift, lo + (k+1)·2^shift)`. The step is a power of two so the
/// kernel indexes with a shift, not a division; the smallest one covering
/// the span in [`LUT_LEN`] entries (so 512 to 1024 of them fall inside it).
pub fn table(palette: &Palette, span_units: u32) -> (u32, Vec<u32>) {
    let step = span_units
        .div_ceil(LUT_LEN as u32)
        .max(1)
        .next_power_of_two();
    let shift = step.trailing_zeros();
    let lut = (0..LUT_LEN)
        .map(|k| {
            let t = (k as f64 + 0.5) * step as f64 / span_units as f64;
            pack(palette.sample(t), 255)
        })
        .collect();
    (shift, lut)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn palette_ends_and_middle() {
        let p = Palette::new(vec![(0.0, [0, 0, 0]), (1.0, [200, 100, 50])]).unwrap();
        assert_eq!(p.sample(-1.0), [0, 0, 0]);
        assert_eq!(p.sample(0.5), [100, 50, 25]);
        assert_eq!(p.sample(2.0), [200, 100, 50]);
        assert!(Palette::new(vec![(0.0, [0; 3]), (0.5, [0; 3])]).is_none());
    }

    #[test]
    fn muted_keeps_lightness_and_loses_colour() {
        let p = Palette::new(vec![(0.0, [200, 100, 0]), (1.0, [0, 0, 255])]).unwrap();
        let g = p.muted(1.0).sample(0.0);
        assert!(g[0] == g[1] && g[1] == g[2], "{g:?}");
        assert_eq!(p.muted(0.0), p);
    }

    #[test]
    fn table_covers_the_span() {
        let (shift, lut) = table(&Palette::natural(), 1_500_000);
        assert_eq!(lut.len(), LUT_LEN);
        assert!((1usize << shift) * LUT_LEN >= 1_500_000);
        assert!((1usize << shift) * LUT_LEN < 2 * 1_500_000);
        assert_eq!(lut[0] >> 24, 255);
        // Snow at the top, green at the bottom.
        let top = lut[LUT_LEN - 1].to_le_bytes();
        let bottom = lut[0].to_le_bytes();
        assert!(top[..3].iter().all(|&c| c > 240), "{top:?}");
        assert!(bottom[1] > bottom[0] && bottom[1] > bottom[2], "{bottom:?}");
    }
}
