//! The preview renderer's limits: sizing, refused options and parameters,
//! determinism across thread counts, and robustness over sizes, data and
//! extreme heights.

use crate::common::render::plain;
use proptest::prelude::*;
use terrasynth::Heightfield;
use terrasynth::io::TypeMask;
use terrasynth::render::prepare::UNITS_PER_M;
use terrasynth::render::{
    Contours, Grid, Lighting, RenderError, RenderOptions, Sea, TypeOverlay, prepare, render,
};
use terrasynth::stages::shade::{self, flags};

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
        let (ow, oh) = terrasynth::render::preview_size::fit(w, h, 512, 2048);
        assert_eq!(p.image.dimensions(), (ow as u32, oh as u32));
    }
}

proptest! {
    #![proptest_config(crate::common::proptest_cases(48))]

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
        let (ow, oh) = terrasynth::render::preview_size::fit(w, h, 64, 2048);
        prop_assert_eq!(p.image.dimensions(), (ow as u32, oh as u32));
        prop_assert!(p.image.pixels().all(|px| px[3] == 255));
    }
}
