//! Fractal sums of gradient noise (seed 002 §4.3, "Noise Synthesis").
//!
//! # Amplitude convention
//!
//! Octave `i` (counting from 0) samples noise at frequency `f · λ^i` with
//! amplitude `a_i = λ^(−H·i)`, so octave 0 has amplitude 1 and
//!
//! ```text
//! fbm(p) = Σ_{i < octaves} a_i · T(n_i(p)),   |fbm| ≤ A = Σ a_i  (Fractal::amplitude_sum)
//! ```
//!
//! where `n_i ∈ [−1, 1]` is [`gradient_noise`] and `T` the octave [`Shape`].
//! This is Musgrave's program convention (Ebert et al. 2003, ch. 16). De
//! Carpentier writes the same sum with `w = λ^(−β/2)`, `β = 1 + 2H`, i.e. his
//! `H` is ours minus ½: our `H = 1` with `λ = 2` is his `H = ½` (Brownian,
//! `w = ½`). The sum is not normalised; divide by [`Fractal::amplitude_sum`]
//! for a [−1, 1] result.
//!
//! `λ^(−H)` is computed once with [`math::pow`] (square roots and products
//! only) and the per-octave values by repeated multiplication, so results are
//! bit-reproducible. Each octave gets its own seed, a hashed offset and a
//! rotation by atan(3/4) ≈ 36.87° relative to the previous one (an exact
//! rational rotation, cos = 0.8, sin = 0.6), so lattice axes and lattice
//! zeros of successive octaves never line up.

use super::error::{ProceduralError, check_range};
use super::math;
use super::noise::{gradient_noise, pcg, unit};

/// The transform `T(n)` applied to each octave's noise before summing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Shape {
    /// `T(n) = n`: plain fBm, values in [−1, 1].
    Plain,
    /// `T(n) = 1 − |n|`: sharp crests where the noise crosses zero; [0, 1].
    Ridged,
    /// `T(n) = |n|`: rounded bumps with creases between them (Perlin's
    /// turbulence); [0, 1].
    Billowy,
}

impl Shape {
    #[inline]
    pub fn apply(self, n: f64) -> f64 {
        match self {
            Shape::Plain => n,
            Shape::Ridged => 1.0 - n.abs(),
            Shape::Billowy => n.abs(),
        }
    }

    /// Range of `T(n)` for `n ∈ [−1, 1]`.
    pub fn range(self) -> (f64, f64) {
        match self {
            Shape::Plain => (-1.0, 1.0),
            Shape::Ridged | Shape::Billowy => (0.0, 1.0),
        }
    }
}

/// A fractal sum of noise octaves; see the module documentation for the
/// amplitude convention. Coordinates are in any unit (the styles use metres);
/// `frequency` is in noise cells per unit.
#[derive(Debug, Clone, PartialEq)]
pub struct Fractal {
    pub seed: u32,
    /// Frequency of octave 0, in noise lattice cells per coordinate unit
    /// (1 / feature size). Must be > 0.
    pub frequency: f64,
    /// Frequency ratio λ between successive octaves, in [1.01, 16] (2 is usual).
    pub lacunarity: f64,
    /// Roughness exponent H in [0, 4]: octave `i` has amplitude `λ^(−H·i)`.
    /// Larger H gives smoother terrain.
    pub h: f64,
    /// Number of octaves, 1..=24.
    pub octaves: u32,
    pub shape: Shape,
}

/// Rotation between successive octaves: the 3-4-5 triangle, exact in binary.
const ROT_COS: f64 = 0.8;
const ROT_SIN: f64 = 0.6;

impl Fractal {
    /// Plain fBm with λ = 2, H = 1 and 8 octaves.
    pub fn new(seed: u32, frequency: f64) -> Fractal {
        Fractal {
            seed,
            frequency,
            lacunarity: 2.0,
            h: 1.0,
            octaves: 8,
            shape: Shape::Plain,
        }
    }

    /// Checks every parameter against its documented range.
    pub fn check(&self) -> Result<(), ProceduralError> {
        check_range(
            "frequency",
            self.frequency,
            f64::MIN_POSITIVE,
            1e9,
            "a finite value > 0",
        )?;
        check_range(
            "lacunarity",
            self.lacunarity,
            1.01,
            16.0,
            "a value in 1.01..=16",
        )?;
        check_range("H", self.h, 0.0, 4.0, "a value in 0..=4")?;
        check_range(
            "octaves",
            self.octaves as f64,
            1.0,
            24.0,
            "an integer in 1..=24",
        )
    }

    /// The amplitude ratio between successive octaves, `λ^(−H)`.
    pub fn persistence(&self) -> f64 {
        1.0 / math::pow(self.lacunarity, self.h)
    }

    /// `a_i` for every octave, by the same repeated multiplication as [`Self::sample`].
    pub fn amplitudes(&self) -> Vec<f64> {
        let w = self.persistence();
        let mut a = 1.0;
        (0..self.octaves)
            .map(|_| {
                let this = a;
                a *= w;
                this
            })
            .collect()
    }

    /// `A = Σ a_i`: the bound on `|sample|`, and the normaliser to [−1, 1].
    pub fn amplitude_sum(&self) -> f64 {
        self.amplitudes().iter().sum()
    }

    /// The fractal at (x, y): `Σ a_i T(n_i)` over all octaves.
    pub fn sample(&self, x: f64, y: f64) -> f64 {
        self.sample_octaves(x, y, 0, self.octaves)
    }

    /// The partial sum over octaves `first..end` (the seed's `L_min..L_max`).
    /// Splitting a sum into ranges gives the same octaves as the whole sum,
    /// so a coarse level can be refined with exactly the octaves it lacks.
    pub fn sample_octaves(&self, x: f64, y: f64, first: u32, end: u32) -> f64 {
        let mut sum = 0.0;
        self.for_octaves(x, y, end, |i, amp, n| {
            if i >= first {
                sum += amp * self.shape.apply(n);
            }
        });
        sum
    }

    /// Calls `f(i, a_i, n_i(x, y))` for octaves `0..end`, in order.
    fn for_octaves(&self, x: f64, y: f64, end: u32, mut f: impl FnMut(u32, f64, f64)) {
        let w = self.persistence();
        let (mut amp, mut freq) = (1.0, self.frequency);
        let (mut c, mut s) = (1.0, 0.0);
        for i in 0..end.min(self.octaves) {
            let seed = pcg(self.seed.wrapping_add(i.wrapping_mul(0x9E37_79B9)));
            let ox = unit(pcg(seed ^ 0x68E3_1DA4)) * 4096.0;
            let oy = unit(pcg(seed ^ 0xB5B7_B6D5)) * 4096.0;
            let (u, v) = (x * freq, y * freq);
            let n = gradient_noise(seed, c * u - s * v + ox, s * u + c * v + oy);
            f(i, amp, n);
            amp *= w;
            freq *= self.lacunarity;
            (c, s) = (c * ROT_COS - s * ROT_SIN, s * ROT_COS + c * ROT_SIN);
        }
    }
}

/// A heterogeneous multifractal (seed 002 §4.3): octave `i > 0` is scaled by
/// `G = clamp(offset + gain · m, 0, 1)`, where `m` is the mean of the shaped
/// values of the octaves before it (their sum divided by their amplitude sum).
/// With a positive `gain`, detail is added where the coarse terrain is high
/// and suppressed where it is low: rough crests above smooth valleys, which
/// plain fBm (statistically the same everywhere) cannot produce.
///
/// `offset = 1, gain = 0` gives exactly [`Fractal::sample`]. The output stays
/// within `A · range(T)` since every weight is in [0, 1].
#[derive(Debug, Clone, PartialEq)]
pub struct Multifractal {
    pub fractal: Fractal,
    /// Weight of the detail where the coarse mean is 0; in [−4, 4].
    pub offset: f64,
    /// How strongly the coarse mean raises the weight of finer octaves; in [−16, 16].
    pub gain: f64,
}

impl Multifractal {
    pub fn check(&self) -> Result<(), ProceduralError> {
        self.fractal.check()?;
        check_range("offset", self.offset, -4.0, 4.0, "a value in -4..=4")?;
        check_range("gain", self.gain, -16.0, 16.0, "a value in -16..=16")
    }

    pub fn sample(&self, x: f64, y: f64) -> f64 {
        self.sample_octaves(x, y, 0, self.fractal.octaves)
    }

    /// The contribution of octaves `first..end`, each weighted by the mean
    /// of all the octaves before it: `sample_octaves(0, k) +
    /// sample_octaves(k, n)` equals `sample`, so coarse levels can be refined.
    pub fn sample_octaves(&self, x: f64, y: f64, first: u32, end: u32) -> f64 {
        let (mut sum, mut amp_sum, mut part) = (0.0, 0.0, 0.0);
        self.fractal.for_octaves(x, y, end, |i, amp, n| {
            let t = self.fractal.shape.apply(n);
            let weight = if i == 0 {
                1.0
            } else {
                (self.offset + self.gain * (sum / amp_sum)).clamp(0.0, 1.0)
            };
            sum += amp * weight * t;
            amp_sum += amp;
            if i >= first {
                part += amp * weight * t;
            }
        });
        part
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn octave_ranges_add_up_to_the_whole() {
        let f = Fractal {
            octaves: 7,
            ..Fractal::new(3, 0.013)
        };
        for k in 0..50 {
            let (x, y) = (k as f64 * 17.3, k as f64 * -5.1);
            let whole = f.sample(x, y);
            let split = f.sample_octaves(x, y, 0, 3) + f.sample_octaves(x, y, 3, 7);
            assert!((whole - split).abs() < 1e-12);
        }
    }

    #[test]
    fn persistence_follows_the_documented_exponent() {
        let f = Fractal {
            lacunarity: 2.0,
            h: 0.5,
            ..Fractal::new(1, 1.0)
        };
        assert!((f.persistence() - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-15);
        let a = f.amplitudes();
        assert_eq!(a.len(), 8);
        for (i, ai) in a.iter().enumerate() {
            let want = 2f64.powf(-0.5 * i as f64);
            assert!((ai - want).abs() < 1e-14, "a_{i} = {ai}, want {want}");
        }
    }

    #[test]
    fn bad_parameters_are_named() {
        let f = Fractal {
            lacunarity: 0.5,
            ..Fractal::new(1, 1.0)
        };
        assert!(f.check().unwrap_err().to_string().contains("lacunarity"));
        let f = Fractal {
            octaves: 0,
            ..Fractal::new(1, 1.0)
        };
        assert!(f.check().unwrap_err().to_string().contains("1..=24"));
        assert!(Fractal::new(1, f64::NAN).check().is_err());
    }
}
