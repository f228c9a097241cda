//! Arithmetic that gives the same bits on every machine.
//!
//! IEEE 754 rounds `+ − × ÷` and `sqrt` exactly, so any expression built only
//! from them is reproducible across CPUs, compilers and thread counts (Rust
//! never contracts `a * b + c` into a fused multiply-add on its own). libm's
//! transcendentals (`powf`, `exp`, `sin`…) carry no such guarantee, so the
//! generators whose output is pinned by golden hashes use these helpers
//! instead.

/// `x^e` for `x > 0` and `e >= 0`, from multiplications and square roots only.
///
/// The integer part of `e` is applied by binary exponentiation; the fraction
/// `f = Σ b_k 2^-k` (its binary digits) multiplies in `x^(2^-k)`, the k-th
/// repeated square root of `x`. Every step is exactly rounded, so the result is
/// bit-reproducible and within a few tens of ulps of the true power.
/// Outside the domain (or for non-finite inputs) the result is NaN.
pub fn pow(x: f64, e: f64) -> f64 {
    if !(x > 0.0 && e >= 0.0 && x.is_finite() && e.is_finite()) {
        return f64::NAN;
    }
    let whole = e.floor();
    let mut frac = e - whole;
    let mut result = 1.0;
    let mut base = x;
    let mut n = whole as u64;
    while n > 0 {
        if n & 1 == 1 {
            result *= base;
        }
        base *= base;
        n >>= 1;
    }
    let mut root = x;
    while frac > 0.0 {
        root = root.sqrt();
        frac *= 2.0;
        if frac >= 1.0 {
            result *= root;
            frac -= 1.0;
        }
        if root == 1.0 {
            break;
        }
    }
    result
}

/// Hermite smoothstep of `t` clamped to [0, 1]: 0 at 0, 1 at 1, flat at both ends.
pub fn smoothstep(t: f64) -> f64 {
    let t = t.clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Linear interpolation from `a` (t = 0) to `b` (t = 1).
pub fn lerp(a: f64, b: f64, t: f64) -> f64 {
    a + (b - a) * t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pow_matches_libm_closely() {
        for &(x, e) in &[
            (2.0, 0.5),
            (2.0, 0.9),
            (2.17, 1.3),
            (1.9, 0.0),
            (3.0, 2.0),
            (10.0, 0.123_456),
            (0.5, 2.75),
        ] {
            let want = f64::powf(x, e);
            let got = pow(x, e);
            assert!(
                ((got - want) / want).abs() < 1e-13,
                "pow({x}, {e}) = {got}, libm says {want}"
            );
        }
        assert_eq!(pow(2.0, 3.0), 8.0);
        assert_eq!(pow(7.0, 0.0), 1.0);
        assert!(pow(-1.0, 0.5).is_nan() && pow(2.0, -1.0).is_nan());
    }

    #[test]
    fn smoothstep_is_clamped_and_symmetric() {
        assert_eq!(smoothstep(-1.0), 0.0);
        assert_eq!(smoothstep(2.0), 1.0);
        assert_eq!(smoothstep(0.5), 0.5);
        for i in 0..=10 {
            let t = i as f64 / 10.0;
            assert!((smoothstep(t) + smoothstep(1.0 - t) - 1.0).abs() < 1e-15);
        }
    }
}
