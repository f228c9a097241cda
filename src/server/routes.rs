//! The HTTP API (JSON unless said otherwise; `{id}` is a session):
//!
//! | method, path | body → answer |
//! |---|---|
//! | `GET /`, `GET /assets/…` | the page (embedded) |
//! | `GET /api/info` | database (types, exemplars, height range), loading progress, limits |
//! | `GET /api/exemplars/{i}/preview.png` | an exemplar's relief, for lassos on exemplars |
//! | `POST /api/sessions` | none, or `{"scene": doc}` → first frame + `session` id |
//! | `GET /api/sessions/{id}` | → the shown document and history |
//! | `PUT /api/sessions/{id}/scene?commit=true` | scene document → frame (`commit=false`: a drag's intermediate state, not an undo step) |
//! | `POST /api/sessions/{id}/undo`, `…/redo` | → frame + the document now shown |
//! | `PUT /api/sessions/{id}/view` | `{"contours", "types", "range"}` → frame |
//! | `GET /api/sessions/{id}/preview.png` | the last frame's preview |
//! | `GET /api/sessions/{id}/tile.png?revision=N` | the part of the preview frame N changed (header `x-rect: x0,y0,x1,y1`) |
//! | `GET /api/sessions/{id}/heights` | binary: u32 width, u32 height, u32 stride, then f32 metres (≤ 512² samples) |
//! | `GET /api/sessions/{id}/export?format=exr[&sidecar=true]` | a download (any writable format, or `preview`) |
//! | `POST /api/sessions/{id}/save` | writes the `--scene` file → `{"path"}` |
//! | `POST /api/sessions/{id}/ping`, `…/close` | keep alive; free the slot |
//!
//! A frame: `revision`, `size`, `seed`, `history {undo, redo}`,
//! `timing_ms {queued, edits, synth, render, total}`, `changed {pixels,
//! bounds}`, `rebuilt`, `heights_m {min, max}`, `overlay {curves,
//! junctions}`, `view` (and `scene` after undo/redo/create); or
//! `{"superseded": true}` when a newer document replaced it in the queue.

use super::editor::{Handle, Reply, Task};
use super::error::ApiError;
use super::view::View;
use super::{App, DbState, assets};
use crate::database::Database;
use crate::heightfield::Heightfield;
use crate::io::{self, Format, WriteOptions};
use axum::Router;
use axum::body::{Body, Bytes};
use axum::extract::rejection::BytesRejection;
use axum::extract::{DefaultBodyLimit, Path, RawQuery, Request, State};
use axum::http::{HeaderMap, HeaderValue, Method, StatusCode, header};
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
        .route("/api/exemplars/{index}/preview.png", get(exemplar))
        .route("/api/sessions", post(create))
        .route("/api/sessions/{id}", get(state))
        .route("/api/sessions/{id}/scene", put(put_scene))
        .route("/api/sessions/{id}/undo", post(undo))
        .route("/api/sessions/{id}/redo", post(redo))
        .route("/api/sessions/{id}/view", put(put_view))
        .route("/api/sessions/{id}/preview.png", get(preview))
        .route("/api/sessions/{id}/tile.png", get(tile))
        .route("/api/sessions/{id}/heights", get(heights))
        .route("/api/sessions/{id}/export", get(export))
        .route("/api/sessions/{id}/save", post(save))
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
    if !app.hosts.is_empty() && !app.hosts.contains(&host) {
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
        "no such page or endpoint (see the API table in src/server/routes.rs)".into(),
    )
}

async fn method_not_allowed(method: Method) -> Response {
    let e = ApiError::malformed("$", format!("method {method} is not allowed here"));
    (StatusCode::METHOD_NOT_ALLOWED, axum::Json(e.body())).into_response()
}

async fn index() -> Response {
    asset_response("index.html")
}

async fn asset(Path(path): Path<String>) -> Response {
    asset_response(&path)
}

fn asset_response(path: &str) -> Response {
    match assets::get(path) {
        Some((mime, bytes)) => ([(header::CONTENT_TYPE, mime)], bytes).into_response(),
        None => ApiError::NotFound(format!("no asset {path:?}")).into_response(),
    }
}

impl App {
    fn ready(&self) -> Result<&'static Database, ApiError> {
        match &*self.db.read().unwrap_or_else(|e| e.into_inner()) {
            DbState::Ready(db) => Ok(db),
            DbState::Loading => Err(ApiError::NotReady(
                "the exemplar database is still loading; the page shows its progress".into(),
            )),
            DbState::Failed(e) => Err(ApiError::NotReady(e.clone())),
        }
    }
}

/// A JSON body (empty allowed), with its media type checked.
fn json_body(headers: &HeaderMap, body: Result<Bytes, BytesRejection>, limit: usize) -> Api<Bytes> {
    let body = body.map_err(|e| match e.status() {
        StatusCode::PAYLOAD_TOO_LARGE => ApiError::TooLarge { limit },
        _ => ApiError::malformed("$", e.body_text()),
    })?;
    if body.is_empty() {
        return Ok(body);
    }
    let json = headers
        .get(header::CONTENT_TYPE)
        .and_then(|v| v.to_str().ok())
        .is_some_and(|v| {
            v.split(';')
                .next()
                .is_some_and(|t| t.trim() == "application/json")
        });
    if !json {
        return Err(ApiError::MediaType);
    }
    Ok(body)
}

/// Query parameters; only `allowed` names, each at most once.
fn query(raw: Option<String>, allowed: &[&str]) -> Api<Vec<(String, String)>> {
    let pairs: Vec<(String, String)> = raw
        .as_deref()
        .unwrap_or("")
        .split('&')
        .filter(|p| !p.is_empty())
        .map(|p| {
            let (k, v) = p.split_once('=').unwrap_or((p, ""));
            (k.to_string(), v.to_string())
        })
        .collect();
    for (i, (k, _)) in pairs.iter().enumerate() {
        if !allowed.contains(&k.as_str()) {
            return Err(ApiError::malformed(
                k.clone(),
                format!("unknown parameter: expected {}", allowed.join(", ")),
            ));
        }
        if pairs[..i].iter().any(|(q, _)| q == k) {
            return Err(ApiError::malformed(k.clone(), "given more than once"));
        }
    }
    Ok(pairs)
}

fn flag(pairs: &[(String, String)], name: &str, default: bool) -> Api<bool> {
    match pairs
        .iter()
        .find(|(k, _)| k == name)
        .map(|(_, v)| v.as_str())
    {
        None => Ok(default),
        Some("true" | "1") => Ok(true),
        Some("false" | "0") => Ok(false),
        Some(v) => Err(ApiError::malformed(
            name,
            format!("{v:?} is not true or false"),
        )),
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
        "status": status,
        "error": error,
        "progress": {
            "stage": *p.stage.lock().unwrap_or_else(|e| e.into_inner()),
            "done": p.done.load(std::sync::atomic::Ordering::Relaxed),
            "total": p.total.load(std::sync::atomic::Ordering::Relaxed),
        },
        "database": database,
        "scene_file": app.scene_file.as_ref().map(|p| p.display().to_string()),
        "sessions": {"open": app.registry.open(), "limit": app.registry.limit},
        "max_request_bytes": app.max_request_bytes,
        "export_formats": Format::ALL.iter().filter(|f| f.can_write()).map(|f| f.name()).collect::<Vec<_>>(),
    }))
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

async fn exemplar(State(app): State<Arc<App>>, Path(index): Path<String>) -> Api<Response> {
    let db = app.ready()?;
    let count = db.meta().exemplars.len();
    let i = index
        .parse::<usize>()
        .ok()
        .filter(|&i| i < count)
        .ok_or_else(|| {
            ApiError::invalid(
                "index",
                format!("{index:?} is not an exemplar index in 0..={}", count - 1),
            )
        })?;
    let cached = app
        .exemplar_previews
        .lock()
        .unwrap_or_else(|e| e.into_inner())[i]
        .clone();
    let png = match cached {
        Some(p) => p,
        None => {
            let png = tokio::task::spawn_blocking(move || exemplar_png(db, i))
                .await
                .map_err(|e| ApiError::Internal(e.to_string()))??;
            let png = Arc::new(png);
            app.exemplar_previews
                .lock()
                .unwrap_or_else(|e| e.into_inner())[i] = Some(png.clone());
            png
        }
    };
    Ok(png_response(png.to_vec(), None))
}

/// An exemplar's level-0 heights, rendered like the terrain.
fn exemplar_png(db: &Database, i: usize) -> Api<Vec<u8>> {
    let r = db.level(0).layout.rects[i];
    let q = db.quantization();
    let n = r.texels() as usize;
    let start = r.offset as usize;
    let data: Vec<f32> = db.heights()[start..start + n]
        .iter()
        .map(|&u| q.metres(u as f64) as f32)
        .collect();
    let cell = db.meta().exemplars[i].cell_size_m;
    let hf = Heightfield::from_vec(r.width as usize, r.height as usize, cell, data)
        .map_err(|e| ApiError::Internal(e.to_string()))?;
    let style = super::view::Style::new(db);
    let view = View {
        range: false,
        ..View::default()
    };
    let image = style.render(&hf, None, view).map_err(ApiError::Internal)?;
    crate::render::encode_png(&image).map_err(|e| ApiError::Internal(e.to_string()))
}

fn png_response(bytes: Vec<u8>, download: Option<String>) -> Response {
    let mut r = ([(header::CONTENT_TYPE, "image/png")], bytes).into_response();
    r.headers_mut()
        .insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    if let Some(name) = download
        && let Ok(v) = HeaderValue::from_str(&format!("attachment; filename=\"{name}\""))
    {
        r.headers_mut().insert(header::CONTENT_DISPOSITION, v);
    }
    r
}

async fn create(
    State(app): State<Arc<App>>,
    headers: HeaderMap,
    body: Result<Bytes, BytesRejection>,
) -> Api {
    let db = app.ready()?;
    let body = json_body(&headers, body, app.max_request_bytes)?;
    let doc = if body.is_empty() {
        app.initial.clone()
    } else {
        let v: Value = serde_json::from_slice(&body)
            .map_err(|e| ApiError::malformed("$", format!("not valid JSON: {e}")))?;
        let o = v.as_object().ok_or_else(|| {
            ApiError::malformed("$", "expected an object {\"scene\": …} or no body")
        })?;
        if let Some(k) = o.keys().find(|k| *k != "scene") {
            return Err(ApiError::malformed(
                k.clone(),
                "unknown field: expected scene",
            ));
        }
        o.get("scene")
            .cloned()
            .ok_or_else(|| ApiError::malformed("scene", "missing: expected a scene document"))?
    };
    // Field paths inside {"scene": …} are the document's own.
    let scene = app.policy.check_value(&doc)?;
    let style = app
        .style
        .read()
        .unwrap_or_else(|e| e.into_inner())
        .clone()
        .ok_or_else(|| ApiError::NotReady("the database is not ready".into()))?;
    let policy = app.policy.clone();
    let (w, h) = (scene.width, scene.height);
    let (id, rx) = app
        .registry
        .admit(w, h, || Handle::spawn(db, policy, style, doc, scene))?;
    match reply(rx).await {
        Ok(axum::Json(mut frame)) => {
            frame["session"] = json!(id);
            Ok(axum::Json(frame))
        }
        Err(e) => {
            app.registry.close(&id);
            Err(e)
        }
    }
}

async fn state(State(app): State<Arc<App>>, Path(id): Path<String>) -> Api {
    let h = app.registry.get(&id)?;
    let latest = h
        .latest()
        .ok_or_else(|| ApiError::NotReady("the first frame is not ready".into()))?;
    Ok(axum::Json(
        json!({"revision": latest.revision, "scene": latest.committed}),
    ))
}

async fn put_scene(
    State(app): State<Arc<App>>,
    Path(id): Path<String>,
    RawQuery(raw): RawQuery,
    headers: HeaderMap,
    body: Result<Bytes, BytesRejection>,
) -> Api {
    let h = app.registry.get(&id)?;
    let q = query(raw, &["commit"])?;
    let commit = flag(&q, "commit", true)?;
    let body = json_body(&headers, body, app.max_request_bytes)?;
    if body.is_empty() {
        return Err(ApiError::malformed(
            "$",
            "expected a scene document as the body",
        ));
    }
    let (doc, scene) = app.policy.check(&body)?;
    reply(h.submit(Task::Scene {
        doc,
        scene: Box::new(scene),
        commit,
    }))
    .await
}

async fn undo(State(app): State<Arc<App>>, Path(id): Path<String>) -> Api {
    reply(app.registry.get(&id)?.submit(Task::Undo)).await
}

async fn redo(State(app): State<Arc<App>>, Path(id): Path<String>) -> Api {
    reply(app.registry.get(&id)?.submit(Task::Redo)).await
}

async fn put_view(
    State(app): State<Arc<App>>,
    Path(id): Path<String>,
    headers: HeaderMap,
    body: Result<Bytes, BytesRejection>,
) -> Api {
    let h = app.registry.get(&id)?;
    let body = json_body(&headers, body, app.max_request_bytes)?;
    let v: Value = serde_json::from_slice(&body)
        .map_err(|e| ApiError::malformed("$", format!("not valid JSON: {e}")))?;
    let o = v
        .as_object()
        .ok_or_else(|| ApiError::malformed("$", "expected an object of true/false layers"))?;
    let mut view = View::default();
    for (k, val) in o {
        let slot = match k.as_str() {
            "contours" => &mut view.contours,
            "types" => &mut view.types,
            "range" => &mut view.range,
            _ => {
                return Err(ApiError::malformed(
                    k.clone(),
                    "unknown layer: expected contours, types, range",
                ));
            }
        };
        *slot = val
            .as_bool()
            .ok_or_else(|| ApiError::invalid(k.clone(), format!("{val} is not true or false")))?;
    }
    reply(h.submit(Task::View(view))).await
}

fn latest(app: &App, id: &str) -> Api<super::editor::Latest> {
    app.registry
        .get(id)?
        .latest()
        .ok_or_else(|| ApiError::NotReady("the first frame is not ready".into()))
}

async fn preview(State(app): State<Arc<App>>, Path(id): Path<String>) -> Api<Response> {
    let h = app.registry.get(&id)?;
    let (revision, png) = tokio::task::spawn_blocking(move || h.preview_png())
        .await
        .map_err(|e| ApiError::Internal(e.to_string()))?
        .ok_or_else(|| ApiError::NotReady("the first frame is not ready".into()))??;
    let mut r = png_response(png.to_vec(), None);
    if let Ok(v) = HeaderValue::from_str(&revision.to_string()) {
        r.headers_mut().insert("x-revision", v);
    }
    Ok(r)
}

async fn tile(
    State(app): State<Arc<App>>,
    Path(id): Path<String>,
    RawQuery(raw): RawQuery,
) -> Api<Response> {
    let q = query(raw, &["revision"])?;
    let text = q
        .iter()
        .find(|(k, _)| k == "revision")
        .map(|(_, v)| v.as_str())
        .ok_or_else(|| ApiError::malformed("revision", "missing: expected a frame's revision"))?;
    let revision: u64 = text.parse().map_err(|_| {
        ApiError::malformed("revision", format!("{text:?} is not a revision number"))
    })?;
    let t = app.registry.get(&id)?.tile(revision).ok_or_else(|| {
        ApiError::NotFound(format!(
            "no tile of revision {revision}: it is too old (load preview.png instead)"
        ))
    })?;
    let mut r = png_response(t.png.to_vec(), None);
    let rect = t.rect.map(|v| v.to_string()).join(",");
    if let Ok(v) = HeaderValue::from_str(&rect) {
        r.headers_mut().insert("x-rect", v);
    }
    Ok(r)
}

/// At most this many samples per side in `heights`.
const HEIGHTS_SIDE: usize = 512;

async fn heights(State(app): State<Arc<App>>, Path(id): Path<String>) -> Api<Response> {
    let hf = latest(&app, &id)?.heightfield;
    let stride = hf.width().max(hf.height()).div_ceil(HEIGHTS_SIDE);
    let (w, h) = (hf.width().div_ceil(stride), hf.height().div_ceil(stride));
    let mut out = Vec::with_capacity(12 + 4 * w * h);
    for v in [w as u32, h as u32, stride as u32] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for y in 0..h {
        for x in 0..w {
            out.extend_from_slice(&hf.get(x * stride, y * stride).to_le_bytes());
        }
    }
    Ok(([(header::CONTENT_TYPE, "application/octet-stream")], out).into_response())
}

/// File extension of a writable format.
fn extension(f: Format) -> &'static str {
    match f {
        Format::Png16 | Format::Png8 => "png",
        Format::Tiff => "tif",
        other => other.name(),
    }
}

async fn export(
    State(app): State<Arc<App>>,
    Path(id): Path<String>,
    RawQuery(raw): RawQuery,
) -> Api<Response> {
    let q = query(raw, &["format", "sidecar"])?;
    let sidecar = flag(&q, "sidecar", false)?;
    let writable: Vec<&str> = Format::ALL
        .iter()
        .filter(|f| f.can_write())
        .map(|f| f.name())
        .collect();
    let expected = || format!("one of {}, or preview", writable.join(", "));
    let name = q
        .iter()
        .find(|(k, _)| k == "format")
        .map(|(_, v)| v.clone())
        .ok_or_else(|| {
            ApiError::malformed("format", format!("missing: expected {}", expected()))
        })?;
    let l = latest(&app, &id)?;
    let stem = app
        .scene_file
        .as_ref()
        .and_then(|p| p.file_stem())
        .map(|s| s.to_string_lossy().into_owned())
        .filter(|s| {
            s.chars()
                .all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c))
        })
        .unwrap_or_else(|| "terrain".into());
    if name == "preview" {
        let png =
            crate::render::encode_png(&l.image).map_err(|e| ApiError::Internal(e.to_string()))?;
        return Ok(png_response(png, Some(format!("{stem}-preview.png"))));
    }
    let format = Format::from_name(&name)
        .filter(|f| f.can_write())
        .ok_or_else(|| ApiError::invalid("format", format!("{name:?} is not {}", expected())))?;
    if sidecar && !format.uses_sidecar() {
        return Err(ApiError::invalid(
            "sidecar",
            format!("{format} has no sidecar: only png16, r16 and r32 do"),
        ));
    }
    let hf = l.heightfield.clone();
    let enc =
        tokio::task::spawn_blocking(move || io::encode(&hf, format, &WriteOptions::default()))
            .await
            .map_err(|e| ApiError::Internal(e.to_string()))?
            .map_err(|e| ApiError::Internal(format!("encoding {format} failed: {e}")))?;
    let (bytes, file, mime) = match (sidecar, enc.sidecar) {
        (true, Some(sc)) => (sc, format!("{stem}-terrain.json"), "application/json"),
        _ => (
            enc.bytes,
            format!("{stem}-terrain.{}", extension(format)),
            "application/octet-stream",
        ),
    };
    let mut r = ([(header::CONTENT_TYPE, mime)], Body::from(bytes)).into_response();
    if let Ok(v) = HeaderValue::from_str(&format!("attachment; filename=\"{file}\"")) {
        r.headers_mut().insert(header::CONTENT_DISPOSITION, v);
    }
    Ok(r)
}

async fn save(State(app): State<Arc<App>>, Path(id): Path<String>) -> Api {
    let l = latest(&app, &id)?;
    let path = app.scene_file.clone().ok_or(ApiError::NoSavePath)?;
    let text = serde_json::to_string_pretty(&l.committed)
        .map_err(|e| ApiError::Internal(e.to_string()))?;
    let p = path.clone();
    tokio::task::spawn_blocking(move || io::write_atomic(&p, text.as_bytes()))
        .await
        .map_err(|e| ApiError::Internal(e.to_string()))?
        .map_err(|e| ApiError::Internal(format!("saving failed: {e}")))?;
    Ok(axum::Json(
        json!({"path": path.display().to_string(), "revision": l.revision}),
    ))
}

async fn ping(State(app): State<Arc<App>>, Path(id): Path<String>) -> Api<StatusCode> {
    app.registry.get(&id)?.touch();
    Ok(StatusCode::NO_CONTENT)
}

async fn close(State(app): State<Arc<App>>, Path(id): Path<String>) -> Api<StatusCode> {
    match app.registry.close(&id) {
        true => Ok(StatusCode::NO_CONTENT),
        false => Err(ApiError::NoSession(id)),
    }
}
