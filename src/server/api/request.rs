//! Reading what a request carries: its JSON body (media type and size
//! checked), query parameters, and the small bodies of the view and
//! new-session endpoints. Pure functions apart from [`json_body`], fuzzed
//! by `fuzz/fuzz_targets/documents/editor_request.rs`; scene documents themselves
//! go through [`crate::scene`]'s parser (its own fuzz target).

use super::error::ApiError;
use crate::server::editor::view::View;
use axum::body::Bytes;
use axum::extract::path::ErrorKind;
use axum::extract::rejection::{BytesRejection, PathRejection};
use axum::extract::{FromRequestParts, Path};
use axum::http::request::Parts;
use axum::http::{HeaderMap, StatusCode, header};
use serde_json::Value;

type Api<T> = Result<T, ApiError>;

/// The one parameter of a route's path (`{id}`, `{index}`, `{*path}`),
/// percent-decoded; one that is not UTF-8 is a 400 naming the parameter
/// (axum's own rejection would be plain text).
pub struct PathParam(pub String);

impl<S: Send + Sync> FromRequestParts<S> for PathParam {
    type Rejection = ApiError;

    async fn from_request_parts(parts: &mut Parts, state: &S) -> Api<PathParam> {
        match Path::<String>::from_request_parts(parts, state).await {
            Ok(Path(v)) => Ok(PathParam(v)),
            Err(PathRejection::FailedToDeserializePathParams(e)) => {
                let field = match e.kind() {
                    ErrorKind::InvalidUtf8InPathParam { key }
                    | ErrorKind::ParseErrorAtKey { key, .. }
                    | ErrorKind::DeserializeError { key, .. } => key.clone(),
                    _ => "$".into(),
                };
                Err(ApiError::malformed(field, e.body_text()))
            }
            Err(e) => Err(ApiError::malformed("$", e.body_text())),
        }
    }
}

/// A JSON body (empty allowed), with its media type checked.
pub fn json_body(
    headers: &HeaderMap,
    body: Result<Bytes, BytesRejection>,
    limit: usize,
) -> Api<Bytes> {
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

/// Query parameters (`a=1&b=x`, taken as they are: the API's values need
/// no percent-decoding); only `allowed` names, each at most once.
pub fn query(raw: Option<&str>, allowed: &[&str]) -> Api<Vec<(String, String)>> {
    let pairs: Vec<(String, String)> = raw
        .unwrap_or("")
        .split('&')
        .filter(|p| !p.is_empty())
        .map(|p| {
            let (k, v) = p.split_once('=').unwrap_or((p, ""));
            (k.to_string(), v.to_string())
        })
        .collect();
    for (i, (k, _)) in pairs.iter().enumerate() {
        if k.is_empty() {
            return Err(ApiError::malformed("$", "a query parameter without a name"));
        }
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

/// A true/false parameter.
pub fn flag(pairs: &[(String, String)], name: &str, default: bool) -> Api<bool> {
    match param(pairs, name) {
        None => Ok(default),
        Some("true" | "1") => Ok(true),
        Some("false" | "0") => Ok(false),
        Some(v) => Err(ApiError::malformed(
            name,
            format!("{v:?} is not true or false"),
        )),
    }
}

/// The one flag of a query that must give it: each value is a different
/// action (reload or merge, keep or discard), so there is no default, and
/// `missing` (the error when it is left out) says what each value does.
pub fn required_flag(raw: Option<&str>, name: &str, missing: &str) -> Api<bool> {
    let pairs = query(raw, &[name])?;
    match param(&pairs, name) {
        None => Err(ApiError::malformed(name, missing)),
        Some(_) => flag(&pairs, name, false),
    }
}

/// A parameter's value, if given.
pub fn param<'a>(pairs: &'a [(String, String)], name: &str) -> Option<&'a str> {
    pairs
        .iter()
        .find(|(k, _)| k == name)
        .map(|(_, v)| v.as_str())
}

fn json(body: &[u8]) -> Api<Value> {
    serde_json::from_slice(body)
        .map_err(|e| ApiError::malformed("$", format!("not valid JSON: {e}")))
}

/// `PUT …/view`: `{"contours", "types", "range"}`, each true or false
/// (absent = shown).
pub fn view(body: &[u8]) -> Api<View> {
    let v = json(body)?;
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
    Ok(view)
}

/// `POST /api/sessions`: no body (the server's scene), or `{"scene": doc}`
/// (the document, checked later with its own paths).
pub fn new_session(body: &[u8]) -> Api<Option<Value>> {
    if body.is_empty() {
        return Ok(None);
    }
    let v = json(body)?;
    let o = v
        .as_object()
        .ok_or_else(|| ApiError::malformed("$", "expected an object {\"scene\": …} or no body"))?;
    if let Some(k) = o.keys().find(|k| *k != "scene") {
        return Err(ApiError::malformed(
            k.clone(),
            "unknown field: expected scene",
        ));
    }
    o.get("scene")
        .cloned()
        .map(Some)
        .ok_or_else(|| ApiError::malformed("scene", "missing: expected a scene document"))
}

/// `?revision=N` of a tile.
pub fn revision(pairs: &[(String, String)]) -> Api<u64> {
    let text = param(pairs, "revision")
        .ok_or_else(|| ApiError::malformed("revision", "missing: expected a frame's revision"))?;
    text.parse()
        .map_err(|_| ApiError::malformed("revision", format!("{text:?} is not a revision number")))
}
