//! What the editor's HTTP API answers when a request cannot be served: a
//! status code and a JSON body `{"error": {"status", "field", "message"}}`
//! whose `field` is the JSON path of the offending value (`$` for the body
//! itself, a query or path parameter's name otherwise), so the page can
//! point at it and a script can act on it.

use crate::scene::SceneError;
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use thiserror::Error;

/// A request the editor refuses or could not serve.
#[non_exhaustive]
#[derive(Debug, Error)]
pub enum ApiError {
    /// The body or a parameter is not what the endpoint reads (400).
    #[error("{field}: {message}")]
    Malformed { field: String, message: String },
    /// Well-formed, but a value is out of range or not allowed (422).
    #[error("{field}: {message}")]
    Invalid { field: String, message: String },
    /// A scene document that does not parse or check (422).
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The body is larger than `--max-request-mib` (413).
    #[error("the request body is larger than {limit} bytes")]
    TooLarge { limit: usize },
    /// A JSON body without `Content-Type: application/json` (415).
    #[error("the body must be sent with Content-Type: application/json")]
    MediaType,
    /// Unknown or closed session (404, field `id`: the path's session).
    #[error("no editor session {0:?}: it was closed, timed out or never existed; reload the page")]
    NoSession(String),
    /// No such resource (404).
    #[error("{0}")]
    NotFound(String),
    /// Every session slot is taken (503).
    #[error(
        "{open} editor sessions are open, the limit (--max-sessions {open}): close another tab; a tab not heard from for {idle_s} s gives its slot up"
    )]
    Full { open: usize, idle_s: u64 },
    /// Not enough memory for another session of this size (503).
    #[error(
        "a {width}x{height} session needs about {needed_mib} MiB and {available_mib} MiB are available: close another tab or choose a smaller size"
    )]
    Memory {
        width: usize,
        height: usize,
        needed_mib: u64,
        available_mib: u64,
    },
    /// The database is still loading, or failed to (503).
    #[error("{0}")]
    NotReady(String),
    /// Saving without a scene path (409).
    #[error(
        "this server was started without --scene, so it has no file to save to: restart it with --scene PATH, or use Download"
    )]
    NoSavePath,
    /// Another tab saved after this session's document was loaded (409,
    /// field `revision`: the page tells it from [`ApiError::NoSavePath`]).
    #[error(
        "{path} was saved from another tab after this one opened it: saving now would overwrite that work. Reload it (take the file's version), merge (this tab's changes on top of it), or save anyway to replace it"
    )]
    SaveConflict { path: String },
    /// A request from another site or host name (403).
    #[error("{0}")]
    Forbidden(String),
    /// Writing a file or encoding a result failed (500).
    #[error("{0}")]
    Internal(String),
}

impl ApiError {
    pub fn malformed(field: impl Into<String>, message: impl Into<String>) -> ApiError {
        ApiError::Malformed {
            field: field.into(),
            message: message.into(),
        }
    }

    pub fn invalid(field: impl Into<String>, message: impl Into<String>) -> ApiError {
        ApiError::Invalid {
            field: field.into(),
            message: message.into(),
        }
    }

    pub fn status(&self) -> StatusCode {
        match self {
            ApiError::Malformed { .. } => StatusCode::BAD_REQUEST,
            ApiError::Invalid { .. } | ApiError::Scene(_) => StatusCode::UNPROCESSABLE_ENTITY,
            ApiError::TooLarge { .. } => StatusCode::PAYLOAD_TOO_LARGE,
            ApiError::MediaType => StatusCode::UNSUPPORTED_MEDIA_TYPE,
            ApiError::NoSession(_) | ApiError::NotFound(_) => StatusCode::NOT_FOUND,
            ApiError::Full { .. } | ApiError::Memory { .. } | ApiError::NotReady(_) => {
                StatusCode::SERVICE_UNAVAILABLE
            }
            ApiError::NoSavePath | ApiError::SaveConflict { .. } => StatusCode::CONFLICT,
            ApiError::Forbidden(_) => StatusCode::FORBIDDEN,
            ApiError::Internal(_) => StatusCode::INTERNAL_SERVER_ERROR,
        }
    }

    /// The JSON path or parameter the error is about (`$`: the request).
    pub fn field(&self) -> &str {
        match self {
            ApiError::Malformed { field, .. } | ApiError::Invalid { field, .. } => field,
            ApiError::Scene(e) => &e.path,
            ApiError::NoSession(_) => "id",
            ApiError::SaveConflict { .. } => "revision",
            _ => "$",
        }
    }

    /// The message without the field (the field travels separately).
    pub fn message(&self) -> String {
        match self {
            ApiError::Malformed { message, .. } | ApiError::Invalid { message, .. } => {
                message.clone()
            }
            ApiError::Scene(e) => e.kind.to_string(),
            other => other.to_string(),
        }
    }

    /// The body this error is answered with.
    pub fn body(&self) -> serde_json::Value {
        serde_json::json!({
            "error": {
                "status": self.status().as_u16(),
                "field": self.field(),
                "message": self.message(),
            }
        })
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        (self.status(), axum::Json(self.body())).into_response()
    }
}
