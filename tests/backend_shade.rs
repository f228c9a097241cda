//! Stage `shade` (the preview renderer): `kernels/shade.wgsl` gives the
//! same RGBA bytes as `render::shade` on random heightfields under every
//! rendering option, and on crops of the real DEMs with their type masks.
//!
//! Needs `--features gpu` and a Vulkan adapter (lavapipe will do); without
//! one every test prints why and passes without checking anything.
#![cfg(feature = "gpu")]

use proptest::prelude::*;
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;
use terrasynth::Heightfield;
use terrasynth::backend::gpu::Context;
use terrasynth::render::{
    Contours, Lighting, Palette, RenderOptions, TypeMask, TypeOverlay, prepare,
    shade::{self, flags},
};

mod common;

const DEM: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/dem");

fn ctx() -> Option<Arc<Context>> {
    common::gpu::context()
}

/// Renders on both backends; returns the flags used, for coverage checks.
fn check(ctx: &Context, hf: &Heightfield, o: &RenderOptions, what: &str) -> u32 {
    let prep = prepare(hf, o).unwrap();
    let mut cpu = vec![0u32; prep.heights.len()];
    shade::shade(&prep.params, &prep.buffers(), &mut cpu).unwrap();
    let gpu = ctx.shade(&prep.params, &prep.buffers()).unwrap();
    if let Some(i) = (0..cpu.len()).find(|&i| cpu[i] != gpu[i]) {
        panic!(
            "{what}: first difference at pixel {i} (height {}): GPU {:08x} vs CPU {:08x}",
            prep.heights[i], gpu[i], cpu[i]
        );
    }
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
    #![proptest_config(ProptestConfig::with_cases(32))]

    #[test]
    fn shade_matches_on_random_heightfields(
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
        let Some(ctx) = ctx() else { return Ok(()) };
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
        check(&ctx, &hf, &o, "random heightfield");
    }
}

/// A 256² crop of every shared DEM, with its type mask, contours, sea, a
/// grid, and both lighting models: every branch of the kernel on real data.
#[test]
fn shade_matches_on_shared_dems() {
    let Some(ctx) = ctx() else { return };
    let dir = Path::new(DEM);
    if !dir.exists() {
        eprintln!("{DEM} not found: real-DEM shade cross-check skipped");
        return;
    }
    let mut seen = 0;
    let mut used = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let Some(stem) = name.strip_suffix("_types.png") else {
            continue;
        };
        let hf =
            terrasynth::io::read(&dir.join(format!("{stem}.png")), &Default::default()).unwrap();
        let m = TypeMask::read(&path).unwrap();
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
            used |= check(&ctx, &crop, &o, stem);
        }
        seen += 1;
    }
    assert!(seen >= 1, "no DEM with a type mask in {DEM}");
    let all = flags::CONTOURS | flags::GRID | flags::SEA | flags::TYPES | flags::ASPECT_WEIGHTS;
    assert_eq!(
        used & all,
        all,
        "every kernel feature exercised on real data"
    );
}
