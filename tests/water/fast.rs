//! The fast paths of `water` against plain reference implementations: the
//! fill in parallel strips against one priority-flood of the whole grid,
//! and D8's branch-free choice against a one-by-one lexicographic scan.

use std::cmp::Reverse;
use std::collections::BinaryHeap;
use terrasynth::water::d8::{self, CLOCKWISE, Edges, OUTLET, Surface};
use terrasynth::water::{fill, sea};

/// A deterministic pseudo-random value in [0, 1) for cell `i`.
fn noise(i: usize, seed: u64) -> f32 {
    let mut v =
        (i as u64 ^ seed.wrapping_mul(0x9E37_79B9_7F4A_7C15)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    v ^= v >> 31;
    v = v.wrapping_mul(0x94D0_49BB_1331_11EB);
    v ^= v >> 29;
    (v >> 40) as f32 / (1u64 << 24) as f32
}

/// Basins tens of cells wide (so lakes cross the strips' edges), with
/// metre noise and heights on a 0.5 m step (so levels tie).
fn terrain(w: usize, h: usize) -> Vec<f32> {
    (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            let z = 60.0 * (x / 41.0).sin() * (y / 29.0).cos()
                + 20.0 * (y / 97.0).sin()
                + 8.0 * noise(i, 1);
            // + 0.0: no -0.0, which both floods raise to a 0.0 level (its
            // bits change) where this reference's `<` leaves it.
            (z * 2.0).round() / 2.0 + 0.0
        })
        .collect()
}

/// One priority-flood of the whole grid with std's binary heap (Barnes et
/// al. 2014, Algorithm 1): the reference.
fn reference_fill(z: &[f32], w: usize, h: usize, sea: Option<(&[bool], f32)>) -> Vec<f32> {
    let mut z = z.to_vec();
    let mut closed = vec![false; w * h];
    let mut open = BinaryHeap::new();
    // Heights in order as integers: negative floats' bits run backwards.
    let key = |v: f32| {
        let b = v.to_bits();
        Reverse(if b >> 31 == 1 { !b } else { b | 1 << 31 })
    };
    let mut seed = |i: usize, z: &mut [f32], open: &mut BinaryHeap<_>| {
        if !closed[i] {
            closed[i] = true;
            open.push((key(z[i]), i));
        }
    };
    if let Some((m, level)) = sea {
        for i in (0..w * h).filter(|&i| m[i]) {
            z[i] = level;
            seed(i, &mut z, &mut open);
        }
    }
    for i in (0..w * h).filter(|&i| {
        let (x, y) = (i % w, i / w);
        x == 0 || y == 0 || x == w - 1 || y == h - 1
    }) {
        seed(i, &mut z, &mut open);
    }
    while let Some((_, c)) = open.pop() {
        let (x, y) = ((c % w) as isize, (c / w) as isize);
        for &(dx, dy, _) in &CLOCKWISE {
            let (nx, ny) = (x + dx, y + dy);
            if nx < 0 || ny < 0 || nx >= w as isize || ny >= h as isize {
                continue;
            }
            let k = ny as usize * w + nx as usize;
            if !closed[k] {
                closed[k] = true;
                if z[k] < z[c] {
                    z[k] = z[c];
                }
                open.push((key(z[k]), k));
            }
        }
    }
    z
}

#[test]
fn the_fill_in_strips_is_one_flood_of_the_whole_grid() {
    // 16384 wide: strips of 64 rows, so 300 rows make four strips (the last
    // one 108 rows), with basins across every seam.
    let (w, h) = (16384, 300);
    let z = terrain(w, h);
    let want = reference_fill(&z, w, h, None);
    let got = fill::priority_flood(&z, w, h, None);
    let raised = want.iter().zip(&z).filter(|(f, z)| f > z).count();
    assert!(
        raised > w * h / 10,
        "a test with lakes: {raised} cells raised"
    );
    let differ = got
        .iter()
        .zip(&want)
        .filter(|(a, b)| a.to_bits() != b.to_bits())
        .count();
    assert_eq!(differ, 0, "cells filled differently from one flood");
    // With a sea: its cells are outlets at sea level, inside strips too.
    let m = sea::mask(&z, w, h, -30.0);
    assert!(m.iter().filter(|&&s| s).count() > w, "a test with a sea");
    let want = reference_fill(&z, w, h, Some((&m, -30.0)));
    let got = fill::priority_flood(&z, w, h, Some((&m, -30.0)));
    assert!(
        got.iter()
            .zip(&want)
            .all(|(a, b)| a.to_bits() == b.to_bits())
    );
}

/// D8 as its tie rule reads: every neighbour in clockwise order, the
/// lexicographic (drop, gradient drop) over distance, strictly above (0, 0).
fn reference_receivers(s: &Surface<'_>) -> Vec<u32> {
    let (w, h) = (s.width, s.height);
    let g = |i: usize| s.gradient.map_or(0.0, |g| g[i] as f64);
    (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as isize, (i / w) as isize);
            let mut best = (0.0, 0.0, OUTLET);
            for &(dx, dy, dist) in &CLOCKWISE {
                let (nx, ny) = (x + dx, y + dy);
                if nx < 0 || ny < 0 || nx >= w as isize || ny >= h as isize {
                    continue;
                }
                let k = ny as usize * w + nx as usize;
                let dz = (s.heights[i] as f64 - s.heights[k] as f64) / dist;
                let dg = (g(i) - g(k)) / dist;
                if dz > best.0 || (dz == best.0 && dg > best.1) {
                    best = (dz, dg, k as u32);
                }
            }
            best.2
        })
        .collect()
}

#[test]
fn d8_chooses_as_the_one_by_one_tie_rule() {
    // Heights on three levels and a gradient on four: ties everywhere,
    // between cardinals, diagonals and both, with and without a gradient.
    let (w, h) = (257, 131);
    let z: Vec<f32> = (0..w * h).map(|i| (noise(i, 2) * 3.0).floor()).collect();
    let g: Vec<u32> = (0..w * h).map(|i| (noise(i, 3) * 4.0) as u32).collect();
    for gradient in [None, Some(&g[..])] {
        let s = Surface {
            heights: &z,
            width: w,
            height: h,
            gradient,
            sinks: None,
        };
        let want = reference_receivers(&s);
        let got = d8::receivers(&s, Edges::Inside);
        let differ = (0..w * h).filter(|&i| got[i] != want[i]).count();
        assert_eq!(
            differ,
            0,
            "receivers differ (gradient: {})",
            gradient.is_some()
        );
        let outlets = want.iter().filter(|&&r| r == OUTLET).count();
        assert!(outlets > 100 && outlets < w * h / 2, "{outlets} outlets");
    }
}
