//! The editor's HTTP API (`terrasynth::server`), over real sockets on
//! 127.0.0.1: every endpoint, the errors bad requests get (status and the
//! field they name), coalescing, history, saving and the restart that
//! reloads the saved scene. (Limits and mangled requests:
//! `tests/serve/limits.rs`.)
use crate::common;
use crate::common::editor::{N, create, doc, expect_error, heights, put_scene, serve};
use crate::common::http;
use serde_json::{Value, json};
use std::time::Duration;
use terrasynth::io::{self, Format, ReadOptions};
use terrasynth::scene::Scene;

#[test]
fn info_page_and_assets() {
    let s = serve(N, None, 2);
    let a = s.addr;
    let info = http::get(a, "/api/info").json();
    assert_eq!(info["status"], "ready");
    assert!(!info["database"]["types"].as_array().unwrap().is_empty());
    assert!(
        info["export_formats"]
            .as_array()
            .unwrap()
            .contains(&json!("exr"))
    );
    let page = http::get(a, "/");
    assert_eq!(page.status, 200);
    assert!(
        page.header("content-type")
            .unwrap()
            .starts_with("text/html")
    );
    assert!(String::from_utf8_lossy(&page.body).contains("/assets/js/main.js"));
    // Nothing from elsewhere: the browser may load only this server's files.
    let policy = page.header("content-security-policy").unwrap();
    assert!(policy.starts_with("default-src 'self';"), "{policy}");
    for asset in ["editor.css", "js/main.js", "js/tools.js", "js/panel.js"] {
        let r = http::get(a, &format!("/assets/{asset}"));
        assert_eq!(r.status, 200, "{asset}");
        assert!(!r.body.is_empty(), "{asset}");
    }
    expect_error(&http::get(a, "/assets/nope.js"), 404, "$");
    expect_error(&http::get(a, "/api/nothing"), 404, "$");
    expect_error(
        &http::request(a, "DELETE", "/api/info", None, None),
        405,
        "$",
    );
    let ex = http::get(a, "/api/exemplars/0/preview.png");
    assert_eq!(ex.status, 200);
    assert_eq!(&ex.body[..8], b"\x89PNG\r\n\x1a\n");
    expect_error(&http::get(a, "/api/exemplars/99/preview.png"), 422, "index");
}

#[test]
fn sessions_edits_and_their_errors() {
    let s = serve(N, None, 2);
    let a = s.addr;
    let (id, first) = create(a);
    assert_eq!(first["scene"], doc());
    assert_eq!(first["size"], json!([N, N]));
    let h0 = heights(a, &id);
    assert_eq!(h0.len(), N * N);

    // A point changes the terrain around it, and only there.
    let mut d = doc();
    d["points"] = json!([{"id": "p", "at": [20, 20], "height_m": 2500, "radius_px": 6}]);
    let f = put_scene(a, &id, &d, true).json();
    let b = f["changed"]["bounds"].as_array().unwrap();
    assert!(
        b[2].as_u64().unwrap() <= 40 && b[3].as_u64().unwrap() <= 40,
        "{f}"
    );
    assert!(f["changed"]["pixels"].as_u64().unwrap() > 0);
    assert_eq!(f["history"], json!({"undo": 1, "redo": 0}));
    assert!(f["timing_ms"]["synth"].as_f64().unwrap() > 0.0);
    let h1 = heights(a, &id);
    assert_ne!(h0, h1);
    assert_eq!(h0[63 * N + 63].to_bits(), h1[63 * N + 63].to_bits());

    // Bad documents name the field and change nothing.
    let mut bad = d.clone();
    bad["points"][0]["radius_px"] = json!(-1);
    expect_error(&put_scene(a, &id, &bad, true), 422, "points[0].radius_px");
    let mut bad = d.clone();
    bad["curves"] = json!([{"points": [[1, 1], [1, 1]], "widgets": []}]);
    expect_error(&put_scene(a, &id, &bad, true), 422, "curves[0].widgets");
    let mut bad = d.clone();
    bad["types"] = json!({"strokes": [{"type": "glacier", "points": [[3, 3]], "radius_px": 2}]});
    expect_error(&put_scene(a, &id, &bad, true), 422, "types.strokes[0].type");
    let mut bad = d.clone();
    bad["database"] = json!("/tmp/other.tsdb");
    expect_error(&put_scene(a, &id, &bad, true), 422, "database");
    let mut bad = d.clone();
    bad["freeze"] = json!({"mask": "/etc/passwd"});
    expect_error(&put_scene(a, &id, &bad, true), 422, "freeze.mask");
    let mut bad = d.clone();
    bad["colour"] = json!("red");
    expect_error(&put_scene(a, &id, &bad, true), 422, "colour");
    let path = format!("/api/sessions/{id}/scene");
    expect_error(
        &http::request(a, "PUT", &path, Some(b"{\"size\": "), None),
        400,
        "$",
    );
    expect_error(&http::request(a, "PUT", &path, Some(b"[]"), None), 422, "$");
    expect_error(&http::request(a, "PUT", &path, None, None), 400, "$");
    expect_error(
        &http::request(
            a,
            "PUT",
            &path,
            Some(d.to_string().as_bytes()),
            Some("text/plain"),
        ),
        415,
        "$",
    );
    expect_error(
        &http::put(a, &format!("{path}?commit=maybe"), &d),
        400,
        "commit",
    );
    expect_error(
        &http::put(a, &format!("{path}?comit=true"), &d),
        400,
        "comit",
    );
    expect_error(&http::put(a, "/api/sessions/0123/scene", &d), 404, "id");
    assert_eq!(heights(a, &id), h1, "a refused edit changed the terrain");
    assert_eq!(
        http::get(a, &format!("/api/sessions/{id}")).json()["scene"],
        d
    );

    // View toggles.
    let v = http::put(
        a,
        &format!("/api/sessions/{id}/view"),
        &json!({"contours": false}),
    );
    assert_eq!(v.status, 200);
    assert_eq!(v.json()["view"]["contours"], false);
    let bad = http::put(
        a,
        &format!("/api/sessions/{id}/view"),
        &json!({"shadows": true}),
    );
    expect_error(&bad, 400, "shadows");
    let bad = http::put(a, &format!("/api/sessions/{id}/view"), &json!({"types": 1}));
    expect_error(&bad, 422, "types");
}

#[test]
fn history_commits_and_drags() {
    let s = serve(N, None, 2);
    let a = s.addr;
    let (id, _) = create(a);
    expect_error(
        &http::post(a, &format!("/api/sessions/{id}/undo"), None),
        422,
        "$",
    );
    let point = |x: f64| {
        let mut d = doc();
        d["points"] = json!([{"at": [x, 30], "height_m": 900, "radius_px": 5}]);
        d
    };
    assert_eq!(put_scene(a, &id, &point(20.0), true).status, 200);
    // A drag: intermediate states are no undo steps.
    for x in [22.0, 24.0, 26.0] {
        assert_eq!(put_scene(a, &id, &point(x), false).status, 200);
    }
    let f = put_scene(a, &id, &point(28.0), true).json();
    assert_eq!(f["history"], json!({"undo": 2, "redo": 0}));
    let u = http::post(a, &format!("/api/sessions/{id}/undo"), None).json();
    assert_eq!(u["scene"], point(20.0));
    assert_eq!(u["history"], json!({"undo": 1, "redo": 1}));
    let u = http::post(a, &format!("/api/sessions/{id}/undo"), None).json();
    assert_eq!(u["scene"], doc());
    let r = http::post(a, &format!("/api/sessions/{id}/redo"), None).json();
    assert_eq!(r["scene"], point(20.0));
    // A new edit drops the redo steps.
    put_scene(a, &id, &point(40.0), true);
    expect_error(
        &http::post(a, &format!("/api/sessions/{id}/redo"), None),
        422,
        "$",
    );
}

/// While one document is synthesized, a newer one replaces any queued one:
/// the replaced request is answered `superseded`, the newest is shown.
#[test]
fn queued_documents_coalesce_latest_wins() {
    let s = serve(N, None, 2);
    let a = s.addr;
    let (id, _) = create(a);
    let seeded = |seed: u32, x: f64| {
        let mut d = doc();
        d["seed"] = json!(seed);
        d["points"] = json!([{"at": [x, 30], "height_m": 900, "radius_px": 5}]);
        d
    };
    // A slow first job: a new seed at a larger size is a whole new session
    // (a second or so; the next two arrive within 120 ms).
    let mut slow = seeded(9, 10.0);
    slow["size"] = json!([1024, 1024]);
    let id2 = id.clone();
    let t1 = std::thread::spawn(move || put_scene(a, &id2, &slow, true));
    std::thread::sleep(Duration::from_millis(60));
    let id2 = id.clone();
    let t2 = std::thread::spawn(move || put_scene(a, &id2, &seeded(9, 20.0), false));
    std::thread::sleep(Duration::from_millis(60));
    let t3 = put_scene(a, &id, &seeded(9, 30.0), false);
    let (r1, r2) = (t1.join().unwrap(), t2.join().unwrap());
    assert_eq!(r1.status, 200);
    assert_eq!(r1.json()["rebuilt"], "size changed");
    assert_eq!(r2.json(), json!({"superseded": true}));
    assert_eq!(t3.status, 200);
    assert_eq!(t3.json()["rebuilt"], "size changed");
    let shown = http::get(a, &format!("/api/sessions/{id}")).json();
    // The committed document: the first (the others were not commits).
    assert_eq!(shown["scene"]["points"][0]["at"], json!([10.0, 30]));
}

/// With "types" on, a painted stroke tints only where it is painted
/// (issue 43: one stroke greyed the whole map): pixels whose heights and
/// neighbours' heights did not change, away from the stroke, keep their
/// colour exactly.
#[test]
fn painted_types_keep_the_tint_elsewhere() {
    let s = serve(N, None, 2);
    let a = s.addr;
    let (id, _) = create(a);
    let preview = || {
        let png = http::get(a, &format!("/api/sessions/{id}/preview.png"));
        image::load_from_memory(&png.body).unwrap().to_rgba8()
    };
    let (p0, h0) = (preview(), heights(a, &id));
    let name = http::get(a, "/api/info").json()["database"]["types"][0]["name"].clone();
    let mut d = doc();
    d["types"] = json!({"strokes": [{"type": name, "points": [[8, 8], [14, 8]], "radius_px": 2}]});
    assert_eq!(put_scene(a, &id, &d, true).status, 200);
    let (p1, h1) = (preview(), heights(a, &id));
    let still = |x: usize, y: usize| {
        (y.saturating_sub(1)..(y + 2).min(N)).all(|j| {
            (x.saturating_sub(1)..(x + 2).min(N))
                .all(|i| h0[j * N + i].to_bits() == h1[j * N + i].to_bits())
        })
    };
    let (mut same, mut total) = (0, 0);
    for (x, y, px) in p1.enumerate_pixels() {
        let (x, y) = (x as usize, y as usize);
        if y > 16 && still(x, y) {
            total += 1;
            same += (px == p0.get_pixel(x as u32, y as u32)) as usize;
        }
    }
    assert!(total > N * N / 4, "{total} pixels kept their heights");
    assert_eq!(
        same, total,
        "{same} of {total} unchanged pixels kept their colour"
    );
}

#[test]
fn previews_tiles_heights_and_exports() {
    let s = serve(N, None, 2);
    let a = s.addr;
    let (id, first) = create(a);
    let png = http::get(a, &format!("/api/sessions/{id}/preview.png"));
    assert_eq!(png.status, 200);
    let img = image::load_from_memory(&png.body).unwrap();
    assert_eq!((img.width() as usize, img.height() as usize), (N, N));
    let t0 = first["tile"]["revision"].as_u64().unwrap();
    assert_eq!(first["tile"]["rect"], json!([0, 0, N, N]));
    let mut d = doc();
    d["points"] = json!([{"at": [20, 20], "height_m": 2500, "radius_px": 6}]);
    let f = put_scene(a, &id, &d, true).json();
    let rect: Vec<usize> = serde_json::from_value(f["tile"]["rect"].clone()).unwrap();
    assert!(rect[2] - rect[0] < N && rect[3] - rect[1] < N, "{f}");
    let rev = f["tile"]["revision"].as_u64().unwrap();
    assert!(rev > t0);
    let tile = http::get(a, &format!("/api/sessions/{id}/tile.png?revision={rev}"));
    assert_eq!(tile.status, 200);
    let timg = image::load_from_memory(&tile.body).unwrap().to_rgba8();
    assert_eq!(
        (timg.width() as usize, timg.height() as usize),
        (rect[2] - rect[0], rect[3] - rect[1])
    );
    // The tile is that part of the new preview.
    let full = http::get(a, &format!("/api/sessions/{id}/preview.png"));
    let full = image::load_from_memory(&full.body).unwrap().to_rgba8();
    for (x, y, p) in timg.enumerate_pixels() {
        assert_eq!(p, full.get_pixel(x + rect[0] as u32, y + rect[1] as u32));
    }
    expect_error(
        &http::get(a, &format!("/api/sessions/{id}/tile.png")),
        400,
        "revision",
    );
    expect_error(
        &http::get(a, &format!("/api/sessions/{id}/tile.png?revision=x")),
        400,
        "revision",
    );
    expect_error(
        &http::get(a, &format!("/api/sessions/{id}/tile.png?revision=99999")),
        404,
        "$",
    );

    let hf = heights(a, &id);
    let hr = http::get(a, &format!("/api/sessions/{id}/heights"));
    assert_eq!(hr.header("x-revision"), Some(rev.to_string().as_str()));
    let hb = hr.body;
    let word = |k: usize| u32::from_le_bytes(hb[4 * k..4 * k + 4].try_into().unwrap());
    assert_eq!((word(0), word(1), word(2)), (N as u32, N as u32, 1));
    assert_eq!(
        f32::from_le_bytes(hb[12 + 4 * 70..12 + 4 * 71].try_into().unwrap()),
        hf[70]
    );

    // Download names: every file distinct, each sidecar named as the reader
    // looks for it beside its heights (`io::sidecar_path`).
    let file = |r: &http::Response| {
        let d = r.header("content-disposition").unwrap().to_string();
        assert!(d.starts_with("attachment; filename=\""), "{d}");
        d["attachment; filename=\"".len()..d.len() - 1].to_string()
    };
    let mut names = std::collections::BTreeSet::new();
    for f in Format::ALL.iter().filter(|f| f.can_write()) {
        let r = http::get(a, &format!("/api/sessions/{id}/export?format={}", f.name()));
        assert_eq!(r.status, 200, "{f}");
        assert!(names.insert(file(&r)), "{f}: {} downloaded twice", file(&r));
        let sidecar = f.uses_sidecar().then(|| {
            let s = http::get(
                a,
                &format!("/api/sessions/{id}/export?format={}&sidecar=true", f.name()),
            );
            assert_eq!(s.status, 200, "{f} sidecar");
            let want = io::sidecar_path(std::path::Path::new(&file(&r)));
            assert_eq!(std::path::PathBuf::from(file(&s)), want, "{f} sidecar");
            assert!(names.insert(file(&s)), "{f}: {} downloaded twice", file(&s));
            s.body
        });
        let opts = ReadOptions {
            size: Some((N, N)),
            ..ReadOptions::default()
        };
        let back = io::decode(&r.body, *f, sidecar.as_deref(), &opts).unwrap();
        // Every export holds the session's heights, to its format's own
        // precision (exact for exr, tiff, asc and r32; half a 16-bit step
        // of the range for png16 and r16; the Terragen step for ter).
        let (lo, hi) = hf
            .iter()
            .fold((f32::MAX, f32::MIN), |(a, b), &v| (a.min(v), b.max(v)));
        let cell = back.cell_size();
        let want = terrasynth::Heightfield::from_fn(N, N, cell, |x, y| hf[y * N + x]).unwrap();
        common::assert_close(&want, &back, common::precision(*f, lo, hi, cell), f.name());
    }
    let pv = http::get(a, &format!("/api/sessions/{id}/export?format=preview"));
    assert_eq!(&pv.body[..4], b"\x89PNG");
    let e = |q: &str| http::get(a, &format!("/api/sessions/{id}/export{q}"));
    expect_error(&e(""), 400, "format");
    expect_error(&e("?format=jpeg"), 422, "format");
    expect_error(&e("?format=png8"), 422, "format");
    expect_error(&e("?format=exr&sidecar=true"), 422, "sidecar");
    expect_error(&e("?format=exr&size=2"), 400, "size");
}

#[test]
fn pastes_and_new_parameters_start_a_new_session() {
    let s = serve(N, None, 2);
    let a = s.addr;
    let (id, _) = create(a);
    let mut d = doc();
    d["pastes"] = json!([{"source": "exemplar", "exemplar": 1, "lasso": [[10, 10], [40, 12], [30, 40]], "to": [40, 40], "delta_m": 50}]);
    let f = put_scene(a, &id, &d, true).json();
    assert_eq!(f["rebuilt"], Value::Null, "{f}");
    assert!(f["changed"]["pixels"].as_u64().unwrap() > 0);
    // Removing the paste (undo) cannot be an edit of this session: the
    // state kept before it is swapped back (tests/serve/paste_undo.rs).
    let u = http::post(a, &format!("/api/sessions/{id}/undo"), None).json();
    assert_eq!(
        (&u["rebuilt"], &u["restored"]),
        (&Value::Null, &json!(true))
    );
    // A session opened on a paste kept nothing from before it: removing
    // the paste starts a new session.
    let (opened, _) = common::editor::create_with(a, &d);
    let u = put_scene(a, &opened, &doc(), true).json();
    assert_eq!(u["rebuilt"], "a paste was removed or changed");
    let mut bad = d.clone();
    bad["pastes"][0]["exemplar"] = json!(77);
    expect_error(&put_scene(a, &id, &bad, true), 422, "pastes[0].exemplar");
    let mut bigger = doc();
    bigger["size"] = json!([96, 80]);
    let f = put_scene(a, &id, &bigger, true).json();
    assert_eq!(f["rebuilt"], "size changed");
    assert_eq!(f["size"], json!([96, 80]));
    assert_eq!(heights(a, &id).len(), 96 * 80);
}

#[test]
fn save_writes_only_the_scene_file_and_a_restart_reloads_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("design.json");
    let s = serve(N, None, 2);
    let (id, _) = create(s.addr);
    expect_error(
        &http::post(s.addr, &format!("/api/sessions/{id}/save"), None),
        409,
        "$",
    );
    drop(s);

    let s = serve(N, Some(path.clone()), 2);
    let a = s.addr;
    let (id, _) = create(a);
    let mut d = doc();
    d["points"] = json!([{"id": "peak", "at": [20, 20], "height_m": 2500, "radius_px": 6}]);
    d["freeze"] = json!({"strokes": [{"points": [[50, 50]], "radius_px": 5}, {"erase": true, "points": [[50, 50]], "radius_px": 2}]});
    put_scene(a, &id, &d, true);
    let r = http::post(a, &format!("/api/sessions/{id}/save"), None);
    assert_eq!(r.status, 200, "{}", r.json());
    let files: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(files, vec![std::ffi::OsString::from("design.json")]);
    let saved = Scene::read(&path).unwrap();
    assert_eq!(saved.points[0].id, "peak");
    drop(s);

    // A new server on the same file starts from the saved design, and
    // removes what a save killed midway left beside it (not others' files).
    let orphan = dir.path().join(".design.json.99999999.0.tmp");
    let other = dir.path().join(".notes.json.99999999.0.tmp");
    std::fs::write(&orphan, b"{").unwrap();
    std::fs::write(&other, b"{").unwrap();
    let s = serve(N, Some(path.clone()), 2);
    assert!(!orphan.exists() && other.exists());
    let (_, f) = create(s.addr);
    assert_eq!(f["scene"], d);
}

/// Two tabs on one scene file (issue 43): a tab opened after another saved
/// starts from that save, and a tab whose document predates a save cannot
/// overwrite it unless it says so; it can reload the saved file (an undo
/// step) or merge its changes on top of it.
#[test]
fn a_save_from_another_tab_is_never_overwritten_silently() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("design.json");
    let s = serve(N, Some(path.clone()), 3);
    let a = s.addr;
    let (one, _) = create(a);
    let (two, _) = create(a);
    let save = |id: &str, force: bool| {
        let q = if force { "?force=true" } else { "" };
        http::post(a, &format!("/api/sessions/{id}/save{q}"), None)
    };
    let reload = |id: &str, q: &str| http::post(a, &format!("/api/sessions/{id}/reload{q}"), None);
    let point =
        |id: &str, x: u32| json!({"id": id, "at": [x, 20], "height_m": 900, "radius_px": 6});
    let mut ridge = doc();
    ridge["points"] = json!([point("ridge", 20)]);
    put_scene(a, &one, &ridge, true);
    assert_eq!(save(&one, false).status, 200);
    // A tab opened now starts from tab one's save, not the server's start.
    let (three, f) = create(a);
    assert_eq!(f["scene"], ridge);
    // Tab two loaded before that save: its heartbeat says so, its save is
    // refused, the file kept.
    let stale =
        |id: &str| http::post(a, &format!("/api/sessions/{id}/ping"), None).json()["stale"].clone();
    assert_eq!((stale(&one), stale(&two)), (json!(false), json!(true)));
    let mut knoll = doc();
    knoll["points"] = json!([point("knoll", 40)]);
    put_scene(a, &two, &knoll, true);
    let e = expect_error(&save(&two, false), 409, "revision");
    assert!(e.contains("another tab") && e.contains("merge"), "{e}");
    assert_eq!(Scene::read(&path).unwrap().points[0].id, "ridge");
    // Tab one saves again (its own save is its base); tab three, opened
    // from the first save, is now behind and refused too.
    assert_eq!(save(&one, false).status, 200);
    expect_error(&save(&three, false), 409, "revision");
    // Reload: tab three shows the file; undo brings its own back.
    expect_error(&reload(&three, ""), 400, "merge");
    expect_error(&reload(&three, "?merge=perhaps"), 400, "merge");
    expect_error(&reload("nope", "?merge=false"), 404, "id");
    put_scene(a, &three, &doc(), true);
    let r = reload(&three, "?merge=false");
    assert_eq!(r.status, 200, "{}", r.json());
    assert_eq!(r.json()["scene"], ridge);
    assert_eq!(stale(&three), json!(false), "up to date after reloading");
    assert_eq!(save(&three, false).status, 200);
    let u = http::post(a, &format!("/api/sessions/{three}/undo"), None).json();
    assert_eq!(u["scene"], doc());
    // Merge: tab two's knoll on top of the saved ridge; its save then
    // goes through and holds both.
    expect_error(&save(&two, false), 409, "revision");
    let r = reload(&two, "?merge=true");
    assert_eq!(r.status, 200, "{}", r.json());
    assert_eq!(
        r.json()["scene"]["points"],
        json!([point("ridge", 20), point("knoll", 40)])
    );
    assert_eq!(save(&two, false).status, 200);
    let ids: Vec<String> = Scene::read(&path)
        .unwrap()
        .points
        .iter()
        .map(|p| p.id.clone())
        .collect();
    assert_eq!(ids, ["ridge", "knoll"]);
    // Forced, tab one replaces the file, and is then up to date.
    expect_error(&save(&one, false), 409, "revision");
    assert_eq!(save(&one, true).status, 200);
    assert_eq!(Scene::read(&path).unwrap().points.len(), 1);
    assert_eq!(save(&one, false).status, 200);
    expect_error(&save(&two, false), 409, "revision");
}
