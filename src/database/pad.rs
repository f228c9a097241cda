//! The mirrored pad around every exemplar: [`PAD`] texels of level 0 on
//! each side, mirrored from the exemplar at build time.
//!
//! Why: synthesis coordinates stay [`MARGIN`] texels inside every exemplar
//! at every level, and synthesis starts at level
//! [`MAX_START_LEVEL`](crate::synth::coarse::MAX_START_LEVEL), where a
//! texel is 8 pixels across — so without a pad the outer 16 pixels of
//! every exemplar side were (almost) never drawn. Measured on the north
//! German plain (733², seeds 11–13): 0.5–2 % of the output came from its
//! outer 16 pixels, 8.5 % of its area, and that rim is where its lowest,
//! most pitted land lies. With the pad, the level-3 interior is exactly the
//! real exemplar (the coarse start and its [`Profile`](crate::synth::coarse::Profile)
//! draw from the real area only), and finer levels may wander into the pad,
//! which holds mirrored real content, like the start's mirrored blocks.
//!
//! The mirror does not repeat the edge texel (−1 ↦ 1): a repeated edge
//! would make a flat pair of rows along every exemplar side. Users never
//! see padded coordinates: [`super::ExemplarMeta::to_exemplar`] maps an
//! atlas texel back to the exemplar pixel whose height it holds.

use super::layout::MARGIN;

/// Pad of a new database, level-0 texels per side: [`MARGIN`] texels of the
/// start level (3), so that the start level's interior is the real exemplar.
pub const PAD: u32 = MARGIN << 3;

/// Largest pad a database file may declare (keeps every size arithmetic far
/// from overflow; new databases use [`PAD`]).
pub const MAX_PAD: u32 = 1024;

/// The exemplar index that padded offset `i` (may be negative or ≥ n)
/// mirrors, for an axis of `n ≥ 1` texels: reflection about the first and
/// last texel, repeated for pads wider than the exemplar.
pub fn reflect(i: i64, n: u32) -> u32 {
    if n == 1 {
        return 0;
    }
    let period = 2 * (i64::from(n) - 1);
    let m = i.rem_euclid(period);
    (if m < i64::from(n) { m } else { period - m }) as u32
}

/// `data` (`width × height`, row-major) with `pad` mirrored texels added on
/// every side.
pub fn pad_grid<T: Copy>(data: &[T], width: usize, height: usize, pad: u32) -> Vec<T> {
    let p = i64::from(pad);
    let (pw, ph) = (width + 2 * pad as usize, height + 2 * pad as usize);
    let xs: Vec<usize> = (0..pw as i64)
        .map(|x| reflect(x - p, width as u32) as usize)
        .collect();
    (0..ph as i64)
        .flat_map(|y| {
            let row = reflect(y - p, height as u32) as usize * width;
            xs.iter().map(move |&x| data[row + x])
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reflect_mirrors_without_repeating_the_edge() {
        let n = 5;
        let got: Vec<u32> = (-6..11).map(|i| reflect(i, n)).collect();
        assert_eq!(got, [2, 3, 4, 3, 2, 1, 0, 1, 2, 3, 4, 3, 2, 1, 0, 1, 2]);
        assert_eq!(reflect(-16, 16), 14);
        assert_eq!(reflect(-3, 1), 0);
        let grid: Vec<u32> = (0..6).collect(); // 3 × 2
        let padded = pad_grid(&grid, 3, 2, 2);
        assert_eq!(padded.len(), 7 * 6);
        // Row −1 mirrors row 1; column −1 mirrors column 1.
        assert_eq!(&padded[2 * 7 + 2..2 * 7 + 5], &[0, 1, 2]);
        assert_eq!(padded[7 + 1], grid[3 + 1]);
        assert_eq!(padded[2 * 7 + 1], grid[1]);
    }
}
