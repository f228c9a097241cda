//! Stage `fill_ssd` (the patch engine's round-one hole-filling cost): the
//! scalar oracle, the explicit-SIMD CPU table and, with `--features gpu`
//! and an adapter, `kernels/fill_ssd.wgsl` give the same table — on random
//! and extreme windows (proptest), random centred candidate tables, and
//! real candidate tables of a shared-DEM source against a window of
//! another DEM; and centring leaves the DC-corrected SSD unchanged while no
//! cell is clamped.

use proptest::prelude::*;
use terrasynth::patch::fill::hole_fill::user_cells;
use terrasynth::patch::place::candidates::{COARSE, PreparedSource};
use terrasynth::patch::place::costs::ssd_dc;
use terrasynth::stages::fill_ssd::{FILL_CLAMP, centre_cells};

use crate::common::dem;
use crate::common::states::xorshift;
use crate::common::variants::{self, assert_agree};

/// `m × m` user cells, candidate cells and validity for `m` in 1..=32
/// (patch sizes 8..256), values anywhere in the clamp range.
fn case() -> impl Strategy<Value = (Vec<i32>, Vec<i32>, Vec<bool>)> {
    (1usize..=32).prop_flat_map(|m| {
        let n = m * m;
        let v = prop_oneof![
            4 => -FILL_CLAMP..=FILL_CLAMP,
            1 => Just(FILL_CLAMP),
            1 => Just(-FILL_CLAMP),
        ];
        (
            prop::collection::vec(v.clone(), n),
            prop::collection::vec(v, n),
            prop::collection::vec(any::<bool>(), n),
        )
    })
}

proptest! {
    #![proptest_config(crate::common::proptest_cases(500))]
    /// One candidate, one transform: every variant gives the oracle's
    /// value.
    #[test]
    fn fill_ssd_agrees_on_one_window((user, cand, valid) in case()) {
        let mask: Vec<i32> = valid.iter().map(|&v| -(v as i32)).collect();
        let user: Vec<i32> = user.iter().zip(&valid).map(|(&u, &v)| if v { u } else { 0 }).collect();
        let k = valid.iter().filter(|&&v| v).count() as i64;
        assert_agree(&variants::fill_ssd(&[user], &[mask], &cand, k), "one window");
    }

    /// Centring leaves the DC-corrected SSD (`patch::place::costs::ssd_dc`, the
    /// unclamped definition) unchanged while no cell is clamped, on every
    /// variant.
    #[test]
    fn centring_keeps_the_dc_corrected_ssd(
        (user, cand, valid) in case(),
        shift_u in -200_000i32..200_000,
        shift_c in -200_000i32..200_000,
    ) {
        // Heights far from zero (a source's absolute level) and with a
        // spread inside the clamp after centring.
        let raw_u: Vec<i32> = user.iter().map(|&v| v / 2 + shift_u).collect();
        let raw_c: Vec<i32> = cand.iter().map(|&v| v / 2 + shift_c).collect();
        let (mut cu, mut cc) = (raw_u.clone(), raw_c.clone());
        let k = centre_cells(&mut cu, Some(&valid));
        centre_cells(&mut cc, None);
        let mask: Vec<i32> = valid.iter().map(|&v| -(v as i32)).collect();
        let (want, _) = ssd_dc(&raw_u, &raw_c, &valid);
        let want = if k == 0 { 0 } else { want };
        for (name, got) in variants::fill_ssd(&[cu], &[mask], &cc, k) {
            prop_assert_eq!(got, vec![want], "{}", name);
        }
    }
}

/// The user's `m × m` cells permuted into every transform's frame, as
/// `patch::fill::hole_fill` builds them.
fn perms(cells: &[i32], valid: &[bool], m: usize) -> (Vec<Vec<i32>>, Vec<Vec<i32>>, i64) {
    user_cells(&mut cells.to_vec(), valid, m)
}

proptest! {
    #![proptest_config(crate::common::proptest_cases(24))]

    /// Random cells over the whole clamp range (so s2 passes 32 bits for
    /// large windows), random validity (none, some, all), 2..=32 cells a
    /// side (patch 16..=256) and 1..=40 candidates.
    #[test]
    fn fill_ssd_agrees_on_random_cells(
        m in 2usize..=32, n in 1usize..=40, extreme in any::<bool>(),
        seed in any::<u64>(), valid_every in 0usize..4,
    ) {
        let mut next = xorshift(seed);
        let mut value = || {
            let r = next();
            if extreme && r % 3 == 0 {
                if r & 8 == 0 { 40_000 } else { -40_000 }
            } else {
                (r >> 20) as i32 % (2 * FILL_CLAMP + 1)
            }
        };
        let user: Vec<i32> = (0..m * m).map(|_| value()).collect();
        let mut cells: Vec<i32> = (0..n * m * m).map(|_| value()).collect();
        for c in cells.chunks_mut(m * m) {
            centre_cells(c, None);
        }
        let valid: Vec<bool> = (0..m * m)
            .map(|i| valid_every != 0 && (i % (valid_every + 1) != 0 || valid_every == 3))
            .collect();
        let (u, k, count) = perms(&user, &valid, m);
        assert_agree(&variants::fill_ssd(&u, &k, &cells, count), &format!("random m {m}, {n} candidates"));
    }
}

/// Real tables: every fill candidate of a prepared shared-DEM source, under
/// every transform, against a half-filled window cut from another DEM.
#[test]
fn fill_ssd_agrees_on_shared_dem_sources() {
    let read = |name| dem::heights(name, "the real-table fill_ssd cross-check");
    let (Some(a), Some(b)) = (read("pyrenees_andorra"), read("thuringia_hills")) else {
        return;
    };
    let params = terrasynth::patch::Params::default();
    let m = params.patch / COARSE;
    let src = PreparedSource::prepare("pyrenees", &a.crop(0, 0, 384, 384).unwrap(), &params, 1.0)
        .unwrap();
    assert!(src.fill_cells.len() >= 16 * m * m, "too few candidates");
    // The user window: the 8×-reduced mean heights (decimetres) of a patch
    // of the other DEM, its lower-left half filled.
    let (ox, oy) = (200, 150);
    let mut cells = vec![0i32; m * m];
    for cy in 0..m {
        for cx in 0..m {
            let mut s = 0.0f64;
            for y in 0..COARSE {
                for x in 0..COARSE {
                    s += b.get(ox + cx * COARSE + x, oy + cy * COARSE + y) as f64;
                }
            }
            cells[cy * m + cx] = (s / (COARSE * COARSE) as f64 * 10.0).round() as i32;
        }
    }
    let valid: Vec<bool> = (0..m * m).map(|i| i % m <= i / m).collect();
    let (u, k, count) = perms(&cells, &valid, m);
    let runs = variants::fill_ssd(&u, &k, &src.fill_cells, count);
    assert_agree(&runs, "pyrenees candidates vs a thuringia window");
}
