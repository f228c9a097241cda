//! Scene files: a valid scene parses to what it says; each kind of bad
//! scene gives its own error naming the JSON path and the allowed range;
//! type paint and freeze rasters; the fuzz corpus replays cleanly.

use serde_json::{Value, json};
use std::path::Path;
use terrasynth::scene::{Freeze, PasteSource, Scene, SceneErrorKind, TypePaint};
use terrasynth::synth::control::Lift;

fn base() -> Value {
    json!({
        "version": 1,
        "size": [128, 96],
        "seed": 7,
        "points": [{"id": "peak", "at": [30, 40], "height_m": 900, "slope_deg": 10, "slope_direction_deg": 90, "radius_px": 12}],
        "curves": [
            {"points": [[0, 50], [60, 48], [128, 52]], "widgets": [{"at": 0.5, "height_m": 300, "slope_deg": [20, 25], "reach_px": [10, 14]}]},
            {"id": "ridge", "points": [[64, 0], [64, 96]], "smoothing": 0, "widgets": [
                {"at": 0, "height_m": 600, "slope_deg": [-30, -30], "reach_px": [8, 8]},
                {"at": 1, "height_m": 700, "slope_deg": [-30, -20], "reach_px": [8, 9]}]}
        ],
        "junctions": [{"at": [64, 49], "height_m": 450}],
        "types": {"strokes": [{"type": "hills", "points": [[10, 10], [40, 10]], "radius_px": 5}]},
        "freeze": {"strokes": [{"points": [[100, 80]], "radius_px": 6}]},
        "pastes": [{"source": "exemplar", "exemplar": 1, "lasso": [[10, 10], [40, 12], [30, 40]], "to": [90, 20], "delta_m": -50}]
    })
}

fn parse(v: &Value) -> Result<Scene, terrasynth::scene::SceneError> {
    Scene::parse(v.to_string().as_bytes(), Path::new("data/scenes/test.json"))
}

#[test]
fn a_valid_scene_parses_to_what_it_says() {
    let s = parse(&base()).unwrap();
    assert_eq!((s.width, s.height, s.seed, s.passes), (128, 96, 7, 2));
    assert_eq!(s.jitter, 0.4);
    assert_eq!(s.database, None);
    assert_eq!(s.points[0].id, "peak");
    assert_eq!(s.points[0].radius_px, 12.0);
    assert_eq!(s.curves[0].id, "curves[0]");
    assert_eq!(s.curves[0].spec.smoothing, 2);
    assert_eq!(s.curves[1].spec.widgets[1].slope_deg, [-30.0, -20.0]);
    assert_eq!(s.curves[1].spec.widgets[1].reach_px, [8.0, 9.0]);
    assert_eq!(s.junctions[0].height_m, 450.0);
    assert!(matches!(&s.types, Some(TypePaint::Strokes(v)) if v[0].0.as_deref() == Some("hills")));
    assert!(matches!(&s.freeze, Some(Freeze::Strokes(v)) if v.len() == 1));
    assert_eq!(s.pastes[0].source, PasteSource::Exemplar(1));
    assert_eq!(s.pastes[0].delta_m, -50.0);
    // Version 1 had only the source's own heights.
    assert_eq!(s.pastes[0].lift, Lift::Source);
    // Version 2 lands pastes on the ground unless one says otherwise.
    let mut v = base();
    v["version"] = json!(2);
    let mut second = v["pastes"][0].clone();
    second["lift"] = json!("source");
    v["pastes"].as_array_mut().unwrap().push(second);
    let s2 = parse(&v).unwrap();
    assert_eq!(
        (s2.pastes[0].lift, s2.pastes[1].lift),
        (Lift::Ground, Lift::Source)
    );
    // Paths are relative to the scene file.
    let mut v = base();
    v["database"] = json!("db/ex.tsdb");
    assert_eq!(
        parse(&v).unwrap().database.unwrap(),
        Path::new("data/scenes/db/ex.tsdb")
    );
}

/// Applies `edit` to the base scene and returns (path, message).
fn fails(edit: impl FnOnce(&mut Value)) -> (String, SceneErrorKind, String) {
    let mut v = base();
    edit(&mut v);
    let e = parse(&v).expect_err("must fail");
    let msg = e.to_string();
    assert!(msg.starts_with("data/scenes/test.json: "), "{msg}");
    (e.path, *e.kind, msg)
}

#[test]
fn missing_fields_name_their_path() {
    let (path, kind, msg) = fails(|v| drop(v.as_object_mut().unwrap().remove("size")));
    assert_eq!(path, "size");
    assert!(matches!(kind, SceneErrorKind::Missing(_)), "{msg}");
    let (path, _, msg) = fails(|v| {
        drop(
            v["curves"][1]["widgets"][0]
                .as_object_mut()
                .unwrap()
                .remove("height_m"),
        )
    });
    assert_eq!(path, "curves[1].widgets[0].height_m", "{msg}");
    assert!(msg.contains("missing field"), "{msg}");
    let (path, _, _) = fails(|v| drop(v["points"][0].as_object_mut().unwrap().remove("radius_px")));
    assert_eq!(path, "points[0].radius_px");
    let (path, _, _) = fails(|v| drop(v["pastes"][0].as_object_mut().unwrap().remove("exemplar")));
    assert_eq!(path, "pastes[0].exemplar");
}

#[test]
fn unknown_fields_are_errors_listing_the_allowed_ones() {
    let (path, kind, msg) = fails(|v| v["curves"][0]["widgets"][0]["heigth_m"] = json!(1));
    assert_eq!(path, "curves[0].widgets[0].heigth_m");
    assert!(matches!(kind, SceneErrorKind::Unknown(_)));
    assert!(msg.contains("at, height_m, slope_deg, reach_px"), "{msg}");
    let (path, _, _) = fails(|v| v["colour"] = json!("red"));
    assert_eq!(path, "colour");
    let (path, _, _) = fails(|v| v["types"]["image"] = json!("t.png"));
    assert_eq!(path, "types", "both forms at once");
}

#[test]
fn out_of_range_values_name_path_and_range() {
    type Edit = Box<dyn FnOnce(&mut Value)>;
    let cases: Vec<(Edit, &str, &str)> = vec![
        (
            Box::new(|v| v["curves"][1]["widgets"][0]["height_m"] = json!(1e9)),
            "curves[1].widgets[0].height_m",
            "-20000..=20000 m",
        ),
        (
            Box::new(|v| v["curves"][0]["widgets"][0]["at"] = json!(1.5)),
            "curves[0].widgets[0].at",
            "0..=1",
        ),
        (
            Box::new(|v| v["curves"][0]["widgets"][0]["reach_px"] = json!([0, 5])),
            "curves[0].widgets[0].reach_px[0]",
            "0 < reach <= 4096 pixels",
        ),
        (
            Box::new(|v| v["curves"][0]["widgets"][0]["slope_deg"] = json!([10, 90])),
            "curves[0].widgets[0].slope_deg[1]",
            "-85..=85 degrees",
        ),
        (
            Box::new(|v| v["curves"][0]["widgets"][0]["slope_deg"] = json!(10)),
            "curves[0].widgets[0].slope_deg",
            "[left, right]",
        ),
        (
            Box::new(|v| v["curves"][0]["points"][2] = json!([129, 5])),
            "curves[0].points[2][0]",
            "x in 0..=128 pixels",
        ),
        (
            Box::new(|v| v["points"][0]["slope_deg"] = json!(81)),
            "points[0].slope_deg",
            "0..=80 degrees",
        ),
        (
            Box::new(|v| v["points"][0]["at"] = json!([1, 2, 3])),
            "points[0].at",
            "[x, y]",
        ),
        (
            Box::new(|v| v["size"] = json!([0, 10])),
            "size[0]",
            "1..=65535",
        ),
        (
            Box::new(|v| v["seed"] = json!(-1)),
            "seed",
            "0..=4294967295",
        ),
        (
            Box::new(|v| v["jitter"] = json!(5)),
            "jitter",
            "0..=4 texels",
        ),
        (Box::new(|v| v["passes"] = json!(17)), "passes", "0..=16"),
        (Box::new(|v| v["version"] = json!(3)), "version", "1 or 2"),
        (
            Box::new(|v| v["pastes"][0]["lift"] = json!("sky")),
            "pastes[0].lift",
            "\"ground\" or \"source\"",
        ),
        (
            Box::new(|v| v["freeze"]["strokes"][0]["radius_px"] = json!(-2)),
            "freeze.strokes[0].radius_px",
            "0 < radius",
        ),
        (
            Box::new(|v| v["pastes"][0]["source"] = json!("clipboard")),
            "pastes[0].source",
            "\"terrain\" or \"exemplar\"",
        ),
        (
            Box::new(|v| v["pastes"][0]["lasso"] = json!([[1, 1], [2, 2]])),
            "pastes[0].lasso",
            "3..=",
        ),
        (
            Box::new(|v| v["points"][0]["id"] = json!("ridge")),
            "curves[1].id",
            "an id no other item",
        ),
    ];
    for (edit, want_path, want_range) in cases {
        let (path, kind, msg) = fails(edit);
        assert_eq!(path, want_path, "{msg}");
        assert!(matches!(kind, SceneErrorKind::Invalid { .. }), "{msg}");
        assert!(msg.contains(want_range), "{msg} should state {want_range}");
    }
}

#[test]
fn a_curve_needs_two_distinct_points_and_a_widget() {
    let (path, _, msg) = fails(|v| v["curves"][0]["points"] = json!([[3, 3]]));
    assert_eq!(path, "curves[0].points");
    assert!(msg.contains("an array of 2..="), "{msg}");
    let (path, _, msg) = fails(|v| v["curves"][1]["points"] = json!([[3, 3], [3, 3]]));
    assert_eq!(path, "curves[1].points");
    assert!(msg.contains("not all the same"), "{msg}");
    let (path, _, _) = fails(|v| v["curves"][0]["widgets"] = json!([]));
    assert_eq!(path, "curves[0].widgets");
}

#[test]
fn malformed_json_is_an_error_at_the_document() {
    let e = Scene::parse(b"{\"size\": [1, 2],", Path::new("x.json")).unwrap_err();
    assert_eq!(e.path, "$");
    assert!(matches!(*e.kind, SceneErrorKind::Json(_)));
    assert!(e.to_string().contains("line 1"), "{e}");
}

#[test]
fn type_strokes_paint_database_indices_and_unknown_names_fail() {
    let names: Vec<String> = ["sea", "flat", "hills", "mountains"]
        .map(String::from)
        .to_vec();
    let s = parse(&base()).unwrap();
    let r = s.type_raster(&names).unwrap().unwrap();
    assert_eq!(r.len(), 128 * 96);
    assert_eq!(r[10 * 128 + 20], 2, "on the stroke");
    assert_eq!(r[60 * 128 + 20], 255, "unpainted = unconstrained");
    let painted = r.iter().filter(|&&t| t == 2).count();
    // A 30 px stroke with round caps of radius 5: ≈ 30·10 + π·25 = 379 px.
    assert!((340..420).contains(&painted), "{painted}");
    let mut v = base();
    v["types"]["strokes"][0]["type"] = json!("glacier");
    let e = parse(&v).unwrap().type_raster(&names).unwrap_err();
    assert_eq!(e.path, "types.strokes[0].type");
    assert!(
        e.to_string().contains("\"glacier\"")
            && e.to_string().contains("sea, flat, hills, mountains"),
        "{e}"
    );
    let f = s.freeze_raster().unwrap().unwrap();
    assert!(f[80 * 128 + 100] && !f[0]);
}

#[test]
fn mask_images_must_match_the_scene_size() {
    use terrasynth::io::maps::type_mask::TypeMask;
    let dir = tempfile::tempdir().unwrap();
    let mut mask = TypeMask::new(128, 96, vec![255; 128 * 96]).unwrap();
    mask.indices[5] = 1;
    mask.names.insert(1, "mountains".into());
    mask.write(&dir.path().join("t.png"), "x", "test").unwrap();
    let small = TypeMask::new(64, 96, vec![0; 64 * 96]).unwrap();
    small
        .write(&dir.path().join("small.png"), "x", "test")
        .unwrap();
    let names: Vec<String> = ["sea", "flat", "hills", "mountains"]
        .map(String::from)
        .to_vec();
    let scene_at =
        |v: &Value| Scene::parse(v.to_string().as_bytes(), &dir.path().join("s.json")).unwrap();
    let mut v = base();
    v["types"] = json!({"image": "t.png"});
    v["freeze"] = json!({"mask": "t.png"});
    let s = scene_at(&v);
    // Image index 1 is "mountains": database index 3.
    let t = s.type_raster(&names).unwrap().unwrap();
    assert_eq!((t[5], t[6]), (3, 255));
    let f = s.freeze_raster().unwrap().unwrap();
    assert_eq!((f[5], f[6]), (true, true), "255 is non-zero: frozen");
    v["types"] = json!({"image": "small.png"});
    v["freeze"] = json!({"mask": "small.png"});
    let s = scene_at(&v);
    let e = s.type_raster(&names).unwrap_err();
    assert_eq!(e.path, "types.image");
    assert!(
        matches!(
            *e.kind,
            SceneErrorKind::MaskSize {
                width: 64,
                height: 96,
                ..
            }
        ),
        "{e}"
    );
    assert!(
        e.to_string().contains("64x96 but the scene is 128x96"),
        "{e}"
    );
    assert_eq!(s.freeze_raster().unwrap_err().path, "freeze.mask");
    v["freeze"] = json!({"mask": "missing.png"});
    let e = scene_at(&v).freeze_raster().unwrap_err();
    assert_eq!(e.path, "freeze.mask");
    assert!(e.to_string().contains("missing.png"), "{e}");
}

/// The fuzz seeds: every one parses or fails with an error, never panics;
/// the example scenes in data/scenes are among the valid ones.
#[test]
fn fuzz_corpus_and_example_scenes_replay_cleanly() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut n = 0;
    let mut valid = 0;
    for dir in ["fuzz/corpus/scene", "data/scenes"] {
        for entry in std::fs::read_dir(root.join(dir)).unwrap() {
            let p = entry.unwrap().path();
            if p.extension().is_none_or(|e| e != "json") && dir == "data/scenes" {
                continue;
            }
            let bytes = std::fs::read(&p).unwrap();
            let r = std::panic::catch_unwind(|| Scene::parse(&bytes, &p).map(|_| ()));
            match r {
                Ok(Ok(())) => valid += 1,
                Ok(Err(e)) => assert!(!e.to_string().is_empty()),
                Err(_) => panic!("{} panicked the parser", p.display()),
            }
            if dir == "data/scenes" {
                assert!(
                    Scene::parse(&bytes, &p).is_ok(),
                    "example {} must be valid",
                    p.display()
                );
            }
            n += 1;
        }
    }
    assert!(n >= 10 && valid >= 3, "{n} inputs, {valid} valid");
}

#[test]
fn eraser_strokes_paint_back_to_unconstrained_and_thaw() {
    let names: Vec<String> = ["sea", "flat", "hills"].map(String::from).to_vec();
    let mut v = base();
    v["types"]["strokes"]
        .as_array_mut()
        .unwrap()
        .push(json!({"erase": true, "points": [[25, 10]], "radius_px": 3}));
    v["freeze"]["strokes"]
        .as_array_mut()
        .unwrap()
        .push(json!({"erase": true, "points": [[100, 80]], "radius_px": 2}));
    let s = parse(&v).unwrap();
    assert!(matches!(&s.types, Some(TypePaint::Strokes(t)) if t[1].0.is_none()));
    let r = s.type_raster(&names).unwrap().unwrap();
    assert_eq!(r[10 * 128 + 25], 255, "erased");
    assert_eq!(r[10 * 128 + 35], 2, "still painted beside the eraser");
    let f = s.freeze_raster().unwrap().unwrap();
    assert!(!f[80 * 128 + 100], "thawed");
    assert!(f[80 * 128 + 104], "still frozen beside the eraser");
    // An eraser has no type, and `erase` is a boolean.
    v["types"]["strokes"][1]["type"] = json!("hills");
    assert_eq!(parse(&v).unwrap_err().path, "types.strokes[1].type");
    let mut v = base();
    v["freeze"]["strokes"][0]["erase"] = json!("yes");
    assert_eq!(parse(&v).unwrap_err().path, "freeze.strokes[0].erase");
}

proptest::proptest! {
    #![proptest_config(crate::common::proptest_cases(48))]

    /// The stroke painter (segment capsules, rows in parallel) paints what
    /// the definition says: a pixel takes the last stroke that comes within
    /// its radius of the pixel's centre.
    #[test]
    fn stroke_rasters_follow_the_definition(
        strokes in proptest::collection::vec(
            (proptest::collection::vec((-10.0f64..70.0, -10.0f64..50.0), 1..6), 0.5f64..9.0, proptest::bool::ANY),
            1..6,
        )
    ) {
        let (w, h) = (61usize, 43usize);
        let list: Vec<Value> = strokes
            .iter()
            .map(|(pts, r, erase)| {
                let pts: Vec<[f64; 2]> = pts.iter().map(|&(x, y)| [x.clamp(0.0, w as f64), y.clamp(0.0, h as f64)]).collect();
                json!({"erase": erase, "points": pts, "radius_px": r})
            })
            .collect();
        let v = json!({"size": [w, h], "seed": 1, "freeze": {"strokes": list}});
        let s = parse(&v).unwrap();
        let got = s.freeze_raster().unwrap().unwrap();
        let Some(Freeze::Strokes(parsed)) = &s.freeze else { panic!() };
        for y in 0..h {
            for x in 0..w {
                let p = glam::DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
                let mut want = false;
                for (frozen, st) in parsed {
                    let d = if st.points.len() == 1 {
                        p.distance(st.points[0])
                    } else {
                        st.points.windows(2).map(|s| {
                            let d = s[1] - s[0];
                            let t = if d.length_squared() > 0.0 { ((p - s[0]).dot(d) / d.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
                            p.distance(s[0] + d * t)
                        }).fold(f64::INFINITY, f64::min)
                    };
                    if d <= st.radius_px {
                        want = *frozen;
                    }
                }
                proptest::prop_assert_eq!(got[y * w + x], want, "pixel ({}, {})", x, y);
            }
        }
    }
}
