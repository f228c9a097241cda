//! Range mapping (seed 002 §4.3): reshaping heights after synthesis.
//!
//! Heights are first normalised to [0, 1] so a mapping means the same thing
//! whatever produced them. Perlin's bias and gain use `t^(ln b / ln ½)`,
//! a libm power; we use Schlick's rational forms (Graphics Gems IV, 1994),
//! which share their defining properties (`bias_b(½) = b`, `gain_g(½) = ½`,
//! identity at ½, fixed end points) with only `+ − × ÷`, so they are
//! bit-reproducible.

use super::math::smoothstep;
use crate::heightfield::Heightfield;
use rayon::prelude::*;

/// Schlick's bias: monotone on [0, 1], fixes 0 and 1, maps ½ to `b`.
/// `b > ½` lifts the middle (plateaus above narrow cuts: the seed's "canyon"
/// effect); `b < ½` lowers it (broad valleys: "glacier"); `b = ½` is the
/// identity. `b` must lie in (0, 1).
pub fn bias(b: f64, t: f64) -> f64 {
    t / ((1.0 / b - 2.0) * (1.0 - t) + 1.0)
}

/// Perlin's gain built on [`bias`]: an S-curve symmetric about (½, ½).
/// `g < ½` flattens the middle heights (the seed's "midland" effect),
/// `g > ½` steepens them, `g = ½` is the identity. `g` must lie in (0, 1).
pub fn gain(g: f64, t: f64) -> f64 {
    if t < 0.5 {
        bias(1.0 - g, 2.0 * t) * 0.5
    } else {
        1.0 - bias(1.0 - g, 2.0 - 2.0 * t) * 0.5
    }
}

/// Terracing: `steps` flat treads separated by steep risers. Each band
/// `[i, i+1) / steps` keeps its lower part flat at `i / steps` and rises
/// smoothly to the next tread over its upper fraction `riser` ∈ (0, 1], so
/// the walls are about `1.5 / riser` times steeper than the input slope.
/// Continuous and monotone; `riser = 1` gives smooth (not flat) steps.
pub fn terrace(t: f64, steps: u32, riser: f64) -> f64 {
    let n = steps.max(1) as f64;
    let s = t * n;
    let i = s.floor();
    let f = s - i;
    let r = smoothstep((f - (1.0 - riser)) / riser);
    (i + r) / n
}

/// Rescales a heightfield to [0, 1] in place and returns the old (min, max);
/// `None` if it has no valid sample. A flat field becomes all zeros.
pub fn normalize(hf: &mut Heightfield) -> Option<(f32, f32)> {
    let s = hf.stats()?;
    let (lo, span) = (s.min as f64, (s.max - s.min) as f64);
    let inv = if span > 0.0 { 1.0 / span } else { 0.0 };
    map(hf, |v| (v - lo) * inv);
    Some((s.min, s.max))
}

/// Applies `f` to every sample (in f64), in parallel by row.
pub fn map(hf: &mut Heightfield, f: impl Fn(f64) -> f64 + Sync) {
    let w = hf.width();
    hf.data_mut().par_chunks_mut(w).for_each(|row| {
        for v in row {
            *v = f(*v as f64) as f32;
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bias_and_gain_laws() {
        for i in 0..=20 {
            let t = i as f64 / 20.0;
            assert!((bias(0.5, t) - t).abs() < 1e-15, "bias(½) is the identity");
            assert!((gain(0.5, t) - t).abs() < 1e-15, "gain(½) is the identity");
            for g in [0.2, 0.7] {
                // gain is point-symmetric about (½, ½)
                assert!((gain(g, t) + gain(g, 1.0 - t) - 1.0).abs() < 1e-14);
            }
        }
        for b in [0.1, 0.3, 0.8, 0.95] {
            assert_eq!(bias(b, 0.0), 0.0);
            assert_eq!(bias(b, 1.0), 1.0);
            assert!((bias(b, 0.5) - b).abs() < 1e-15);
            let mut prev = -1.0;
            for i in 0..=100 {
                let v = bias(b, i as f64 / 100.0);
                assert!(v > prev, "bias({b}) must increase");
                prev = v;
            }
        }
        assert!(gain(0.2, 0.25) > 0.25 && gain(0.8, 0.25) < 0.25);
    }

    #[test]
    fn terrace_is_monotone_continuous_and_flat_on_treads() {
        let (steps, riser) = (4, 0.3);
        let mut prev = terrace(0.0, steps, riser);
        for i in 1..=4000 {
            let t = i as f64 / 4000.0;
            let v = terrace(t, steps, riser);
            assert!(v >= prev, "monotone at {t}");
            assert!(v - prev < 0.01, "continuous at {t}: jump {}", v - prev);
            prev = v;
        }
        // the lower 70 % of each band is one flat tread
        assert_eq!(terrace(0.26, steps, riser), 0.25);
        assert_eq!(terrace(0.40, steps, riser), 0.25);
        assert_eq!(terrace(1.0, steps, riser), 1.0);
    }

    #[test]
    fn normalize_maps_onto_the_unit_interval() {
        let mut hf = Heightfield::from_vec(3, 1, 1.0, vec![10.0, 30.0, 20.0]).unwrap();
        assert_eq!(normalize(&mut hf), Some((10.0, 30.0)));
        assert_eq!(hf.data(), &[0.0, 1.0, 0.5]);
    }
}
