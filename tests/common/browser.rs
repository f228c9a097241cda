//! Driving Debian's headless Chromium over WebDriver (chromedriver,
//! through fantoccini) for the editor's browser test and latency bench:
//! starting the driver, real pointer actions at terrain positions, and
//! waiting for the page's frames.
#![allow(dead_code)]

use fantoccini::actions::{InputSource, MouseActions, PointerAction};
use fantoccini::{Client, ClientBuilder, Locator};
use serde_json::{Value, json};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// Where the browser tests put their screenshots (created):
/// `$TERRASYNTH_SCREENSHOTS`, else `target/editor-screenshots/`.
pub fn screenshots() -> PathBuf {
    let dir = std::env::var_os("TERRASYNTH_SCREENSHOTS")
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/editor-screenshots")
        });
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// chromium and chromedriver, or why the caller should skip: a message,
/// or a panic when `TERRASYNTH_REQUIRE_BROWSER` is set.
pub fn executables() -> Option<(PathBuf, PathBuf)> {
    let required = std::env::var_os("TERRASYNTH_REQUIRE_BROWSER").is_some_and(|v| !v.is_empty());
    match (
        find(&["chromium", "chromium-browser"]),
        find(&["chromedriver"]),
    ) {
        (Some(c), Some(d)) => Some((c, d)),
        _ => {
            assert!(
                !required,
                "TERRASYNTH_REQUIRE_BROWSER is set but chromium or chromedriver is missing (apt-get install chromium chromium-driver)"
            );
            eprintln!(
                "skipped: needs chromium and chromedriver (Debian: apt-get install chromium chromium-driver)"
            );
            None
        }
    }
}

/// Where the browser of [`connect`]`(…, dir)` saves downloads.
pub fn downloads(dir: &Path) -> PathBuf {
    dir.join("downloads")
}

/// A WebDriver session in a fresh headless Chromium profile under `dir`;
/// downloads go to [`downloads`]`(dir)` without asking, several per page
/// included (an export with a sidecar is two).
pub async fn connect(driver: &Driver, chromium: &Path, dir: &Path) -> Client {
    let caps = json!({
        "goog:chromeOptions": {
            "prefs": {
                "download.default_directory": downloads(dir),
                "download.prompt_for_download": false,
                "profile.default_content_setting_values.automatic_downloads": 1,
            },
            "binary": chromium,
            "args": [
                "--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                "--disable-background-networking", "--disable-component-update",
                "--disable-sync", "--no-first-run", "--window-size=1400,900",
                format!("--user-data-dir={}", dir.join("chromium-profile").display()),
            ],
        }
    });
    ClientBuilder::new(hyper_util::client::legacy::connect::HttpConnector::new())
        .capabilities(caps.as_object().expect("an object").clone())
        .connect(&format!("http://127.0.0.1:{}", driver.port))
        .await
        .expect("a WebDriver session")
}

fn find(names: &[&str]) -> Option<PathBuf> {
    let path = std::env::var_os("PATH").unwrap_or_default();
    for dir in std::env::split_paths(&path).chain([PathBuf::from("/usr/bin")]) {
        for n in names {
            let p = dir.join(n);
            if p.is_file() {
                return Some(p);
            }
        }
    }
    None
}

/// chromedriver, stopped (by its own id) when dropped.
pub struct Driver {
    child: Child,
    port: u16,
}

impl Drop for Driver {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

pub fn start_driver(exe: &Path) -> Driver {
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let child = Command::new(exe)
        .arg(format!("--port={port}"))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("chromedriver starts");
    let d = Driver { child, port };
    let t = Instant::now();
    while std::net::TcpStream::connect(("127.0.0.1", port)).is_err() {
        assert!(
            t.elapsed() < Duration::from_secs(20),
            "chromedriver did not listen"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    d
}

/// Runs `scenario` in a fresh headless Chromium (its profile under
/// `dir`), closing the browser even when a step fails (chromedriver alone
/// would leave it running).
pub fn in_chromium<T>(
    (chromium, driver): &(PathBuf, PathBuf),
    dir: &Path,
    scenario: impl AsyncFnOnce(&Client) -> T,
) -> T {
    let wd = start_driver(driver);
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap();
    let c = rt.block_on(connect(&wd, chromium, dir));
    let outcome =
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| rt.block_on(scenario(&c))));
    let _ = rt.block_on(c.close());
    drop(wd);
    outcome.unwrap_or_else(|p| std::panic::resume_unwind(p))
}

pub async fn js(c: &Client, script: &str) -> Value {
    c.execute(script, vec![])
        .await
        .unwrap_or_else(|e| panic!("{script}: {e}"))
}

pub async fn wait_for(c: &Client, what: &str, script: &str, secs: u64) {
    let t = Instant::now();
    loop {
        if js(c, script).await == json!(true) {
            return;
        }
        if t.elapsed() > Duration::from_secs(secs) {
            let status = js(c, "return document.getElementById('status')?.innerText").await;
            panic!("timed out waiting for {what}; status line: {status}");
        }
        tokio::time::sleep(Duration::from_millis(40)).await;
    }
}

/// Waits for a frame newer than `rev` with nothing in flight, and for the
/// page's height samples (cursor readout, cross-sections) to be that
/// frame's.
pub async fn settled(c: &Client, rev: i64) {
    let script = format!(
        "const ed = window.terrasynth; return !!ed && ed.revision > {rev} && !ed.api.busy() && !!ed.heights && ed.heights.revision >= ed.revision"
    );
    wait_for(c, &format!("a frame after revision {rev}"), &script, 90).await;
}

pub async fn revision(c: &Client) -> i64 {
    js(c, "return window.terrasynth.revision")
        .await
        .as_i64()
        .unwrap()
}

/// Viewport coordinates of a terrain position.
pub async fn screen(c: &Client, p: (f64, f64)) -> (f64, f64) {
    let v = js(
        c,
        &format!(
            "const q = window.terrasynth.map.toScreen([{}, {}]); const r = document.getElementById('map').getBoundingClientRect(); return [q[0] + r.left, q[1] + r.top];",
            p.0, p.1
        ),
    )
    .await;
    (v[0].as_f64().unwrap(), v[1].as_f64().unwrap())
}

/// A left-button drag through terrain positions (a click when only one).
pub async fn drag(c: &Client, pts: &[(f64, f64)]) {
    let mut at = Vec::with_capacity(pts.len());
    for p in pts {
        at.push(screen(c, *p).await);
    }
    drag_screen(c, &at).await;
}

/// A left-button drag through viewport positions (a click when only one).
pub async fn drag_screen(c: &Client, pts: &[(f64, f64)]) {
    let mut m = MouseActions::new("mouse".into());
    let first = pts[0];
    m = m
        .then(PointerAction::MoveTo {
            duration: None,
            x: first.0.round(),
            y: first.1.round(),
        })
        .then(PointerAction::Down { button: 0 });
    for &q in &pts[1..] {
        m = m.then(PointerAction::MoveTo {
            duration: Some(Duration::from_millis(60)),
            x: q.0.round(),
            y: q.1.round(),
        });
    }
    m = m.then(PointerAction::Up { button: 0 });
    c.perform_actions(m).await.expect("pointer actions");
}

pub async fn click(c: &Client, css: &str) {
    c.find(Locator::Css(css))
        .await
        .unwrap_or_else(|e| panic!("{css}: {e}"))
        .click()
        .await
        .unwrap_or_else(|e| panic!("click {css}: {e}"));
}

pub async fn shot(c: &Client, dir: &Path, name: &str) {
    let png = c.screenshot().await.expect("screenshot");
    std::fs::write(dir.join(format!("{name}.png")), png).unwrap();
}
