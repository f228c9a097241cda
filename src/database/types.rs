//! Terrain types (paper §5.2): every exemplar texel carries a type T⁰; each
//! coarser level takes the most frequent type of its 2^i × 2^i block of T⁰;
//! and for each type a short pre-drawn list of coordinates serves seeding
//! when all correction candidates are rejected.
//!
//! Masks are [`crate::io::TypeMask`]s (8-bit index PNG + names JSON). Types
//! are identified across exemplars *by name*, so "mountains" in two masks is
//! one type. An exemplar without a mask is of type `unlabelled`.

use super::error::DbError;
use super::layout::{LevelLayout, pack};
use crate::hash::hash4;
use crate::io::TypeMask;

/// Most types in one database: target sets are u32 bit masks (DESIGN §3).
pub const MAX_TYPES: usize = 32;
/// Seed coordinates stored per type and level.
pub const SEEDS_PER_TYPE: usize = 64;
/// Marks an unused seed slot.
pub const NO_SEED: u32 = u32::MAX;
/// The type of exemplars given without a mask.
pub const UNLABELLED: &str = "unlabelled";

/// Maps every exemplar's local indices to global type ids (by name, in order
/// of first appearance). Returns the names and per-exemplar T⁰ (global ids).
pub fn unify(
    masks: &[Option<&TypeMask>],
    sizes: &[(usize, usize)],
    names_of_exemplars: &[String],
) -> Result<(Vec<String>, Vec<Vec<u8>>), DbError> {
    let mut names: Vec<String> = Vec::new();
    let id_of = |name: String, names: &mut Vec<String>| -> usize {
        match names.iter().position(|n| *n == name) {
            Some(i) => i,
            None => {
                names.push(name);
                names.len() - 1
            }
        }
    };
    let mut t0 = Vec::with_capacity(masks.len());
    for (e, mask) in masks.iter().enumerate() {
        let (w, h) = sizes[e];
        match mask {
            None => {
                let id = id_of(UNLABELLED.to_string(), &mut names);
                t0.push(vec![id as u8; w * h]);
            }
            Some(m) => {
                if (m.width, m.height) != (w, h) {
                    return Err(DbError::MaskSize {
                        name: names_of_exemplars[e].clone(),
                        mask_w: m.width,
                        mask_h: m.height,
                        width: w,
                        height: h,
                    });
                }
                let mut local = [u8::MAX; 256];
                let mut present = [false; 256];
                for &i in &m.indices {
                    present[i as usize] = true;
                }
                for i in 0..256 {
                    if present[i] {
                        local[i] = id_of(m.name_of(i as u8), &mut names) as u8;
                    }
                }
                if names.len() > MAX_TYPES {
                    return Err(DbError::TooManyTypes(names.len()));
                }
                t0.push(m.indices.iter().map(|&i| local[i as usize]).collect());
            }
        }
    }
    if names.len() > MAX_TYPES {
        return Err(DbError::TooManyTypes(names.len()));
    }
    Ok((names, t0))
}

/// T^i of one exemplar: the most frequent T⁰ type in each 2^i × 2^i block
/// (ties go to the lowest type id). Computed from T⁰ directly, since a
/// majority of majorities is not the majority.
pub fn majority(t0: &[u8], width: usize, level: usize, out_w: usize, out_h: usize) -> Vec<u8> {
    let b = 1usize << level;
    let mut out = Vec::with_capacity(out_w * out_h);
    for by in 0..out_h {
        for bx in 0..out_w {
            let mut hist = [0u32; MAX_TYPES];
            for y in by * b..(by + 1) * b {
                for &t in &t0[y * width + bx * b..y * width + (bx + 1) * b] {
                    hist[t as usize] += 1;
                }
            }
            let best = (0..MAX_TYPES)
                .max_by(|&a, &c| hist[a].cmp(&hist[c]).then(c.cmp(&a)))
                .expect("MAX_TYPES > 0");
            out.push(best as u8);
        }
    }
    out
}

/// Per type, up to [`SEEDS_PER_TYPE`] interior texels of that type at this
/// level, chosen by smallest hash (a deterministic uniform sample); unused
/// slots hold [`NO_SEED`]. Layout: `types × SEEDS_PER_TYPE` packed coordinates.
pub fn seeds(layout: &LevelLayout, types: &[u8], type_count: usize, level: u32) -> Vec<u32> {
    let mut ranked: Vec<Vec<(u32, u32)>> = vec![Vec::new(); type_count];
    for r in &layout.rects {
        for y in 0..r.height {
            for x in r.x0..r.x0 + r.width {
                if r.is_interior(x, y) {
                    let t = types[r.index(x, y)] as usize;
                    ranked[t].push((hash4(0x5eed, level, x, y), pack(x, y)));
                }
            }
        }
    }
    let mut out = vec![NO_SEED; type_count * SEEDS_PER_TYPE];
    for (t, mut list) in ranked.into_iter().enumerate() {
        list.sort_unstable();
        for (s, &(_, c)) in list.iter().take(SEEDS_PER_TYPE).enumerate() {
            out[t * SEEDS_PER_TYPE + s] = c;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn majority_rule_with_lowest_id_on_ties() {
        // 4x4 T0, level 1 → 2x2 blocks.
        #[rustfmt::skip]
        let t0 = [
            0, 1, 2, 2,
            1, 1, 2, 3,
            3, 3, 0, 1,
            0, 0, 1, 0,
        ];
        assert_eq!(majority(&t0, 4, 1, 2, 2), vec![1, 2, 0, 0]);
        // Level 2: one block; counts 0:5, 1:5, 2:3, 3:3 → tie → 0.
        assert_eq!(majority(&t0, 4, 2, 1, 1), vec![0]);
    }

    #[test]
    fn names_unify_across_masks() {
        let a = TypeMask {
            width: 2,
            height: 1,
            indices: vec![0, 1],
            names: [(0, "sea".into()), (1, "hills".into())].into(),
        };
        let b = TypeMask {
            width: 2,
            height: 1,
            indices: vec![3, 3],
            names: [(3, "hills".into())].into(),
        };
        let (names, t0) = unify(
            &[Some(&a), None, Some(&b)],
            &[(2, 1), (1, 1), (2, 1)],
            &["a".into(), "u".into(), "b".into()],
        )
        .unwrap();
        assert_eq!(names, vec!["sea", "hills", UNLABELLED]);
        assert_eq!(t0, vec![vec![0, 1], vec![2], vec![1, 1]]);
        assert!(matches!(
            unify(&[Some(&a)], &[(3, 1)], &["a".into()]),
            Err(DbError::MaskSize { .. })
        ));
    }
}
