//! `terrasynth serve`: the interactive editor (paper §3). A local HTTP
//! server (axum on tokio) serves a web page, embedded in the binary, and a
//! JSON API over editing [`crate::synth::session::Session`]s, one per tab.
//!
//! ```text
//! browser ──HTTP/JSON──► routes ──► registry ──► editor thread (Session, history, preview)
//!    ▲  page: map, handles, brushes                 │ scene document → SceneEdits → Session::apply
//!    └──────── preview PNG (the `shade` stage) ◄────┘ → render
//! ```
//!
//! The page sends the whole scene document (the scene-file format of
//! [`crate::scene`]) with every edit; the server finds what changed and
//! re-synthesizes only that, coherently. Loopback only; requests naming
//! another host, or coming from another site, are refused; bodies
//! are bounded; every bad request gets a 4xx JSON error naming the field.
//! The server writes the scene file given with `--scene` (on Save,
//! atomically) and, while a tab has unsaved changes, an autosave beside it
//! that the next start offers to recover (`autosave.rs`); exports are
//! downloads.

pub mod api;
mod autosave;
mod document;
mod editor;
mod registry;

pub use api::error::ApiError;
pub use editor::view::View;

use crate::backend::engine::Engine;
use crate::database::{Database, DbError};
use crate::progress::Progress;
use crate::scene::{Freeze, Scene, SceneEdits, SceneError, TypePaint};
use serde_json::Value;
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, RwLock};
use std::time::Duration;
use thiserror::Error;

/// Where the database comes from.
#[derive(Clone)]
pub enum DbSource {
    /// The embedded default (built and cached on first use).
    Embedded,
    /// A `.tsdb` file.
    File(PathBuf),
    /// Already loaded (tests share one).
    Loaded(&'static Database),
}

/// How to serve.
#[derive(Clone)]
pub struct Config {
    pub bind: SocketAddr,
    /// `--db`; a scene that names a database uses that one.
    pub database: Option<DbSource>,
    /// Loaded at start when it exists, and the file Save writes.
    pub scene: Option<PathBuf>,
    /// Size and seed of a new design (no `--scene`, or one not yet saved).
    pub size: (usize, usize),
    pub seed: u32,
    pub max_sessions: usize,
    pub max_request_bytes: usize,
    /// A session whose page has not been heard from for this long (the
    /// page pings every quarter of it) gives its slot to another tab.
    pub idle: Duration,
    /// How long after the last edit unsaved work is autosaved.
    pub autosave_delay: Duration,
    /// Where a server without `--scene` autosaves (the CLI: the user cache
    /// dir); with `--scene`, the side file beside it. None: no autosave.
    pub unsaved_autosave: Option<PathBuf>,
    /// Where sessions synthesize and previews are shaded (`--backend`):
    /// the same bytes on every engine, so a GPU only makes edits faster.
    pub engine: Engine,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            bind: SocketAddr::from(([127, 0, 0, 1], 8080)),
            database: None,
            scene: None,
            size: (1024, 1024),
            seed: 1,
            max_sessions: 4,
            max_request_bytes: 16 << 20,
            idle: Duration::from_secs(8),
            autosave_delay: Duration::from_secs(2),
            unsaved_autosave: None,
            engine: Engine::default(),
        }
    }
}

/// Why the server cannot start.
#[non_exhaustive]
#[derive(Debug, Error)]
pub enum ServeError {
    /// The editor has no authentication: anyone who reaches it can read
    /// and change the terrain and make the server write its scene file.
    #[error(
        "--bind {0}: the editor listens on loopback only (127.0.0.1 or [::1]); to reach it from another machine, forward a port (ssh -L 8080:127.0.0.1:8080 host)"
    )]
    NotLoopback(SocketAddr),
    #[error("cannot listen on {addr}: {source}")]
    Bind {
        addr: SocketAddr,
        source: std::io::Error,
    },
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error(
        "--db {db} and the scene's database {scene} differ: pass one (the scene's \"database\" field, or --db for a new scene)"
    )]
    DatabaseMismatch { db: String, scene: String },
    #[error("--size {0}x{1} is invalid: {2}")]
    Size(usize, usize, String),
    #[error("cannot start the server: {0}")]
    Runtime(std::io::Error),
}

/// The database as the page sees it while it loads.
#[derive(Clone)]
enum DbState {
    Loading,
    Ready(&'static Database),
    Failed(String),
}

/// Progress of the database load, for the page's progress bar.
#[derive(Default)]
struct LoadProgress {
    stage: Mutex<String>,
    done: AtomicU64,
    total: AtomicU64,
}

impl Progress for LoadProgress {
    fn start(&self, stage: &str, total: u64) {
        *self.stage.lock().unwrap_or_else(|e| e.into_inner()) = stage.to_string();
        self.total.store(total, Ordering::Relaxed);
        self.done.store(0, Ordering::Relaxed);
    }
    fn advance(&self, n: u64) {
        self.done.fetch_add(n, Ordering::Relaxed);
    }
    fn finish(&self) {
        self.done
            .store(self.total.load(Ordering::Relaxed), Ordering::Relaxed);
    }
}

/// What every request handler shares.
pub(crate) struct App {
    db: RwLock<DbState>,
    progress: LoadProgress,
    style: RwLock<Option<Arc<editor::view::Style>>>,
    policy: Arc<document::Policy>,
    /// The document a new tab starts from — the scene file as last saved
    /// (or as the server found it, or a blank one) — and its revision.
    /// Why the last save and not the file as found: a tab opened after
    /// another saved started from the server's start and, saved, dropped
    /// that work (issue 43).
    saved: tokio::sync::Mutex<Saved>,
    registry: registry::Registry,
    scene_file: Option<PathBuf>,
    max_request_bytes: usize,
    /// Host names requests may name (the loopback names of the port).
    hosts: Vec<String>,
    exemplar_previews: Mutex<Vec<Option<Arc<Vec<u8>>>>>,
    /// This run of the server: a page reloaded while it runs restores its
    /// unsaved document; after a restart the saved scene is loaded.
    instance: String,
    /// None without `--scene` and [`Config::unsaved_autosave`].
    autosave: Option<autosave::Autosave>,
    /// Where every session synthesizes and shades ([`Config::engine`]).
    engine: Engine,
}

/// The scene file's document as last saved, and how many saves it took.
pub(crate) struct Saved {
    /// Shared with the sessions that stand on it (their merge base).
    pub doc: Arc<Value>,
    pub revision: u64,
}

/// A server running on its own threads.
pub struct Running {
    pub addr: SocketAddr,
    app: Arc<App>,
    shutdown: Option<tokio::sync::oneshot::Sender<()>>,
    thread: Option<std::thread::JoinHandle<()>>,
    autosaver: Option<std::thread::JoinHandle<()>>,
}

impl Running {
    /// The page's address.
    pub fn url(&self) -> String {
        format!("http://{}/", self.addr)
    }

    /// Waits until the database is loaded (or failed to load).
    pub fn wait_ready(&self) -> Result<(), String> {
        loop {
            match &*self.app.db.read().unwrap_or_else(|e| e.into_inner()) {
                DbState::Ready(_) => return Ok(()),
                DbState::Failed(e) => return Err(e.clone()),
                DbState::Loading => {}
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    /// Stops serving and closes every session.
    pub fn stop(mut self) {
        self.halt();
    }

    fn halt(&mut self) {
        if let Some(tx) = self.shutdown.take() {
            let _ = tx.send(());
        }
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
        // No edit comes any more: what is pending is written now.
        if let Some(a) = &self.app.autosave {
            a.stop();
        }
        if let Some(t) = self.autosaver.take() {
            let _ = t.join();
        }
        self.app.registry.close_all();
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        self.halt();
    }
}

/// Binds, starts loading the database, and serves on background threads.
pub fn start(config: Config) -> Result<Running, ServeError> {
    if !config.bind.ip().is_loopback() {
        return Err(ServeError::NotLoopback(config.bind));
    }
    let (width, height) = config.size;
    crate::size::check_dims(width, height)
        .map_err(|e| ServeError::Size(width, height, e.to_string()))?;
    let (mut app, source) = prepare(&config)?;
    // Saves and autosaves a killed server left half-written.
    let written = config
        .scene
        .iter()
        .chain(app.autosave.as_ref().map(|a| &a.path));
    for file in written {
        let n = crate::io::remove_orphans(file);
        if n > 0 {
            eprintln!(
                "removed {n} temporary file(s) an interrupted save left beside {}",
                file.display()
            );
        }
    }
    let listener = std::net::TcpListener::bind(config.bind).map_err(|source| ServeError::Bind {
        addr: config.bind,
        source,
    })?;
    listener
        .set_nonblocking(true)
        .map_err(ServeError::Runtime)?;
    let addr = listener.local_addr().map_err(ServeError::Runtime)?;
    // DNS rebinding: a page of another site that resolves its own name to
    // 127.0.0.1 still sends its own name as the Host.
    let port = addr.port();
    app.hosts = vec![
        format!("127.0.0.1:{port}"),
        format!("localhost:{port}"),
        format!("[::1]:{port}"),
    ];
    let app = Arc::new(app);
    load_database(app.clone(), source);
    let autosaver = autosave::spawn(app.clone()).map_err(ServeError::Runtime)?;
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .thread_name("terrasynth-serve")
        .build()
        .map_err(ServeError::Runtime)?;
    let (tx, rx) = tokio::sync::oneshot::channel::<()>();
    let router = api::routes::router(app.clone());
    let listener = {
        let _guard = runtime.enter();
        tokio::net::TcpListener::from_std(listener).map_err(ServeError::Runtime)?
    };
    let thread = std::thread::Builder::new()
        .name("terrasynth-serve".into())
        .spawn(move || {
            runtime.block_on(async move {
                let served = axum::serve(listener, router)
                    .with_graceful_shutdown(async {
                        let _ = rx.await;
                    })
                    .await;
                if let Err(e) = served {
                    eprintln!("error: the server stopped: {e}");
                }
            });
        })
        .map_err(ServeError::Runtime)?;
    Ok(Running {
        addr,
        app,
        shutdown: Some(tx),
        thread: Some(thread),
        autosaver: Some(autosaver),
    })
}

/// Serves until Ctrl-C; `ready` is called with the address once listening.
pub fn run(config: Config, ready: impl FnOnce(&Running)) -> Result<(), ServeError> {
    let running = start(config)?;
    ready(&running);
    let (tx, rx) = std::sync::mpsc::channel();
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .map_err(ServeError::Runtime)?;
    std::thread::spawn(move || {
        rt.block_on(async {
            let _ = tokio::signal::ctrl_c().await;
        });
        let _ = tx.send(());
    });
    let _ = rx.recv();
    running.stop();
    Ok(())
}

/// Reads the scene (if any), settles the database and builds the shared state.
fn prepare(config: &Config) -> Result<(App, DbSource), ServeError> {
    let existing = match &config.scene {
        Some(p) if p.exists() => Some(Scene::read(p)?),
        _ => None,
    };
    let source = match (
        &config.database,
        existing.as_ref().and_then(|s| s.database.clone()),
    ) {
        (Some(DbSource::File(db)), Some(s)) if !same_file(db, &s) => {
            return Err(ServeError::DatabaseMismatch {
                db: db.display().to_string(),
                scene: s.display().to_string(),
            });
        }
        (Some(src), _) => src.clone(),
        (None, Some(s)) => DbSource::File(s),
        (None, None) => DbSource::Embedded,
    };
    let file = config
        .scene
        .clone()
        .unwrap_or_else(|| PathBuf::from("editor-scene.json"));
    let db_path = match &source {
        DbSource::File(p) => Some(p.clone()),
        _ => None,
    };
    let (initial, database_value) = match (&existing, &config.scene) {
        (Some(_), Some(p)) => {
            let bytes = std::fs::read(p).map_err(|e| {
                SceneError::new(
                    p,
                    "$",
                    crate::scene::SceneErrorKind::Io(crate::io::IoError::os(p, e)),
                )
            })?;
            let v: Value = serde_json::from_slice(&bytes).map_err(|e| {
                SceneError::new(p, "$", crate::scene::SceneErrorKind::Json(e.to_string()))
            })?;
            let dbv = v.get("database").cloned().filter(|d| !d.is_null());
            (v, dbv)
        }
        _ => {
            let dbv = db_path.as_ref().map(|p| {
                Value::String(
                    std::path::absolute(p)
                        .unwrap_or_else(|_| p.clone())
                        .display()
                        .to_string(),
                )
            });
            (
                document::blank(config.size.0, config.size.1, config.seed, dbv.as_ref()),
                dbv,
            )
        }
    };
    let policy = document::Policy {
        file: file.clone(),
        database: db_path,
        database_value,
        types_image: match existing.as_ref().and_then(|s| s.types.as_ref()) {
            Some(TypePaint::Image(p)) => Some(p.clone()),
            _ => None,
        },
        freeze_mask: match existing.as_ref().and_then(|s| s.freeze.as_ref()) {
            Some(Freeze::Mask(p)) => Some(p.clone()),
            _ => None,
        },
    };
    let side = match &config.scene {
        Some(p) => Some(autosave::side_file(p)),
        None => config.unsaved_autosave.clone(),
    };
    let autosave = side.map(|side| {
        let found = autosave::find(&side, config.scene.as_deref(), &initial);
        autosave::Autosave::new(side, config.autosave_delay, found)
    });
    let app = App {
        db: RwLock::new(DbState::Loading),
        progress: LoadProgress::default(),
        style: RwLock::new(None),
        policy: Arc::new(policy),
        saved: tokio::sync::Mutex::new(Saved {
            doc: Arc::new(initial),
            revision: 0,
        }),
        registry: registry::Registry::new(config.max_sessions.max(1), config.idle),
        scene_file: config.scene.clone(),
        max_request_bytes: config.max_request_bytes,
        hosts: Vec::new(),
        exemplar_previews: Mutex::new(Vec::new()),
        instance: registry::new_id(),
        autosave,
        engine: config.engine.clone(),
    };
    Ok((app, source))
}

fn same_file(a: &Path, b: &Path) -> bool {
    let abs = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    abs(a) == abs(b)
}

/// Loads (or builds) the database on a thread, then checks the initial
/// document against it, so a scene naming an unknown type fails here, once.
fn load_database(app: Arc<App>, source: DbSource) {
    std::thread::spawn(move || {
        let loaded: Result<&'static Database, DbError> = match source {
            DbSource::Loaded(db) => Ok(db),
            // One database per server, alive as long as the process: the
            // sessions borrow it from their threads.
            DbSource::File(p) => Database::load(&p).map(|db| &*Box::leak(Box::new(db))),
            DbSource::Embedded => {
                let dir = crate::database::default::cache_dir();
                crate::database::default::load_or_build(&dir, &app.progress)
                    .map(|(db, _)| &*Box::leak(Box::new(db)))
            }
        };
        let state = match loaded {
            Err(e) => DbState::Failed(format!("the database could not be loaded: {e}")),
            Ok(db) => {
                let checked = app
                    .policy
                    .check_value(&app.saved.blocking_lock().doc)
                    .and_then(|scene| Ok(SceneEdits::new().edits(&scene, db)?));
                match checked {
                    Err(e) => DbState::Failed(format!("the scene cannot be edited: {e}")),
                    Ok(_) => {
                        *app.style.write().unwrap_or_else(|e| e.into_inner()) =
                            Some(Arc::new(editor::view::Style::new(db)));
                        *app.exemplar_previews
                            .lock()
                            .unwrap_or_else(|e| e.into_inner()) =
                            vec![None; db.meta().exemplars.len()];
                        DbState::Ready(db)
                    }
                }
            }
        };
        *app.db.write().unwrap_or_else(|e| e.into_inner()) = state;
    });
}
