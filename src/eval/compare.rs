//! The realism ratio: a synthesis's distance from its reference, per
//! descriptor, in units of the distance between the reference's two halves.

use super::distance::{distribution_distance, scalar_distance};
use super::{DESCRIPTORS, Descriptors, EvalError, MIN_SIDE, Value, describe};
use crate::heightfield::Heightfield;
use serde::Serialize;

/// Smallest half distance a ratio divides by. Two halves of one terrain can
/// agree on a descriptor by chance (measured on the 8 shared DEMs: some
/// half distances of β, ε and the hypsometric integral are below 0.01, where
/// the typical one is 0.03–0.2), and a ratio over such a near-zero would
/// let one scalar dominate the mean. 0.05 is the size of difference
/// the descriptors cannot resolve reliably anyway: 5 % of a scalar's
/// magnitude, or a twentieth of a distribution's 10–90 % spread.
pub const FLOOR: f64 = 0.05;

/// A reference terrain described whole and as two halves (left and right,
/// each `⌊w/2⌋` wide), with the distances between the halves: computed once
/// and compared with any number of syntheses.
#[derive(Debug, Clone)]
pub struct Reference {
    pub whole: Descriptors,
    pub left: Descriptors,
    pub right: Descriptors,
    /// d(left, right) per descriptor.
    pub halves: Vec<f64>,
}

/// Distances between two terrains' descriptors, in [`DESCRIPTORS`] order.
pub fn distances(a: &Descriptors, b: &Descriptors) -> Vec<f64> {
    a.values
        .iter()
        .zip(&b.values)
        .map(|(x, y)| match (x, y) {
            (Value::Distribution(x), Value::Distribution(y)) => distribution_distance(x, y),
            (x, y) => scalar_distance(x.summary(), y.summary()),
        })
        .collect()
}

impl Reference {
    /// Describes `hf` and its halves. It must be at least `2 × MIN_SIDE`
    /// cells wide.
    pub fn new(hf: &Heightfield) -> Result<Reference, EvalError> {
        let (w, h) = (hf.width(), hf.height());
        if w < 2 * MIN_SIDE || h < MIN_SIDE {
            return Err(EvalError::TooSmall {
                width: w,
                height: h,
                min: 2 * MIN_SIDE,
            });
        }
        let half = w / 2;
        let left = hf.crop(0, 0, half, h).expect("inside");
        let right = hf.crop(w - half, 0, half, h).expect("inside");
        let (whole, (left, right)) = rayon::join(
            || describe(hf),
            || rayon::join(|| describe(&left), || describe(&right)),
        );
        let (whole, left, right) = (whole?, left?, right?);
        let halves = distances(&left, &right);
        Ok(Reference {
            whole,
            left,
            right,
            halves,
        })
    }

    /// Compares a synthesis's descriptors with this reference.
    pub fn compare(&self, synth: &Descriptors) -> Comparison {
        let d = distances(synth, &self.whole);
        let descriptors: Vec<DescriptorResult> = DESCRIPTORS
            .iter()
            .enumerate()
            .map(|(i, info)| DescriptorResult {
                id: info.id,
                unit: info.unit,
                synth: synth.values[i].summary(),
                reference: self.whole.values[i].summary(),
                left: self.left.values[i].summary(),
                right: self.right.values[i].summary(),
                distance: d[i],
                halves: self.halves[i],
                ratio: d[i] / self.halves[i].max(FLOOR),
            })
            .collect();
        let ratio = descriptors.iter().map(|r| r.ratio).sum::<f64>() / descriptors.len() as f64;
        let pair = |s: f64, r: f64| Pair {
            synth: s,
            reference: r,
            ratio: quotient(s, r),
        };
        Comparison {
            ratio,
            descriptors,
            median_slope: pair(synth.median_slope(), self.whole.median_slope()),
            relief: pair(synth.relief, self.whole.relief),
            pits: pair(synth.pits(), self.whole.pits()),
        }
    }
}

/// s / r, with 0 / 0 = 1 (nothing where there was nothing).
fn quotient(s: f64, r: f64) -> f64 {
    if r == 0.0 && s == 0.0 { 1.0 } else { s / r }
}

/// Describes both terrains and compares them (for one-off comparisons; use
/// [`Reference`] to compare many syntheses with one reference).
pub fn compare(synth: &Heightfield, reference: &Heightfield) -> Result<Comparison, EvalError> {
    let (s, r) = rayon::join(|| describe(synth), || Reference::new(reference));
    Ok(r?.compare(&s?))
}

/// One descriptor's comparison. Values are the median of a distribution or
/// the scalar itself.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DescriptorResult {
    pub id: &'static str,
    pub unit: &'static str,
    pub synth: f64,
    pub reference: f64,
    pub left: f64,
    pub right: f64,
    /// d(synthesis, reference).
    pub distance: f64,
    /// d(left half, right half) of the reference.
    pub halves: f64,
    /// distance / max(halves, [`FLOOR`]).
    pub ratio: f64,
}

/// A quantity on both terrains and their quotient synth / reference.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Pair {
    pub synth: f64,
    pub reference: f64,
    pub ratio: f64,
}

/// A synthesis compared with its reference.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Comparison {
    /// The realism ratio: mean of the descriptors' ratios.
    pub ratio: f64,
    pub descriptors: Vec<DescriptorResult>,
    /// Degrees.
    pub median_slope: Pair,
    /// 1st–99th percentile height range, metres (ratio = relief kept).
    pub relief: Pair,
    /// Pit fraction.
    pub pits: Pair,
}
