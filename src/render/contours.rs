//! Contour lines: choosing the interval, and the line styles handed to the
//! `shade` kernel (which decides per pixel where the lines fall).

/// Every fifth contour is an index contour, as on printed topographic maps.
pub const INDEX_EVERY: u32 = 5;
/// The automatic interval aims for at most this many levels over the relief
/// (and, with 1-2-5 steps, more than `MAX_LINES / 2.5`).
pub const MAX_LINES: f64 = 20.0;

/// A contour interval in metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Contours {
    /// A "nice" interval (1, 2 or 5 × 10ᵏ m) giving 8–20 levels over the relief.
    Auto,
    /// Every this many metres.
    Every(f64),
    /// No contour lines.
    Off,
}

/// The smallest 1-2-5 × 10ᵏ interval giving at most [`MAX_LINES`] levels
/// over `relief_m`; `None` for flat ground.
pub fn nice_interval(relief_m: f64) -> Option<f64> {
    if !(relief_m.is_finite() && relief_m > 0.0) {
        return None;
    }
    let raw = relief_m / MAX_LINES;
    let mut decade = 10f64.powf(raw.log10().floor());
    loop {
        for m in [1.0, 2.0, 5.0] {
            // A hair of tolerance so that e.g. 100 m / 20 picks exactly 5 m.
            if m * decade >= raw * (1.0 - 1e-9) {
                return Some(m * decade);
            }
        }
        decade *= 10.0;
    }
}

/// Line colours (sRGB, alpha = opacity) and half widths in pixels.
pub const CONTOUR_COLOUR: [u8; 4] = [92, 58, 30, 110];
pub const INDEX_COLOUR: [u8; 4] = [84, 50, 24, 150];
pub const CONTOUR_HALF_WIDTH_PX: f64 = 0.4;
pub const INDEX_HALF_WIDTH_PX: f64 = 0.6;
pub const COAST_COLOUR: [u8; 4] = [36, 74, 120, 200];
pub const COAST_HALF_WIDTH_PX: f64 = 0.5;
/// Minor contours closer than this fade out (fully gone at half of it).
pub const MIN_SPACING_PX: f64 = 4.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nice_intervals() {
        assert_eq!(nice_interval(100.0), Some(5.0));
        assert_eq!(nice_interval(345.0), Some(20.0));
        assert_eq!(nice_interval(2681.0), Some(200.0));
        assert_eq!(nice_interval(0.05), Some(0.005));
        assert_eq!(nice_interval(0.0), None);
        for r in [0.3, 7.0, 13.0, 99.0, 101.0, 640.0, 1223.0, 8848.0] {
            let i = nice_interval(r).unwrap();
            let lines = r / i;
            assert!(
                (8.0..=20.0 + 1e-9).contains(&lines),
                "{r}: {i} gives {lines}"
            );
        }
    }
}
