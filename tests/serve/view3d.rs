//! The editor's 3D view (web/js/view3d.js) in headless Chromium, whose
//! WebGL is software (SwiftShader): on a generated terrain, toggled from
//! the map, it must draw relief — a canvas of many colours with real
//! contrast, and clearly unlike the same camera at exaggeration 0 (a flat
//! mesh) — so a blank canvas, an unbound texture or a mesh without heights
//! fails. It must follow edits: a point placed on the map and an undo made
//! in 3D each bring that frame's heights and preview into the view, and
//! a browser without WebGL gets a message in the view, not an exception.
//! Screenshots go to `target/editor-screenshots/` (or
//! `$TERRASYNTH_SCREENSHOTS`).
//!
//! Without chromium and chromedriver the test says so and passes, unless
//! `TERRASYNTH_REQUIRE_BROWSER` is set.
use crate::common;
use crate::common::browser::{
    click, drag, executables, in_chromium, js, revision, screenshots, settled, wait_for,
};
use crate::common::editor;
use fantoccini::actions::{InputSource, KeyAction, KeyActions};
use fantoccini::{Client, Locator};
use image::RgbImage;
use serde_json::json;
use std::path::Path;
use std::time::Instant;

/// Waits until the 3D view has drawn, after draw number `after`, the
/// heights and the preview of revision `rev` or newer, and that draw is on
/// screen; the number of that draw.
async fn drawn(c: &Client, after: i64, rev: i64) -> i64 {
    let script = format!(
        "const d = document.querySelector('#view3d canvas').dataset;
         return Number(d.draws || 0) > {after} && Number(d.heightsRevision) >= {rev} && Number(d.imageRevision) >= {rev}"
    );
    wait_for(c, &format!("a 3D draw of revision {rev}"), &script, 60).await;
    // Two animation frames: the draw has reached the compositor.
    c.execute_async(
        "const done = arguments[0]; requestAnimationFrame(() => requestAnimationFrame(() => done(true)));",
        vec![],
    )
    .await
    .expect("animation frames");
    draws(c).await
}

async fn draws(c: &Client) -> i64 {
    js(
        c,
        "return Number(document.querySelector('#view3d canvas').dataset.draws || 0)",
    )
    .await
    .as_i64()
    .unwrap()
}

/// The 3D canvas as the page shows it (WebDriver's element screenshot).
async fn canvas(c: &Client, dir: &Path, name: &str) -> RgbImage {
    let el = c.find(Locator::Css("#view3d canvas")).await.unwrap();
    let png = el.screenshot().await.expect("a screenshot of the 3D view");
    std::fs::write(dir.join(format!("{name}.png")), &png).unwrap();
    image::load_from_memory(&png).unwrap().to_rgb8()
}

/// Distinct colours and the standard deviation of luminance (0–255).
fn contrast(img: &RgbImage) -> (usize, f64) {
    let mut colours = std::collections::HashSet::new();
    let (mut s, mut s2) = (0.0, 0.0);
    for p in img.pixels() {
        colours.insert(p.0);
        let y = 0.299 * p[0] as f64 + 0.587 * p[1] as f64 + 0.114 * p[2] as f64;
        s += y;
        s2 += y * y;
    }
    let n = (img.width() * img.height()) as f64;
    (colours.len(), (s2 / n - (s / n).powi(2)).max(0.0).sqrt())
}

/// The share of the terrain's pixels (those not the background in either
/// image) whose colour differs by more than 24 in a channel.
fn differing(a: &RgbImage, b: &RgbImage) -> f64 {
    assert_eq!(a.dimensions(), b.dimensions());
    let background = a.get_pixel(0, 0).0;
    let (mut n, mut terrain) = (0, 0);
    for (p, q) in a.pixels().zip(b.pixels()) {
        if p.0 == background && q.0 == background {
            continue;
        }
        terrain += 1;
        n += (0..3).any(|k| p[k].abs_diff(q[k]) > 24) as usize;
    }
    n as f64 / terrain.max(1) as f64
}

async fn key(c: &Client, k: char) {
    let keys = KeyActions::new("keyboard".into())
        .then(KeyAction::Down { value: k })
        .then(KeyAction::Up { value: k });
    c.perform_actions(keys).await.expect("key actions");
}

async fn shown(c: &Client) -> bool {
    js(c, "return !document.getElementById('view3d').hidden")
        .await
        .as_bool()
        .unwrap()
}

#[test]
fn the_3d_view_draws_relief_and_follows_edits() {
    let Some(browser) = executables() else {
        return;
    };
    let started = Instant::now();
    let dir = tempfile::tempdir().unwrap();
    let server = editor::serve(256, None, 2);
    let shots = screenshots();
    in_chromium(&browser, dir.path(), async |c| {
        c.goto(&server.url()).await.unwrap();
        settled(c, -1).await;
        let rev = revision(c).await;

        // The button shows the 3D view in the map's place.
        click(c, "#toggle-3d").await;
        assert!(shown(c).await, "the 3D button shows the 3D view");
        let n = drawn(c, 0, rev).await;
        let message = js(c, "const m = document.querySelector('#view3d .message'); return m.hidden ? null : m.textContent").await;
        assert_eq!(
            message,
            json!(null),
            "the 3D view could not draw (headless Chromium's WebGL is SwiftShader; newer versions may need --enable-unsafe-swiftshader)"
        );
        let relief = canvas(c, &shots, "view3d-relief").await;
        common::browser::shot(c, &shots, "view3d-page").await;
        let (colours, std) = contrast(&relief);
        eprintln!("3D view: {colours} colours, luminance std {std:.1}");
        assert!(
            colours > 2000 && std > 25.0,
            "the 3D view looks blank: {colours} colours, luminance std {std:.1}"
        );

        // The same camera with no exaggeration: a flat mesh, which must look
        // clearly different (the heights move the surface on screen).
        js(
            c,
            "const s = document.getElementById('exaggeration'); s.value = '0'; s.dispatchEvent(new Event('input'));",
        )
        .await;
        let n = drawn(c, n, rev).await;
        let flat = canvas(c, &shots, "view3d-flat").await;
        let d = differing(&relief, &flat);
        eprintln!(
            "3D view at 1× vs 0×: {:.1}% of the terrain's pixels differ",
            100.0 * d
        );
        assert!(
            d > 0.15,
            "the 3D view at 1× is nearly the flat one: {:.1}% of the terrain's pixels differ",
            100.0 * d
        );
        js(
            c,
            "const s = document.getElementById('exaggeration'); s.value = '1'; s.dispatchEvent(new Event('input'));",
        )
        .await;
        drawn(c, n, rev).await;

        // A tool brings the map back; a point placed there reaches the 3D
        // view (toggled with its key) with its frame's heights and preview.
        click(c, "[data-tool=point]").await;
        assert!(!shown(c).await, "picking a tool goes back to the map");
        drag(c, &[(128.0, 128.0)]).await;
        settled(c, rev).await;
        let rev = revision(c).await;
        let n = draws(c).await;
        key(c, '3').await;
        assert!(shown(c).await, "the 3 key shows the 3D view");
        let n = drawn(c, n, rev).await;

        // An undo made while the 3D view shows redraws it.
        click(c, "#undo").await;
        settled(c, rev).await;
        let rev = revision(c).await;
        drawn(c, n, rev).await;
        assert!(shown(c).await, "undo keeps the 3D view");
        let errors = js(c, "return window.__errors || []").await;
        assert_eq!(errors, json!([]), "the page logged errors");

        // A browser without WebGL: the view says so, and nothing throws.
        c.refresh().await.unwrap();
        settled(c, -1).await;
        js(
            c,
            "const get = HTMLCanvasElement.prototype.getContext;
             HTMLCanvasElement.prototype.getContext = function (kind, ...rest) {
               return kind.startsWith('webgl') ? null : get.call(this, kind, ...rest);
             };",
        )
        .await;
        key(c, '3').await;
        let message = js(c, "const m = document.querySelector('#view3d .message'); return m.hidden ? null : m.textContent").await;
        assert!(
            message.as_str().is_some_and(|m| m.contains("WebGL")),
            "without WebGL the 3D view says so: {message}"
        );
        let errors = js(c, "return window.__errors || []").await;
        assert_eq!(errors, json!([]), "the page logged errors without WebGL");
    });
    eprintln!(
        "the 3D view test took {:.1} s",
        started.elapsed().as_secs_f64()
    );
}
