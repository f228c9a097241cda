//! What comes out of a session besides frames: the preview and its tiles,
//! sampled heights, exports (downloads in any writable format), the saved
//! scene file, and exemplar previews.

use super::error::ApiError;
use super::request::{self, PathParam};
use crate::backend::engine::Engine;
use crate::database::Database;
use crate::io::{self, Format, WriteOptions};
use crate::server::App;
use crate::server::editor::view::View;
use axum::body::Body;
use axum::extract::{RawQuery, State};
use axum::http::{HeaderValue, header};
use axum::response::{IntoResponse, Response};
use serde_json::json;
use std::sync::Arc;

type Api<T = axum::Json<serde_json::Value>> = Result<T, ApiError>;

pub async fn exemplar(State(app): State<Arc<App>>, PathParam(index): PathParam) -> Api<Response> {
    let db = app.ready()?;
    let count = db.meta().exemplars.len();
    let i = index
        .parse::<usize>()
        .ok()
        .filter(|&i| i < count)
        .ok_or_else(|| {
            ApiError::invalid(
                "index",
                format!("{index:?} is not an exemplar index in 0..{count}"),
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
            let engine = app.engine.clone();
            let png = tokio::task::spawn_blocking(move || exemplar_png(db, &engine, i))
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

/// An exemplar's level-0 heights, rendered like the terrain (on `engine`).
fn exemplar_png(db: &Database, engine: &Engine, i: usize) -> Api<Vec<u8>> {
    let hf = db.exemplar(i);
    let style = crate::server::editor::view::Style::new(db);
    let view = View {
        range: false,
        ..View::default()
    };
    let image = style
        .render(engine, &hf, None, view)
        .map_err(ApiError::Internal)?;
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

fn latest(app: &App, id: &str) -> Api<crate::server::editor::Latest> {
    app.registry
        .get(id)?
        .latest()
        .ok_or_else(|| ApiError::NotReady("the first frame is not ready".into()))
}

pub async fn preview(State(app): State<Arc<App>>, PathParam(id): PathParam) -> Api<Response> {
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

pub async fn tile(
    State(app): State<Arc<App>>,
    PathParam(id): PathParam,
    RawQuery(raw): RawQuery,
) -> Api<Response> {
    let revision = request::revision(&request::query(raw.as_deref(), &["revision"])?)?;
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

pub async fn heights(State(app): State<Arc<App>>, PathParam(id): PathParam) -> Api<Response> {
    let l = latest(&app, &id)?;
    let hf = l.heightfield;
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
    Ok((
        [
            (header::CONTENT_TYPE, "application/octet-stream".to_string()),
            (
                header::HeaderName::from_static("x-revision"),
                l.revision.to_string(),
            ),
        ],
        out,
    )
        .into_response())
}

/// File extension of a writable format.
fn extension(f: Format) -> &'static str {
    match f {
        Format::Png16 | Format::Png8 => "png",
        Format::Tiff => "tif",
        other => other.name(),
    }
}

pub async fn export(
    State(app): State<Arc<App>>,
    PathParam(id): PathParam,
    RawQuery(raw): RawQuery,
) -> Api<Response> {
    let q = request::query(raw.as_deref(), &["format", "sidecar"])?;
    let sidecar = request::flag(&q, "sidecar", false)?;
    let writable: Vec<&str> = Format::ALL
        .iter()
        .filter(|f| f.can_write())
        .map(|f| f.name())
        .collect();
    let expected = || format!("one of {}, or preview", writable.join(", "));
    let name = request::param(&q, "format")
        .ok_or_else(|| ApiError::malformed("format", format!("missing: expected {}", expected())))?
        .to_string();
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
    // A format with a sidecar names both files after itself: the reader
    // finds `X.json` beside `X.png`, and the png16, r16 and r32 sidecars of
    // one terrain, downloaded to one folder, no longer overwrite each other.
    let base = match format.uses_sidecar() {
        true => format!("{stem}-terrain-{}", format.name()),
        false => format!("{stem}-terrain"),
    };
    let (bytes, file, mime) = match (sidecar, enc.sidecar) {
        (true, Some(sc)) => (sc, format!("{base}.json"), "application/json"),
        _ => (
            enc.bytes,
            format!("{base}.{}", extension(format)),
            "application/octet-stream",
        ),
    };
    let mut r = ([(header::CONTENT_TYPE, mime)], Body::from(bytes)).into_response();
    if let Ok(v) = HeaderValue::from_str(&format!("attachment; filename=\"{file}\"")) {
        r.headers_mut().insert(header::CONTENT_DISPOSITION, v);
    }
    Ok(r)
}

/// `POST /api/sessions/{id}/save[?force=true]`: writes the session's
/// committed document to the scene file — refused (409) when another tab
/// saved after this session's document was loaded, unless forced.
pub async fn save(
    State(app): State<Arc<App>>,
    PathParam(id): PathParam,
    RawQuery(raw): RawQuery,
) -> Api {
    let q = request::query(raw.as_deref(), &["force"])?;
    let force = request::flag(&q, "force", false)?;
    let h = app.registry.get(&id)?;
    let l = latest(&app, &id)?;
    let path = app.scene_file.clone().ok_or(ApiError::NoSavePath)?;
    let text = serde_json::to_string_pretty(&l.committed)
        .map_err(|e| ApiError::Internal(e.to_string()))?;
    // Held across the write: two saves never interleave.
    let mut saved = app.saved.lock().await;
    if !force && h.base().0 != saved.revision {
        return Err(ApiError::SaveConflict {
            path: path.display().to_string(),
        });
    }
    let p = path.clone();
    tokio::task::spawn_blocking(move || io::write_atomic(&p, text.as_bytes()))
        .await
        .map_err(|e| ApiError::Internal(e.to_string()))?
        .map_err(|e| ApiError::Internal(format!("saving failed: {e}")))?;
    if let Some(a) = &app.autosave {
        a.saved(&h);
    }
    saved.doc = Arc::new(l.committed.clone());
    saved.revision += 1;
    h.set_base(saved.revision, saved.doc.clone());
    Ok(axum::Json(
        json!({"path": path.display().to_string(), "revision": l.revision}),
    ))
}
