//! DC-corrected feathering (seed 002 §7.4.1). A plain `lerp(dst, src, mask)`
//! raises or lowers the whole brushed area when the two terrains sit at
//! different base heights (Fig. 7.8). Splitting both into their mean (the DC
//! component, taken over the mask's support) and the rest, and blending the
//! two parts separately, keeps the destination's level and takes only the
//! source's relief.

use super::Inputs;

/// Blends `src` into `dst` in place with weights `mask` in `[0, 1]`:
/// `dst' = lerp(dst − μ_d, src − μ_s, m) + μ_d`, where μ are the
/// mask-weighted means. With `keep_level = false` the mean is lerped too
/// (`+ lerp(μ_d, μ_s, m)`), which is the plain feather.
pub fn feather(inputs: Inputs<'_>, keep_level: bool) {
    let Inputs { dst, src, mask, .. } = inputs;
    let (mut wsum, mut dsum, mut ssum) = (0.0f64, 0.0f64, 0.0f64);
    for ((&d, &s), &m) in dst.iter().zip(src).zip(mask) {
        wsum += m as f64;
        dsum += m as f64 * d as f64;
        ssum += m as f64 * s as f64;
    }
    if wsum == 0.0 {
        return;
    }
    let (md, ms) = (dsum / wsum, ssum / wsum);
    for ((d, &s), &m) in dst.iter_mut().zip(src).zip(mask) {
        let m = m as f64;
        let detail = (1.0 - m) * (*d as f64 - md) + m * (s as f64 - ms);
        let level = if keep_level {
            md
        } else {
            (1.0 - m) * md + m * ms
        };
        *d = (detail + level) as f32;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::blend::BlendError;

    #[test]
    fn keeps_the_destination_level_and_takes_the_source_relief() {
        let (w, h) = (16, 1);
        let mut dst = vec![100.0f32; w];
        let src: Vec<f32> = (0..w)
            .map(|x| 500.0 + if x % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let mask = vec![1.0f32; w];
        feather(Inputs::new(w, h, &mut dst, &src, &mask).unwrap(), true);
        for (x, v) in dst.iter().enumerate() {
            let want = 100.0 + if x % 2 == 0 { 1.0 } else { -1.0 };
            assert!((v - want).abs() < 1e-4, "{x}: {v}");
        }
    }

    #[test]
    fn zero_mask_changes_nothing_and_bad_mask_is_refused() {
        let mut dst = vec![1.0f32, 2.0, 3.0];
        feather(
            Inputs::new(3, 1, &mut dst, &[9.0; 3], &[0.0; 3]).unwrap(),
            true,
        );
        assert_eq!(dst, [1.0, 2.0, 3.0]);
        let e = Inputs::new(3, 1, &mut dst, &[9.0; 3], &[0.0, 1.5, 0.0]).unwrap_err();
        assert!(matches!(e, BlendError::Mask { x: 1, y: 0, .. }), "{e}");
    }
}
