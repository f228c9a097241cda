//! Graph-cut seams: the max-flow result is the minimum seam, checked
//! against brute force on small constructed cases.

use proptest::prelude::*;
use terrasynth::patch::merge::graphcut::{Label, min_cut};

/// Cost of a labelling: the sum of costs of neighbour pairs that differ.
fn seam_cost(w: usize, h: usize, new: &[bool], ch: &[i64], cv: &[i64]) -> i64 {
    let mut c = 0;
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            if x + 1 < w && new[i] != new[i + 1] {
                c += ch[i];
            }
            if y + 1 < h && new[i] != new[i + w] {
                c += cv[i];
            }
        }
    }
    c
}

fn brute_force(w: usize, h: usize, labels: &[Label], ch: &[i64], cv: &[i64]) -> i64 {
    let free: Vec<usize> = (0..w * h).filter(|&i| labels[i] == Label::Free).collect();
    let mut best = i64::MAX;
    for bits in 0u32..(1 << free.len()) {
        let mut new: Vec<bool> = labels.iter().map(|&l| l == Label::New).collect();
        for (k, &i) in free.iter().enumerate() {
            new[i] = bits >> k & 1 == 1;
        }
        best = best.min(seam_cost(w, h, &new, ch, cv));
    }
    best
}

fn case() -> impl Strategy<Value = (usize, usize, Vec<Label>, Vec<i64>, Vec<i64>)> {
    (1usize..=4, 1usize..=4).prop_flat_map(|(w, h)| {
        let n = w * h;
        (
            Just(w),
            Just(h),
            prop::collection::vec(
                prop_oneof![3 => Just(Label::Free), 1 => Just(Label::Old), 1 => Just(Label::New)],
                n,
            ),
            prop::collection::vec(0i64..50, n),
            prop::collection::vec(0i64..50, n),
        )
    })
}

proptest! {
    #![proptest_config(crate::common::proptest_cases(400))]
    #[test]
    fn max_flow_finds_the_minimum_seam((w, h, labels, ch, cv) in case()) {
        let seam = min_cut(w, h, &labels, &ch, &cv);
        let want = brute_force(w, h, &labels, &ch, &cv);
        prop_assert_eq!(seam.cost, want);
        // The returned labelling respects the constraints and costs what was reported.
        for (i, &l) in labels.iter().enumerate() {
            match l {
                Label::Old => prop_assert!(!seam.take_new[i]),
                Label::New => prop_assert!(seam.take_new[i]),
                Label::Free => {}
            }
        }
        prop_assert_eq!(seam_cost(w, h, &seam.take_new, &ch, &cv), want);
    }
}

#[test]
fn a_constructed_overlap_is_cut_along_the_cheap_column() {
    // 6×4: column 0 old, column 5 new; cutting between columns 3 and 4 is cheap.
    let (w, h) = (6, 4);
    let labels: Vec<Label> = (0..w * h)
        .map(|i| match i % w {
            0 => Label::Old,
            5 => Label::New,
            _ => Label::Free,
        })
        .collect();
    let ch: Vec<i64> = (0..w * h)
        .map(|i| if i % w == 3 { 1 } else { 10 })
        .collect();
    let cv = vec![10i64; w * h];
    let seam = min_cut(w, h, &labels, &ch, &cv);
    assert_eq!(seam.cost, 4);
    for i in 0..w * h {
        assert_eq!(seam.take_new[i], i % w >= 4, "pixel {i}");
    }
}
