//! The HTTP API (JSON unless said otherwise; `{id}` is a session):
//!
//! | method, path | body → answer |
//! |---|---|
//! | `GET /`, `GET /assets/…` | the page (embedded) |
//! | `GET /api/info` | database (types, exemplars, height range), loading progress, limits, `recovery` (unsaved work found at start: `{path, modified_ms}`, or null) |
//! | `GET /api/exemplars/{i}/preview.png` | an exemplar's relief, for lassos on exemplars |
//! | `POST /api/sessions` | none, or `{"scene": doc}` → first frame + `session` id |
//! | `GET /api/sessions/{id}` | → the shown document (`scene`), what its undo history holds (`history_bytes`, estimated) and what the states kept to undo pastes hold (`checkpoint_bytes`) |
//! | `PUT /api/sessions/{id}/scene?commit=true` | scene document → frame (`commit=false`: a drag's intermediate state, not an undo step) |
//! | `POST /api/sessions/{id}/undo`, `…/redo` | → frame + the document now shown |
//! | `PUT /api/sessions/{id}/view` | `{"contours", "types", "range"}` → frame |
//! | `GET /api/sessions/{id}/preview.png` | the last frame's preview |
//! | `GET /api/sessions/{id}/tile.png?revision=N` | the part of the preview frame N changed (header `x-rect: x0,y0,x1,y1`) |
//! | `GET /api/sessions/{id}/heights` | binary: u32 width, u32 height, u32 stride, then f32 metres (≤ 512² samples); header `x-revision` |
//! | `GET /api/sessions/{id}/export?format=exr[&sidecar=true]` | a download (any writable format, or `preview`) |
//! | `POST /api/sessions/{id}/save[?force=true]` | writes the `--scene` file → `{"path"}`; 409 when another tab saved after this session's document was loaded (unless forced) |
//! | `POST /api/sessions/{id}/reload?merge=false` | → frame + `scene`: the scene file as last saved becomes the session's document (an undo step: undo brings this tab's back); the answer to a 409 on save |
//! | `POST /api/sessions/{id}/reload?merge=true` | → frame + `scene`: this tab's changes since it loaded, replayed on the file as last saved (`src/server/document/merge.rs`); Save then writes it |
//! | `POST /api/sessions/{id}/recovery?keep=true` | → frame + `scene`: the recovered document becomes the session's (an undo step, unsaved); 404 when no recovery is pending |
//! | `POST /api/sessions/{id}/recovery?keep=false` | → `{"discarded": path}`: the autosave file is deleted |
//! | `POST /api/sessions/{id}/ping` | the page's heartbeat (`info.sessions.heartbeat_ms`) → `{"stale"}`: true when another tab saved the scene file after this session's document was loaded (the page offers reload/merge before a save is refused) |
//! | `POST /api/sessions/{id}/close` | free the slot (on page hide, by beacon) |
//!
//! A frame: `revision`, `size`, `seed`, `backend` (`cpu` or `gpu`:
//! where it was synthesized and shaded, `serve --backend`), `history {undo, redo}`,
//! `timing_ms {queued, edits, synth, render, total}`, `changed {pixels,
//! bounds}`, `rebuilt`, `heights_m {min, max}`, `overlay {curves,
//! junctions}`, `view` (and `scene` after undo/redo/create; `baked`,
//! `[{index, targets}]`, when the document had sculpt strokes without
//! targets: they are baked from the terrain shown, and the page keeps
//! them); or
//! `{"superseded": true}` when a newer document replaced it in the queue.

use super::error::ApiError;
use super::request::{self, PathParam, json_body};
use super::{assets, output};
use crate::database::Database;
use crate::io::Format;
use crate::server::editor::{Handle, Reply, Shared, Task};
use crate::server::{App, DbState};
use axum::Router;
use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::{DefaultBodyLimit, RawQuery, Request, State};
use axum::http::{HeaderMap, Method, StatusCode, header};
use axum::middleware::{self, Next};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post, put};
use serde_json::{Value, json};
use std::sync::Arc;

type Api<T = axum::Json<Value>> = Result<T, ApiError>;

pub fn router(app: Arc<App>) -> Router {
    let limit = app.max_request_bytes;
    Router::new()
        .route("/", get(index))
        .route("/assets/{*path}", get(asset))
        .route("/api/info", get(info))
        .route("/api/exemplars/{index}/preview.png", get(output::exemplar))
        .route("/api/sessions", post(create))
        .route("/api/sessions/{id}", get(state))
        .route("/api/sessions/{id}/scene", put(put_scene))
        .route("/api/sessions/{id}/undo", post(undo))
        .route("/api/sessions/{id}/redo", post(redo))
        .route("/api/sessions/{id}/view", put(put_view))
        .route("/api/sessions/{id}/preview.png", get(output::preview))
        .route("/api/sessions/{id}/tile.png", get(output::tile))
        .route("/api/sessions/{id}/heights", get(output::heights))
        .route("/api/sessions/{id}/export", get(output::export))
        .route("/api/sessions/{id}/save", post(output::save))
        .route("/api/sessions/{id}/reload", post(reload))
        .route("/api/sessions/{id}/recovery", post(recovery))
        .route("/api/sessions/{id}/ping", post(ping))
        .route("/api/sessions/{id}/close", post(close))
        .fallback(not_found)
        .method_not_allowed_fallback(method_not_allowed)
        .layer(DefaultBodyLimit::max(limit))
        .layer(middleware::from_fn_with_state(app.clone(), guard))
        .with_state(app)
}

/// Refuses requests that name another host (DNS rebinding) or that
/// change something from another site's page (cross-site requests).
async fn guard(State(app): State<Arc<App>>, req: Request, next: Next) -> Response {
    // Owned copies: nothing borrowed from the request may live across the
    // await below (the body is not Sync).
    let host = header_text(req.headers(), header::HOST).unwrap_or_default();
    let origin = header_text(req.headers(), header::ORIGIN);
    if !app.hosts.contains(&host) {
        return ApiError::Forbidden(format!(
            "Host {host:?} is not this server: open it as http://{}/",
            app.hosts[0]
        ))
        .into_response();
    }
    if !matches!(*req.method(), Method::GET | Method::HEAD)
        && let Some(origin) = origin
        && origin != format!("http://{host}")
    {
        return ApiError::Forbidden(format!(
            "requests from {origin} may not change this editor: only its own page may"
        ))
        .into_response();
    }
    next.run(req).await
}

fn header_text(headers: &HeaderMap, name: header::HeaderName) -> Option<String> {
    headers
        .get(name)
        .and_then(|v| v.to_str().ok())
        .map(str::to_string)
}

async fn not_found() -> ApiError {
    ApiError::NotFound(
        "no such page or endpoint (see the API table in src/server/api/routes.rs)".into(),
    )
}

async fn method_not_allowed(method: Method) -> Response {
    let e = ApiError::malformed("$", format!("method {method} is not allowed here"));
    (StatusCode::METHOD_NOT_ALLOWED, axum::Json(e.body())).into_response()
}

async fn index() -> Response {
    asset_response("index.html")
}

async fn asset(PathParam(path): PathParam) -> Response {
    asset_response(&path)
}

/// What the page may load: only this server's own files (so nothing can
/// come from a CDN, even by mistake: the browser refuses it and the page
/// reports the violation), blob images (tiles) and inline style attributes
/// (palette swatches).
const CONTENT_POLICY: &str = "default-src 'self'; img-src 'self' blob: data:; style-src 'self' 'unsafe-inline'; object-src 'none'; base-uri 'none'; frame-ancestors 'none'";

fn asset_response(path: &str) -> Response {
    match assets::get(path) {
        Some((mime, bytes)) => (
            [
                (header::CONTENT_TYPE, mime),
                (header::CONTENT_SECURITY_POLICY, CONTENT_POLICY),
                (header::X_CONTENT_TYPE_OPTIONS, "nosniff"),
            ],
            bytes,
        )
            .into_response(),
        None => ApiError::NotFound(format!("no asset {path:?}")).into_response(),
    }
}

impl App {
    pub(super) fn ready(&self) -> Result<&'static Database, ApiError> {
        match &*self.db.read().unwrap_or_else(|e| e.into_inner()) {
            DbState::Ready(db) => Ok(db),
            DbState::Loading => Err(ApiError::NotReady(
                "the exemplar database is still loading; the page shows its progress".into(),
            )),
            DbState::Failed(e) => Err(ApiError::NotReady(e.clone())),
        }
    }
}

async fn reply(rx: tokio::sync::oneshot::Receiver<Reply>) -> Api {
    match rx.await {
        Ok(r) => r.map(axum::Json),
        Err(_) => Err(ApiError::Internal(
            "the session stopped; reload the page".into(),
        )),
    }
}

async fn info(State(app): State<Arc<App>>) -> axum::Json<Value> {
    let state = app.db.read().unwrap_or_else(|e| e.into_inner()).clone();
    let (status, error, database) = match state {
        DbState::Loading => ("loading", None, Value::Null),
        DbState::Failed(e) => ("failed", Some(e), Value::Null),
        DbState::Ready(db) => ("ready", None, database_info(&app, db)),
    };
    let p = &app.progress;
    axum::Json(json!({
        "version": env!("CARGO_PKG_VERSION"),
        "instance": app.instance,
        "status": status,
        "error": error,
        "progress": {
            "stage": *p.stage.lock().unwrap_or_else(|e| e.into_inner()),
            "done": p.done.load(std::sync::atomic::Ordering::Relaxed),
            "total": p.total.load(std::sync::atomic::Ordering::Relaxed),
        },
        "database": database,
        "scene_file": app.scene_file.as_ref().map(|p| p.display().to_string()),
        "recovery": recovery_info(&app),
        // The page pings four times per idle time: a missed ping or two is
        // no reason to lose the slot.
        "sessions": {
            "open": app.registry.open(),
            "limit": app.registry.limit,
            "heartbeat_ms": app.registry.idle.as_millis() / 4,
        },
        "max_request_bytes": app.max_request_bytes,
        "export_formats": Format::ALL.iter().filter(|f| f.can_write()).map(|f| f.name()).collect::<Vec<_>>(),
    }))
}

fn recovery_info(app: &App) -> Value {
    let Some(a) = &app.autosave else {
        return Value::Null;
    };
    match a.recovery() {
        None => Value::Null,
        Some(r) => json!({
            "path": a.path.display().to_string(),
            "modified_ms": r.modified.duration_since(std::time::UNIX_EPOCH).map(|d| d.as_millis() as u64).unwrap_or(0),
        }),
    }
}

fn database_info(app: &App, db: &Database) -> Value {
    let style = app.style.read().unwrap_or_else(|e| e.into_inner()).clone();
    let range = style.as_ref().map(|s| s.range).unwrap_or((0.0, 1.0));
    let types: Vec<Value> = db
        .type_names()
        .iter()
        .enumerate()
        .map(|(i, n)| json!({"index": i, "name": n, "colour": crate::render::types::type_colour(i as u8)}))
        .collect();
    let exemplars: Vec<Value> = db
        .meta()
        .exemplars
        .iter()
        .enumerate()
        .map(|(i, e)| json!({"index": i, "name": e.name, "size": [e.width, e.height], "cell_size_m": e.cell_size_m}))
        .collect();
    json!({
        "types": types,
        "exemplars": exemplars,
        "range_m": [range.0, range.1],
        "cell_size_m": db.meta().exemplars.first().map(|e| e.cell_size_m),
    })
}

async fn create(
    State(app): State<Arc<App>>,
    headers: HeaderMap,
    body: Result<Bytes, BytesRejection>,
) -> Api {
    let db = app.ready()?;
    let body = json_body(&headers, body, app.max_request_bytes)?;
    let base = {
        let saved = app.saved.lock().await;
        (saved.revision, saved.doc.clone())
    };
    let doc = request::new_session(&body)?.unwrap_or_else(|| (*base.1).clone());
    // Field paths inside {"scene": …} are the document's own.
    let scene = app.policy.check_value(&doc)?;
    let style = app
        .style
        .read()
        .unwrap_or_else(|e| e.into_inner())
        .clone()
        .ok_or_else(|| ApiError::NotReady("the database is not ready".into()))?;
    let shared = Shared {
        db,
        policy: app.policy.clone(),
        style,
        engine: app.engine.clone(),
    };
    let (w, h) = (scene.width, scene.height);
    let (id, rx) = app
        .registry
        .admit(w, h, || Handle::spawn(shared, doc, scene, base))?;
    let mut pending = app.registry.until_answered(&id);
    let mut frame = reply(rx).await?;
    pending.done = true;
    // A tab reopening its unsaved document after a lost session.
    changed(&app, &id);
    frame["session"] = json!(id);
    Ok(frame)
}

async fn state(State(app): State<Arc<App>>, PathParam(id): PathParam) -> Api {
    let h = app.registry.get(&id)?;
    let latest = h
        .latest()
        .ok_or_else(|| ApiError::NotReady("the first frame is not ready".into()))?;
    Ok(axum::Json(
        json!({"revision": latest.revision, "scene": latest.committed, "history_bytes": latest.history_bytes, "checkpoint_bytes": latest.checkpoint_bytes}),
    ))
}

async fn put_scene(
    State(app): State<Arc<App>>,
    PathParam(id): PathParam,
    RawQuery(raw): RawQuery,
    headers: HeaderMap,
    body: Result<Bytes, BytesRejection>,
) -> Api {
    let h = app.registry.get(&id)?;
    let q = request::query(raw.as_deref(), &["commit"])?;
    let commit = request::flag(&q, "commit", true)?;
    let body = json_body(&headers, body, app.max_request_bytes)?;
    if body.is_empty() {
        return Err(ApiError::malformed(
            "$",
            "expected a scene document as the body",
        ));
    }
    let (doc, scene) = app.policy.check(&body)?;
    let frame = reply(h.submit(Task::Scene {
        doc,
        scene: Box::new(scene),
        commit,
    }))
    .await?;
    if commit {
        changed(&app, &id);
    }
    Ok(frame)
}

async fn undo(State(app): State<Arc<App>>, PathParam(id): PathParam) -> Api {
    let frame = reply(app.registry.get(&id)?.submit(Task::Undo)).await?;
    changed(&app, &id);
    Ok(frame)
}

async fn redo(State(app): State<Arc<App>>, PathParam(id): PathParam) -> Api {
    let frame = reply(app.registry.get(&id)?.submit(Task::Redo)).await?;
    changed(&app, &id);
    Ok(frame)
}

/// Session `id`'s committed document may have changed: the autosave
/// thread writes it after its delay (never here, on the request path).
fn changed(app: &App, id: &str) {
    if let (Some(a), Ok(h)) = (&app.autosave, app.registry.get(id)) {
        a.changed(&h);
    }
}

/// `POST …/reload?merge=true|false`: the page's answer to a refused
/// (stale) save. The session then stands on the file as last saved, so
/// its next save is no longer refused; the new document is an undo step,
/// so reloading loses nothing of this tab's work.
async fn reload(
    State(app): State<Arc<App>>,
    PathParam(id): PathParam,
    RawQuery(raw): RawQuery,
) -> Api {
    let h = app.registry.get(&id)?;
    let merge = request::required_flag(
        raw.as_deref(),
        "merge",
        "missing: expected false (take the saved file's version) or true (this tab's changes on top of it)",
    )?;
    let (revision, theirs) = {
        let saved = app.saved.lock().await;
        (saved.revision, saved.doc.clone())
    };
    let doc = match merge {
        false => (*theirs).clone(),
        true => {
            let mine = h
                .committed()
                .ok_or_else(|| ApiError::NotReady("the first frame is not ready".into()))?;
            crate::server::document::merge::merge(&h.base().1, &mine, &theirs)
        }
    };
    let frame = commit_document(&app, &h, doc).await?;
    h.set_base(revision, theirs);
    changed(&app, &id);
    Ok(frame)
}

/// `POST …/recovery?keep=true|false`: the artist's answer to the unsaved
/// work found at start. Keep shows it in this session as an edit (so undo
/// goes back to the saved scene and Save writes it); discard deletes it.
async fn recovery(
    State(app): State<Arc<App>>,
    PathParam(id): PathParam,
    RawQuery(raw): RawQuery,
) -> Api {
    let h = app.registry.get(&id)?;
    let keep = request::required_flag(
        raw.as_deref(),
        "keep",
        "missing: expected true (keep the recovered work) or false (discard it)",
    )?;
    let none = || {
        ApiError::NotFound("no unsaved work is waiting for recovery: it was kept or discarded already (in another tab?)".into())
    };
    let a = app.autosave.as_ref().ok_or_else(none)?;
    let found = a.recovery().ok_or_else(none)?;
    if !keep {
        a.remove().map_err(|e| ApiError::Internal(e.to_string()))?;
        a.resolved();
        return Ok(axum::Json(
            json!({"discarded": a.path.display().to_string()}),
        ));
    }
    // A document that no longer checks (a hand-edited file, a changed
    // database) is refused naming its field, and stays pending.
    let frame = commit_document(&app, &h, found.doc).await?;
    a.resolved();
    a.changed(&h);
    Ok(frame)
}

/// A whole document applied as a committed edit (an undo step, so
/// nothing of the tab's work is lost), answered with its frame and the
/// document as `scene` for the page to take up: what a reload and a kept
/// recovery do. A document that does not check is refused naming its field.
async fn commit_document(app: &App, h: &Handle, doc: Value) -> Api {
    let scene = app.policy.check_value(&doc)?;
    let mut frame = reply(h.submit(Task::Scene {
        doc: doc.clone(),
        scene: Box::new(scene),
        commit: true,
    }))
    .await?;
    frame["scene"] = doc;
    Ok(frame)
}

async fn put_view(
    State(app): State<Arc<App>>,
    PathParam(id): PathParam,
    headers: HeaderMap,
    body: Result<Bytes, BytesRejection>,
) -> Api {
    let h = app.registry.get(&id)?;
    let body = json_body(&headers, body, app.max_request_bytes)?;
    let view = request::view(&body)?;
    reply(h.submit(Task::View(view))).await
}

async fn ping(State(app): State<Arc<App>>, PathParam(id): PathParam) -> Api {
    let h = app.registry.get(&id)?;
    h.touch();
    let saved = app.saved.lock().await.revision;
    Ok(axum::Json(json!({"stale": h.base().0 != saved})))
}

async fn close(State(app): State<Arc<App>>, PathParam(id): PathParam) -> Api<StatusCode> {
    match app.registry.close(&id) {
        true => Ok(StatusCode::NO_CONTENT),
        false => Err(ApiError::NoSession(id)),
    }
}
