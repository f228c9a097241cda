//! Exemplar database: contents, invariants and the file format.

use proptest::prelude::*;
use std::sync::OnceLock;
use terrasynth::database::{
    self, BuildOptions, Database, ExemplarInput, appearance, c2, c2_cache, layout, types,
};
use terrasynth::io::TypeMask;
use terrasynth::{Heightfield, progress::Silent};

use crate::common::dem::{self, DEM};

/// Two exemplars: real DEM crops when ../shared is present (with their type
/// masks), synthetic ridges otherwise.
fn inputs() -> Vec<ExemplarInput> {
    let crop = |name: &str, x: usize, y: usize, w: usize, h: usize| {
        dem::exemplar(name, (x, y, w, h), true)
    };
    match (
        crop("riviera_coast", 100, 150, 200, 160),
        crop("pyrenees_andorra", 300, 200, 144, 176),
    ) {
        (Some(a), Some(b)) => vec![a, b],
        _ => {
            eprintln!("{DEM} not found: using synthetic exemplars");
            let synth = |w, h, s: f32| {
                Heightfield::from_fn(w, h, 30.0, |x, y| {
                    let (x, y) = (x as f32, y as f32);
                    300.0 * ((x * 0.05 * s).sin() * (y * 0.043).cos()).abs()
                        + 20.0 * (x * 0.3 + y * 0.17).sin()
                })
                .unwrap()
            };
            vec![
                ExemplarInput {
                    name: "a".into(),
                    heights: synth(200, 160, 1.0),
                    types: None,
                },
                ExemplarInput {
                    name: "b".into(),
                    heights: synth(144, 176, 1.7),
                    types: None,
                },
            ]
        }
    }
}

fn built() -> &'static Database {
    static DB: OnceLock<Database> = OnceLock::new();
    DB.get_or_init(|| {
        let opts = BuildOptions {
            levels: 3,
            ..Default::default()
        };
        database::build(inputs(), &opts, &Silent).unwrap().0
    })
}

#[test]
fn similarity_entries_are_interior_admissible_and_c1_is_identity() {
    let db = built();
    for i in 0..db.level_count() {
        let l = db.level(i);
        for (e, r) in l.layout.rects.iter().enumerate() {
            for k in 0..r.texels() {
                let (ux, uy) = r.coords(r.offset + k);
                let u = layout::pack(ux, uy);
                let [c1, c2] = l.candidates(u);
                assert_eq!(c1, u, "C1 must be the identity");
                let (vx, vy) = layout::unpack(c2);
                let ve = l
                    .layout
                    .exemplar_at(l.columns, vx, vy)
                    .expect("C2 inside an exemplar");
                assert!(l.layout.rects[ve].is_interior(vx, vy), "C2 on an edge");
                assert!(
                    ve != e || vx.abs_diff(ux) >= 5 || vy.abs_diff(uy) >= 5,
                    "C2 is a trivial match"
                );
            }
        }
    }
}

#[test]
fn mode_one_is_the_weighted_mean_height() {
    let db = built();
    let (g, _) = appearance::weights();
    let l = db.level(0);
    let heights = db.heights();
    for r in &l.layout.rects {
        for y in (0..r.height).step_by(3) {
            for x in (r.x0..r.x0 + r.width).step_by(5) {
                let mut mean = 0.0;
                for (k, gk) in g.iter().enumerate() {
                    let sx = (x as i64 + (k % 5) as i64 - 2)
                        .clamp(r.x0 as i64, (r.x0 + r.width - 1) as i64);
                    let sy = (y as i64 + (k / 5) as i64 - 2).clamp(0, r.height as i64 - 1);
                    mean += gk * heights[r.index(sx as u32, sy as u32)] as f64;
                }
                let m1 = appearance::unpack_texel(l.appearance[r.index(x, y)])[0] as i32
                    - appearance::MODE1_BIAS;
                // Both sides quantize: E⁰ per sample (±½) and mode 1 once (±½).
                assert!(
                    (m1 as f64 - mean).abs() <= 1.0,
                    "mode 1 {m1} vs weighted mean {mean}"
                );
            }
        }
    }
}

#[test]
fn pca_modes_are_orthonormal_and_heights_quantize_within_half_a_unit() {
    let db = built();
    for l in &db.meta().levels {
        let m = &l.basis.modes;
        for i in 0..3 {
            for j in 0..3 {
                let d: f64 = m[i]
                    .iter()
                    .zip(&m[j])
                    .map(|(a, b)| *a as f64 * *b as f64)
                    .sum();
                assert!((d - if i == j { 1.0 } else { 0.0 }).abs() < 1e-5);
            }
        }
    }
    let q = db.quantization();
    let r = db.level(0).layout.rects[0];
    let original = &inputs()[0].heights;
    for y in 0..r.height {
        for x in 0..r.width {
            let back = q.metres(db.heights()[r.index(r.x0 + x, y)] as f64);
            assert!(
                (back - original.get(x as usize, y as usize) as f64).abs()
                    <= q.scale_m * 0.5 + 1e-6
            );
        }
    }
}

#[test]
fn type_pyramid_is_the_block_majority_and_seeds_have_their_type() {
    let db = built();
    let l0 = db.level(0);
    let ntypes = db.type_names().len();
    for i in 1..db.level_count() {
        let l = db.level(i);
        let b = 1u32 << i;
        for (e, r) in l.layout.rects.iter().enumerate() {
            let r0 = l0.layout.rects[e];
            for y in 0..r.height {
                for x in 0..r.width {
                    let mut hist = vec![0u32; ntypes];
                    for yy in y * b..(y + 1) * b {
                        for xx in x * b..(x + 1) * b {
                            hist[l0.types[r0.index(r0.x0 + xx, yy)] as usize] += 1;
                        }
                    }
                    let max = *hist.iter().max().unwrap();
                    let want = hist.iter().position(|&c| c == max).unwrap();
                    assert_eq!(l.types[r.index(r.x0 + x, y)] as usize, want);
                }
            }
        }
        for t in 0..ntypes {
            for &s in &l.seeds[t * types::SEEDS_PER_TYPE..(t + 1) * types::SEEDS_PER_TYPE] {
                if s != types::NO_SEED {
                    let (x, y) = layout::unpack(s);
                    let e = l.layout.exemplar_at(l.columns, x, y).unwrap();
                    assert_eq!(l.types[l.layout.rects[e].index(x, y)] as usize, t);
                }
            }
        }
    }
}

#[test]
fn save_load_save_is_byte_identical_and_build_is_thread_independent() {
    let db = built();
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.tsdb"), dir.path().join("b.tsdb"));
    db.save(&a).unwrap();
    let loaded = Database::load(&a).unwrap();
    loaded.save(&b).unwrap();
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    assert_eq!(loaded.meta(), db.meta());
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| {
            database::build(
                inputs(),
                &BuildOptions {
                    levels: 3,
                    ..Default::default()
                },
                &Silent,
            )
            .unwrap()
            .0
        });
    assert!(
        one.file_bytes() == db.file_bytes(),
        "1-thread build differs"
    );
}

#[test]
fn memory_is_under_the_target() {
    let db = built();
    // 15 B/px at level 0, 13 at coarser levels, plus metadata: well under 26.
    assert!(db.bytes_per_pixel() < 26.0, "{} B/px", db.bytes_per_pixel());
}

#[test]
fn wrong_version_and_garbage_are_refused_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("v.tsdb");
    let mut bytes = built().file_bytes().to_vec();
    bytes[8] = 99;
    std::fs::write(&p, &bytes).unwrap();
    let e = Database::load(&p).unwrap_err().to_string();
    assert!(e.contains("version 99") && e.contains("v.tsdb"), "{e}");
    std::fs::write(&p, b"hello").unwrap();
    assert!(
        Database::load(&p)
            .unwrap_err()
            .to_string()
            .contains("truncated")
    );
    std::fs::write(&p, b"").unwrap();
    assert!(
        Database::load(&p)
            .unwrap_err()
            .to_string()
            .contains("empty")
    );
}

proptest! {
    #![proptest_config(crate::common::proptest_cases(64))]

    #[test]
    fn any_flipped_byte_or_truncation_is_a_clean_error(
        pos in any::<prop::sample::Index>(),
        bit in 0u8..8,
        cut in any::<prop::sample::Index>(),
    ) {
        let bytes = built().file_bytes();
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("x.tsdb");
        let mut flipped = bytes.to_vec();
        flipped[pos.index(bytes.len())] ^= 1 << bit;
        std::fs::write(&p, &flipped).unwrap();
        prop_assert!(Database::load(&p).is_err());
        std::fs::write(&p, &bytes[..cut.index(bytes.len())]).unwrap();
        prop_assert!(Database::load(&p).is_err());
    }
}

/// The fuzz seeds of the database loader and the type-mask reader decode
/// (they are valid), and every prefix of them is refused without a panic.
#[test]
fn fuzz_seeds_load_and_their_prefixes_fail_cleanly() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus");
    let files = |t: &str| {
        let mut v: Vec<_> = std::fs::read_dir(root.join(t))
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        v.sort();
        assert!(!v.is_empty(), "no {t} seeds");
        v
    };
    for p in files("tsdb") {
        let bytes = std::fs::read(&p).unwrap();
        let db = Database::from_bytes(&bytes, &p).unwrap();
        assert_eq!(db.file_bytes(), &bytes[..]);
        for cut in (0..bytes.len()).step_by(97) {
            let err = Database::from_bytes(&bytes[..cut], &p).unwrap_err();
            assert!(err.to_string().contains(&*p.to_string_lossy()), "{err}");
        }
    }
    // C₂ table files: the seed keeps the tables of the tsdb seed (a
    // golden file: `TERRASYNTH_BLESS=1` rewrites it, for review).
    let tiny =
        Database::from_bytes(&std::fs::read(root.join("tsdb/tiny.tsdb")).unwrap(), &root).unwrap();
    let tables: Vec<Vec<c2::Quad>> = (0..tiny.level_count())
        .map(|i| c2::gather(&tiny.level(i)))
        .collect();
    let views: Vec<&[c2::Quad]> = tables.iter().map(|t| t.as_slice()).collect();
    let expected = c2_cache::encode(tiny.fingerprint(), &views);
    let seed = root.join("c2_cache/tiny.c2");
    if std::env::var_os("TERRASYNTH_BLESS").is_some() {
        std::fs::create_dir_all(seed.parent().unwrap()).unwrap();
        std::fs::write(&seed, &expected).unwrap();
    }
    assert_eq!(files("c2_cache"), std::slice::from_ref(&seed));
    let bytes = std::fs::read(&seed).unwrap();
    assert!(
        bytes == expected,
        "{} is not tiny.tsdb's tables",
        seed.display()
    );
    let counts: Vec<usize> = tables.iter().map(|t| t.len()).collect();
    let ranges = c2_cache::decode(&bytes, tiny.fingerprint(), &counts).unwrap();
    assert_eq!(ranges.len(), tiny.level_count());
    for cut in 0..bytes.len() {
        assert!(c2_cache::decode(&bytes[..cut], tiny.fingerprint(), &counts).is_err());
    }
    for p in files("type_mask") {
        let bytes = std::fs::read(&p).unwrap();
        let (json, png) = bytes[1..].split_at(bytes[0] as usize);
        let mask = TypeMask::decode(png, (!json.is_empty()).then_some(json)).unwrap();
        assert_eq!((mask.width, mask.height), (48, 48));
        assert_eq!(mask.names.len(), if json.is_empty() { 0 } else { 5 });
        // Cuts into the pixel data (a missing 12-byte IEND trailer alone
        // loses nothing, and the PNG decoder accepts it).
        for cut in (0..png.len() - 12).step_by(7) {
            assert!(TypeMask::decode(&png[..cut], None).is_err(), "cut at {cut}");
        }
    }
}
