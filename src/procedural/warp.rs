//! Domain warping (seed 002 §4.3, "Domain Mapping"): a function is evaluated
//! at displaced coordinates `P(x, y) = (x + a·N₁(x, y), y + a·N₂(x, y))`.
//! Straight noise features (ridges along lattice-aligned zero crossings,
//! round blobs) become curved, folded and stretched, like terrain shaped by
//! faults and drainage rather than by a lattice.

use super::error::ProceduralError;
use super::fbm::Fractal;
use super::noise::pcg;

/// Displacement by two independent fractals.
#[derive(Debug, Clone, PartialEq)]
pub struct Warp {
    /// N₁: displacement along x.
    pub dx: Fractal,
    /// N₂: displacement along y.
    pub dy: Fractal,
    /// Scale `a` of both displacements, in coordinate units (metres for the
    /// styles). The displacement is at most `a` times the fractal's
    /// [`Fractal::amplitude_sum`].
    pub amplitude: f64,
}

impl Warp {
    /// A warp whose y displacement uses `fractal` with a rehashed seed, so the
    /// two components are uncorrelated.
    pub fn new(fractal: Fractal, amplitude: f64) -> Warp {
        let dy = Fractal {
            seed: pcg(fractal.seed ^ 0x2545_F491),
            ..fractal.clone()
        };
        Warp {
            dx: fractal,
            dy,
            amplitude,
        }
    }

    pub fn check(&self) -> Result<(), ProceduralError> {
        self.dx.check()?;
        self.dy.check()?;
        super::error::check_range(
            "warp amplitude",
            self.amplitude,
            0.0,
            1e9,
            "a finite value >= 0",
        )
    }

    /// The displaced coordinates of (x, y).
    pub fn apply(&self, x: f64, y: f64) -> (f64, f64) {
        (
            x + self.amplitude * self.dx.sample(x, y),
            y + self.amplitude * self.dy.sample(x, y),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_amplitude_is_the_identity_and_displacement_is_bounded() {
        let f = Fractal {
            octaves: 4,
            ..Fractal::new(9, 0.01)
        };
        let bound = 50.0 * f.amplitude_sum();
        let none = Warp::new(f.clone(), 0.0);
        let warp = Warp::new(f, 50.0);
        let mut moved = 0.0f64;
        for k in 0..200 {
            let (x, y) = (k as f64 * 13.7, 1000.0 - k as f64 * 3.3);
            assert_eq!(none.apply(x, y), (x, y));
            let (wx, wy) = warp.apply(x, y);
            assert!((wx - x).abs() <= bound && (wy - y).abs() <= bound);
            moved = moved.max((wx - x).abs()).max((wy - y).abs());
        }
        assert!(moved > 5.0, "the warp barely moves anything: {moved}");
    }
}
