//! The preview renderer: the `shade` kernel against scalar expectations
//! (plane shading, contour placement, red range, nodata, types), sizing,
//! determinism across thread counts, robustness over sizes, the shared DEMs
//! and the CLI.

use image::Rgba;
use proptest::prelude::*;
use std::path::{Path, PathBuf};
use std::process::Command;
use terrasynth::Heightfield;
use terrasynth::render::prepare::{NODATA_COLOUR, NODATA_HATCH, RANGE_COLOUR, UNITS_PER_M};
use terrasynth::render::shade::{self, ShadeParams, flags};
use terrasynth::render::tint::{WATER_SHALLOW, pack};
use terrasynth::render::{
    Contours, Grid, Light, Lighting, Palette, RenderError, RenderOptions, Sea, TypeMask,
    TypeOverlay, prepare, render,
};

const GREY: [u8; 3] = [200, 200, 200];

/// Options that isolate one feature: a constant grey palette, no contours,
/// no water, no resizing.
fn plain() -> RenderOptions {
    RenderOptions {
        min_size: 1,
        contours: Contours::Off,
        sea: Sea::Off,
        palette: Palette::new(vec![(0.0, GREY), (1.0, GREY)]).unwrap(),
        ..RenderOptions::default()
    }
}

fn west_light() -> Lighting {
    Lighting {
        lights: vec![Light {
            azimuth_deg: 270.0,
            altitude_deg: 45.0,
            weight: 1.0,
        }],
        aspect_weighted: false,
        shadow: 0.25,
        highlight: 0.5,
    }
}

fn px(img: &image::RgbaImage, x: u32, y: u32) -> [u8; 4] {
    img.get_pixel(x, y).0
}

fn dem_dir() -> Option<PathBuf> {
    let d = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/dem"));
    if d.is_dir() {
        Some(d.to_path_buf())
    } else {
        eprintln!("skipping: {} is absent", d.display());
        None
    }
}

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
fn type_mask_must_match_the_heightfield() {
    let hf = Heightfield::new(6, 2, 1.0).unwrap();
    let o = RenderOptions {
        types: Some(TypeOverlay::new(TypeMask::new(2, 6, vec![0; 12]).unwrap())),
        ..plain()
    };
    let err = render(&hf, &o).unwrap_err();
    assert!(matches!(err, RenderError::TypesSize { .. }), "{err}");
    assert!(err.to_string().contains("2x6"), "{err}");
}

#[test]
fn type_masks_read_from_png_with_names() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.png");
    let mut img = image::GrayImage::new(3, 2);
    img.put_pixel(1, 0, image::Luma([4]));
    img.save(&path).unwrap();
    std::fs::write(dir.path().join("m.json"), r#"{"types": {"4": "canyon"}}"#).unwrap();
    let m = TypeMask::read(&path).unwrap();
    assert_eq!((m.width, m.height), (3, 2));
    assert_eq!(m.indices, &[0, 4, 0, 0, 0, 0]);
    assert_eq!(m.names[&4], "canyon");

    // Not 8-bit greyscale, truncated, or with bad names: a clear error.
    let rgb = dir.path().join("rgb.png");
    image::RgbImage::new(2, 2).save(&rgb).unwrap();
    let e = TypeMask::read(&rgb).unwrap_err().to_string();
    assert!(
        e.contains("rgb.png") && e.contains("8-bit greyscale"),
        "{e}"
    );
    let cut = dir.path().join("cut.png");
    std::fs::write(&cut, &std::fs::read(&path).unwrap()[..40]).unwrap();
    assert!(TypeMask::read(&cut).is_err());
    std::fs::write(dir.path().join("m.json"), "{").unwrap();
    let e = TypeMask::read(&path).unwrap_err().to_string();
    assert!(e.contains("m.json"), "{e}");
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
fn sizes_for_a_person() {
    let big = Heightfield::from_fn(4100, 20, 1.0, |x, _| x as f32).unwrap();
    let p = render(&big, &RenderOptions::default()).unwrap();
    assert_eq!(p.image.dimensions(), (2048, 10));
    let o = RenderOptions {
        max_size: 1000,
        ..RenderOptions::default()
    };
    assert_eq!(render(&big, &o).unwrap().image.width(), 1000);
    // A small maximum wins over the default minimum.
    let o = RenderOptions {
        max_size: 300,
        ..RenderOptions::default()
    };
    let small = Heightfield::new(100, 100, 1.0).unwrap();
    assert_eq!(render(&small, &o).unwrap().image.width(), 300);
    let tiny = Heightfield::from_fn(100, 60, 1.0, |x, y| (x * y) as f32).unwrap();
    let p = render(&tiny, &RenderOptions::default()).unwrap();
    assert_eq!(p.image.dimensions(), (600, 360));
    assert_eq!(p.info.px_per_cell_x, 6.0);
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

#[test]
fn bad_options_are_refused_with_the_allowed_range() {
    let hf = Heightfield::new(4, 4, 1.0).unwrap();
    let cases: Vec<RenderOptions> = vec![
        RenderOptions {
            max_size: 0,
            ..RenderOptions::default()
        },
        RenderOptions {
            exaggeration: f64::NAN,
            ..RenderOptions::default()
        },
        RenderOptions {
            contours: Contours::Every(0.0),
            ..RenderOptions::default()
        },
        RenderOptions {
            range: Some((5.0, 1.0)),
            ..RenderOptions::default()
        },
        RenderOptions {
            sea: Sea::Level(f64::NAN),
            ..RenderOptions::default()
        },
        RenderOptions {
            lighting: Lighting {
                lights: vec![],
                ..Lighting::default()
            },
            ..RenderOptions::default()
        },
    ];
    for o in cases {
        let e = render(&hf, &o).unwrap_err();
        assert!(
            matches!(e, RenderError::Option { .. }) && e.to_string().contains("expected"),
            "{e}"
        );
    }
}

#[test]
fn same_bytes_on_any_thread_count() {
    let hf = Heightfield::from_fn(300, 200, 7.0, |x, y| {
        let (x, y) = (x as f32 * 0.05, y as f32 * 0.07);
        if (x - 5.0).abs() < 0.3 {
            f32::NAN
        } else {
            (x.sin() * y.cos() * 80.0) + x * 9.0
        }
    })
    .unwrap();
    let o = RenderOptions {
        grid: Grid::Metres(200.0),
        range: Some((-20.0, 90.0)),
        ..RenderOptions::default()
    };
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| render(&hf, &o).unwrap().image.into_raw())
    };
    assert_eq!(run(1), run(3));
}

#[test]
fn kernel_survives_extreme_heights_and_scales() {
    // Alternating ±max heights give the largest gradients the bound allows.
    let m = shade::MAX_ABS_HEIGHT as f32 / UNITS_PER_M as f32;
    let hf = Heightfield::from_fn(7, 5, 1.0, |x, y| if (x + y) % 2 == 0 { m } else { -m }).unwrap();
    for (cell, ex) in [(1e-3, 1000.0), (1.0, 1.0), (1e5, 1e-3)] {
        let mut hf = hf.clone();
        hf.set_cell_size(cell).unwrap();
        let o = RenderOptions {
            exaggeration: ex,
            contours: Contours::Every(0.001),
            grid: Grid::Cells(2.0),
            range: Some((-1.0, 1.0)),
            sea: Sea::Level(0.0),
            min_size: 1,
            ..RenderOptions::default()
        };
        let p = prepare(&hf, &o).unwrap();
        assert!(p.params.flags & flags::SEA != 0);
        let mut out = vec![0; p.heights.len()];
        shade::shade(&p.params, &p.buffers(), &mut out).unwrap();
        assert!(out.iter().all(|&c| c >> 24 == 255));
    }
}

#[test]
fn invalid_params_are_refused_before_the_loop() {
    let hf = Heightfield::new(4, 4, 1.0).unwrap();
    let p = prepare(&hf, &RenderOptions::default()).unwrap();
    let mut out = vec![0; 16];
    let mut bad = p.params;
    bad.tint_len += 1;
    assert!(shade::shade(&bad, &p.buffers(), &mut out).is_err());
    let mut bad = p.params;
    bad.slope_x_clamp = i32::MAX;
    assert!(shade::shade(&bad, &p.buffers(), &mut out).is_err());
    let mut heights = p.heights.clone();
    heights[3] = shade::MAX_ABS_HEIGHT + 1;
    let b = shade::ShadeBuffers {
        heights: &heights,
        ..p.buffers()
    };
    assert!(shade::shade(&p.params, &b, &mut out).is_err());
    assert!(shade::shade(&p.params, &p.buffers(), &mut out[..15]).is_err());
}

#[test]
fn odd_sizes_do_not_panic() {
    for (w, h) in [(1, 1), (3, 2049), (2049, 3), (1, 700), (2, 1)] {
        let hf = Heightfield::from_fn(w, h, 30.0, |x, y| ((x * 7 + y * 3) % 50) as f32).unwrap();
        let p = render(&hf, &RenderOptions::default()).unwrap();
        let (ow, oh) = terrasynth::render::resample::fit(w, h, 512, 2048);
        assert_eq!(p.image.dimensions(), (ow as u32, oh as u32));
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn any_size_and_data_renders(
        w in 1usize..40,
        h in 1usize..40,
        seed in any::<u32>(),
        amp in prop_oneof![Just(0.0f32), 0.01f32..10.0, 10.0f32..9000.0],
        holes in 0u32..4,
        contour in prop_oneof![Just(Contours::Auto), Just(Contours::Off), (0.001f64..500.0).prop_map(Contours::Every)],
        sea in prop_oneof![Just(Sea::Auto), Just(Sea::Off), (-100.0f64..100.0).prop_map(Sea::Level)],
        cell in 0.01f64..5000.0,
    ) {
        let hf = Heightfield::from_fn(w, h, cell, |x, y| {
            let k = (x as u32).wrapping_mul(73856093) ^ (y as u32).wrapping_mul(19349663) ^ seed;
            if holes > 0 && k % 7 < holes { f32::NAN } else { (k % 1000) as f32 / 1000.0 * amp - amp / 3.0 }
        }).unwrap();
        let o = RenderOptions { contours: contour, sea, min_size: 64, ..RenderOptions::default() };
        let p = render(&hf, &o).unwrap();
        let (ow, oh) = terrasynth::render::resample::fit(w, h, 64, 2048);
        prop_assert_eq!(p.image.dimensions(), (ow as u32, oh as u32));
        prop_assert!(p.image.pixels().all(|px| px[3] == 255));
    }
}

#[test]
fn png_output_is_written_atomically_and_reads_back() {
    let hf = Heightfield::from_fn(30, 20, 1.0, |x, y| (x + y) as f32).unwrap();
    let p = render(&hf, &RenderOptions::default()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("p.png");
    terrasynth::render::write_png(&path, &p.image).unwrap();
    let back = image::open(&path).unwrap().to_rgba8();
    assert_eq!(back, p.image);
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    let missing = dir.path().join("no/such/dir.png");
    assert!(terrasynth::render::write_png(&missing, &p.image).is_err());
}

#[test]
fn overlays_draw_in_cell_coordinates() {
    let hf = Heightfield::from_fn(64, 64, 1.0, |_, _| 1.0).unwrap();
    let mut p = render(&hf, &plain()).unwrap();
    let before = p.image.clone();
    let red = Rgba([255, 0, 0, 255]);
    p.canvas().point((32.0, 32.0), 2.0, red);
    assert_eq!(p.image.get_pixel(32, 32).0, [255, 0, 0, 255]);
    assert_eq!(p.image.get_pixel(10, 10), before.get_pixel(10, 10));
}

#[test]
fn every_shared_dem_renders_with_its_types() {
    let Some(dir) = dem_dir() else { return };
    let mut seen = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let Some(stem) = name.strip_suffix("_types.png") else {
            continue;
        };
        let hf =
            terrasynth::io::read(&dir.join(format!("{stem}.png")), &Default::default()).unwrap();
        let mask = TypeMask::read(&path).unwrap();
        assert!(!mask.names.is_empty(), "{stem}: type names");
        let o = RenderOptions {
            types: Some(TypeOverlay::new(mask)),
            grid: Grid::Metres(5000.0),
            ..RenderOptions::default()
        };
        let p = render(&hf, &o).unwrap();
        assert_eq!(p.image.width() as usize, hf.width(), "{stem}");
        let i = &p.info;
        let (lo, hi) = i.height_range_m.unwrap();
        let lines = (hi - lo) / i.contour_interval_m.unwrap();
        assert!(
            (8.0..=20.0).contains(&lines),
            "{stem}: {lines} contour levels"
        );
        assert_eq!(
            i.sea_level_m.is_some(),
            lo < 0.0,
            "{stem}: water iff below 0 m"
        );
        // A real picture: many distinct colours.
        let mut colours: Vec<u32> = p.image.pixels().map(|c| u32::from_le_bytes(c.0)).collect();
        colours.sort_unstable();
        colours.dedup();
        assert!(
            colours.len() > 1000,
            "{stem}: only {} colours",
            colours.len()
        );
        seen += 1;
    }
    assert_eq!(seen, 8, "expected the 8 shared DEMs");
}

fn cli() -> Command {
    Command::new(env!("CARGO_BIN_EXE_terrasynth"))
}

#[test]
fn cli_renders_and_explains() {
    let help = cli().args(["render", "--help"]).output().unwrap();
    let text = String::from_utf8_lossy(&help.stdout);
    for flag in [
        "--contour",
        "--no-contours",
        "--grid",
        "--range",
        "--types",
        "--exaggeration",
        "--max-size",
    ] {
        assert!(text.contains(flag), "help lacks {flag}");
    }

    let dir = tempfile::tempdir().unwrap();
    let hf = Heightfield::from_fn(40, 30, 10.0, |x, y| (x * y) as f32 - 50.0).unwrap();
    let input = dir.path().join("t.png");
    terrasynth::io::write(&hf, &input, &Default::default()).unwrap();
    let out = dir.path().join("p.png");
    let run = cli()
        .args([
            "render",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ])
        .args(["--range", "-10:500", "--grid", "5", "--contour", "25"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{err}");
    assert!(err.contains("contours every 25 m"), "{err}");
    assert!(image::open(&out).is_ok());

    // A mask of the wrong size: non-zero exit, message names both sizes.
    let mask = dir.path().join("m.png");
    image::GrayImage::new(3, 3).save(&mask).unwrap();
    let run = cli()
        .args([
            "render",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ])
        .args(["--types", mask.to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success());
    assert!(err.contains("3x3") && err.contains("40x30"), "{err}");
    assert!(!err.contains("panicked"), "{err}");

    let run = cli()
        .args([
            "render",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ])
        .args(["--range", "9:1"])
        .output()
        .unwrap();
    assert!(!run.status.success());
    assert!(String::from_utf8_lossy(&run.stderr).contains("MIN:MAX"));
}
