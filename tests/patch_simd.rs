//! The explicit-SIMD round-one fill kernel gives the same bytes as its
//! scalar oracle on random and extreme inputs, and centring leaves the
//! DC-corrected SSD unchanged while no cell is clamped.

use proptest::prelude::*;
use terrasynth::patch::costs::ssd_dc;
use terrasynth::stages::fill_ssd::{FILL_CLAMP, centre_cells, fill_ssd, fill_ssd_scalar};

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
    #![proptest_config(ProptestConfig::with_cases(500))]
    #[test]
    fn simd_fill_kernel_equals_the_scalar_oracle((user, cand, valid) in case()) {
        let mask: Vec<i32> = valid.iter().map(|&v| -(v as i32)).collect();
        let user: Vec<i32> = user.iter().zip(&valid).map(|(&u, &v)| if v { u } else { 0 }).collect();
        let k = valid.iter().filter(|&&v| v).count() as i64;
        prop_assert_eq!(fill_ssd(&user, &mask, &cand, k), fill_ssd_scalar(&user, &mask, &cand, k));
    }

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
        prop_assert_eq!(fill_ssd(&cu, &mask, &cc, k), want);
    }
}
