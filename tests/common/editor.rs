//! Starting the editor's server in a test (on 127.0.0.1, an ephemeral
//! port, the embedded default database built once per test binary) and
//! the API calls the HTTP tests share.

use super::http::{self, Response};
use serde_json::{Value, json};
use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::OnceLock;
use terrasynth::database::{Database, default};
use terrasynth::progress::Silent;
use terrasynth::server::{self, Config, DbSource, Running};

pub fn database() -> &'static Database {
    static DB: OnceLock<&'static Database> = OnceLock::new();
    DB.get_or_init(|| Box::leak(Box::new(default::build_default(&Silent).unwrap())))
}

/// A running server, ready (database loaded).
pub fn serve(size: usize, scene: Option<PathBuf>, max_sessions: usize) -> Running {
    serve_with(size, scene, |c| c.max_sessions = max_sessions)
}

/// [`serve`] with the test's own settings (port, idle time, …).
pub fn serve_with(size: usize, scene: Option<PathBuf>, tweak: impl FnOnce(&mut Config)) -> Running {
    let mut config = Config {
        bind: SocketAddr::from(([127, 0, 0, 1], 0)),
        database: Some(DbSource::Loaded(database())),
        scene,
        size: (size, size),
        seed: 3,
        max_sessions: 2,
        ..Config::default()
    };
    tweak(&mut config);
    let running = server::start(config).expect("the server starts");
    running.wait_ready().expect("the database loads");
    running
}

/// The session's heights (an r32 export: little-endian f32, row-major).
pub fn heights(addr: SocketAddr, session: &str) -> Vec<f32> {
    let r = http::get(addr, &format!("/api/sessions/{session}/export?format=r32"));
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.body));
    r.body
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}

/// The heights a fresh synthesis of document `d` gives (a session opened
/// on it, as `synth --scene` gives: `tests/synth/sculpt.rs`), row-major.
pub fn fresh_heights(d: &Value) -> Vec<f32> {
    use terrasynth::scene::{Scene, SceneEdits};
    let db = database();
    let scene = Scene::parse(d.to_string().as_bytes(), std::path::Path::new("fresh.json")).unwrap();
    let mut edits = SceneEdits::new();
    let mut session = SceneEdits::session(db, &scene).unwrap();
    let frame = session.apply(edits.edits(&scene, db).unwrap()).unwrap();
    frame.heightfield.data().to_vec()
}

/// The side of the API tests' terrains.
pub const N: usize = 64;

/// The document a new session of [`serve`]`(N, None, _)` shows.
pub fn doc() -> Value {
    json!({"version": 2, "size": [N, N], "seed": 3, "points": [], "curves": []})
}

/// A new session: its id and first frame.
pub fn create(addr: SocketAddr) -> (String, Value) {
    let r = http::post(addr, "/api/sessions", None);
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.body));
    let f = r.json();
    (f["session"].as_str().unwrap().to_string(), f)
}

/// A new session on document `d`: its id and first frame.
pub fn create_with(addr: SocketAddr, d: &Value) -> (String, Value) {
    let r = http::post(addr, "/api/sessions", Some(&json!({ "scene": d })));
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.body));
    let f = r.json();
    (f["session"].as_str().unwrap().to_string(), f)
}

pub fn put_scene(addr: SocketAddr, s: &str, d: &Value, commit: bool) -> Response {
    http::put(addr, &format!("/api/sessions/{s}/scene?commit={commit}"), d)
}

/// `r` is a JSON error with this status that names `field`; its message.
pub fn expect_error(r: &Response, status: u16, field: &str) -> String {
    assert_eq!(
        r.status,
        status,
        "expected {status} naming {field}: {}",
        String::from_utf8_lossy(&r.body)
    );
    assert_eq!(r.error_field(), field, "{}", r.json());
    let message = r.json()["error"]["message"].as_str().unwrap().to_string();
    assert!(!message.is_empty());
    message
}

/// `terrasynth serve` as its own process (for what only a process shows:
/// its resident memory, its stderr, a kill), stopped by its own id when
/// dropped.
pub struct Process {
    pub child: std::process::Child,
    pub addr: SocketAddr,
    /// What it said on stderr until it listened.
    pub said: String,
}

impl Drop for Process {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Starts `terrasynth serve --bind 127.0.0.1:0 ARGS` with its database
/// cache under `cache`, and waits until it listens (its database may
/// still be loading).
pub fn spawn(args: &[&std::ffi::OsStr], cache: &std::path::Path) -> Process {
    use std::io::{BufRead, BufReader};
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_terrasynth"))
        .args(["serve", "--bind", "127.0.0.1:0"])
        .args(args)
        .env("TERRASYNTH_CACHE_DIR", cache)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("terrasynth serve starts");
    let stderr = child.stderr.take().unwrap();
    let mut p = Process {
        child,
        addr: SocketAddr::from(([127, 0, 0, 1], 0)),
        said: String::new(),
    };
    let mut lines = BufReader::new(stderr).lines();
    p.addr = loop {
        let Some(Ok(line)) = lines.next() else {
            panic!("the server stopped: {}", p.said);
        };
        p.said.push_str(&line);
        p.said.push('\n');
        if let Some(rest) = line.split("open http://").nth(1) {
            break rest.split('/').next().unwrap().parse().unwrap();
        }
    };
    // Keep reading, so a chatty server never blocks on a full pipe.
    std::thread::spawn(move || for _ in lines {});
    p
}
