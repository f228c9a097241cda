//! Stage `fill_ssd` (the patch engine's round-one hole-filling cost), CPU ≡
//! GPU byte for byte: random centred cells and masks (proptest), and real
//! candidate tables of shared-DEM sources against a window of another DEM.
//!
//! Needs `--features gpu` and a Vulkan adapter (see `common::gpu`).
#![cfg(feature = "gpu")]

use proptest::prelude::*;
use std::path::Path;
use terrasynth::patch::candidates::{COARSE, PreparedSource};
use terrasynth::patch::hole_fill::user_cells;
use terrasynth::stages::fill_ssd::{FILL_CLAMP, centre_cells, fill_ssd_scalar, fill_ssd_table};

mod common;
use common::dem::DEM;

/// The user's `m × m` cells permuted into every transform's frame, as
/// `patch::hole_fill` builds them.
fn perms(cells: &[i32], valid: &[bool], m: usize) -> (Vec<Vec<i32>>, Vec<Vec<i32>>, i64) {
    user_cells(&mut cells.to_vec(), valid, m)
}

/// The table on both backends (and the scalar oracle for every entry).
fn check(user: &[Vec<i32>], mask: &[Vec<i32>], cells: &[i32], count: i64, what: &str) {
    let Some(ctx) = common::gpu::context() else {
        return;
    };
    let per = user[0].len();
    let cpu = fill_ssd_table(user, mask, cells, count);
    let src = ctx.upload_fill_source(cells, per).unwrap();
    let gpu = ctx.fill_ssd(&src, user, mask, count).unwrap();
    assert_eq!(
        cpu.len(),
        cells.len() / per * user.len(),
        "{what}: table size"
    );
    for (i, (c, g)) in cpu.iter().zip(&gpu).enumerate() {
        let (k, v) = (i / user.len(), i % user.len());
        let oracle = fill_ssd_scalar(&user[v], &mask[v], &cells[k * per..(k + 1) * per], count);
        assert_eq!(
            *c, oracle,
            "{what}: candidate {k}, transform {v}: SIMD vs scalar"
        );
        assert_eq!(*g, *c, "{what}: candidate {k}, transform {v}: GPU vs CPU");
    }
    assert_eq!(gpu.len(), cpu.len(), "{what}: GPU table size");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Random cells over the whole clamp range (so s2 passes 32 bits for
    /// large windows), random validity (none, some, all), 2..=32 cells a
    /// side (patch 16..=256) and 1..=40 candidates.
    #[test]
    fn fill_ssd_matches_on_random_cells(
        m in 2usize..=32, n in 1usize..=40, extreme in any::<bool>(),
        seed in any::<u64>(), valid_every in 0usize..4,
    ) {
        let mut x = seed | 1;
        let mut next = || { x ^= x << 13; x ^= x >> 7; x ^= x << 17; x };
        let mut value = || {
            let r = next();
            if extreme && r % 3 == 0 {
                if r & 8 == 0 { 40_000 } else { -40_000 }
            } else {
                (r >> 20) as i32 % (2 * FILL_CLAMP + 1)
            }
        };
        let user: Vec<i32> = (0..m * m).map(|_| value()).collect();
        let mut cells: Vec<i32> = (0..n * m * m).map(|_| value()).collect();
        for c in cells.chunks_mut(m * m) {
            centre_cells(c, None);
        }
        let valid: Vec<bool> = (0..m * m)
            .map(|i| valid_every != 0 && (i % (valid_every + 1) != 0 || valid_every == 3))
            .collect();
        let (u, k, count) = perms(&user, &valid, m);
        check(&u, &k, &cells, count, &format!("random m {m}, {n} candidates"));
    }
}

/// Real tables: every fill candidate of a prepared shared-DEM source, under
/// every transform, against a half-filled window cut from another DEM.
#[test]
fn fill_ssd_matches_on_shared_dem_sources() {
    let dir = Path::new(DEM);
    let read =
        |name: &str| terrasynth::io::read(&dir.join(format!("{name}.png")), &Default::default());
    let (Ok(a), Ok(b)) = (read("pyrenees_andorra"), read("thuringia_hills")) else {
        eprintln!("skipping: the shared DEMs are not in {}", dir.display());
        return;
    };
    let params = terrasynth::patch::Params::default();
    let m = params.patch / COARSE;
    let src = PreparedSource::prepare("pyrenees", &a.crop(0, 0, 384, 384).unwrap(), &params, 1.0)
        .unwrap();
    assert!(src.fill_cells.len() >= 16 * m * m, "too few candidates");
    // The user window: the 8×-reduced mean heights (decimetres) of a patch
    // of the other DEM, its lower-left half filled.
    let (ox, oy) = (200, 150);
    let mut cells = vec![0i32; m * m];
    for cy in 0..m {
        for cx in 0..m {
            let mut s = 0.0f64;
            for y in 0..COARSE {
                for x in 0..COARSE {
                    s += b.get(ox + cx * COARSE + x, oy + cy * COARSE + y) as f64;
                }
            }
            cells[cy * m + cx] = (s / (COARSE * COARSE) as f64 * 10.0).round() as i32;
        }
    }
    let valid: Vec<bool> = (0..m * m).map(|i| i % m <= i / m).collect();
    let (u, k, count) = perms(&cells, &valid, m);
    check(
        &u,
        &k,
        &src.fill_cells,
        count,
        "pyrenees candidates vs a thuringia window",
    );
}

/// End to end: a Y-branch sketch built from two shared-DEM crops, with
/// stage `fill_ssd` on each backend, writes the same heights.
#[test]
fn sketch_synthesis_matches_end_to_end() {
    use terrasynth::backend::Choice;
    use terrasynth::patch::fill_ssd::FillCost;
    use terrasynth::patch::sketch::Sketch;
    use terrasynth::patch::{self, Library, Params};
    use terrasynth::progress::Silent;
    if common::gpu::context().is_none() {
        return;
    }
    let mut src = Vec::new();
    for name in ["pyrenees_andorra", "thuringia_hills"] {
        let Ok(hf) = terrasynth::io::read(
            &Path::new(DEM).join(format!("{name}.png")),
            &Default::default(),
        ) else {
            eprintln!("skipping: the shared DEMs are not in {DEM}");
            return;
        };
        src.push((name.to_string(), hf.crop(200, 200, 256, 256).unwrap()));
    }
    let params = Params {
        patch: 32,
        ..Params::default()
    };
    let lib = Library::prepare(&src, &params, &Silent).unwrap();
    let sketch = Sketch::from_json(
        br#"{"width": 160, "height": 160, "strokes": [
        {"kind": "ridge", "width": 8, "points": [[80, 90], [30, 20]]},
        {"kind": "ridge", "width": 8, "points": [[80, 90], [130, 20]]},
        {"kind": "valley", "width": 8, "points": [[20, 80], [45, 150]]}]}"#,
        Path::new("y.json"),
    )
    .unwrap();
    let run = |choice| {
        let (cost, notice) = FillCost::choose(choice, &lib).unwrap();
        assert!(notice.is_none(), "{notice:?}");
        let s = patch::synthesize_with(&lib, &sketch, 160, 160, &cost, &Silent).unwrap();
        (cost.name(), s)
    };
    let (cpu_name, cpu) = run(Choice::Cpu);
    let (gpu_name, gpu) = run(Choice::Gpu);
    assert_eq!((cpu_name, gpu_name), ("cpu", "gpu"));
    assert!(gpu.stats.fill_patches > 0, "the fill stage must have run");
    let (a, b) = (cpu.heightfield.data(), gpu.heightfield.data());
    if let Some(i) = (0..a.len()).find(|&i| a[i].to_bits() != b[i].to_bits()) {
        panic!("pixel {i}: GPU {} vs CPU {}", b[i], a[i]);
    }
}
