//! Stage `shade` (the preview renderer): the CPU stage and, with
//! `--features gpu` and an adapter, `kernels/shade.wgsl` give the same RGBA
//! bytes on random heightfields under every rendering option, and on crops
//! of the real DEMs with their type masks. Without a GPU there is nothing
//! to compare against: every test says so and passes.

use proptest::prelude::*;
use std::collections::BTreeMap;
use std::path::Path;
use terrasynth::Heightfield;
use terrasynth::io::TypeMask;
use terrasynth::render::{Contours, Lighting, Palette, RenderOptions, TypeOverlay, prepare};
use terrasynth::stages::shade::flags;

use crate::common::dem::{DEM, typed_stems};
use crate::common::variants::{self, assert_agree, gpu_or_skip};

/// Shades `hf` prepared under `o` on every variant; returns the flags
/// used, for coverage checks.
fn check(hf: &Heightfield, o: &RenderOptions, what: &str) -> u32 {
    let prep = prepare(hf, o).unwrap();
    assert_agree(&variants::shade(&prep.params, &prep.buffers()), what);
    prep.params.flags
}

fn mask(w: usize, h: usize, seed: u32) -> TypeMask {
    TypeMask {
        width: w,
        height: h,
        indices: (0..w * h)
            .map(|i| {
                let k = (i as u32 / 5).wrapping_mul(0x9E37_79B9) ^ seed;
                [0, 1, 2, 255][(k >> 28) as usize % 4]
            })
            .collect(),
        names: BTreeMap::from([(0, "a".into()), (1, "b".into()), (2, "c".into())]),
    }
}

proptest! {
    #![proptest_config(crate::common::proptest_cases(32))]

    #[test]
    fn shade_agrees_on_random_heightfields(
        w in 1usize..48,
        h in 1usize..48,
        seed in any::<u32>(),
        amp in prop_oneof![Just(0.0f32), 0.01f32..10.0, 10.0f32..9000.0],
        holes in 0u32..3,
        contour in prop_oneof![Just(Contours::Auto), Just(Contours::Off), (0.001f64..500.0).prop_map(Contours::Every)],
        sea in prop_oneof![Just(terrasynth::render::Sea::Auto), Just(terrasynth::render::Sea::Off), (-100.0f64..100.0).prop_map(terrasynth::render::Sea::Level)],
        grid in prop_oneof![Just(terrasynth::render::Grid::Off), (2.0f64..9.0).prop_map(terrasynth::render::Grid::Cells)],
        range in prop::option::of((-50.0f64..0.0, 0.0f64..50.0)),
        usgs in any::<bool>(),
        types in any::<bool>(),
        exaggeration in 0.1f64..20.0,
        cell in 0.01f64..5000.0,
    ) {
        if !gpu_or_skip("shade") {
            return Ok(());
        }
        let hf = Heightfield::from_fn(w, h, cell, |x, y| {
            let k = (x as u32).wrapping_mul(73856093) ^ (y as u32).wrapping_mul(19349663) ^ seed;
            if holes > 0 && k % 7 < holes { f32::NAN } else { (k % 1000) as f32 / 1000.0 * amp - amp / 3.0 }
        }).unwrap();
        let o = RenderOptions {
            contours: contour,
            sea,
            grid,
            range,
            exaggeration,
            lighting: if usgs { Lighting::usgs() } else { Lighting::default() },
            types: types.then(|| TypeOverlay::new(mask(w, h, seed))),
            min_size: 1,
            max_size: 256,
            ..RenderOptions::default()
        };
        check(&hf, &o, "random heightfield");
    }
}

/// A 256² crop of every shared DEM, with its type mask, contours, sea, a
/// grid, and both lighting models: every branch of the kernel on real data.
#[test]
fn shade_agrees_on_shared_dems() {
    if !gpu_or_skip("shade") {
        return;
    }
    let Some(stems) = typed_stems("real-DEM shade cross-check") else {
        return;
    };
    let dir = Path::new(DEM);
    let mut used = 0;
    for stem in &stems {
        let hf =
            terrasynth::io::read(&dir.join(format!("{stem}.png")), &Default::default()).unwrap();
        let m = TypeMask::read(&dir.join(format!("{stem}_types.png"))).unwrap();
        let (w, h) = (hf.width().min(256), hf.height().min(256));
        let (x0, y0) = ((hf.width() - w) / 2, (hf.height() - h) / 2);
        let crop = hf.crop(x0, y0, w, h).unwrap();
        let mask = m.crop(x0, y0, w, h).unwrap();
        for (k, lighting) in [Lighting::default(), Lighting::usgs()]
            .into_iter()
            .enumerate()
        {
            let o = RenderOptions {
                types: Some(TypeOverlay::new(mask.clone())),
                grid: terrasynth::render::Grid::Cells(32.0),
                sea: terrasynth::render::Sea::Level(crop.stats().unwrap().min as f64 + 40.0),
                palette: if k == 0 {
                    Palette::natural()
                } else {
                    RenderOptions::default().palette
                },
                lighting,
                exaggeration: 2.0,
                min_size: 1,
                ..RenderOptions::default()
            };
            used |= check(&crop, &o, stem);
        }
    }
    assert!(!stems.is_empty(), "no DEM with a type mask in {DEM}");
    let all = flags::CONTOURS | flags::GRID | flags::SEA | flags::TYPES | flags::ASPECT_WEIGHTS;
    assert_eq!(
        used & all,
        all,
        "every kernel feature exercised on real data"
    );
}
