//! [`Ranked`], the one heap key of the crate's priority queues (the
//! database's best-bin-first search, the procedural drainage's
//! priority flood): a float priority with an index to break ties, totally
//! ordered, so that `BinaryHeap` pops in one reproducible order even with
//! equal priorities (and never panics on NaN).

use std::cmp::Ordering;

/// Ordered by `0` in IEEE total order (`total_cmp`), then by `1`, both
/// ascending; wrap it in [`std::cmp::Reverse`] to pop the smallest first.
#[derive(Debug, Clone, Copy)]
pub struct Ranked<F>(pub F, pub u32);

macro_rules! ranked {
    ($t:ty) => {
        impl Ord for Ranked<$t> {
            fn cmp(&self, other: &Self) -> Ordering {
                self.0.total_cmp(&other.0).then(self.1.cmp(&other.1))
            }
        }
    };
}
ranked!(f32);
ranked!(f64);

impl<F> PartialOrd for Ranked<F>
where
    Ranked<F>: Ord,
{
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl<F> PartialEq for Ranked<F>
where
    Ranked<F>: Ord,
{
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl<F> Eq for Ranked<F> where Ranked<F>: Ord {}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;

    #[test]
    fn pops_by_priority_then_index() {
        let mut heap = BinaryHeap::new();
        for (p, i) in [
            (2.0f32, 1),
            (1.0, 7),
            (2.0, 0),
            (f32::NAN, 3),
            (-0.0, 4),
            (0.0, 2),
        ] {
            heap.push(Reverse(Ranked(p, i)));
        }
        let order: Vec<u32> = std::iter::from_fn(|| heap.pop().map(|Reverse(r)| r.1)).collect();
        assert_eq!(order, [4, 2, 7, 0, 1, 3]);
    }
}
