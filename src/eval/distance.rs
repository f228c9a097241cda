//! How two terrains' descriptors are compared (the definitions of
//! `../shared/REALISM.md`):
//!
//! - a **distribution** by the Wasserstein-1 distance of its 199 quantiles
//!   (the midpoints (k + ½) / 199 of 199 equal-probability slices: 0.25 %,
//!   0.75 %, …, 99.75 %; the mean absolute difference of matching
//!   quantiles), divided by the pooled 10–90 % range (the 90th minus the
//!   10th percentile of both samples together), so that it is unit-free and
//!   "1" means "shifted by a typical spread";
//! - a **scalar** by |a − b| / (|a| + |b|) (0 when both are 0), in [0, 1].
//!
//! Quantiles interpolate linearly between order statistics: the q-quantile of
//! n sorted values is at position q·(n − 1).

use rayon::prelude::*;

/// Number of quantiles the Wasserstein distance compares.
pub const QUANTILES: usize = 199;

/// A descriptor's values over a terrain, sorted ascending, NaN-free.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Sample {
    sorted: Vec<f32>,
}

impl Sample {
    /// Sorts `values` (NaN values are dropped: they carry no measurement).
    pub fn new(mut values: Vec<f32>) -> Sample {
        values.retain(|v| !v.is_nan());
        values.par_sort_unstable_by(f32::total_cmp);
        Sample { sorted: values }
    }

    pub fn values(&self) -> &[f32] {
        &self.sorted
    }

    pub fn len(&self) -> usize {
        self.sorted.len()
    }

    pub fn is_empty(&self) -> bool {
        self.sorted.is_empty()
    }

    /// The q-quantile (q in 0..=1); NaN for an empty sample.
    pub fn quantile(&self, q: f64) -> f64 {
        interpolate(q, self.len(), |k| self.sorted[k])
    }

    pub fn median(&self) -> f64 {
        self.quantile(0.5)
    }

    /// Mean and (population) standard deviation.
    pub fn mean_std(&self) -> (f64, f64) {
        let n = self.len().max(1) as f64;
        let mean = self.sum_by(|v| v) / n;
        let var = self.sum_by(|v| (v - mean).powi(2)) / n;
        (mean, var.sqrt())
    }

    /// Σ f(v) over the sample: fixed chunks in parallel, their sums added in
    /// order. Why not rayon's `sum`: it splits by work stealing, so its
    /// rounding — and `eval`'s last digits — changed from run to run.
    fn sum_by(&self, f: impl Fn(f64) -> f64 + Sync) -> f64 {
        let parts: Vec<f64> = (self.sorted.par_chunks(1 << 14))
            .map(|c| c.iter().map(|&v| f(v as f64)).sum())
            .collect();
        parts.iter().sum()
    }
}

/// The q-quantile of `n` sorted values read through `at(k)`.
fn interpolate(q: f64, n: usize, at: impl Fn(usize) -> f32) -> f64 {
    if n == 0 {
        return f64::NAN;
    }
    let pos = q.clamp(0.0, 1.0) * (n - 1) as f64;
    let k = pos.floor() as usize;
    let t = pos - k as f64;
    let lo = at(k) as f64;
    if k + 1 < n && t > 0.0 {
        lo + t * (at(k + 1) as f64 - lo)
    } else {
        lo
    }
}

/// The k-th smallest (0-based) of two sorted slices taken together, without
/// merging them: binary search on how many come from `a`.
fn kth_of_union(a: &[f32], b: &[f32], k: usize) -> f32 {
    debug_assert!(k < a.len() + b.len());
    let (mut lo, mut hi) = ((k + 1).saturating_sub(b.len()), (k + 1).min(a.len()));
    loop {
        let i = (lo + hi) / 2;
        let j = k + 1 - i;
        if i < a.len() && j > 0 && b[j - 1] > a[i] {
            lo = i + 1; // b's part reaches past a[i]: take more from a
        } else if i > 0 && j < b.len() && a[i - 1] > b[j] {
            hi = i - 1; // a's part reaches past b[j]: take fewer from a
        } else {
            let from_a = if i > 0 { a[i - 1] } else { f32::NEG_INFINITY };
            let from_b = if j > 0 { b[j - 1] } else { f32::NEG_INFINITY };
            return from_a.max(from_b);
        }
    }
}

/// The q-quantile of both samples pooled.
pub fn pooled_quantile(a: &Sample, b: &Sample, q: f64) -> f64 {
    interpolate(q, a.len() + b.len(), |k| {
        kth_of_union(&a.sorted, &b.sorted, k)
    })
}

/// Wasserstein-1 distance of the 199 quantiles, in the samples' unit.
pub fn wasserstein(a: &Sample, b: &Sample) -> f64 {
    (0..QUANTILES)
        .map(|k| {
            let q = (k as f64 + 0.5) / QUANTILES as f64;
            (a.quantile(q) - b.quantile(q)).abs()
        })
        .sum::<f64>()
        / QUANTILES as f64
}

/// [`wasserstein`] over the pooled 10–90 % range. Identical samples give 0;
/// if the pooled range is 0 (more than 80 % of both samples share one value)
/// but the quantiles differ, the distance is taken over the pooled 0–100 %
/// range instead, and is 0 only if that is 0 too.
pub fn distribution_distance(a: &Sample, b: &Sample) -> f64 {
    if a.is_empty() || b.is_empty() {
        return f64::NAN;
    }
    let w = wasserstein(a, b);
    if w == 0.0 {
        return 0.0;
    }
    let range = pooled_quantile(a, b, 0.9) - pooled_quantile(a, b, 0.1);
    let range = if range > 0.0 {
        range
    } else {
        pooled_quantile(a, b, 1.0) - pooled_quantile(a, b, 0.0)
    };
    w / range
}

/// |a − b| / (|a| + |b|); 0 when both are 0.
pub fn scalar_distance(a: f64, b: f64) -> f64 {
    let s = a.abs() + b.abs();
    if s == 0.0 { 0.0 } else { (a - b).abs() / s }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_interpolate_between_order_statistics() {
        let s = Sample::new(vec![3.0, 1.0, f32::NAN, 2.0, 4.0]);
        assert_eq!(s.values(), &[1.0, 2.0, 3.0, 4.0]);
        assert_eq!(s.quantile(0.0), 1.0);
        assert_eq!(s.quantile(1.0), 4.0);
        assert!((s.quantile(0.5) - 2.5).abs() < 1e-12);
        assert!((s.quantile(1.0 / 6.0) - 1.5).abs() < 1e-12);
    }

    #[test]
    fn pooled_quantiles_equal_those_of_the_concatenation() {
        let a = Sample::new((0..37).map(|i| ((i * 13) % 37) as f32 * 0.5).collect());
        let b = Sample::new((0..20).map(|i| ((i * 7) % 20) as f32 + 3.25).collect());
        let both = Sample::new(a.values().iter().chain(b.values()).copied().collect());
        for k in 0..=20 {
            let q = k as f64 / 20.0;
            assert_eq!(pooled_quantile(&a, &b, q), both.quantile(q), "q = {q}");
            assert_eq!(pooled_quantile(&b, &a, q), both.quantile(q), "q = {q}");
        }
    }

    /// A shift by c moves every quantile by c: W1 = c, and over a pooled
    /// range the distance is c / range.
    #[test]
    fn a_shift_is_its_own_wasserstein_distance() {
        let a = Sample::new((0..1000).map(|i| i as f32 / 10.0).collect());
        let b = Sample::new(a.values().iter().map(|v| v + 5.0).collect());
        assert!((wasserstein(&a, &b) - 5.0).abs() < 1e-4);
        let range = pooled_quantile(&a, &b, 0.9) - pooled_quantile(&a, &b, 0.1);
        assert!((distribution_distance(&a, &b) - 5.0 / range).abs() < 1e-6);
        assert_eq!(distribution_distance(&a, &a), 0.0);
        assert_eq!(scalar_distance(1.0, 3.0), 0.5);
        assert_eq!(scalar_distance(0.0, 0.0), 0.0);
        assert_eq!(scalar_distance(-1.0, 1.0), 1.0);
    }
}
