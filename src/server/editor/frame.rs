//! The state an editor thread owns: the [`Session`], the scene and
//! document as last applied, the undo history, the preview it patches, and
//! how to turn a task into a frame (edits of the session, or a new session
//! when a document cannot be an edit of it).

use super::checkpoints::{Checkpoint, Checkpoints, MAX_BYTES};
use super::view::{View, encode_rect, overlay};
use super::{Reply, Shared, Task};
use crate::backend::engine::Engine;
use crate::database::Database;
use crate::heightfield::Heightfield;
use crate::scene::{Scene, SceneEdits};
use crate::server::api::error::ApiError;
use crate::server::document::history::History;
use crate::server::document::rebuild_reason;
use crate::synth::session::{Frame, Session, change};
use crate::synth::union;
use image::RgbaImage;
use serde_json::{Value, json};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Milliseconds with 0.01 resolution.
fn ms(d: Duration) -> f64 {
    (d.as_secs_f64() * 1e5).round() / 100.0
}

/// Where the time of one frame went.
#[derive(Debug, Default, Clone, Copy)]
struct Timing {
    /// Keeping the state before a paste, or swapping a kept one in.
    keep: Duration,
    edits: Duration,
    synth: Duration,
    render: Duration,
}

/// The session and everything around it, owned by the thread.
pub struct Editor {
    shared: Shared,
    session: Session<'static>,
    edits: SceneEdits,
    scene: Scene,
    doc: Value,
    pub history: History,
    view: View,
    pub revision: u64,
    pub heightfield: Arc<Heightfield>,
    /// The preview, kept to patch: a frame re-renders only where it changed.
    pub image: RgbaImage,
    /// The painted type raster the preview shows.
    types: Option<Vec<u8>>,
    /// This frame's changed part of the preview: its rectangle and PNG.
    pub tile: Option<([usize; 4], Arc<Vec<u8>>)>,
    /// The last frame's change and timing, and why it rebuilt (if it did).
    changed: Option<(usize, Option<[usize; 4]>)>,
    timing: Timing,
    rebuilt: Option<&'static str>,
    /// A failed `Session::apply` after `SceneEdits` moved on: the next
    /// document starts a new session.
    stale: bool,
    /// The sculpt strokes this frame baked (`{index, targets}`).
    baked: Vec<Value>,
    /// States kept around pastes (undo and redo of a paste swap them).
    pub checkpoints: Checkpoints,
    /// Whether this frame's state was a kept one swapped in.
    restored: bool,
}

impl Editor {
    pub fn new(shared: Shared, doc: Value, scene: Scene) -> Result<Editor, ApiError> {
        let (session, edits, frame, timing) = start(shared.db, &shared.engine, &scene)?;
        let mut ed = Editor {
            shared,
            session,
            edits,
            history: History::new(doc.clone()),
            doc,
            scene,
            view: View::default(),
            revision: 0,
            heightfield: Arc::new(frame.heightfield),
            image: RgbaImage::new(0, 0),
            types: None,
            tile: None,
            changed: None,
            timing,
            rebuilt: None,
            stale: false,
            baked: Vec::new(),
            checkpoints: Checkpoints::default(),
            restored: false,
        };
        ed.render(true)?;
        Ok(ed)
    }

    pub fn run(&mut self, task: Task, waited: Duration) -> Reply {
        let t = Instant::now();
        let with_doc = !matches!(task, Task::Scene { .. });
        self.baked.clear();
        match task {
            Task::Scene {
                mut doc,
                mut scene,
                commit,
            } => {
                self.baked = self.bake(&mut doc, &mut scene)?;
                self.show(doc.clone(), *scene)?;
                if commit {
                    self.history.commit(doc);
                }
            }
            Task::Undo | Task::Redo => {
                let undo = matches!(task, Task::Undo);
                let doc = match undo {
                    true => self.history.undo().cloned(),
                    false => self.history.redo().cloned(),
                };
                let Some(doc) = doc else {
                    return Err(ApiError::invalid(
                        "$",
                        format!("nothing to {}", if undo { "undo" } else { "redo" }),
                    ));
                };
                let applied = self
                    .shared
                    .policy
                    .check_value(&doc)
                    .and_then(|scene| self.show(doc, scene));
                if let Err(e) = applied {
                    // Keep the cursor on what is shown.
                    match undo {
                        true => self.history.redo(),
                        false => self.history.undo(),
                    };
                    return Err(e);
                }
            }
            Task::View(v) => {
                self.view = v;
                self.changed = Some((0, None));
                self.timing = Timing::default();
                self.rebuilt = None;
                self.restored = false;
                self.render(true)?;
            }
        }
        self.revision += 1;
        Ok(self.frame_reply(Some(waited), t.elapsed(), with_doc))
    }

    /// Bakes the sculpt strokes the page has just painted (no targets yet)
    /// against the terrain shown, into `doc` and `scene`; returns their
    /// indices and targets for the reply (the page keeps them in its
    /// document, so later edits and undo carry them).
    fn bake(&self, doc: &mut Value, scene: &mut Scene) -> Result<Vec<Value>, ApiError> {
        if scene.sculpt.iter().all(|s| s.targets.is_some()) {
            return Ok(Vec::new());
        }
        let hf = &self.heightfield;
        if (hf.width(), hf.height()) != (scene.width, scene.height) {
            return Err(ApiError::invalid(
                "sculpt",
                "a new stroke is baked on the terrain shown: change the size or seed in its own edit",
            ));
        }
        let mut out = Vec::new();
        for i in scene.bake_sculpt(hf) {
            let targets = crate::scene::targets_json(&scene.sculpt[i]);
            if let Some(s) = doc.get_mut("sculpt").and_then(|s| s.get_mut(i)) {
                s["targets"] = targets.clone();
            }
            out.push(json!({"index": i, "targets": targets}));
        }
        Ok(out)
    }

    /// Applies a checked document: as edits of the session (from a kept
    /// state when one saves a paste or a new session, see
    /// [`Editor::restore`]), or in a new session when it cannot be an edit
    /// (see [`rebuild_reason`]).
    fn show(&mut self, doc: Value, scene: Scene) -> Result<(), ApiError> {
        let shown = self.heightfield.clone();
        let t = Instant::now();
        self.restored = self.restore(&scene);
        self.timing.keep = t.elapsed();
        self.rebuilt = match self.stale {
            true => Some("the previous edit failed"),
            false => rebuild_reason(&self.scene, &scene),
        };
        if self.rebuilt.is_some() {
            // The new session is built beside the old one (a new size is
            // checked as a new tab's is).
            crate::server::registry::check_memory(scene.width, scene.height)?;
            let (session, edits, frame, timing) =
                start(self.shared.db, &self.shared.engine, &scene)?;
            self.session = session;
            self.edits = edits;
            self.stale = false;
            self.timing = timing;
            self.changed = Some(change_of(&self.heightfield, &frame.heightfield));
            self.heightfield = Arc::new(frame.heightfield);
            self.checkpoints.clear();
        } else {
            // After a swap (a paste deleted before the last one, the later
            // ones pasted again) the newest kept state must stay the one
            // shown before, which an error below swaps back.
            if !self.restored && scene.pastes.len() > self.scene.pastes.len() {
                let t = Instant::now();
                self.keep();
                self.timing.keep += t.elapsed();
            }
            let t = Instant::now();
            let list = match self.edits.edits(&scene, self.shared.db) {
                Ok(list) => list,
                Err(e) => {
                    if self.restored {
                        // Show what was shown: the state left is the newest kept.
                        self.restored = false;
                        self.swap_in_newest();
                    }
                    return Err(e.into());
                }
            };
            self.timing.edits = t.elapsed();
            if list.is_empty() {
                self.timing.synth = Duration::ZERO;
                self.changed = Some((0, None));
            } else {
                let frame = self.session.apply(list).map_err(|e| {
                    self.stale = true;
                    ApiError::invalid("$", e.to_string())
                })?;
                self.timing.synth = frame.time;
                self.changed = frame.change.map(|c| (c.pixels, c.bounds));
                self.heightfield = Arc::new(frame.heightfield);
            }
            if self.restored {
                // What the page shows changes by the swap and the edits.
                self.changed = Some(change_of(&shown, &self.heightfield));
            }
        }
        self.scene = scene;
        self.doc = doc;
        self.render(self.rebuilt.is_some())
    }

    /// Keeps the session's state before a paste, unless it could not be
    /// kept within [`MAX_BYTES`] or the system is short of memory (then
    /// undoing the paste starts a new session, as without a kept state).
    fn keep(&mut self) {
        let bytes = self.session.snapshot_bytes();
        let short = crate::io::available_memory().is_some_and(|a| a < 2 * bytes as u64);
        if bytes > MAX_BYTES || short {
            return;
        }
        let state = match self
            .checkpoints
            .recycle(Checkpoint::bytes_for(bytes, &self.edits))
        {
            Some(mut s) => {
                self.session.snapshot_into(&mut s);
                s
            }
            None => self.session.snapshot(),
        };
        self.checkpoints.push(Checkpoint::new(
            self.scene.clone(),
            self.edits.clone(),
            state,
            self.heightfield.clone(),
        ));
    }

    /// Swaps in a kept state that has `scene`'s pastes when the shown one
    /// has other pastes (undo, redo or delete of a paste): no synthesis,
    /// where a new session or the paste would take one. When none has
    /// them and the shown state holds a paste `scene` lacks (a paste
    /// deleted before the last one), the kept state with most of `scene`'s
    /// first pastes: the edits then paste the rest again. The state left
    /// is kept in its place (redo swaps it back). True when it swapped.
    fn restore(&mut self, scene: &Scene) -> bool {
        if self.stale || self.scene.pastes == scene.pastes {
            return false;
        }
        let shown_fits = scene.pastes.starts_with(&self.scene.pastes);
        match self.checkpoints.take(scene, !shown_fits) {
            Some(c) => self.swap_in(c),
            None => false,
        }
    }

    /// Swaps in the newest kept state (it has the scene shown before the
    /// last swap).
    fn swap_in_newest(&mut self) {
        if let Some(c) = self.checkpoints.take_newest() {
            self.swap_in(c);
        }
    }

    /// Swaps in a kept state and keeps the one it replaces.
    fn swap_in(&mut self, mut c: Checkpoint) -> bool {
        if !self.session.swap(&mut c.state) {
            return false;
        }
        std::mem::swap(&mut self.edits, &mut c.edits);
        std::mem::swap(&mut self.scene, &mut c.scene);
        std::mem::swap(&mut self.heightfield, &mut c.heightfield);
        // Its size changed with what it holds now.
        let c = Checkpoint::new(c.scene, c.edits, c.state, c.heightfield);
        self.checkpoints.push(c);
        true
    }

    /// Updates the preview: the whole of it (`whole`, or when it is
    /// scaled), else only where heights or painted types changed, grown by
    /// the `shade` stage's one-pixel reach.
    fn render(&mut self, whole: bool) -> Result<(), ApiError> {
        let t = Instant::now();
        let fail = |e: String| ApiError::Internal(format!("rendering the preview failed: {e}"));
        let types = self.edits.type_raster().map(<[u8]>::to_vec);
        let (w, h) = (self.heightfield.width(), self.heightfield.height());
        let heights = self.changed.and_then(|(_, b)| b).map(|b| {
            [
                b[0].saturating_sub(1),
                b[1].saturating_sub(1),
                (b[2] + 1).min(w),
                (b[3] + 1).min(h),
            ]
        });
        let painted = if self.view.types {
            type_change(self.types.as_deref(), types.as_deref(), w)
        } else {
            None
        };
        let mut rect = union(heights, painted);
        // A whole render when asked, for the first frame, or when the
        // window cannot be patched in place.
        let (shared, hf, view) = (&self.shared, &self.heightfield, self.view);
        let mut whole = whole || self.image.width() == 0;
        if let (false, Some(r)) = (whole, rect) {
            let done = (shared.style)
                .render_window(
                    &shared.engine,
                    hf,
                    types.as_deref(),
                    view,
                    &mut self.image,
                    r,
                )
                .map_err(fail)?;
            whole = !done;
        }
        if whole {
            self.image = (shared.style)
                .render(&shared.engine, hf, types.as_deref(), view)
                .map_err(fail)?;
            let (w, h) = (self.image.width() as usize, self.image.height() as usize);
            rect = Some([0, 0, w, h]);
        }
        self.tile = match rect {
            Some(r) => Some((r, Arc::new(encode_rect(&self.image, r).map_err(fail)?))),
            None => None,
        };
        self.types = types;
        self.timing.render = t.elapsed();
        Ok(())
    }

    pub fn frame_reply(&self, waited: Option<Duration>, total: Duration, with_doc: bool) -> Value {
        let stats = self.heightfield.stats();
        let (undo, redo) = self.history.counts();
        let mut reply = json!({
            "revision": self.revision,
            "size": [self.scene.width, self.scene.height],
            "seed": self.scene.seed,
            "backend": self.session.synthesizer().backend_name(),
            "history": {"undo": undo, "redo": redo},
            "timing_ms": {
                "queued": waited.map(ms).unwrap_or(0.0),
                "keep": ms(self.timing.keep),
                "edits": ms(self.timing.edits),
                "synth": ms(self.timing.synth),
                "render": ms(self.timing.render),
                "total": ms(total),
            },
            "changed": self.changed.map(|(pixels, bounds)| json!({"pixels": pixels, "bounds": bounds})),
            "rebuilt": self.rebuilt,
            "restored": self.restored,
            "heights_m": stats.map(|s| json!({"min": s.min, "max": s.max})),
            "overlay": overlay(&self.edits, &self.scene),
            "view": self.view,
            "tile": self.tile.as_ref().map(|(rect, _)| json!({"revision": self.revision, "rect": rect})),
        });
        if with_doc {
            reply["scene"] = self.doc.clone();
        }
        if !self.baked.is_empty() {
            reply["baked"] = Value::from(self.baked.clone());
        }
        reply
    }
}

/// A new session on `scene` running on `engine`, with its first frame.
fn start(
    db: &'static Database,
    engine: &Engine,
    scene: &Scene,
) -> Result<(Session<'static>, SceneEdits, Frame, Timing), ApiError> {
    let mut edits = SceneEdits::new();
    let t = Instant::now();
    let list = edits.edits(scene, db)?;
    let edits_time = t.elapsed();
    let mut session =
        SceneEdits::session(db, scene).map_err(|e| ApiError::invalid("$", e.to_string()))?;
    session
        .synthesizer_mut()
        .use_engine(engine.clone())
        .map_err(|e| ApiError::Internal(e.to_string()))?;
    let frame = session
        .apply(list)
        .map_err(|e| ApiError::invalid("$", e.to_string()))?;
    let timing = Timing {
        keep: Duration::ZERO,
        edits: edits_time,
        synth: frame.time,
        render: Duration::ZERO,
    };
    Ok((session, edits, frame, timing))
}

/// Bounds of the pixels whose painted type differs (`None` = nothing
/// painted, all 255).
fn type_change(old: Option<&[u8]>, new: Option<&[u8]>, width: usize) -> Option<[usize; 4]> {
    let at = |m: Option<&[u8]>, k: usize| m.map_or(255, |m| m[k]);
    let n = old.or(new)?.len();
    let mut b: Option<[usize; 4]> = None;
    for k in (0..n).filter(|&k| at(old, k) != at(new, k)) {
        let (x, y) = (k % width, k / width);
        b = union(b, Some([x, y, x + 1, y + 1]));
    }
    b
}

/// Pixels that differ between two heightfields, and their bounds (all
/// when sizes differ).
fn change_of(old: &Heightfield, new: &Heightfield) -> (usize, Option<[usize; 4]>) {
    if (old.width(), old.height()) != (new.width(), new.height()) {
        return (new.len(), Some([0, 0, new.width(), new.height()]));
    }
    let c = change(old, new);
    (c.pixels, c.bounds)
}
