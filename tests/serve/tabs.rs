//! Two tabs on one scene file in headless Chromium (issue 43, "never lose
//! work"): tab A saves a point; tab B, opened before that save, is told
//! by its heartbeat, places another point and saves. B's save is refused
//! and B is told (a banner naming the other tab's save), the file keeps
//! A's work; B's "Merge and save" writes both. Then A, now the stale one, is refused in turn, and its
//! "Reload saved" shows the file's version, after which A saves cleanly.
//!
//! Skipped without chromium and chromedriver unless
//! `TERRASYNTH_REQUIRE_BROWSER` is set.
use crate::common::browser::{
    click, drag, executables, in_chromium, js, revision, settled, wait_for,
};
use crate::common::editor;
use fantoccini::Client;
use fantoccini::wd::WindowHandle;
use std::path::Path;
use terrasynth::scene::Scene;

const SIZE: usize = 128;

/// The points of the scene file, as (id, x, y).
fn saved_points(file: &Path) -> Vec<(String, f64, f64)> {
    let scene = Scene::read(file).unwrap();
    scene
        .points
        .iter()
        .map(|p| (p.id.clone(), p.at.x.round(), p.at.y.round()))
        .collect()
}

/// Places a point at `at` in the current tab and waits for its frame.
async fn place(c: &Client, at: (f64, f64)) {
    click(c, "[data-tool=point]").await;
    let rev = revision(c).await;
    drag(c, &[at]).await;
    settled(c, rev).await;
}

/// Clicks `button` and waits until the page either saved or was refused
/// (the conflict banner); true when saved.
async fn saved_after(c: &Client, button: &str) -> bool {
    js(c, "document.getElementById('status-main').textContent = ''; document.body.dataset.conflict = ''").await;
    click(c, button).await;
    wait_for(
        c,
        "the save's answer",
        "return document.getElementById('status-main').textContent.startsWith('saved ') || document.body.dataset.conflict === 'open'",
        30,
    )
    .await;
    js(c, "return document.body.dataset.conflict !== 'open'").await == serde_json::json!(true)
}

async fn to(c: &Client, tab: &WindowHandle) {
    c.switch_to_window(tab.clone()).await.unwrap();
}

#[test]
fn a_stale_save_is_told_and_reload_and_merge_work() {
    let Some(browser) = executables() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("design.json");
    let server = editor::serve(SIZE, Some(file.clone()), 3);
    in_chromium(&browser, dir.path(), async |c| {
        c.goto(&server.url()).await.unwrap();
        settled(c, -1).await;
        let a = c.window().await.unwrap();
        let b = c.new_window(true).await.unwrap().handle;
        to(c, &b).await;
        c.goto(&server.url()).await.unwrap();
        settled(c, -1).await;

        to(c, &a).await;
        place(c, (30.0, 30.0)).await;
        assert!(saved_after(c, "#save").await, "A's first save");
        assert_eq!(saved_points(&file), [("point-1".into(), 30.0, 30.0)]);

        // B loaded before A's save: the heartbeat tells it before it
        // saves, and its save is refused and it is told again.
        to(c, &b).await;
        wait_for(
            c,
            "B told of A's save",
            "return document.body.dataset.conflict === 'open'",
            20,
        )
        .await;
        place(c, (90.0, 90.0)).await;
        assert!(
            !saved_after(c, "#save").await,
            "B's stale save went through"
        );
        let told = js(
            c,
            "return document.getElementById('conflict-text').textContent",
        )
        .await;
        assert!(told.as_str().unwrap().contains("another tab"), "{told}");
        assert_eq!(
            saved_points(&file),
            [("point-1".into(), 30.0, 30.0)],
            "no lost save"
        );
        // Merge: B's point on top of A's (both were named point-1 in their tab).
        assert!(
            saved_after(c, "#conflict-merge").await,
            "B's merge and save"
        );
        let both = vec![
            ("point-1".into(), 30.0, 30.0),
            ("point-1-2".into(), 90.0, 90.0),
        ];
        assert_eq!(saved_points(&file), both);
        assert_eq!(js(c, "return window.terrasynth.doc.points.length").await, 2);
        assert_eq!(js(c, "return window.__errors").await, serde_json::json!([]));

        // A is now the stale one: refused; Reload shows the file's version.
        to(c, &a).await;
        wait_for(
            c,
            "A told of B's save",
            "return document.body.dataset.conflict === 'open'",
            20,
        )
        .await;
        place(c, (20.0, 110.0)).await;
        assert!(
            !saved_after(c, "#save").await,
            "A's stale save went through"
        );
        assert_eq!(saved_points(&file), both, "no lost save");
        let rev = revision(c).await;
        click(c, "#conflict-reload").await;
        settled(c, rev).await;
        let shown = js(c, "return window.terrasynth.doc.points.map(p => p.id)").await;
        assert_eq!(shown, serde_json::json!(["point-1", "point-1-2"]));
        assert!(saved_after(c, "#save").await, "A's save after reloading");
        assert_eq!(saved_points(&file), both);
        assert_eq!(js(c, "return window.__errors").await, serde_json::json!([]));
    });
    server.stop();
}
