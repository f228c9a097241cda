//! Autosave and recovery (`src/server/autosave.rs`): unsaved edits reach
//! `<scene>.autosave.json` without touching the scene file; a server
//! stopped without saving offers them at its next start, and Keep makes
//! them the session's document while Discard deletes them; Save removes
//! the side file; a corrupt side file is named on stderr, left on disk,
//! and the server serves anyway. Last, the banner and its Keep button in
//! headless Chromium (skipped without a browser unless
//! `TERRASYNTH_REQUIRE_BROWSER` is set).
use crate::common::browser::{click, executables, in_chromium, js, settled, wait_for};
use crate::common::editor::{self, N, create, doc, expect_error, put_scene, serve_with};
use crate::common::http;
use serde_json::{Value, json};
use std::ffi::OsStr;
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime};
use terrasynth::server::Running;

/// A server on `scene` that autosaves 300 ms after an edit.
fn serve(scene: &Path) -> Running {
    serve_with(N, Some(scene.to_path_buf()), |c| {
        c.autosave_delay = Duration::from_millis(300)
    })
}

fn side(scene: &Path) -> PathBuf {
    scene.with_file_name(format!(
        "{}.autosave.json",
        scene.file_name().unwrap().to_string_lossy()
    ))
}

/// Waits up to 20 s for `done`.
fn until(what: &str, done: impl Fn() -> bool) {
    let t = Instant::now();
    while !done() {
        assert!(t.elapsed() < Duration::from_secs(20), "timed out: {what}");
        std::thread::sleep(Duration::from_millis(50));
    }
}

fn read_json(p: &Path) -> Value {
    serde_json::from_slice(&std::fs::read(p).unwrap()).unwrap()
}

fn live(a: SocketAddr, id: &str) -> Value {
    http::get(a, &format!("/api/sessions/{id}")).json()["scene"].clone()
}

fn recovery(a: SocketAddr, id: &str, q: &str) -> http::Response {
    http::post(a, &format!("/api/sessions/{id}/recovery{q}"), None)
}

fn with_point(x: u32) -> Value {
    let mut d = doc();
    d["points"] = json!([{"id": "p", "at": [x, 20], "height_m": 2500, "radius_px": 6}]);
    d
}

/// Saves a blank scene, edits it, and stops the server without saving:
/// the edit is left in the side file. Returns the edited document.
fn edit_and_stop(scene: &Path, x: u32) -> Value {
    let s = serve(scene);
    let (id, _) = create(s.addr);
    let r = http::post(s.addr, &format!("/api/sessions/{id}/save"), None);
    assert_eq!(r.status, 200, "{}", r.json());
    let saved = read_json(scene);
    let d = with_point(x);
    assert_eq!(put_scene(s.addr, &id, &d, true).status, 200);
    until("the autosave", || side(scene).exists());
    assert_eq!(read_json(&side(scene)), live(s.addr, &id));
    assert_eq!(read_json(&side(scene)), d);
    // Autosave never writes the scene file.
    assert_eq!(read_json(scene), saved);
    drop(s);
    d
}

#[test]
fn unsaved_work_is_autosaved_and_kept_at_the_next_start() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("design.json");
    let d = edit_and_stop(&scene, 20);

    let s = serve(&scene);
    let a = s.addr;
    let info = http::get(a, "/api/info").json();
    assert_eq!(
        info["recovery"]["path"],
        json!(side(&scene).display().to_string())
    );
    assert!(info["recovery"]["modified_ms"].as_u64().unwrap() > 0);
    let (id, first) = create(a);
    // A new tab starts from the saved scene; the work waits for a decision.
    assert_eq!(first["scene"], doc());
    expect_error(&recovery(a, &id, ""), 400, "keep");
    expect_error(&recovery(a, &id, "?keep=maybe"), 400, "keep");
    expect_error(&recovery(a, "nope", "?keep=true"), 404, "id");
    let r = recovery(a, &id, "?keep=true");
    assert_eq!(r.status, 200, "{}", r.json());
    assert_eq!(r.json()["scene"], d);
    assert_eq!(live(a, &id), d);
    assert_eq!(r.json()["history"]["undo"], 1, "{}", r.json());
    assert!(http::get(a, "/api/info").json()["recovery"].is_null());
    expect_error(&recovery(a, &id, "?keep=true"), 404, "$");

    // Kept means unsaved: Save writes it, and the side file goes.
    let r = http::post(a, &format!("/api/sessions/{id}/save"), None);
    assert_eq!(r.status, 200, "{}", r.json());
    assert_eq!(read_json(&scene), d);
    assert!(!side(&scene).exists());
    std::thread::sleep(Duration::from_millis(800));
    assert!(!side(&scene).exists(), "no autosave of the saved document");
    drop(s);
    let s = serve(&scene);
    assert!(http::get(s.addr, "/api/info").json()["recovery"].is_null());
}

#[test]
fn discarded_work_is_deleted() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("design.json");
    edit_and_stop(&scene, 30);
    let s = serve(&scene);
    let (id, _) = create(s.addr);
    let r = recovery(s.addr, &id, "?keep=false");
    assert_eq!(r.status, 200, "{}", r.json());
    assert!(!side(&scene).exists());
    assert_eq!(live(s.addr, &id), doc());
    assert!(http::get(s.addr, "/api/info").json()["recovery"].is_null());

    // Undoing back to the saved document removes the side file too.
    put_scene(s.addr, &id, &with_point(40), true);
    until("the autosave", || side(&scene).exists());
    assert_eq!(
        http::post(s.addr, &format!("/api/sessions/{id}/undo"), None).status,
        200
    );
    until("the side file to go", || !side(&scene).exists());
}

/// The ids of the points a document holds, in order.
fn point_ids(d: &Value) -> Vec<String> {
    d["points"]
        .as_array()
        .map(|ps| {
            ps.iter()
                .map(|p| p["id"].as_str().unwrap().to_string())
                .collect()
        })
        .unwrap_or_default()
}

/// Every tab's unsaved work is in the side file (issue 43: only the tab
/// edited last was): two tabs each place a point and both are there; one
/// tab saves and the other's point stays there; a tab closed unsaved keeps
/// its work there while another edits; and the next start offers it all.
#[test]
fn every_tab_is_autosaved() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("design.json");
    let s = serve_with(N, Some(scene.clone()), |c| {
        c.autosave_delay = Duration::from_millis(300);
        c.max_sessions = 3;
    });
    let a = s.addr;
    let (one, _) = create(a);
    let (two, _) = create(a);
    let point =
        |id: &str, x: u32| json!({"id": id, "at": [x, 20], "height_m": 900, "radius_px": 5});
    let with = |ps: Value| {
        let mut d = doc();
        d["points"] = ps;
        d
    };
    let side_ids = || {
        std::fs::read(side(&scene))
            .ok()
            .and_then(|b| serde_json::from_slice::<Value>(&b).ok())
            .map(|d| point_ids(&d))
    };
    let holds = |ids: &[&str]| side_ids().is_some_and(|got| got == ids);
    put_scene(a, &one, &with(json!([point("a", 10)])), true);
    put_scene(a, &two, &with(json!([point("b", 40)])), true);
    until("both tabs' points in the side file", || holds(&["a", "b"]));
    // Tab one saves: its point is saved, tab two's is still unsaved.
    let r = http::post(a, &format!("/api/sessions/{one}/save"), None);
    assert_eq!(r.status, 200, "{}", r.json());
    until("tab two's work after tab one's save", || holds(&["a", "b"]));
    // Tab two closes unsaved; tab one moves its point: both still there.
    assert_eq!(
        http::post(a, &format!("/api/sessions/{two}/close"), None).status,
        204
    );
    put_scene(a, &one, &with(json!([point("a", 12)])), true);
    until("the moved point", || {
        read_json(&side(&scene))["points"][0]["at"] == json!([12, 20])
    });
    assert!(holds(&["a", "b"]), "{:?}", side_ids());
    drop(s);
    let s = serve(&scene);
    let (id, _) = create(s.addr);
    let r = recovery(s.addr, &id, "?keep=true");
    assert_eq!(point_ids(&r.json()["scene"]), ["a", "b"]);
}

#[test]
fn a_side_file_older_than_the_scene_is_not_offered() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("design.json");
    edit_and_stop(&scene, 20);
    let f = std::fs::File::options().write(true).open(&scene).unwrap();
    f.set_modified(SystemTime::now() + Duration::from_secs(60))
        .unwrap();
    let s = serve(&scene);
    assert!(http::get(s.addr, "/api/info").json()["recovery"].is_null());
}

/// The binary: a corrupt side file is named on stderr with the parse
/// error, left as it is, and the server still answers.
#[test]
fn a_corrupt_side_file_is_reported_and_left_alone() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("design.json");
    std::fs::write(&scene, doc().to_string()).unwrap();
    std::fs::write(side(&scene), b"{\"version\": 2, \"size\": [").unwrap();
    let f = std::fs::File::options()
        .write(true)
        .open(side(&scene))
        .unwrap();
    f.set_modified(SystemTime::now() + Duration::from_secs(60))
        .unwrap();
    // Its database load starts in the background; it is killed first.
    let server = editor::spawn(
        &[OsStr::new("--scene"), scene.as_os_str()],
        &dir.path().join("cache"),
    );
    let info = http::get(server.addr, "/api/info");
    let said = server.said.clone();
    drop(server);
    assert_eq!(info.status, 200);
    assert!(info.json()["recovery"].is_null());
    let name = side(&scene).display().to_string();
    assert!(
        said.contains(&name) && said.contains("cannot be read") && said.contains("EOF"),
        "{said}"
    );
    assert_eq!(
        std::fs::read(side(&scene)).unwrap(),
        b"{\"version\": 2, \"size\": ["
    );
}

#[test]
fn the_page_offers_the_recovered_work_and_keeps_it() {
    let Some(browser) = executables() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("design.json");
    let d = edit_and_stop(&scene, 20);
    let s = serve(&scene);
    let url = s.url();
    let page = in_chromium(&browser, dir.path(), async |c| {
        c.goto(&url).await.unwrap();
        settled(c, -1).await;
        wait_for(
            c,
            "the recovery banner",
            "return !document.getElementById('recovery').hidden",
            30,
        )
        .await;
        let text = js(c, "return document.getElementById('recovery').innerText").await;
        let rev = js(c, "return window.terrasynth.revision").await;
        click(c, "#recovery-keep").await;
        settled(c, rev.as_i64().unwrap()).await;
        let hidden = js(c, "return document.getElementById('recovery').hidden").await;
        let shown = js(c, "return window.terrasynth.doc").await;
        let session = js(c, "return window.terrasynth.api.session").await;
        let errors = js(c, "return window.__errors").await;
        (text, hidden, shown, session, errors)
    });
    let (text, hidden, shown, session, errors) = page;
    let text = text.as_str().unwrap();
    assert!(
        text.contains("Unsaved work from") && text.contains("Keep it"),
        "{text}"
    );
    assert_eq!(hidden, json!(true));
    assert_eq!(shown, d);
    assert_eq!(live(s.addr, session.as_str().unwrap()), d);
    assert_eq!(errors, json!([]));
}
