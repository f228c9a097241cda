//! The procedural toolbox's noise: gradient noise, fractal sums and
//! multifractals — their ranges, continuity and amplitude conventions.
//! (Erosion, types and the styles' golden outputs: `procedural.rs`.)

use proptest::prelude::*;
use terrasynth::procedural::*;

#[test]
fn noise_spans_the_unit_range_and_vanishes_on_the_lattice() {
    let mut max = 0.0f64;
    for i in 0..200_000u32 {
        let (x, y) = (
            (i % 500) as f64 * 0.173 - 40.0,
            (i / 500) as f64 * 0.131 + 7.0,
        );
        let n = gradient_noise(11, x, y);
        assert!(n.abs() <= 1.0, "noise({x}, {y}) = {n}");
        max = max.max(n.abs());
    }
    assert!(max > 0.8, "noise should use its range, max |n| = {max}");
    for (x, y) in [(0, 0), (3, -7), (-100, 55)] {
        assert_eq!(gradient_noise(5, x as f64, y as f64), 0.0);
    }
    assert_ne!(gradient_noise(1, 0.5, 0.5), gradient_noise(2, 0.5, 0.5));
}

proptest! {
    #![proptest_config(crate::common::proptest_cases(256))]

    /// Gradient noise is Lipschitz: a step of 1e-4 lattice units moves it
    /// by at most 1e-3 (the gradient is bounded by a few units).
    #[test]
    fn noise_is_continuous(x in -1.0e4f64..1.0e4, y in -1.0e4f64..1.0e4, seed: u32) {
        let n = gradient_noise(seed, x, y);
        let eps = 1e-4;
        prop_assert!((gradient_noise(seed, x + eps, y) - n).abs() < 1e-3);
        prop_assert!((gradient_noise(seed, x, y + eps) - n).abs() < 1e-3);
    }

    #[test]
    fn fractal_sums_stay_within_the_amplitude_sum(
        x in -1.0e5f64..1.0e5, y in -1.0e5f64..1.0e5, h in 0.0f64..2.0, lac in 1.5f64..3.0,
        octaves in 1u32..10, seed: u32,
    ) {
        for shape in [Shape::Plain, Shape::Ridged, Shape::Billowy] {
            let f = Fractal { h, lacunarity: lac, octaves, shape, ..Fractal::new(seed, 0.01) };
            let a = f.amplitude_sum();
            let v = f.sample(x, y);
            let (lo, hi) = shape.range();
            prop_assert!(v >= lo * a - 1e-9 && v <= hi * a + 1e-9, "{shape:?}: {v} outside ±{a}");
            let m = Multifractal { fractal: f.clone(), offset: 0.3, gain: 1.5 };
            let mv = m.sample(x, y);
            prop_assert!(mv >= lo * a - 1e-9 && mv <= hi * a + 1e-9);
        }
    }

    #[test]
    fn bias_and_gain_are_monotone_with_fixed_ends(b in 0.01f64..0.99, t in 0.0f64..1.0, dt in 0.0f64..0.1) {
        let t2 = (t + dt).min(1.0);
        prop_assert!(remap::bias(b, t) <= remap::bias(b, t2));
        prop_assert!(remap::gain(b, t) <= remap::gain(b, t2) + 1e-15);
        prop_assert_eq!(remap::bias(b, 0.0), 0.0);
        prop_assert_eq!(remap::bias(b, 1.0), 1.0);
        prop_assert!((remap::gain(b, 0.5) - 0.5).abs() < 1e-15);
        prop_assert!((remap::bias(0.5, t) - t).abs() < 1e-15);
    }
}

// ------------------------------------------------------------------ fBm

/// The documented convention, measured: octaves are uncorrelated, so the
/// variance of the sum is the single-octave variance times Σ a_i², with
/// a_i = λ^(−H·i).
#[test]
fn fbm_variance_follows_the_amplitude_convention() {
    let variance = |f: &Fractal| {
        let (mut s, mut s2, n) = (0.0, 0.0, 250_000);
        for i in 0..n {
            let (x, y) = ((i % 500) as f64 * 7.31, (i / 500) as f64 * 7.77);
            let v = f.sample(x, y);
            s += v;
            s2 += v * v;
        }
        s2 / n as f64 - (s / n as f64) * (s / n as f64)
    };
    let one = Fractal {
        octaves: 1,
        ..Fractal::new(4, 1.0 / 40.0)
    };
    let four = Fractal {
        octaves: 4,
        h: 0.5,
        lacunarity: 2.0,
        ..one.clone()
    };
    let a = four.amplitudes();
    for (i, ai) in a.iter().enumerate() {
        assert!((ai - 2f64.powf(-0.5 * i as f64)).abs() < 1e-14);
    }
    let predicted = variance(&one) * a.iter().map(|a| a * a).sum::<f64>();
    let measured = variance(&four);
    assert!(
        (measured / predicted - 1.0).abs() < 0.1,
        "variance {measured}, convention predicts {predicted}"
    );
}

#[test]
fn multifractal_reduces_to_fbm_and_weights_detail_by_height() {
    let f = Fractal {
        octaves: 6,
        shape: Shape::Ridged,
        ..Fractal::new(3, 0.02)
    };
    let plain = Multifractal {
        fractal: f.clone(),
        offset: 1.0,
        gain: 0.0,
    };
    let coarse_only = Multifractal {
        fractal: f.clone(),
        offset: 0.0,
        gain: 0.0,
    };
    let hetero = Multifractal {
        fractal: f.clone(),
        offset: 0.0,
        gain: 1.0,
    };
    let (mut high, mut low) = ((0.0, 0), (0.0, 0));
    for i in 0..20_000 {
        let (x, y) = ((i % 200) as f64 * 2.9, (i / 200) as f64 * 3.1);
        let detail = hetero.sample_octaves(x, y, 1, 6).abs();
        match f.sample_octaves(x, y, 0, 1) {
            c if c > 0.8 => high = (high.0 + detail, high.1 + 1),
            c if c < 0.4 => low = (low.0 + detail, low.1 + 1),
            _ => {}
        }
    }
    let (high, low) = (high.0 / high.1 as f64, low.0 / low.1 as f64);
    assert!(high > 2.0 * low, "detail on crests {high} vs in lows {low}");
    for i in 0..500 {
        let (x, y) = (i as f64 * 3.7, i as f64 * -1.3);
        assert_eq!(plain.sample(x, y), f.sample(x, y));
        assert_eq!(coarse_only.sample(x, y), f.sample_octaves(x, y, 0, 1));
        assert!(
            (plain.sample_octaves(x, y, 0, 2) + plain.sample_octaves(x, y, 2, 6)
                - plain.sample(x, y))
            .abs()
                < 1e-12
        );
    }
}
