//! The preview renderer's picture: the `shade` kernel against scalar
//! expectations (plane shading, contour placement, red range, nodata,
//! types, water, grid, exaggeration).

use crate::common::render::{GREY, plain, px, west_light};
use terrasynth::Heightfield;
use terrasynth::io::TypeMask;
use terrasynth::render::prepare::{NODATA_COLOUR, NODATA_HATCH, RANGE_COLOUR, UNITS_PER_M};
use terrasynth::render::tint::{WATER_SHALLOW, pack};
use terrasynth::render::{
    Contours, Grid, RenderError, RenderOptions, Sea, TypeOverlay, prepare, render,
};
use terrasynth::stages::shade::{self, ShadeParams};

#[test]
fn params_layout_suits_a_wgsl_uniform() {
    assert_eq!(std::mem::size_of::<ShadeParams>() % 16, 0);
    assert_eq!(std::mem::offset_of!(ShadeParams, lights), 0);
    assert_eq!(std::mem::offset_of!(ShadeParams, width), 64);
}

#[test]
fn plane_of_known_slope_gets_the_lambert_value() {
    // z rises eastward with slope s; the light comes from the west at 45°,
    // so the surface faces it: cos θ = (s·cos45 + sin45) / √(1 + s²).
    for (s, cell) in [
        (0.0, 10.0),
        (0.25, 30.0),
        (1.0, 92.5),
        (3.0, 1.0),
        (-0.5, 5.0),
    ] {
        let hf = Heightfield::from_fn(9, 9, cell, |x, _| (s * cell * x as f64) as f32).unwrap();
        let o = RenderOptions {
            lighting: west_light(),
            ..plain()
        };
        let prep = prepare(&hf, &o).unwrap();
        let c45 = std::f64::consts::FRAC_1_SQRT_2;
        let lambert = ((s * c45 + c45) / (1.0 + s * s).sqrt()).max(0.0);
        let slope = |v: f64| (v * shade::SLOPE_ONE as f64).round() as i32;
        let hs = shade::hillshade(&prep.params, slope(s), 0) as f64;
        assert!(
            (hs / 4096.0 - lambert).abs() < 2e-3,
            "slope {s}: {hs} vs {lambert}"
        );

        // Through the whole pipeline: grey × the shading factor.
        let img = render(&hf, &o).unwrap().image;
        let flat = c45;
        let f = if lambert <= flat {
            0.25 + 0.75 * lambert / flat
        } else {
            (0.25 + 0.75 * lambert / flat).min(1.5)
        };
        let expect = if f <= 1.0 {
            200.0 * f
        } else {
            200.0 + 55.0 * (f - 1.0)
        };
        let got = px(&img, 4, 4)[0] as f64;
        assert!((got - expect).abs() <= 1.5, "slope {s}: {got} vs {expect}");
        // A plane shades uniformly, edges included (they replicate).
        assert!(img.pixels().all(|p| p.0 == px(&img, 4, 4)));
    }
}

#[test]
fn hillshade_is_symmetric_and_bounded() {
    let hf = Heightfield::new(3, 3, 1.0).unwrap();
    let p = prepare(&hf, &plain()).unwrap().params;
    for s in [1, 100, 4096, 40_000, shade::MAX_SLOPE] {
        // The default lights are mirror-symmetric about the NW diagonal.
        assert_eq!(shade::hillshade(&p, s, 0), shade::hillshade(&p, 0, s));
        // Rising to the south-east faces the north-west key light.
        assert!(shade::hillshade(&p, s, s) <= 4096);
        assert!(shade::hillshade(&p, s, s) > shade::hillshade(&p, -s, -s));
    }
}

/// Pixels that differ between a render with contours and one without.
fn contour_pixels(hf: &Heightfield, interval: f64) -> Vec<bool> {
    let with = RenderOptions {
        contours: Contours::Every(interval),
        ..plain()
    };
    let a = render(hf, &with).unwrap().image;
    let b = render(hf, &plain()).unwrap().image;
    a.pixels().zip(b.pixels()).map(|(p, q)| p != q).collect()
}

#[test]
fn contours_appear_exactly_where_heights_cross_levels() {
    // A tilted plane (mm-exact heights) crossing many 1 m levels.
    let (w, h) = (64usize, 48usize);
    let height = |x: usize, y: usize| (0.37 * x as f64 + 0.113 * y as f64) as f32;
    let hf = Heightfield::from_fn(w, h, 1.0, height).unwrap();
    let on = contour_pixels(&hf, 1.0);
    let q = |x: usize, y: usize| (height(x, y) as f64 * UNITS_PER_M).round() as i64;
    let level = |v: i64| v.div_euclid(1000);
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            // Every line pixel has a level inside its 3×3 neighbourhood.
            let (mut lo, mut hi) = (i64::MAX, i64::MIN);
            for dy in 0..3 {
                for dx in 0..3 {
                    lo = lo.min(q(x + dx - 1, y + dy - 1));
                    hi = hi.max(q(x + dx - 1, y + dy - 1));
                }
            }
            if on[y * w + x] {
                assert!(
                    level(lo) != level(hi),
                    "line at ({x}, {y}) crosses no level"
                );
            }
            // Every crossing between horizontal neighbours is drawn.
            if x + 1 < w - 1 && level(q(x, y)) != level(q(x + 1, y)) {
                assert!(
                    on[y * w + x] || on[y * w + x + 1],
                    "crossing at ({x}, {y}) not drawn"
                );
            }
        }
    }
    assert!(on.iter().filter(|&&b| b).count() > 200);
}

#[test]
fn flat_ground_on_a_level_draws_no_contour() {
    let hf = Heightfield::from_fn(20, 20, 1.0, |_, _| 100.0).unwrap();
    assert!(contour_pixels(&hf, 10.0).iter().all(|&b| !b));
}

#[test]
fn auto_interval_is_nice() {
    let hf = Heightfield::from_fn(40, 40, 5.0, |x, _| x as f32 * 100.0 / 39.0).unwrap();
    let p = render(&hf, &RenderOptions::default()).unwrap();
    assert_eq!(p.info.contour_interval_m, Some(5.0));
}

#[test]
fn heights_outside_the_range_are_red() {
    // A gentle ramp (2 m per 100 m cell) so shading barely changes colours.
    let hf = Heightfield::from_fn(50, 4, 100.0, |x, _| x as f32 * 2.0).unwrap();
    let o = RenderOptions {
        range: Some((20.0, 80.0)),
        ..plain()
    };
    let img = render(&hf, &o).unwrap().image;
    for x in 0..50u32 {
        let p = px(&img, x, 2);
        let h = x as f64 * 2.0;
        let red = p[0] as i32 > p[1] as i32 + 100 && p[0] as i32 > p[2] as i32 + 100;
        assert_eq!(red, !(20.0..=80.0).contains(&h), "x {x}: {p:?}");
    }
    // The red is the range colour, shaded like the terrain.
    let p = px(&img, 0, 2);
    assert!(p[0].abs_diff(RANGE_COLOUR[0]) < 12, "{p:?}");
}

#[test]
fn nodata_is_hatched_grey_and_does_not_leak() {
    let hf = Heightfield::from_fn(32, 32, 1.0, |x, y| {
        if (8..16).contains(&x) && (8..16).contains(&y) {
            f32::NAN
        } else {
            (x + y) as f32
        }
    })
    .unwrap();
    let o = RenderOptions {
        contours: Contours::Every(3.0),
        ..plain()
    };
    let img = render(&hf, &o).unwrap().image;
    let nodata = [
        pack(NODATA_COLOUR, 255).to_le_bytes(),
        pack(NODATA_HATCH, 255).to_le_bytes(),
    ];
    for y in 0..32 {
        for x in 0..32 {
            let hole = (8..16).contains(&x) && (8..16).contains(&y);
            assert_eq!(nodata.contains(&px(&img, x, y)), hole, "({x}, {y})");
        }
    }
    // Both stripes of the hatch show.
    assert_ne!(px(&img, 8, 8), px(&img, 12, 8));
}

#[test]
fn all_nodata_renders_as_hatch() {
    let hf = Heightfield::from_vec(2, 2, 1.0, vec![f32::NAN; 4]).unwrap();
    let p = render(&hf, &RenderOptions::default()).unwrap();
    assert_eq!(p.image.dimensions(), (512, 512));
    assert_eq!(p.info.contour_interval_m, None);
}

#[test]
fn type_overlay_blends_each_type_colour() {
    let hf = Heightfield::new(6, 2, 1.0).unwrap();
    let mask = TypeMask::new(6, 2, vec![0, 1, 2, 255, 7, 3, 0, 1, 2, 255, 7, 3]).unwrap();
    let mut overlay = TypeOverlay::new(mask);
    overlay.colours[7] = [10, 20, 30, 255];
    let o = RenderOptions {
        types: Some(overlay.clone()),
        ..plain()
    };
    let img = render(&hf, &o).unwrap().image;
    let grey = pack(GREY, 255);
    for (x, &t) in [0u8, 1, 2, 255, 7, 3].iter().enumerate() {
        let expect = if t == 255 {
            grey
        } else {
            let c = u32::from_le_bytes(overlay.colours[t as usize]);
            let a = c >> 24;
            shade::blend(grey, c, a + (a >> 7))
        };
        // Flat ground shades by exactly 1.
        assert_eq!(
            px(&img, x as u32, 1),
            (expect | 0xff00_0000).to_le_bytes(),
            "type {t}"
        );
    }
    assert_eq!(px(&img, 4, 0), [10, 20, 30, 255]);
}

#[test]
fn water_below_sea_level_with_a_coastline() {
    let hf = Heightfield::from_fn(40, 40, 10.0, |x, _| x as f32 * 3.0 - 30.0).unwrap();
    let o = RenderOptions {
        sea: Sea::Auto,
        ..plain()
    };
    let p = render(&hf, &o).unwrap();
    assert_eq!(p.info.sea_level_m, Some(0.0));
    let img = p.image;
    let sea = px(&img, 2, 20);
    assert!(sea[2] > sea[0] + 30, "water is blue: {sea:?}");
    assert!(sea[2].abs_diff(WATER_SHALLOW[2]) < 60);
    let land = px(&img, 35, 20);
    assert!(
        land[0].abs_diff(land[2]) < 10,
        "land keeps its tint: {land:?}"
    );
    // The coastline darkens the first land pixels.
    let coast = (5..20).map(|x| px(&img, x, 20)[1]).min().unwrap();
    assert!(coast < land[1] - 40 && coast < sea[1] - 40);
}

#[test]
fn grid_lines_fall_on_cell_multiples() {
    let hf = Heightfield::from_fn(100, 100, 1.0, |_, _| 5.0).unwrap();
    let mut o = RenderOptions {
        min_size: 512,
        ..plain()
    };
    let base = render(&hf, &o).unwrap().image;
    o.grid = Grid::Cells(10.0);
    let p = render(&hf, &o).unwrap();
    assert_eq!(p.info.px_per_cell_x, 6.0);
    // Row 7 is between horizontal lines: only the vertical lines change it.
    for x in 0..600u32 {
        let on = x % 60 == 0 && x > 0;
        assert_eq!(px(&p.image, x, 7) != px(&base, x, 7), on, "x {x}");
    }
    // Column 7 likewise meets only the horizontal lines.
    for y in 0..600u32 {
        let on = y % 60 == 0 && y > 0;
        assert_eq!(px(&p.image, 7, y) != px(&base, 7, y), on, "y {y}");
    }
    // Too fine a grid is refused, not drawn as grey mush.
    o.grid = Grid::Cells(0.1);
    assert!(matches!(render(&hf, &o), Err(RenderError::Option { .. })));
}

#[test]
fn exaggeration_deepens_shading() {
    let hf = Heightfield::from_fn(9, 9, 10.0, |x, _| x as f32).unwrap();
    let mut o = RenderOptions {
        lighting: west_light(),
        ..plain()
    };
    let flat = px(&render(&hf, &o).unwrap().image, 4, 4)[0];
    o.exaggeration = 5.0;
    let steep = px(&render(&hf, &o).unwrap().image, 4, 4)[0];
    assert!(steep > flat, "{steep} vs {flat}");
}
