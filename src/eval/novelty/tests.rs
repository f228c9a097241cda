use super::*;
use crate::procedural::fbm::Fractal;

/// fBm terrain, `w × h` cells, features ~32 cells across.
fn terrain(w: usize, h: usize, seed: u32) -> Heightfield {
    let f = Fractal::new(seed, 1.0 / 32.0);
    Heightfield::from_fn(w, h, 30.0, |x, y| {
        (f.sample(x as f64, y as f64) * 500.0) as f32
    })
    .unwrap()
}

/// `hf` in orientation `o`, with heights scaled and raised.
fn transformed(hf: &Heightfield, o: Orientation, scale: f32, raise: f32) -> Heightfield {
    let (w, h) = o.size(hf.width(), hf.height());
    Heightfield::from_fn(w, h, hf.cell_size(), |x, y| {
        let (sx, sy) = o.source(x, y, w, h);
        hf.get(sx, sy) * scale + raise
    })
    .unwrap()
}

#[test]
fn a_crop_of_the_exemplar_is_a_copy_in_every_orientation_and_height() {
    let ex = terrain(300, 260, 1);
    let crop = ex.crop(38, 22, 192, 192).unwrap();
    let p = Params::default();
    for o in Orientation::ALL {
        let s = transformed(&crop, o, 1.7, -400.0);
        let n = copies(&s, &[&ex], &p).unwrap();
        assert_eq!(n.scored, 9, "{o:?}: 3 x 3 windows of 64");
        assert_eq!(n.share, 1.0, "{o:?}: {:?}", n.windows);
        assert!(n.median_ncc > 1.0 - 1e-9, "{o:?}: {}", n.median_ncc);
        // It is found where it came from.
        let w = n.windows[0];
        let (ow, oh) = o.size(192, 192);
        let (cx, cy) = o.source(w.x, w.y, ow, oh);
        let (dx, dy) = o.source(w.x + 63, w.y + 63, ow, oh);
        let (sx, sy) = (38 + cx.min(dx), 22 + cy.min(dy));
        assert_eq!((w.source_x, w.source_y), (sx, sy), "{o:?}: {w:?}");
    }
}

#[test]
fn other_terrain_is_not_a_copy() {
    let ex = terrain(300, 300, 1);
    let other = terrain(256, 256, 2);
    let n = copies(&other, &[&ex], &Params::default()).unwrap();
    assert_eq!(n.scored, 16);
    assert_eq!(n.share, 0.0, "{:?}", n.windows);
    assert!(n.median_ncc < 0.9, "{}", n.median_ncc);
    // The same output against two exemplars, one of which holds it: all
    // copies, found in the second.
    let n = copies(&other, &[&ex, &other], &Params::default()).unwrap();
    assert_eq!(n.share, 1.0);
    assert!(n.windows.iter().all(|w| w.exemplar == 1));
}

#[test]
fn flat_windows_are_skipped_against_the_exemplars_windows() {
    let ex = terrain(256, 256, 3);
    // Left half rugged (a crop), right half a plain with a faint tilt.
    let s = Heightfield::from_fn(256, 128, 30.0, |x, y| {
        if x < 128 {
            ex.get(x, y)
        } else {
            100.0 + 0.001 * y as f32
        }
    })
    .unwrap();
    let n = copies(&s, &[&ex], &Params::default()).unwrap();
    assert_eq!((n.scored, n.flat), (4, 4));
    assert!(n.windows.iter().all(|w| w.x < 128));
}

#[test]
fn windows_spread_as_numpy_linspace_rounds() {
    let all: Vec<usize> = (0..256).collect();
    let s = spread(&all, 150);
    assert_eq!(s.len(), 150);
    assert_eq!(&s[..12], &[0, 2, 3, 5, 7, 9, 10, 12, 14, 15, 17, 19]);
    assert_eq!(&s[145..], &[248, 250, 252, 253, 255]);
    let all: Vec<usize> = (0..1681).collect();
    assert_eq!(&spread(&all, 150)[..8], &[0, 11, 23, 34, 45, 56, 68, 79]);
    assert_eq!(spread(&all[..7], 150), &all[..7]);
}

#[test]
fn repetition_finds_a_repeated_landform_and_not_a_window_itself() {
    // A smooth random field: every window correlates > 0.95 with itself
    // shifted by a cell, so counting overlapping positions would call all
    // of it repeated.
    let a = terrain(256, 256, 4);
    let n = repetition(&a, &[], &Params::default()).unwrap();
    assert_eq!(n.scored, 16);
    assert_eq!(n.share, 0.0, "{:?}", n.windows);
    // The left half mirrored into the right: every window has its twin.
    let twin = Heightfield::from_fn(256, 128, 30.0, |x, y| {
        if x < 128 {
            a.get(x, y)
        } else {
            a.get(255 - x, y)
        }
    })
    .unwrap();
    let n = repetition(&twin, &[], &Params::default()).unwrap();
    assert_eq!(n.share, 1.0, "{:?}", n.windows);
    assert!(
        n.windows.iter().all(|w| w.orientation == 1),
        "found as mirrored in x"
    );
}

#[test]
fn halves_compare_top_with_bottom() {
    // Top and bottom the same terrain: the baseline is all copies.
    let a = terrain(256, 128, 5);
    let stacked = Heightfield::from_fn(256, 256, 30.0, |x, y| a.get(x, y % 128)).unwrap();
    assert_eq!(halves(&stacked, &Params::default()).unwrap().share, 1.0);
    let b = terrain(256, 256, 6);
    assert_eq!(halves(&b, &Params::default()).unwrap().share, 0.0);
}

#[test]
fn bad_input_is_refused_with_what_is_wrong() {
    let small = terrain(50, 80, 1);
    let ex = terrain(200, 200, 1);
    let p = Params::default();
    assert!(matches!(
        copies(&small, &[&ex], &p),
        Err(EvalError::TooSmall {
            width: 50,
            height: 80,
            min: 64
        })
    ));
    assert!(matches!(
        copies(&ex, &[&small], &p),
        Err(EvalError::TooSmall { .. })
    ));
    let mut holed = ex.clone();
    holed.set(7, 9, f32::NAN);
    assert!(matches!(
        copies(&holed, &[&ex], &p),
        Err(EvalError::Nodata { x: 7, y: 9, .. })
    ));
    for bad in [
        Params { downsample: 0, ..p },
        Params { window: 6, ..p },
        Params {
            threshold: 1.5,
            ..p
        },
        Params {
            max_windows: 1,
            ..p
        },
    ] {
        assert!(matches!(
            copies(&ex, &[&ex], &bad),
            Err(EvalError::NoveltyParams(_))
        ));
    }
}
