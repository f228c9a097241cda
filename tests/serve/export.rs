//! Every export the editor page offers, downloaded by a real browser
//! (headless Chromium over WebDriver): each format of the Export menu and
//! the preview. Each download must land under its own name (issue 43:
//! the png16, r16 and r32 sidecars all came down as `<scene>-terrain.json`
//! and overwrote each other, losing the 16-bit scale), each sidecar must
//! sit where the reader looks for it beside its heights, and each file,
//! read back through `terrasynth::io` with its sidecar, must hold the
//! session's heights to its format's precision.
//!
//! Skipped without chromium and chromedriver unless
//! `TERRASYNTH_REQUIRE_BROWSER` is set.
use crate::common;
use crate::common::browser::{click, downloads, executables, in_chromium, js, settled};
use crate::common::editor::{self, heights};
use fantoccini::{Client, Locator};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use terrasynth::io::{self, Format, ReadOptions};

const SIZE: usize = 64;

/// The finished downloads in `dir` (Chromium writes `*.crdownload` until
/// a file is complete).
fn finished(dir: &Path) -> BTreeSet<PathBuf> {
    std::fs::read_dir(dir)
        .map(|d| d.map(|e| e.unwrap().path()).collect())
        .unwrap_or_default()
}

/// Clicks `button` and waits until `count` new files have finished
/// downloading and nothing is still coming; the new files.
async fn download(c: &Client, dir: &Path, button: &str, count: usize) -> Vec<PathBuf> {
    let before = finished(dir);
    click(c, button).await;
    let t = Instant::now();
    loop {
        let now = finished(dir);
        let new: Vec<PathBuf> = now.difference(&before).cloned().collect();
        let partial = new
            .iter()
            .any(|p| p.extension().is_some_and(|e| e == "crdownload"));
        if new.len() >= count && !partial {
            // A second file of the same click may still be on its way.
            tokio::time::sleep(Duration::from_millis(600)).await;
            let again: Vec<PathBuf> = finished(dir).difference(&before).cloned().collect();
            if again == new {
                return new;
            }
            continue;
        }
        assert!(
            t.elapsed() < Duration::from_secs(30),
            "{button}: downloads so far {new:?}, {count} expected"
        );
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

#[test]
fn every_export_downloads_with_its_own_sidecar() {
    let Some(browser) = executables() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("design.json");
    let server = editor::serve(SIZE, Some(scene), 2);
    let saved = downloads(dir.path());
    let (session, files) = in_chromium(&browser, dir.path(), async |c| {
        c.goto(&server.url()).await.unwrap();
        settled(c, -1).await;
        let offered = js(
            c,
            "return [...document.getElementById('export-format').options].map(o => o.value)",
        )
        .await;
        let mut files = Vec::new();
        for name in offered.as_array().unwrap() {
            let name = name.as_str().unwrap();
            let f = Format::from_name(name).unwrap_or_else(|| panic!("{name} is no format"));
            c.find(Locator::Css("#export-format"))
                .await
                .unwrap()
                .select_by_value(name)
                .await
                .unwrap();
            let count = 1 + f.uses_sidecar() as usize;
            files.push((Some(f), download(c, &saved, "#export", count).await));
        }
        files.push((None, download(c, &saved, "#export-preview", 1).await));
        assert_eq!(js(c, "return window.__errors").await, serde_json::json!([]));
        let session = js(c, "return window.terrasynth.api.session").await;
        (session.as_str().unwrap().to_string(), files)
    });
    let writable: BTreeSet<&str> = common::writable().iter().map(|f| f.name()).collect();
    let offered: BTreeSet<&str> = files
        .iter()
        .filter_map(|(f, _)| f.map(|f| f.name()))
        .collect();
    assert_eq!(offered, writable, "the menu offers every writable format");

    let hf = heights(server.addr, &session);
    let (lo, hi) = hf
        .iter()
        .fold((f32::MAX, f32::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    let mut names = BTreeSet::new();
    for (f, new) in &files {
        for p in new {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            // Chromium renames a download whose name is taken ("x (1).json").
            assert!(names.insert(name.clone()), "{name} downloaded twice");
            assert!(name.starts_with("design-"), "{name}: named after the scene");
        }
        let Some(f) = f else {
            assert_eq!(&std::fs::read(&new[0]).unwrap()[..4], b"\x89PNG");
            continue;
        };
        let (data, sidecars): (Vec<&PathBuf>, Vec<&PathBuf>) = new
            .iter()
            .partition(|p| !f.uses_sidecar() || p.extension().is_none_or(|e| e != "json"));
        assert_eq!(data.len(), 1, "{f}: {new:?}");
        let data = data[0];
        if f.uses_sidecar() {
            assert_eq!(
                sidecars,
                [&io::sidecar_path(data)],
                "{f}: the sidecar beside its heights"
            );
        }
        let opts = ReadOptions {
            size: Some((SIZE, SIZE)),
            ..ReadOptions::default()
        };
        let back = io::read(data, &opts).unwrap_or_else(|e| panic!("{f}: {e}"));
        let cell = back.cell_size();
        let want =
            terrasynth::Heightfield::from_fn(SIZE, SIZE, cell, |x, y| hf[y * SIZE + x]).unwrap();
        common::assert_close(&want, &back, common::precision(*f, lo, hi, cell), f.name());
        eprintln!(
            "{f}: {}",
            new.iter()
                .map(|p| p.file_name().unwrap().to_string_lossy())
                .collect::<Vec<_>>()
                .join(" + ")
        );
    }
    server.stop();
}
