//! Scenes through editing sessions, on a real DEM: a curve constraint's
//! height profile (within the issue's 2 % of relief), scene-to-scene edits
//! (only what changed is re-set, the curve's distance field is reused, the
//! change stays local), and the CLI (`synth --scene`, `edit`). Skips with a
//! message when ../shared/dem is absent.

use serde_json::json;
use std::path::Path;
use terrasynth::scene::{Scene, SceneEdits};
use terrasynth::synth::control::Constraint;
use terrasynth::synth::session::{Edit, Session};

use crate::common::db::pyrenees_crop;
const SIZE: usize = 256;

fn scene(v: serde_json::Value) -> Scene {
    Scene::parse(v.to_string().as_bytes(), Path::new("test.json")).unwrap()
}

/// An S-shaped curve across the terrain with heights at 30 %, 60 % and
/// 45 % of the exemplar's range.
fn curve_scene(lo: f64, hi: f64, mid_height: f64) -> serde_json::Value {
    let at = |f: f64| lo + f * (hi - lo);
    json!({
        "size": [SIZE, SIZE], "seed": 5,
        "curves": [{"id": "c", "points": [[20, 60], [90, 40], [140, 130], [200, 200], [240, 190]],
            "widgets": [
                {"at": 0.0, "height_m": at(0.3), "slope_deg": [5, 5], "reach_px": [24, 24]},
                {"at": 0.5, "height_m": mid_height, "slope_deg": [5, 5], "reach_px": [24, 24]},
                {"at": 1.0, "height_m": at(0.45), "slope_deg": [5, 5], "reach_px": [24, 24]}]}],
        "points": [{"id": "p", "at": [60, 200], "height_m": at(0.5), "radius_px": 20}]
    })
}

#[test]
fn curve_height_profile_follows_the_widgets_on_a_real_dem() {
    let Some((db, lo, hi)) = pyrenees_crop() else {
        return;
    };
    let relief = hi - lo;
    let sc = scene(curve_scene(*lo, *hi, lo + 0.6 * relief));
    let mut edits = SceneEdits::new();
    let first = edits.edits(&sc, db).unwrap();
    let mut session = Session::new(db, SceneEdits::params(&sc), SIZE, SIZE, sc.seed).unwrap();
    let frame = session.apply(first).unwrap();
    let hf = &frame.heightfield;
    let c = &edits.curves()[0].1;
    // Sample the terrain along the curve, every pixel of arc length (bilinear).
    let mut errs = Vec::new();
    let mut s = 0.0;
    while s <= c.length() {
        let p = c.point_at(s);
        let (x, y) = (p.x - 0.5, p.y - 0.5);
        let (x0, y0) = (
            x.floor().clamp(0.0, (SIZE - 2) as f64),
            y.floor().clamp(0.0, (SIZE - 2) as f64),
        );
        let (tx, ty) = ((x - x0).clamp(0.0, 1.0), (y - y0).clamp(0.0, 1.0));
        let g = |i: f64, j: f64| hf.get(i as usize, j as usize) as f64;
        let h = (g(x0, y0) * (1.0 - tx) + g(x0 + 1.0, y0) * tx) * (1.0 - ty)
            + (g(x0, y0 + 1.0) * (1.0 - tx) + g(x0 + 1.0, y0 + 1.0) * tx) * ty;
        errs.push((h - c.height_at(s)).abs() / relief);

        s += 1.0;
    }
    // The shape: the 5×5 mean of the terrain at the curve's pixels against
    // the profile (the exemplar's detail rides on it, see
    // stages::correct::nudge::own_detail).
    let mut shape = 0.0;
    let mut s = 0.0;
    while s <= c.length() {
        let p = c.point_at(s);
        let (x, y) = (
            (p.x as usize).clamp(2, SIZE - 3),
            (p.y as usize).clamp(2, SIZE - 3),
        );
        let mean = (y - 2..=y + 2)
            .flat_map(|v| (x - 2..=x + 2).map(move |u| hf.get(u, v) as f64))
            .sum::<f64>()
            / 25.0;
        shape += (mean - c.height_at(s)).abs() / relief;
        s += 1.0;
    }
    errs.sort_by(f64::total_cmp);
    let n = errs.len();
    let shape = shape / n as f64;
    eprintln!(
        "the profile's shape (5×5 mean): mean |error| {:.2} % of relief",
        100.0 * shape
    );
    let mean = errs.iter().sum::<f64>() / n as f64;
    let (median, p90, max) = (errs[n / 2], errs[n * 9 / 10], errs[n - 1]);
    eprintln!(
        "curve profile on pyrenees_andorra (relief {relief:.0} m, {n} samples): |error| mean {:.2} %, median {:.2} %, p90 {:.2} %, max {:.2} % of relief",
        100.0 * mean,
        100.0 * median,
        100.0 * p90,
        100.0 * max
    );
    // Without the constraint the terrain is nowhere near the profile.
    let mut free = Session::new(db, SceneEdits::params(&sc), SIZE, SIZE, sc.seed).unwrap();
    let plain = free.apply(vec![]).unwrap().heightfield;
    let mut free_err = 0.0;
    let mut s = 0.0;
    while s <= c.length() {
        let p = c.point_at(s);
        let h = plain.get((p.x as usize).min(SIZE - 1), (p.y as usize).min(SIZE - 1)) as f64;
        free_err += (h - c.height_at(s)).abs() / relief;
        s += 1.0;
    }
    eprintln!(
        "unconstrained terrain along the same curve: mean |error| {:.2} % of relief",
        100.0 * free_err / n as f64
    );
    // Realism along the curve: the fine relief (RMS of the 3×3 high-pass)
    // within 2 px of it, against the unconstrained terrain's there. A curve
    // pinned to its smooth profile would leave a smooth band (paper §5.1's
    // "visually intrusive" over-constraint).
    let near: Vec<(usize, usize)> = (1..SIZE - 1)
        .flat_map(|y| (1..SIZE - 1).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let p = glam::DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
            c.points().iter().any(|q| q.distance(p) <= 2.0)
        })
        .collect();
    let texture = |hf: &terrasynth::Heightfield| {
        let s2: f64 = near
            .iter()
            .map(|&(x, y)| {
                let mut m = 0.0;
                for v in y - 1..=y + 1 {
                    for u in x - 1..=x + 1 {
                        m += hf.get(u, v) as f64 / 9.0;
                    }
                }
                (hf.get(x, y) as f64 - m).powi(2)
            })
            .sum();
        (s2 / near.len() as f64).sqrt()
    };
    let (t_curve, t_free) = (texture(hf), texture(&plain));
    eprintln!("fine relief within 2 px of the curve: {t_curve:.2} m (unconstrained {t_free:.2} m)");
    // Measured: 10.18 m against 11.63 m (88 %); 8.97 m (77 %) when the
    // nudge set each pixel's own height to the profile, before the winner
    // kept its detail (issue 40).
    assert!(t_curve >= 0.8 * t_free, "{t_curve:.2} m vs {t_free:.2} m");
    // Measured: mean 1.09 %, median 0.90 %, p90 2.19 %, max 4.21 % (seed 5),
    // the shape (5×5 mean) 1.06 %; unconstrained 11.2 %. With the pixels'
    // own heights nudged to the profile: 0.69 / 0.59 / 1.45 / 2.88 %, shape
    // 0.74 % — a crest's own texels stand above their 5×5 mean. The issue's
    // goal: within 2 % of relief along the curve's length, asserted on the
    // mean, the median and the shape (single samples keep the finest
    // levels' detail, see stages::correct::nudge::own_detail).
    assert!(
        free_err / n as f64 > 5.0 * mean,
        "the constraint must matter"
    );
    assert!(
        mean <= 0.02,
        "mean profile error {:.2} % of relief",
        100.0 * mean
    );
    assert!(
        median <= 0.02,
        "median profile error {:.2} % of relief",
        100.0 * median
    );
    assert!(
        shape <= 0.02,
        "the profile's shape off by {:.2} % of relief",
        100.0 * shape
    );
}

/// A one-sided cliff (issue 14): a straight curve, flat on its left (north)
/// side, falling at 45° on its right, 92.6 m cells.
#[test]
fn a_one_sided_cliff_is_steep_and_its_top_edge_holds() {
    let Some((db, lo, hi)) = pyrenees_crop() else {
        return;
    };
    let relief = hi - lo;
    let (top, reach) = (lo + 0.75 * relief, 10.0);
    let sc = scene(json!({
        "size": [SIZE, SIZE], "seed": 11,
        "curves": [{"id": "cliff", "points": [[16, 128], [240, 128]], "smoothing": 0,
            "widgets": [
                {"at": 0.0, "height_m": top, "slope_deg": [0, -45], "reach_px": [16, reach]},
                {"at": 1.0, "height_m": top, "slope_deg": [0, -45], "reach_px": [16, reach]}]}]
    }));
    let mut edits = SceneEdits::new();
    let first = edits.edits(&sc, db).unwrap();
    let mut session = Session::new(db, SceneEdits::params(&sc), SIZE, SIZE, sc.seed).unwrap();
    let hf = session.apply(first).unwrap().heightfield;
    let cell = db.meta().exemplars[0].cell_size_m;
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let xs = 48..208;
    // Row 127 (centre 127.5) is the flat side's edge; rows 128.. fall.
    let edge = median(xs.clone().map(|x| hf.get(x, 127) as f64 - top).collect());
    // The face: the first 80 % of the reach (the foot meets free terrain).
    let face = median(
        xs.map(|x| (hf.get(x, 128) as f64 - hf.get(x, 136) as f64) / (8.0 * cell))
            .collect(),
    );
    eprintln!(
        "cliff: top edge {edge:+.0} m ({:.2} % of relief), face {face:.2} m/m (asked 1.00)",
        100.0 * edge.abs() / relief
    );
    // Measured: top edge −37 m (1.65 %), face 0.85 m/m; with the paper's
    // loose hold (s = ½, reach capped at 4·2^i px) 0.58 m/m here, 0.42 on
    // a 512² scene of the whole Pyrenees DEM.
    assert!(edge.abs() <= 0.02 * relief, "top edge {edge:+.0} m");
    assert!(face >= 0.8, "cliff face {face:.2} m/m, asked 1.00");
}

#[test]
fn a_second_scene_only_resets_what_changed_and_stays_local() {
    let Some((db, lo, hi)) = pyrenees_crop() else {
        return;
    };
    let relief = hi - lo;
    let base = scene(curve_scene(*lo, *hi, lo + 0.6 * relief));
    let moved = scene(curve_scene(*lo, *hi, lo + 0.75 * relief));
    let mut edits = SceneEdits::new();
    let first = edits.edits(&base, db).unwrap();
    assert_eq!(first.len(), 2, "a point and a curve");
    assert_eq!(edits.fields_computed(), 1);
    let mut session = Session::new(db, SceneEdits::params(&base), SIZE, SIZE, base.seed).unwrap();
    let f0 = session.apply(first).unwrap();
    // The same scene again: nothing to do, and the frame is bit-identical.
    let none = edits.edits(&base, db).unwrap();
    assert!(none.is_empty(), "{none:?}");
    let same = session.apply(none).unwrap();
    assert_eq!(same.change.as_ref().unwrap().pixels, 0);
    // One widget height changed: one edit, the distance field reused.
    let second = edits.edits(&moved, db).unwrap();
    assert_eq!(second.len(), 1);
    assert!(matches!(&second[0], Edit::SetConstraint(..)));
    assert_eq!(
        edits.fields_computed(),
        1,
        "the curve's shape did not change"
    );
    let f1 = session.apply(second).unwrap();
    let c = &edits.curves()[0].1;
    let [bx0, by0, bx1, by1] = c.bounds();
    let (mut outside, mut outside_big) = (0usize, 0usize);
    for y in 0..SIZE {
        for x in 0..SIZE {
            let inside =
                (x as f64) >= bx0 && (x as f64) < bx1 && (y as f64) >= by0 && (y as f64) < by1;
            if !inside {
                outside += 1;
                let d = (f0.heightfield.get(x, y) - f1.heightfield.get(x, y)).abs() as f64;
                outside_big += (d > 0.01 * relief) as usize;
            }
        }
    }
    eprintln!(
        "raising the curve's middle widget by {:.0} m: {} of {outside} pixels outside its bounds changed by > 1 % of relief",
        0.15 * relief,
        outside_big
    );
    assert!(outside > 1000);
    assert!((outside_big as f64) < 0.02 * outside as f64);
    // Removing the point is one removal.
    let mut v = curve_scene(*lo, *hi, lo + 0.75 * relief);
    v.as_object_mut().unwrap().remove("points");
    let third = edits.edits(&scene(v), db).unwrap();
    assert!(
        matches!(&third[..], [Edit::RemoveConstraint(_)]),
        "{third:?}"
    );
    // A new point is one edit and changes the terrain around it.
    let mut v = curve_scene(*lo, *hi, lo + 0.75 * relief);
    v.as_object_mut().unwrap().remove("points");
    v["points"] =
        json!([{"id": "q", "at": [200, 60], "height_m": hi - 0.05 * relief, "radius_px": 16}]);
    let fourth = edits.edits(&scene(v), db).unwrap();
    assert!(
        matches!(&fourth[..], [Edit::SetConstraint(..)]),
        "{fourth:?}"
    );
    session.apply(third).unwrap();
    let before = session.heightfield().unwrap().get(200, 60);
    let f4 = session.apply(fourth).unwrap();
    let after = f4.heightfield.get(200, 60);
    eprintln!(
        "adding a point at (200, 60): {before:.0} -> {after:.0} m (target {:.0})",
        hi - 0.05 * relief
    );
    assert!(f4.change.unwrap().pixels > 0);
    assert!(
        (after - before) as f64 > 0.05 * relief,
        "{before} -> {after}"
    );
    // A different seed is not an edit.
    let mut v = curve_scene(*lo, *hi, lo + 0.75 * relief);
    v["seed"] = json!(6);
    let e = edits.edits(&scene(v), db).unwrap_err();
    assert_eq!(e.path, "seed");
    assert!(
        e.to_string()
            .contains("the same seed as the session's first scene"),
        "{e}"
    );
}

#[test]
fn cli_synth_scene_and_edit_write_frames_previews_and_a_report() {
    let Some((db, lo, hi)) = pyrenees_crop() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    db.save(&dir.path().join("db.tsdb")).unwrap();
    let relief = hi - lo;
    let write = |name: &str, mid: f64| {
        let mut v = curve_scene(*lo, *hi, mid);
        v["database"] = json!("db.tsdb");
        v["size"] = json!([128, 128]);
        v["curves"][0]["points"] = json!([[10, 30], [60, 20], [120, 100]]);
        v["points"][0]["at"] = json!([30, 100]);
        v["freeze"] = json!({"strokes": [{"points": [[110, 10]], "radius_px": 8}]});
        std::fs::write(dir.path().join(name), v.to_string()).unwrap();
    };
    write("base.json", lo + 0.5 * relief);
    write("e1.json", lo + 0.7 * relief);
    let bin = env!("CARGO_BIN_EXE_terrasynth");
    let out = std::process::Command::new(bin)
        .args(["synth", "--scene"])
        .arg(dir.path().join("base.json"))
        .arg("-o")
        .arg(dir.path().join("one.exr"))
        .arg("--preview")
        .arg(dir.path().join("one.png"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(dir.path().join("one.exr").exists() && dir.path().join("one.png").exists());
    let out = std::process::Command::new(bin)
        .arg("edit")
        .arg(dir.path().join("base.json"))
        .arg(dir.path().join("e1.json"))
        .arg("--out-dir")
        .arg(dir.path().join("frames"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("frames/report.json")).unwrap())
            .unwrap();
    let frames = report["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 2);
    assert!(frames[1]["changed_pixels"].as_u64().unwrap() > 0);
    assert_eq!(frames[1]["edits"], 1);
    for k in 0..2 {
        assert!(dir.path().join(format!("frames/frame_{k:03}.exr")).exists());
        assert!(
            dir.path()
                .join(format!("frames/frame_{k:03}.preview.png"))
                .exists()
        );
    }
    // Frozen pixels did not change to the bit.
    let a = terrasynth::io::read(
        &dir.path().join("frames/frame_000.exr"),
        &Default::default(),
    )
    .unwrap();
    let b = terrasynth::io::read(
        &dir.path().join("frames/frame_001.exr"),
        &Default::default(),
    )
    .unwrap();
    for y in 5..15 {
        for x in 106..114 {
            assert_eq!(
                a.get(x, y).to_bits(),
                b.get(x, y).to_bits(),
                "frozen ({x}, {y})"
            );
        }
    }
    // A bad edit scene fails with its path and leaves no frame behind.
    std::fs::write(
        dir.path().join("bad.json"),
        r#"{"size": [128, 128], "seed": 5, "curves": [{"points": [[1, 1]], "widgets": []}]}"#,
    )
    .unwrap();
    let out = std::process::Command::new(bin)
        .arg("edit")
        .arg(dir.path().join("bad.json"))
        .arg("--out-dir")
        .arg(dir.path().join("bad"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("curves[0].points"), "{err}");
    assert!(!dir.path().join("bad").exists());
}

#[test]
fn overlays_draw_curves_widgets_points_types_and_frozen_regions() {
    let Some((db, lo, hi)) = pyrenees_crop() else {
        return;
    };
    let mut v = curve_scene(*lo, *hi, lo + 0.6 * (hi - lo));
    v["freeze"] = json!({"strokes": [{"points": [[200, 40]], "radius_px": 12}]});
    v["types"] = json!({"strokes": [{"type": db.type_names()[0].clone(), "points": [[40, 230]], "radius_px": 10}]});
    let sc = scene(v);
    let mut edits = SceneEdits::new();
    let first = edits.edits(&sc, db).unwrap();
    let mut session = Session::new(db, SceneEdits::params(&sc), SIZE, SIZE, sc.seed).unwrap();
    let hf = session.apply(first).unwrap().heightfield;
    let names = db.type_names();
    let plain = terrasynth::scene::overlay::preview(&hf, &sc, &edits, names, false).unwrap();
    let drawn = terrasynth::scene::overlay::preview(&hf, &sc, &edits, names, true).unwrap();
    assert_eq!(plain.dimensions(), drawn.dimensions());
    let k = plain.width() as f64 / SIZE as f64;
    let px =
        |img: &image::RgbaImage, x: f64, y: f64| *img.get_pixel((x * k) as u32, (y * k) as u32);
    let c = &edits.curves()[0].1;
    // The curve is drawn dark along its length.
    for f in [0.1, 0.3, 0.7, 0.9] {
        let q = c.point_at(f * c.length());
        let p = px(&drawn, q.x, q.y);
        assert!(p[0] < 60 && p[1] < 60 && p[2] < 60, "curve at {f}: {p:?}");
    }
    // The middle widget is a yellow diamond.
    let q = c.point_at(0.5 * c.length());
    let p = px(&drawn, q.x, q.y);
    assert!(p[0] > 200 && p[1] > 170 && p[2] < 80, "widget: {p:?}");
    // The point: its site is cyan.
    let p = px(&drawn, 60.0, 200.0);
    assert!(p[0] < 80 && p[2] > 200, "point: {p:?}");
    // Frozen region is washed lighter; the painted type tinted.
    let (a, b) = (px(&plain, 200.0, 40.0), px(&drawn, 200.0, 40.0));
    assert!(
        b[0] as i32 + b[1] as i32 + b[2] as i32 > a[0] as i32 + a[1] as i32 + a[2] as i32,
        "{a:?} {b:?}"
    );
    assert_ne!(px(&plain, 40.0, 230.0), px(&drawn, 40.0, 230.0));
}
