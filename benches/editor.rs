//! Editor latency (`cargo bench --bench editor`): edit → updated preview,
//! per edit kind, at 512² and 1024² (or `TERRASYNTH_EDITOR_SIZES=256,512`),
//! measured twice for the same frames: on the server (the frame's own
//! `timing_ms`: document diff and curve fields, synthesis, preview tile)
//! and in headless Chromium (from the page handing the document to its
//! sender to the changed tile drawn on the map).
//!
//! Each edit is made through the page's own edit path (`terrasynth.change`,
//! the function the tools call), one at a time (the page idle in between,
//! so nothing is coalesced), and repeated; the table gives medians. It is
//! printed and written to `target/editor-latency.md`. Without Chromium the
//! bench says so and measures nothing. The last three kinds come last as
//! they add curves: one with 7 widgets (changing its last widget's height
//! moves only the end of its profile, so only that is re-synthesized),
//! long new ones and short new ones (a new shape: its field and envelope
//! are computed).

#[path = "../tests/common/browser.rs"]
mod browser;

use browser::{connect, executables, js, start_driver, wait_for};
use serde_json::Value;
use std::fmt::Write;
use std::net::SocketAddr;
use terrasynth::database::default;
use terrasynth::progress::Silent;
use terrasynth::server::{self, Config, DbSource};

const REPS: usize = 7;

/// Each edit kind: setup (once, not measured) and the measured edit as
/// JavaScript over `ed` (the page) and `k` (the repetition); `S` is the size.
const KINDS: &[(&str, &str)] = &[
    (
        "point (move 20 px)",
        "ed.change(d => { d.points[0].at[0] = S * 0.3 + (k % 2) * 20; }, {kind: 'point'});",
    ),
    (
        "curve widget (height ±100 m)",
        "ed.change(d => { d.curves[0].widgets[0].height_m += (k % 2 ? 100 : -100); }, {kind: 'curve-widget'});",
    ),
    (
        "curve re-sketch (shift 8 px)",
        "ed.change(d => { d.curves[0].points = d.curves[0].points.map(p => [p[0], p[1] + (k % 2 ? 8 : -8)]); }, {kind: 'curve-sketch'});",
    ),
    (
        "type paint (a stroke)",
        "ed.change(d => { d.types.strokes.push({type: ed.info.database.types[k % 3].name, points: [[S*0.1 + k*S*0.1, S*0.8], [S*0.15 + k*S*0.1, S*0.85]], radius_px: S*0.03}); }, {kind: 'type'});",
    ),
    (
        "freeze (a stroke)",
        "ed.change(d => { d.freeze.strokes.push({points: [[S*0.1 + k*S*0.1, S*0.2]], radius_px: S*0.03}); }, {kind: 'freeze'});",
    ),
    (
        "paste (terrain lasso)",
        "ed.change(d => { const x = S*0.1 + k*S*0.1; d.pastes.push({source: 'terrain', lasso: [[x, S*0.4], [x + S*0.06, S*0.4], [x + S*0.03, S*0.46]], to: [x + S*0.05, S*0.55], delta_m: 30}); }, {kind: 'paste'});",
    ),
    (
        "undo (of a point move)",
        "await ed.api.idle(); ed.change(d => { d.points[0].at[1] = S * 0.3 + (k % 2) * 20; }, {kind: 'setup'}); await ed.api.idle(); await ed.undo();",
    ),
    (
        "undo (of a paste)",
        "await ed.api.idle(); ed.change(d => { const x = S*0.1 + k*S*0.1; d.pastes.push({source: 'terrain', lasso: [[x, S*0.7], [x + S*0.06, S*0.7], [x + S*0.03, S*0.76]], to: [x + S*0.05, S*0.85], delta_m: 30}); }, {kind: 'setup'}); await ed.api.idle(); await ed.undo();",
    ),
    (
        "redo (of a paste)",
        "await ed.api.idle(); ed.change(d => { const x = S*0.15 + k*S*0.1; d.pastes.push({source: 'terrain', lasso: [[x, S*0.7], [x + S*0.06, S*0.7], [x + S*0.03, S*0.76]], to: [x + S*0.05, S*0.85], delta_m: 30}); }, {kind: 'setup'}); await ed.api.idle(); await ed.undo(); await ed.api.idle(); await ed.redo();",
    ),
    (
        "delete a paste (the earlier of two)",
        "await ed.api.idle(); ed.change(d => { const x = S*0.1 + k*S*0.1; for (const y of [0.3, 0.45]) d.pastes.push({source: 'terrain', lasso: [[x, S*y], [x + S*0.06, S*y], [x + S*0.03, S*(y + 0.06)]], to: [x + S*0.05, S*(y + 0.1)], delta_m: 30}); }, {kind: 'setup'}); await ed.api.idle(); ed.change(d => { d.pastes.splice(d.pastes.length - 2, 1); }, {kind: 'paste'});",
    ),
    (
        "curve widget, last of 7 (height ±100 m)",
        "if (k == 0) { await ed.api.idle(); ed.change(d => { const r = ed.range(); d.curves.push({id: 'm', points: [[S*0.1, S*0.93], [S*0.5, S*0.96], [S*0.9, S*0.92]], smoothing: 2, widgets: [0, 1, 2, 3, 4, 5, 6].map(i => ({at: i / 6, height_m: r.lo + (0.3 + 0.05 * i) * (r.hi - r.lo), slope_deg: [-20, -20], reach_px: [S*0.03, S*0.03]}))}); }, {kind: 'setup'}); await ed.api.idle(); } ed.change(d => { d.curves.find(c => c.id == 'm').widgets[6].height_m += (k % 2 ? 100 : -100); }, {kind: 'curve-widget'});",
    ),
    (
        "sketch a new long curve (~80 % of the side)",
        "ed.change(d => { const r = ed.range(); const y = S*(0.12 + 0.05*k); d.curves.push({id: 'l' + k, points: [[S*0.1, y], [S*0.5, y + S*0.04], [S*0.9, y - S*0.02]], smoothing: 2, widgets: [{at: 0.5, height_m: (r.lo + r.hi) / 2, slope_deg: [-20, -20], reach_px: [S*0.03, S*0.03]}]}); }, {kind: 'curve-sketch'});",
    ),
    (
        "sketch a new curve (~100 px)",
        "ed.change(d => { const r = ed.range(); const x = S*(0.1 + 0.1*k); d.curves.push({id: 'n' + k, points: [[x, S*0.05], [x + S*0.05, S*0.1], [x + S*0.1, S*0.08]], smoothing: 2, widgets: [{at: 0.5, height_m: (r.lo + r.hi) / 2, slope_deg: [-20, -20], reach_px: [S*0.03, S*0.03]}]}); }, {kind: 'curve-sketch'});",
    ),
];

const SETUP: &str = "ed.change(d => {
  d.points = [{id: 'p', at: [S*0.3, S*0.3], height_m: (ed.range().lo + ed.range().hi) / 2, radius_px: S*0.06}];
  d.curves = [{id: 'c', points: [[S*0.1, S*0.6], [S*0.5, S*0.66], [S*0.9, S*0.62]], smoothing: 2,
    widgets: [{at: 0.5, height_m: ed.range().hi - 0.1 * (ed.range().hi - ed.range().lo), slope_deg: [-25, -25], reach_px: [S*0.05, S*0.05]}]}];
  d.types = {strokes: [{type: ed.info.database.types[0].name, points: [[S*0.05, S*0.95]], radius_px: 2}]};
  d.freeze = {strokes: [{points: [[S*0.95, S*0.05]], radius_px: 2}]};
  d.pastes = [];
}, {kind: 'setup'});";

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    // `cargo bench` passes --bench; `cargo test --benches` runs nothing here.
    if !std::env::args().any(|a| a == "--bench") {
        return;
    }
    let Some((chromium, driver)) = executables() else {
        return;
    };
    let sizes: Vec<usize> = std::env::var("TERRASYNTH_EDITOR_SIZES")
        .unwrap_or_else(|_| "512,1024".into())
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    let db: &'static _ = Box::leak(Box::new(
        default::load_or_build(&default::cache_dir(), &Silent)
            .expect("the default database")
            .0,
    ));
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let mut table = format!(
        "Editor latency, medians of {REPS} edits (load average before: {})\n\n| edit | size | server: edits + fields | synthesis | preview tile | server total | in Chromium: edit → preview |\n|---|---|---|---|---|---|---|\n",
        load.split_whitespace()
            .take(3)
            .collect::<Vec<_>>()
            .join(" ")
    );
    let dir = tempfile::tempdir().unwrap();
    let wd = start_driver(&driver);
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap();
    for &size in &sizes {
        let running = server::start(Config {
            bind: SocketAddr::from(([127, 0, 0, 1], 0)),
            database: Some(DbSource::Loaded(db)),
            size: (size, size),
            ..Config::default()
        })
        .expect("the server starts");
        running.wait_ready().expect("the database loads");
        rt.block_on(async {
            let c = connect(&wd, &chromium, dir.path()).await;
            c.goto(&running.url()).await.unwrap();
            wait_for(&c, "the first frame", "return !!window.terrasynth && !window.terrasynth.api.busy()", 300).await;
            let run = |body: String| {
                let c = &c;
                async move {
                    let script = format!(
                        "const done = arguments[0]; (async () => {{ const ed = window.terrasynth; const S = {size}; {body} await ed.api.idle(); done(true); }})().catch(e => done(String(e)));"
                    );
                    let r = c.execute_async(&script, vec![]).await.expect("the edit runs");
                    assert_eq!(r, Value::Bool(true), "{body}");
                }
            };
            run(SETUP.into()).await;
            for (name, edit) in KINDS {
                let mut rows: Vec<Value> = Vec::new();
                for k in 0..=REPS {
                    let before = js(&c, "return window.terrasynth.latency.length").await.as_u64().unwrap();
                    run(format!("const k = {k}; {edit}")).await;
                    let all = js(&c, "return window.terrasynth.latency").await;
                    let last = all.as_array().unwrap()[before as usize..]
                        .iter()
                        .rfind(|e| e["kind"] != "setup")
                        .cloned()
                        .expect("a measured frame");
                    // The first of each kind warms caches up.
                    if k > 0 {
                        rows.push(last);
                    }
                }
                let m = |key: &str| median(rows.iter().map(|r| r[key].as_f64().unwrap_or(0.0)).collect());
                let line = format!(
                    "| {name} | {size}² | {:.1} ms | {:.1} ms | {:.1} ms | {:.1} ms | {:.1} ms |\n",
                    m("edits_ms"),
                    m("synth_ms"),
                    m("render_ms"),
                    m("server_ms"),
                    m("ms")
                );
                eprint!("{line}");
                table.push_str(&line);
            }
            c.close().await.unwrap();
        });
        running.stop();
    }
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let _ = writeln!(
        table,
        "\n(load average after: {})",
        load.split_whitespace()
            .take(3)
            .collect::<Vec<_>>()
            .join(" ")
    );
    println!("{table}");
    let out = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/editor-latency.md");
    std::fs::write(&out, &table).unwrap();
    eprintln!("wrote {}", out.display());
}
