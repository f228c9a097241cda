//! `terrasynth::mesh` (issue 44): the regular mesh's exact vertices and
//! bounds, the adaptive mesh's triangle budget and measured error on a
//! real DEM, tiles that share their borders bit for bit, and (proptest)
//! watertight, non-degenerate triangulations of random heightfields.

use crate::common;
use proptest::prelude::*;
use std::collections::HashMap;
use std::time::Instant;
use terrasynth::Heightfield;
use terrasynth::mesh::{self, Detail, MeshError, Options, Triangulation, measure, normal_map};

/// A smooth test surface with relief in both directions.
fn hills(w: usize, h: usize, cell: f64) -> Heightfield {
    Heightfield::from_fn(w, h, cell, |x, y| {
        let (x, y) = (x as f32, y as f32);
        100.0 + 40.0 * (x * 0.21).sin() * (y * 0.13).cos() + 0.5 * x
    })
    .unwrap()
}

#[test]
fn regular_mesh_has_every_sample_at_its_metre_position() {
    let hf = hills(7, 5, 30.0);
    let built = mesh::build(&hf, &Options::default()).unwrap();
    let m = &built.meshes[0];
    assert_eq!((built.meshes.len(), m.name.as_str()), (1, "terrain"));
    assert_eq!(m.positions.len(), 35);
    assert_eq!(m.triangles.len(), 2 * 6 * 4);
    let (lo, hi) = mesh::bounds(&m.positions);
    let s = hf.stats().unwrap();
    assert_eq!(lo, [0.0, s.min, 0.0]);
    assert_eq!(hi, [180.0, s.max, 120.0]);
    // Sample (3, 2): X east, Y up, Z south.
    assert!(m.positions.contains(&[90.0, hf.get(3, 2), 60.0]));
    let measured = measure::max_vertical_error(&hf, &built.triangulations);
    assert_eq!((measured.max_error, measured.uncovered), (0.0, 0));
}

#[test]
fn triangles_face_up_and_normals_are_unit_and_up() {
    let hf = hills(9, 9, 10.0);
    for detail in [Detail::Regular, Detail::MaxError(1.0)] {
        let opts = Options {
            detail,
            normals: true,
            uvs: true,
            ..Default::default()
        };
        let m = &mesh::build(&hf, &opts).unwrap().meshes[0];
        for t in &m.triangles {
            let [a, b, c] = t.map(|i| glam::Vec3::from(m.positions[i as usize]));
            assert!(
                (b - a).cross(c - a).y > 0.0,
                "{detail:?}: a triangle faces down"
            );
        }
        for n in &m.normals {
            let n = glam::Vec3::from(*n);
            assert!((n.length() - 1.0).abs() < 1e-6 && n.y > 0.0, "{n}");
        }
        assert!(
            m.uvs
                .iter()
                .all(|uv| (0.0..=1.0).contains(&uv[0]) && (0.0..=1.0).contains(&uv[1]))
        );
        assert!(m.uvs.contains(&[1.0, 1.0]) && m.uvs.contains(&[0.0, 0.0]));
    }
}

#[test]
fn adaptive_mesh_on_a_real_dem_is_small_and_within_its_bound() {
    // 1024² (the size the README times), 3.3 m at 0.5 % of its relief.
    let name = "olympic_peninsula_coast";
    let Some(hf) = common::dem::heights(name, "the adaptive mesh test") else {
        return;
    };
    let s = hf.stats().unwrap();
    let bound = 0.005 * (s.max - s.min);
    let regular = 2 * (hf.width() - 1) * (hf.height() - 1);
    let t = Instant::now();
    let opts = Options {
        detail: Detail::MaxError(bound),
        ..Default::default()
    };
    let built = mesh::build(&hf, &opts).unwrap();
    let ms = t.elapsed().as_secs_f64() * 1e3;
    let m = measure::max_vertical_error(&hf, &built.triangulations);
    let tris = built.meshes[0].triangles.len();
    eprintln!(
        "{name} {}x{}: bound {bound:.3} m, {tris} of {regular} triangles ({:.1} %), measured max error {:.3} m, {ms:.0} ms",
        hf.width(),
        hf.height(),
        100.0 * tris as f64 / regular as f64,
        m.max_error
    );
    assert_eq!((m.uncovered, m.degenerate), (0, 0));
    assert!(m.max_error <= bound, "{} > {bound}", m.max_error);
    assert!(
        m.max_error > 0.5 * bound,
        "the bound is not used: {}",
        m.max_error
    );
    assert!(
        10 * tris <= 3 * regular,
        "{tris} triangles, regular {regular}"
    );
}

#[test]
fn a_triangle_budget_is_met_with_the_smallest_error() {
    let hf = hills(40, 33, 25.0);
    let n = 300;
    let opts = Options {
        detail: Detail::Triangles(n),
        ..Default::default()
    };
    let built = mesh::build(&hf, &opts).unwrap();
    let tris = built.meshes[0].triangles.len();
    assert!(tris <= n, "{tris}");
    // Any smaller bound needs more triangles.
    let finer = f32::from_bits(built.bounds[0].to_bits() - 1);
    let opts = Options {
        detail: Detail::MaxError(finer),
        ..Default::default()
    };
    assert!(mesh::build(&hf, &opts).unwrap().meshes[0].triangles.len() > n);
}

/// Every piece's vertices that lie on a line x = c (or y = c), as bytes.
fn on_line(m: &mesh::Mesh, axis: usize, at: f32) -> Vec<[u8; 12]> {
    let mut v: Vec<[u8; 12]> = m
        .positions
        .iter()
        .filter(|p| p[axis] == at)
        .map(|p| bytemuck::cast(*p))
        .collect();
    v.sort();
    v.dedup();
    v
}

#[test]
fn tiles_share_their_border_vertices_bit_for_bit() {
    let hf = hills(70, 45, 30.0);
    for detail in [Detail::Regular, Detail::MaxError(2.0)] {
        for lods in [1, 3] {
            let opts = Options {
                detail,
                lods,
                tile: Some(16),
                normals: true,
                uvs: true,
                skirt: Some(5.0),
            };
            let built = mesh::build(&hf, &opts).unwrap();
            let (tx, ty) = built.tiles;
            assert_eq!((tx, ty), (5, 3));
            for l in 0..lods {
                let tile = |i: usize, j: usize| &built.meshes[l * tx * ty + j * tx + i];
                let name = match lods {
                    1 => "terrain_x1_y2".to_string(),
                    _ => format!("terrain_x1_y2_LOD{l}"),
                };
                assert_eq!(tile(1, 2).name, name);
                for j in 0..ty {
                    for i in 0..tx - 1 {
                        let x = (16 * (i + 1)) as f32 * 30.0;
                        let (a, b) = (on_line(tile(i, j), 0, x), on_line(tile(i + 1, j), 0, x));
                        assert!(a.len() >= 2 * 2, "{detail:?} LOD{l}: {a:?}");
                        assert_eq!(
                            a,
                            b,
                            "{detail:?} LOD{l}: tiles ({i},{j}) and ({},{j})",
                            i + 1
                        );
                    }
                }
                for j in 0..ty - 1 {
                    for i in 0..tx {
                        let z = (16 * (j + 1)) as f32 * 30.0;
                        let (a, b) = (on_line(tile(i, j), 2, z), on_line(tile(i, j + 1), 2, z));
                        assert_eq!(
                            a,
                            b,
                            "{detail:?} LOD{l}: tiles ({i},{j}) and ({i},{})",
                            j + 1
                        );
                    }
                }
                let pieces = &built.triangulations[l * tx * ty..(l + 1) * tx * ty];
                let m = measure::max_vertical_error(&hf, pieces);
                assert_eq!((m.uncovered, m.degenerate), (0, 0), "{detail:?} LOD{l}");
                if detail != Detail::Regular {
                    assert!(m.max_error <= built.bounds[l], "{detail:?} LOD{l}");
                }
            }
        }
    }
}

#[test]
fn skirts_hang_below_every_outer_edge_and_face_out() {
    let hf = hills(9, 6, 10.0);
    let opts = Options {
        skirt: Some(7.0),
        ..Default::default()
    };
    let m = &mesh::build(&hf, &opts).unwrap().meshes[0];
    // 2 × (8 + 5) boundary edges, each a quad of two triangles.
    assert_eq!(m.triangles.len(), 2 * 8 * 5 + 2 * 26);
    assert_eq!(m.positions.len(), 54 + 26);
    let centre = glam::Vec3::new(40.0, 0.0, 25.0);
    for t in &m.triangles[80..] {
        let [a, b, c] = t.map(|i| glam::Vec3::from(m.positions[i as usize]));
        let n = (b - a).cross(c - a);
        let out = (a + b + c) / 3.0 - centre;
        assert!(
            n.y.abs() < 1e-3 && n.x * out.x + n.z * out.z > 0.0,
            "{n} at {out}"
        );
    }
}

#[test]
fn bad_input_is_refused_with_a_typed_error() {
    let mut hf = hills(8, 8, 10.0);
    hf.set(3, 2, f32::NAN);
    assert!(matches!(
        mesh::build(&hf, &Options::default()),
        Err(MeshError::Nodata {
            count: 1,
            x: 3,
            y: 2
        })
    ));
    let line = hills(8, 1, 10.0);
    assert!(matches!(
        mesh::build(&line, &Options::default()),
        Err(MeshError::TooSmall { .. })
    ));
    let hf = hills(8, 8, 10.0);
    for opts in [
        Options {
            detail: Detail::MaxError(-1.0),
            ..Default::default()
        },
        Options {
            detail: Detail::MaxError(f32::NAN),
            ..Default::default()
        },
        Options {
            lods: 9,
            ..Default::default()
        },
        Options {
            skirt: Some(0.0),
            ..Default::default()
        },
        Options {
            tile: Some(0),
            ..Default::default()
        },
        Options {
            detail: Detail::MaxError(1.0),
            tile: Some(12),
            ..Default::default()
        },
    ] {
        let e = mesh::build(&hf, &opts).unwrap_err();
        assert!(matches!(e, MeshError::Param { .. }), "{opts:?}: {e}");
    }
    let built = mesh::build(&hf, &Options::default()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let e = mesh::write(&dir.path().join("t.fbx"), &built.meshes).unwrap_err();
    assert!(e.to_string().contains("t.fbx"), "{e}");
    let e = mesh::write(&dir.path().join("no/such/dir/t.glb"), &built.meshes).unwrap_err();
    assert!(e.to_string().contains("t.glb"), "{e}");
}

/// Watertight: every edge of two triangles in opposite directions, the
/// others exactly the grid's outline; projected areas add up to the grid.
fn check_watertight(pieces: &[Triangulation], w: u32, h: u32) -> Result<(), TestCaseError> {
    let mut edges: HashMap<([u32; 2], [u32; 2]), i32> = HashMap::new();
    let mut area = 0i64;
    for p in pieces {
        for t in &p.triangles {
            let v = t.map(|i| p.vertices[i as usize]);
            let o = measure::orient(
                v[0].map(i64::from),
                v[1].map(i64::from),
                v[2].map(i64::from),
            );
            prop_assert!(o < 0, "degenerate or flipped triangle {v:?}");
            area -= o;
            for k in 0..3 {
                let (a, b) = (v[k], v[(k + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_default() += if a < b { 1 } else { -1 };
            }
        }
    }
    prop_assert_eq!(area, 2 * (w as i64 - 1) * (h as i64 - 1));
    for ((a, b), n) in edges {
        if n != 0 {
            let outline = (a[0] == b[0] && (a[0] == 0 || a[0] == w - 1))
                || (a[1] == b[1] && (a[1] == 0 || a[1] == h - 1));
            prop_assert!(outline && n.abs() == 1, "open edge {a:?}-{b:?} ({n})");
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(crate::common::proptest_cases(64))]
    #[test]
    fn random_heightfields_mesh_watertight(
        w in 2usize..24,
        h in 2usize..24,
        seed in any::<u64>(),
        bound in prop_oneof![Just(0.0f32), 0.0f32..30.0],
        tile in prop_oneof![Just(None), (1u32..4).prop_map(|k| Some(1usize << k))],
    ) {
        let hf = Heightfield::from_fn(w, h, 1.0, |x, y| {
            let z = (x as u64 * 31 + y as u64 * 17) ^ seed;
            (z.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 58) as f32
        }).unwrap();
        for detail in [Detail::Regular, Detail::MaxError(bound)] {
            let opts = Options { detail, tile, ..Default::default() };
            let built = mesh::build(&hf, &opts).unwrap();
            check_watertight(&built.triangulations, w as u32, h as u32)?;
            let m = measure::max_vertical_error(&hf, &built.triangulations);
            prop_assert_eq!(m.uncovered, 0);
            prop_assert!(m.max_error <= built.bounds[0], "{} > {}", m.max_error, built.bounds[0]);
        }
    }
}

/// The map of a plane rising `gx` per metre east and `gz` per metre south,
/// texel (2, 2) of a 6² map.
fn plane_texel(gx: f32, gz: f32, c: normal_map::Convention) -> [u8; 3] {
    let hf =
        Heightfield::from_fn(6, 6, 10.0, |x, y| 10.0 * (gx * x as f32 + gz * y as f32)).unwrap();
    normal_map::normal_map(&hf, 6, c).unwrap()[2 * 6 + 2]
}

#[test]
fn normal_maps_encode_east_facing_slopes_alike_and_flip_green_only() {
    use normal_map::Convention::{DirectX, OpenGl};
    // Falling 0.5 m per metre to the east: the normal (0.447, 0.894 up, 0).
    for c in [OpenGl, DirectX] {
        assert_eq!(plane_texel(-0.5, 0.0, c), [185, 128, 242], "{c:?}");
        assert_eq!(plane_texel(0.0, 0.0, c), [128, 128, 255], "{c:?}");
    }
    // Falling to the north (rising south): G up in OpenGL, down in DirectX.
    assert_eq!(plane_texel(0.0, 0.5, OpenGl), [128, 185, 242]);
    assert_eq!(plane_texel(0.0, 0.5, DirectX), [128, 70, 242]);
    let hf = hills(33, 20, 15.0);
    let (gl, dx) = (
        normal_map::normal_map(&hf, 40, OpenGl).unwrap(),
        normal_map::normal_map(&hf, 40, DirectX).unwrap(),
    );
    for (a, b) in gl.iter().zip(&dx) {
        assert_eq!((a[0], a[2]), (b[0], b[2]));
        assert!((255 - a[1] as i32 - b[1] as i32).abs() <= 1, "{a:?} {b:?}");
    }
    let mut holes = hills(8, 8, 1.0);
    holes.set(1, 1, f32::NAN);
    assert!(matches!(
        normal_map::normal_map(&holes, 8, OpenGl),
        Err(MeshError::Nodata { .. })
    ));
    assert!(normal_map::normal_map(&hf, 0, OpenGl).is_err());
}
