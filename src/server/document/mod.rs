//! Scene documents as the editor exchanges them: the scene-file JSON of
//! [`crate::scene`] itself, so a design made in the page is a scene the CLI
//! reads (`terrasynth synth --scene`) and the reverse.
//!
//! The page sends the whole document with every edit. That keeps one
//! format and one validator (every error names the JSON path of the value,
//! e.g. `points[2].radius_px`), lets [`crate::scene::SceneEdits`] find what
//! changed, and makes coalescing trivially right: the newest document is
//! the whole truth, so a queued older one can simply be dropped.
//!
//! What the server does not let a document change, because it would read
//! or write files the user did not choose: the database (fixed when the
//! server starts), and the image forms of type paint and freezing
//! (`types.image`, `freeze.mask`) other than those of the scene file the
//! server was started with. The editor paints strokes.
//!
//! Its parts: undo and redo (`history.rs`), kept as differences between
//! documents (`patch.rs`), and the merge of a tab's changes into a file
//! another tab saved since (`merge.rs`).

pub(super) mod history;
pub(super) mod merge;
mod patch;

use crate::scene::{Freeze, Scene, TypePaint};
use crate::server::api::error::ApiError;
use serde_json::{Value, json};
use std::path::{Path, PathBuf};

/// What every document must agree with.
#[derive(Debug, Clone)]
pub struct Policy {
    /// The scene file (anchors relative paths, names the file in errors).
    pub file: PathBuf,
    /// The database every document must name (resolved), `None` for the
    /// embedded one.
    pub database: Option<PathBuf>,
    /// The document's `database` value, as the first document had it.
    pub database_value: Option<Value>,
    /// Image paths the scene file given to the server used.
    pub types_image: Option<PathBuf>,
    pub freeze_mask: Option<PathBuf>,
}

impl Policy {
    /// Parses and checks a document's bytes.
    pub fn check(&self, bytes: &[u8]) -> Result<(Value, Scene), ApiError> {
        let doc: Value = serde_json::from_slice(bytes)
            .map_err(|e| ApiError::malformed("$", format!("not valid JSON: {e}")))?;
        let scene = self.check_value(&doc)?;
        Ok((doc, scene))
    }

    /// Checks a parsed document.
    pub fn check_value(&self, doc: &Value) -> Result<Scene, ApiError> {
        let bytes = serde_json::to_vec(doc).map_err(|e| ApiError::Internal(e.to_string()))?;
        let scene = Scene::parse(&bytes, &self.file)?;
        if !same_path(scene.database.as_deref(), self.database.as_deref()) {
            return Err(ApiError::invalid(
                "database",
                format!(
                    "this server edits with {}; the database is chosen when the server starts (--db)",
                    match &self.database_value {
                        Some(v) => v.to_string(),
                        None => "the embedded database (no \"database\" field)".into(),
                    }
                ),
            ));
        }
        if let Some(TypePaint::Image(p)) = &scene.types
            && !same_path(Some(p), self.types_image.as_deref())
        {
            return Err(ApiError::invalid(
                "types.image",
                "the editor reads only the type image of the scene file it was started with; paint strokes instead",
            ));
        }
        if let Some(Freeze::Mask(p)) = &scene.freeze
            && !same_path(Some(p), self.freeze_mask.as_deref())
        {
            return Err(ApiError::invalid(
                "freeze.mask",
                "the editor reads only the freeze mask of the scene file it was started with; paint strokes instead",
            ));
        }
        Ok(scene)
    }
}

/// Whether two optional paths name the same file (compared as absolute
/// paths, without touching the file system).
fn same_path(a: Option<&Path>, b: Option<&Path>) -> bool {
    let abs = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    match (a, b) {
        (None, None) => true,
        (Some(a), Some(b)) => abs(a) == abs(b),
        _ => false,
    }
}

/// A document with no controls.
pub fn blank(width: usize, height: usize, seed: u32, database: Option<&Value>) -> Value {
    let mut doc = json!({
        "version": 2,
        "size": [width, height],
        "seed": seed,
        "points": [],
        "curves": [],
    });
    if let Some(db) = database {
        doc["database"] = db.clone();
    }
    doc
}

/// Why `new` cannot be an edit of the session that shows `old` (it needs a
/// new session), or `None` when it can. A session keeps its size, seed and
/// parameters, and its pastes are permanent (paper §5.3: a pasted region
/// stays frozen), so removing or changing one starts over.
pub fn rebuild_reason(old: &Scene, new: &Scene) -> Option<&'static str> {
    if (old.width, old.height) != (new.width, new.height) {
        Some("size changed")
    } else if old.seed != new.seed {
        Some("seed changed")
    } else if old.jitter != new.jitter || old.passes != new.passes {
        Some("synthesis parameters changed")
    } else if old.start_exemplar != new.start_exemplar {
        Some("start exemplar changed")
    } else if new.pastes.len() < old.pastes.len()
        || old.pastes.iter().zip(&new.pastes).any(|(a, b)| a != b)
    {
        Some("a paste was removed or changed")
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn policy() -> Policy {
        Policy {
            file: PathBuf::from("/tmp/editor/scene.json"),
            database: None,
            database_value: None,
            types_image: None,
            freeze_mask: None,
        }
    }

    #[test]
    fn errors_name_the_field() {
        let p = policy();
        let e = p.check(b"{\"size\": [64, 64]").unwrap_err();
        assert_eq!((e.status().as_u16(), e.field()), (400, "$"));
        let e = p
            .check(br#"{"size": [64, 64], "seed": 1, "points": [{"at": [1, 1], "height_m": 1, "radius_px": -3}]}"#)
            .unwrap_err();
        assert_eq!(
            (e.status().as_u16(), e.field()),
            (422, "points[0].radius_px")
        );
        let e = p
            .check(br#"{"size": [64, 64], "seed": 1, "database": "other.tsdb"}"#)
            .unwrap_err();
        assert_eq!(e.field(), "database");
        let e = p
            .check(br#"{"size": [64, 64], "seed": 1, "types": {"image": "/etc/t.png"}}"#)
            .unwrap_err();
        assert_eq!(e.field(), "types.image");
        let e = p
            .check(br#"{"size": [64, 64], "seed": 1, "freeze": {"mask": "m.png"}}"#)
            .unwrap_err();
        assert_eq!(e.field(), "freeze.mask");
        assert!(
            p.check(blank(64, 64, 1, None).to_string().as_bytes())
                .is_ok()
        );
    }

    #[test]
    fn pastes_and_parameters_need_a_new_session() {
        let p = policy();
        let scene = |extra: Value| {
            let mut d = blank(64, 64, 1, None);
            for (k, v) in extra.as_object().unwrap() {
                d[k] = v.clone();
            }
            p.check_value(&d).unwrap()
        };
        let paste = json!({"source": "terrain", "lasso": [[1, 1], [9, 1], [5, 8]], "to": [30, 30]});
        let a = scene(json!({}));
        let b = scene(json!({"pastes": [paste.clone()]}));
        assert_eq!(rebuild_reason(&a, &b), None);
        assert!(rebuild_reason(&b, &a).is_some());
        let mut moved = paste.clone();
        moved["to"] = json!([31, 30]);
        assert!(rebuild_reason(&b, &scene(json!({"pastes": [moved]}))).is_some());
        assert!(rebuild_reason(&a, &scene(json!({"seed": 2}))).is_some());
        assert!(rebuild_reason(&a, &scene(json!({"size": [64, 32]}))).is_some());
        let point = json!([{"at": [3, 3], "height_m": 10, "radius_px": 4}]);
        assert_eq!(rebuild_reason(&a, &scene(json!({"points": point}))), None);
    }
}
