//! Nodata filling by harmonic (Laplace) interpolation: every missing sample
//! becomes the average of its neighbours, i.e. the smoothest surface that
//! meets the valid samples around each hole (∇²h = 0 inside, the valid heights
//! on its rim). This is the method the shared SRTM exemplars were void-filled
//! with, it never overshoots the rim's range (maximum principle), and it adds
//! no detail that was not measured — synthesis, not the filler, adds detail.

use crate::heightfield::Heightfield;
use crate::poisson::{self, Method, PoissonError, SolveOptions};

/// What a fill did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FillReport {
    /// Samples that were nodata and now hold interpolated heights.
    pub filled: usize,
    /// Final relative residual of the Laplace solve.
    pub relative_residual: f64,
}

/// Fills every NaN (nodata) sample in place. A grid with no valid sample
/// cannot be filled and is left unchanged with an error.
pub fn fill_nodata(hf: &mut Heightfield) -> Result<FillReport, PoissonError> {
    let (w, h) = (hf.width(), hf.height());
    let fixed: Vec<bool> = hf.data().iter().map(|v| !v.is_nan()).collect();
    let filled = fixed.iter().filter(|&&f| !f).count();
    if filled == 0 {
        return Ok(FillReport {
            filled,
            relative_residual: 0.0,
        });
    }
    let opts = SolveOptions {
        tolerance: 1e-7,
        ..SolveOptions::default()
    };
    let rep = poisson::solve(Method::Cascadic, w, h, hf.data_mut(), &fixed, None, &opts)?;
    Ok(FillReport {
        filled,
        relative_residual: rep.relative_residual,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fills_holes_within_the_rim_range_and_keeps_valid_samples() {
        let mut hf = Heightfield::from_fn(64, 48, 10.0, |x, y| {
            let v = (x * 7 + y * 3) as f32 % 50.0;
            if (10..30).contains(&x) && (5..20).contains(&y) || (x + y) % 17 == 0 {
                f32::NAN
            } else {
                v
            }
        })
        .unwrap();
        let before = hf.clone();
        let s = before.stats().unwrap();
        let rep = fill_nodata(&mut hf).unwrap();
        assert_eq!(rep.filled, before.nodata_count());
        assert_eq!(hf.nodata_count(), 0);
        for (a, b) in before.data().iter().zip(hf.data()) {
            if a.is_nan() {
                assert!(
                    *b >= s.min - 1e-3 && *b <= s.max + 1e-3,
                    "{b} outside rim range"
                );
            } else {
                assert_eq!(a.to_bits(), b.to_bits(), "valid samples must not change");
            }
        }
    }

    #[test]
    fn all_nodata_is_an_error() {
        let mut hf = Heightfield::from_vec(2, 2, 1.0, vec![f32::NAN; 4]).unwrap();
        assert_eq!(fill_nodata(&mut hf), Err(PoissonError::NothingFixed));
    }
}
