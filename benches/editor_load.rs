//! The editor under load (`cargo bench --bench editor_load`): several
//! clients, each with its own 1024² session on one server, move a point
//! (the same one in each session) back and forth as fast as the server answers, for a while; the table
//! gives the latency of a point move over all of them (median, p90, max)
//! and how long opening a session took while the others were editing.
//!
//! Clients are plain HTTP over 127.0.0.1 (the page's own requests: `POST
//! /api/sessions`, then `PUT /api/sessions/{id}/scene?commit=true`, which
//! answers once the frame is made), so the figures are the server's,
//! queueing included; Chromium's drawing adds ~15 ms (`benches/editor.rs`).
//! `TERRASYNTH_EDITOR_CLIENTS` (default 4), `TERRASYNTH_EDITOR_SIZE`
//! (1024) and `TERRASYNTH_EDITOR_SECONDS` (30) change the run; the table is
//! printed and written to `target/editor-load.md`.

#[path = "../tests/common/http.rs"]
mod http;

use serde_json::{Value, json};
use std::net::SocketAddr;
use std::time::{Duration, Instant};
use terrasynth::database::default;
use terrasynth::progress::Silent;
use terrasynth::server::{self, Config, DbSource};

fn env_or(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// The `q` quantile (0–1) of `v`, nearest rank.
fn quantile(v: &mut [f64], q: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v[((v.len() as f64 * q).ceil() as usize).clamp(1, v.len()) - 1]
}

/// One client: opens a session (timed) and moves its point 20 px back and
/// forth until `until`; returns the open time and every move's time (ms).
fn client(addr: SocketAddr, size: usize, height_m: f64, until: Instant) -> (f64, Vec<f64>) {
    let at = |dx: usize| json!([size / 2 + dx, size / 2]);
    let mut doc = json!({"version": 2, "size": [size, size], "seed": 3, "curves": [],
        "points": [{"id": "p", "at": at(0), "height_m": height_m, "radius_px": size / 16}]});
    let t = Instant::now();
    let r = http::post(addr, "/api/sessions", Some(&json!({ "scene": doc })));
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.body));
    let open = t.elapsed().as_secs_f64() * 1e3;
    let id = r.json()["session"].as_str().unwrap().to_string();
    let path = format!("/api/sessions/{id}/scene?commit=true");
    let mut moves = Vec::new();
    let mut i = 0;
    while Instant::now() < until {
        i += 1;
        doc["points"][0]["at"] = at(20 * (i % 2));
        let t = Instant::now();
        let r = http::put(addr, &path, &doc);
        assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.body));
        moves.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let _ = http::post(addr, &format!("/api/sessions/{id}/close"), None);
    (open, moves)
}

fn main() {
    // `cargo bench` passes --bench; `cargo test --benches` runs nothing here.
    if !std::env::args().any(|a| a == "--bench") {
        return;
    }
    let clients = env_or("TERRASYNTH_EDITOR_CLIENTS", 4).max(1);
    let size = env_or("TERRASYNTH_EDITOR_SIZE", 1024);
    let seconds = env_or("TERRASYNTH_EDITOR_SECONDS", 30) as u64;
    let db: &'static _ = Box::leak(Box::new(
        default::load_or_build(&default::cache_dir(), &Silent)
            .expect("the default database")
            .0,
    ));
    let running = server::start(Config {
        bind: SocketAddr::from(([127, 0, 0, 1], 0)),
        database: Some(DbSource::Loaded(db)),
        size: (size, size),
        max_sessions: clients,
        ..Config::default()
    })
    .expect("the server starts");
    running.wait_ready().expect("the database loads");
    let addr = running.addr;
    let info: Value = http::get(addr, "/api/info").json();
    let range = &info["database"]["range_m"];
    let (lo, hi) = (range[0].as_f64().unwrap(), range[1].as_f64().unwrap());
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let until = Instant::now() + Duration::from_secs(seconds);
    // Clients join one after another, so later ones open their session
    // while the earlier ones edit.
    let results: Vec<(f64, Vec<f64>)> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..clients)
            .map(|k| {
                s.spawn(move || {
                    std::thread::sleep(Duration::from_millis(1500 * k as u64));
                    client(addr, size, lo + 0.6 * (hi - lo), until)
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    running.stop();
    let mut moves: Vec<f64> = results.iter().flat_map(|r| r.1.iter().copied()).collect();
    let opens: Vec<String> = results.iter().map(|r| format!("{:.0}", r.0)).collect();
    let table = format!(
        "Editor under load: {clients} clients, {size}² sessions, {seconds} s (load average before: {})\n\n\
         | point moves | median | p90 | max | sessions opened (ms, in joining order) |\n|---|---|---|---|---|\n\
         | {} | {:.0} ms | {:.0} ms | {:.0} ms | {} |\n",
        load.split_whitespace()
            .take(3)
            .collect::<Vec<_>>()
            .join(" "),
        moves.len(),
        quantile(&mut moves, 0.5),
        quantile(&mut moves, 0.9),
        quantile(&mut moves, 1.0),
        opens.join(", ")
    );
    println!("{table}");
    let out = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/editor-load.md");
    std::fs::write(&out, &table).unwrap();
    eprintln!("wrote {}", out.display());
}
