//! Scene-file errors: every one names the file, the JSON path of the value
//! (e.g. `curves[2].widgets[0].height_m`) and what was expected.

use std::path::PathBuf;
use thiserror::Error;

/// A scene that cannot be used.
#[derive(Debug, Error)]
#[error("{}: {path}: {kind}", file.display())]
pub struct SceneError {
    /// The scene file (or `<scene>` for in-memory text).
    pub file: PathBuf,
    /// JSON path of the offending value; `$` for the document itself.
    pub path: String,
    /// Boxed: keeps `Result<_, SceneError>` small on the parser's hot path.
    pub kind: Box<SceneErrorKind>,
}

/// What was wrong.
#[non_exhaustive]
#[derive(Debug, Error)]
pub enum SceneErrorKind {
    #[error("not valid JSON: {0}")]
    Json(String),
    #[error("missing field: expected {0}")]
    Missing(&'static str),
    #[error("unknown field: expected one of {0}")]
    Unknown(String),
    #[error("{found} is invalid: expected {expected}")]
    Invalid { found: String, expected: String },
    #[error("unknown type name {name:?}: the database has {known}")]
    UnknownType { name: String, known: String },
    #[error(
        "mask is {width}x{height} but the scene is {scene_width}x{scene_height}: they must match"
    )]
    MaskSize {
        width: usize,
        height: usize,
        scene_width: usize,
        scene_height: usize,
    },
    #[error(transparent)]
    Io(#[from] crate::io::IoError),
    #[error(transparent)]
    Curve(#[from] crate::synth::control::curve::CurveError),
    #[error(transparent)]
    Render(#[from] crate::render::RenderError),
    #[error(transparent)]
    Session(#[from] crate::synth::session::SessionError),
    #[error(transparent)]
    Control(#[from] crate::synth::control::ControlError),
}

impl SceneError {
    pub fn new(
        file: impl Into<PathBuf>,
        path: impl Into<String>,
        kind: SceneErrorKind,
    ) -> SceneError {
        SceneError {
            file: file.into(),
            path: path.into(),
            kind: Box::new(kind),
        }
    }
}
