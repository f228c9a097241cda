//! Curve properties along arc length: monotone cubic Hermite interpolation
//! of the widget values (paper §3: "we interpolate the widget values … using
//! Hermite curves").
//!
//! The paper does not say which tangents its Hermite curves use. We take
//! Fritsch–Carlson monotone tangents: the curve passes exactly through every
//! widget value, is C¹, and never overshoots between two widgets. Overshoot
//! matters here: a reach or height that dips below both neighbouring widgets
//! would carve a notch the user never asked for (and a reach could go
//! negative). Before the first and after the last key the value is held.

/// One property along the curve: keys at increasing arc length.
#[derive(Debug, Clone, PartialEq)]
pub struct Track {
    s: Vec<f64>,
    v: Vec<f64>,
    m: Vec<f64>,
}

impl Track {
    /// Builds a track from `(arc length, value)` keys (any order; keys closer
    /// than [`MIN_KEY_GAP`] to an earlier one in the list are dropped, so
    /// list the keys that must win first). At least one key is required.
    pub fn new(keys: &[(f64, f64)]) -> Track {
        assert!(!keys.is_empty(), "a track needs at least one key");
        let mut kept: Vec<(f64, f64)> = Vec::with_capacity(keys.len());
        for &(s, v) in keys {
            if kept.iter().all(|&(t, _)| (t - s).abs() >= MIN_KEY_GAP) {
                kept.push((s, v));
            }
        }
        kept.sort_by(|a, b| a.0.total_cmp(&b.0));
        let s: Vec<f64> = kept.iter().map(|k| k.0).collect();
        let v: Vec<f64> = kept.iter().map(|k| k.1).collect();
        let m = tangents(&s, &v);
        Track { s, v, m }
    }

    /// The value at arc length `s`.
    pub fn at(&self, s: f64) -> f64 {
        let n = self.s.len();
        if n == 1 || s <= self.s[0] {
            return self.v[0];
        }
        if s >= self.s[n - 1] {
            return self.v[n - 1];
        }
        let k = self.s.partition_point(|&x| x <= s) - 1;
        let h = self.s[k + 1] - self.s[k];
        let t = (s - self.s[k]) / h;
        let (t2, t3) = (t * t, t * t * t);
        let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
        let h10 = t3 - 2.0 * t2 + t;
        let h01 = -2.0 * t3 + 3.0 * t2;
        let h11 = t3 - t2;
        h00 * self.v[k] + h10 * h * self.m[k] + h01 * self.v[k + 1] + h11 * h * self.m[k + 1]
    }

    /// The largest value the track takes (attained at a key: no overshoot).
    pub fn max(&self) -> f64 {
        self.v.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    }

    /// The keys, `(arc length, value)`.
    pub fn keys(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.s.iter().copied().zip(self.v.iter().copied())
    }
}

/// Keys closer than this (output pixels of arc length) count as one.
pub const MIN_KEY_GAP: f64 = 0.5;

/// Fritsch–Carlson tangents.
fn tangents(s: &[f64], v: &[f64]) -> Vec<f64> {
    let n = s.len();
    if n < 2 {
        return vec![0.0; n];
    }
    let d: Vec<f64> = (0..n - 1)
        .map(|k| (v[k + 1] - v[k]) / (s[k + 1] - s[k]))
        .collect();
    let mut m = vec![0.0; n];
    m[0] = d[0];
    m[n - 1] = d[n - 2];
    for k in 1..n - 1 {
        m[k] = if d[k - 1] * d[k] <= 0.0 {
            0.0
        } else {
            (d[k - 1] + d[k]) / 2.0
        };
    }
    for k in 0..n - 1 {
        if d[k] == 0.0 {
            m[k] = 0.0;
            m[k + 1] = 0.0;
            continue;
        }
        let (a, b) = (m[k] / d[k], m[k + 1] / d[k]);
        let r = a * a + b * b;
        if r > 9.0 {
            let t = 3.0 / r.sqrt();
            m[k] = t * a * d[k];
            m[k + 1] = t * b * d[k];
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn interpolates_keys_exactly_and_holds_outside() {
        let keys = [(0.0, 5.0), (10.0, 20.0), (25.0, -3.0), (40.0, -3.0)];
        let t = Track::new(&keys);
        for &(s, v) in &keys {
            assert_eq!(t.at(s), v, "at {s}");
        }
        assert_eq!(t.at(-5.0), 5.0);
        assert_eq!(t.at(99.0), -3.0);
        // Flat between equal keys.
        assert!((t.at(32.0) + 3.0).abs() < 1e-12);
    }

    #[test]
    fn earlier_keys_win_near_ties() {
        let t = Track::new(&[(10.0, 1.0), (10.2, 9.0), (0.0, 0.0)]);
        assert_eq!(t.at(10.0), 1.0);
        assert_eq!(t.keys().count(), 2);
    }

    proptest! {
        #[test]
        fn hermite_is_exact_at_keys_and_never_overshoots(
            vals in proptest::collection::vec(-100.0f64..100.0, 1..8),
            gaps in proptest::collection::vec(1.0f64..50.0, 8),
            probe in 0.0f64..1.0,
        ) {
            let mut s = 0.0;
            let keys: Vec<(f64, f64)> = vals.iter().enumerate().map(|(i, &v)| {
                s += gaps[i];
                (s, v)
            }).collect();
            let t = Track::new(&keys);
            for &(s, v) in &keys {
                prop_assert!((t.at(s) - v).abs() < 1e-9);
            }
            // Between two keys the value stays within their range.
            for w in keys.windows(2) {
                let x = w[0].0 + probe * (w[1].0 - w[0].0);
                let (lo, hi) = (w[0].1.min(w[1].1), w[0].1.max(w[1].1));
                let y = t.at(x);
                prop_assert!(y >= lo - 1e-9 && y <= hi + 1e-9, "{y} outside {lo}..{hi}");
            }
        }
    }
}
