//! One editor session: a thread that owns a [`Session`] (paper §5.3:
//! coherent re-synthesis of only what an edit changed), the scene as last
//! applied, the undo history and the last preview, and works through a
//! queue of requests from one browser tab.
//!
//! Coalescing (latest wins): a scene document that arrives while another
//! is still queued replaces it, and the replaced request is answered
//! `{"superseded": true}` at once. While a person drags a handle the page
//! sends a document per mouse move; the session never works on a stale
//! one, and a drag costs one synthesis per synthesis time, not per event.
//! Undo, redo and view changes are never dropped.
//!
//! The thread catches a panic of the engine, answers 500 and closes the
//! session, so one bad edit cannot take the server down.

use super::doc::{Policy, rebuild_reason};
use super::error::ApiError;
use super::history::History;
use super::view::{Style, View, encode_rect, overlay};
use crate::database::Database;
use crate::heightfield::Heightfield;
use crate::scene::{Scene, SceneEdits};
use crate::synth::session::{Frame, Session};
use image::RgbaImage;
use serde_json::{Value, json};
use std::collections::VecDeque;
use std::sync::{Arc, Condvar, Mutex, RwLock};
use std::time::{Duration, Instant};
use tokio::sync::oneshot;

/// A reply: the frame's description (JSON) or why there is none.
pub type Reply = Result<Value, ApiError>;

/// What a tab asks of its session.
#[derive(Debug)]
pub enum Task {
    /// Show this document; `commit` makes it an undo step.
    Scene {
        doc: Value,
        scene: Box<Scene>,
        commit: bool,
    },
    Undo,
    Redo,
    View(View),
}

struct Job {
    task: Task,
    reply: oneshot::Sender<Reply>,
    queued: Instant,
}

#[derive(Default)]
struct Queue {
    jobs: VecDeque<Job>,
    closed: bool,
}

/// What the last frame left for readers that need not wait for the queue
/// (the preview, exports, saving).
#[derive(Clone)]
pub struct Latest {
    pub revision: u64,
    /// The whole preview (RGBA, terrain resolution up to 2048).
    pub image: Arc<RgbaImage>,
    pub heightfield: Arc<Heightfield>,
    /// The last committed document (what Save writes).
    pub committed: Value,
}

/// A frame's changed part of the preview, as PNG: the page patches its
/// copy instead of loading the whole image again.
#[derive(Clone)]
pub struct Tile {
    pub revision: u64,
    pub rect: [usize; 4],
    pub png: Arc<Vec<u8>>,
}

/// A PNG and the revision it shows.
pub type Png = (u64, Arc<Vec<u8>>);

/// Tiles kept for pages that fetch them a little late.
const TILES_KEPT: usize = 16;

/// The part of a session that request handlers hold.
pub struct Handle {
    queue: Mutex<Queue>,
    wake: Condvar,
    latest: RwLock<Option<Latest>>,
    tiles: Mutex<VecDeque<Tile>>,
    /// The whole preview's PNG, encoded on demand, by revision.
    full_png: Mutex<Option<(u64, Arc<Vec<u8>>)>>,
    last_used: Mutex<Instant>,
}

impl Handle {
    /// Starts a session's thread on `doc` (already checked by `policy`);
    /// the receiver gets the first frame, or why there is none (then the
    /// session is closed).
    pub fn spawn(
        db: &'static Database,
        policy: Arc<Policy>,
        style: Arc<Style>,
        doc: Value,
        scene: Scene,
    ) -> (Arc<Handle>, oneshot::Receiver<Reply>) {
        let handle = Arc::new(Handle {
            queue: Mutex::new(Queue::default()),
            wake: Condvar::new(),
            latest: RwLock::new(None),
            tiles: Mutex::new(VecDeque::new()),
            full_png: Mutex::new(None),
            last_used: Mutex::new(Instant::now()),
        });
        let (tx, rx) = oneshot::channel();
        let h = handle.clone();
        let spawned = std::thread::Builder::new()
            .name("terrasynth-editor".into())
            .spawn(move || {
                let t = Instant::now();
                let first = guarded(|| Editor::new(db, policy, style, doc, scene));
                match first {
                    Ok(mut ed) => {
                        let reply = ed.frame_reply(None, t.elapsed(), true);
                        h.publish(&ed);
                        let _ = tx.send(Ok(reply));
                        h.serve(&mut ed);
                    }
                    Err(e) => {
                        h.close();
                        let _ = tx.send(Err(e));
                    }
                }
            });
        if let Err(e) = spawned {
            // The receiver learns it from the dropped sender.
            handle.close();
            eprintln!("error: cannot start an editor thread: {e}");
        }
        (handle, rx)
    }

    /// Queues a task; the receiver gets its reply.
    pub fn submit(&self, task: Task) -> oneshot::Receiver<Reply> {
        let (tx, rx) = oneshot::channel();
        self.touch();
        let mut q = self.queue.lock().unwrap_or_else(|e| e.into_inner());
        if q.closed {
            drop(q);
            let _ = tx.send(Err(ApiError::NoSession("this session".into())));
            return rx;
        }
        let mut task = task;
        if let Task::Scene { commit, .. } = &mut task
            && let Some(Job {
                task: Task::Scene { commit: older, .. },
                ..
            }) = q.jobs.back()
        {
            // Latest wins; a commit it replaces is committed by it.
            *commit |= *older;
            let old = q.jobs.pop_back().expect("checked");
            let _ = old.reply.send(Ok(json!({"superseded": true})));
        }
        q.jobs.push_back(Job {
            task,
            reply: tx,
            queued: Instant::now(),
        });
        self.wake.notify_one();
        rx
    }

    /// Stops the thread after its current job; queued jobs are refused.
    pub fn close(&self) {
        let mut q = self.queue.lock().unwrap_or_else(|e| e.into_inner());
        q.closed = true;
        for j in q.jobs.drain(..) {
            let _ = j
                .reply
                .send(Err(ApiError::NoSession("this session".into())));
        }
        self.wake.notify_all();
    }

    pub fn is_closed(&self) -> bool {
        self.queue.lock().unwrap_or_else(|e| e.into_inner()).closed
    }

    /// The last frame's results, once there is one.
    pub fn latest(&self) -> Option<Latest> {
        self.touch();
        self.latest
            .read()
            .unwrap_or_else(|e| e.into_inner())
            .clone()
    }

    /// Marks the session used now (idle sessions may be closed for others).
    pub fn touch(&self) {
        *self.last_used.lock().unwrap_or_else(|e| e.into_inner()) = Instant::now();
    }

    pub fn idle(&self) -> Duration {
        self.last_used
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .elapsed()
    }

    /// A recent frame's tile.
    pub fn tile(&self, revision: u64) -> Option<Tile> {
        self.touch();
        let tiles = self.tiles.lock().unwrap_or_else(|e| e.into_inner());
        tiles.iter().find(|t| t.revision == revision).cloned()
    }

    /// The last frame's whole preview as PNG (encoded once per revision).
    pub fn preview_png(&self) -> Option<Result<Png, ApiError>> {
        let latest = self.latest()?;
        let mut cache = self.full_png.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((rev, png)) = &*cache
            && *rev == latest.revision
        {
            return Some(Ok((*rev, png.clone())));
        }
        let png = match crate::render::encode_png(&latest.image) {
            Ok(p) => Arc::new(p),
            Err(e) => return Some(Err(ApiError::Internal(e.to_string()))),
        };
        *cache = Some((latest.revision, png.clone()));
        Some(Ok((latest.revision, png)))
    }

    fn publish(&self, ed: &Editor) {
        let latest = Latest {
            revision: ed.revision,
            image: Arc::new(ed.image.clone()),
            heightfield: ed.heightfield.clone(),
            committed: ed.history.current().clone(),
        };
        if let Some((rect, png)) = &ed.tile {
            let mut tiles = self.tiles.lock().unwrap_or_else(|e| e.into_inner());
            tiles.push_back(Tile {
                revision: ed.revision,
                rect: *rect,
                png: png.clone(),
            });
            while tiles.len() > TILES_KEPT {
                tiles.pop_front();
            }
        }
        *self.latest.write().unwrap_or_else(|e| e.into_inner()) = Some(latest);
    }

    /// The thread's loop.
    fn serve(&self, ed: &mut Editor) {
        loop {
            let job = {
                let mut q = self.queue.lock().unwrap_or_else(|e| e.into_inner());
                loop {
                    if q.closed {
                        return;
                    }
                    if let Some(j) = q.jobs.pop_front() {
                        break j;
                    }
                    q = self.wake.wait(q).unwrap_or_else(|e| e.into_inner());
                }
            };
            let waited = job.queued.elapsed();
            let reply = guarded(|| ed.run(job.task, waited));
            let broken = matches!(&reply, Err(ApiError::Internal(_)));
            if reply.is_ok() {
                self.publish(ed);
            }
            let _ = job.reply.send(reply);
            if broken {
                self.close();
                return;
            }
        }
    }
}

/// Runs `f`, turning a panic into a 500 (the session is then closed).
fn guarded<T>(f: impl FnOnce() -> Result<T, ApiError>) -> Result<T, ApiError> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).unwrap_or_else(|p| {
        let what = p
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| p.downcast_ref::<&str>().copied())
            .unwrap_or("unknown panic");
        Err(ApiError::Internal(format!(
            "the synthesis failed ({what}); this session is closed, reload the page (your last saved scene is safe)"
        )))
    })
}

/// Milliseconds with 0.01 resolution.
fn ms(d: Duration) -> f64 {
    (d.as_secs_f64() * 1e5).round() / 100.0
}

/// Where the time of one frame went.
#[derive(Debug, Default, Clone, Copy)]
struct Timing {
    edits: Duration,
    synth: Duration,
    render: Duration,
}

/// The session and everything around it, owned by the thread.
struct Editor {
    db: &'static Database,
    policy: Arc<Policy>,
    style: Arc<Style>,
    session: Session<'static>,
    edits: SceneEdits,
    scene: Scene,
    doc: Value,
    history: History,
    view: View,
    revision: u64,
    heightfield: Arc<Heightfield>,
    /// The preview, kept to patch: a frame re-renders only where it changed.
    image: RgbaImage,
    /// The painted type raster the preview shows.
    types: Option<Vec<u8>>,
    /// This frame's changed part of the preview: its rectangle and PNG.
    tile: Option<([usize; 4], Arc<Vec<u8>>)>,
    /// The last frame's change and timing, and why it rebuilt (if it did).
    changed: Option<(usize, Option<[usize; 4]>)>,
    timing: Timing,
    rebuilt: Option<&'static str>,
    /// A failed `Session::apply` after `SceneEdits` moved on: the next
    /// document starts a new session.
    stale: bool,
}

impl Editor {
    fn new(
        db: &'static Database,
        policy: Arc<Policy>,
        style: Arc<Style>,
        doc: Value,
        scene: Scene,
    ) -> Result<Editor, ApiError> {
        let (session, edits, frame, timing) = start(db, &scene)?;
        let mut ed = Editor {
            db,
            policy,
            style,
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
        };
        ed.render(true)?;
        Ok(ed)
    }

    fn run(&mut self, task: Task, waited: Duration) -> Reply {
        let t = Instant::now();
        let with_doc = !matches!(task, Task::Scene { .. });
        match task {
            Task::Scene { doc, scene, commit } => {
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
                self.render(true)?;
            }
        }
        self.revision += 1;
        Ok(self.frame_reply(Some(waited), t.elapsed(), with_doc))
    }

    /// Applies a checked document: as edits of the session, or in a new
    /// session when it cannot be an edit (see [`rebuild_reason`]).
    fn show(&mut self, doc: Value, scene: Scene) -> Result<(), ApiError> {
        self.rebuilt = match self.stale {
            true => Some("the previous edit failed"),
            false => rebuild_reason(&self.scene, &scene),
        };
        if self.rebuilt.is_some() {
            let (session, edits, frame, timing) = start(self.db, &scene)?;
            self.session = session;
            self.edits = edits;
            self.stale = false;
            self.timing = timing;
            self.changed = Some(change_of(&self.heightfield, &frame.heightfield));
            self.heightfield = Arc::new(frame.heightfield);
        } else {
            let t = Instant::now();
            let list = self.edits.edits(&scene, self.db)?;
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
        }
        self.scene = scene;
        self.doc = doc;
        self.render(self.rebuilt.is_some())
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
        let rect = union(heights, painted);
        // Painted types mute the tint everywhere: when the first type is
        // painted or the last erased, the whole preview changes.
        let whole = whole || (self.view.types && self.types.is_some() != types.is_some());
        let full = [
            0,
            0,
            self.image.width() as usize,
            self.image.height() as usize,
        ];
        let rect = match rect {
            _ if whole || self.image.width() == 0 => {
                self.image = self
                    .style
                    .render(&self.heightfield, types.as_deref(), self.view)
                    .map_err(fail)?;
                Some([
                    0,
                    0,
                    self.image.width() as usize,
                    self.image.height() as usize,
                ])
            }
            None => None,
            Some(r) => {
                let done = self
                    .style
                    .render_window(
                        &self.heightfield,
                        types.as_deref(),
                        self.view,
                        &mut self.image,
                        r,
                    )
                    .map_err(fail)?;
                if done {
                    Some(r)
                } else {
                    self.image = self
                        .style
                        .render(&self.heightfield, types.as_deref(), self.view)
                        .map_err(fail)?;
                    Some(full)
                }
            }
        };
        self.tile = match rect {
            Some(r) => Some((r, Arc::new(encode_rect(&self.image, r).map_err(fail)?))),
            None => None,
        };
        self.types = types;
        self.timing.render = t.elapsed();
        Ok(())
    }

    fn frame_reply(&self, waited: Option<Duration>, total: Duration, with_doc: bool) -> Value {
        let stats = self.heightfield.stats();
        let (undo, redo) = self.history.counts();
        let mut reply = json!({
            "revision": self.revision,
            "size": [self.scene.width, self.scene.height],
            "seed": self.scene.seed,
            "history": {"undo": undo, "redo": redo},
            "timing_ms": {
                "queued": waited.map(ms).unwrap_or(0.0),
                "edits": ms(self.timing.edits),
                "synth": ms(self.timing.synth),
                "render": ms(self.timing.render),
                "total": ms(total),
            },
            "changed": self.changed.map(|(pixels, bounds)| json!({"pixels": pixels, "bounds": bounds})),
            "rebuilt": self.rebuilt,
            "heights_m": stats.map(|s| json!({"min": s.min, "max": s.max})),
            "overlay": overlay(&self.edits, &self.scene),
            "view": self.view,
            "tile": self.tile.as_ref().map(|(rect, _)| json!({"revision": self.revision, "rect": rect})),
        });
        if with_doc {
            reply["scene"] = self.doc.clone();
        }
        reply
    }
}

/// A new session on `scene`, with its first frame.
fn start(
    db: &'static Database,
    scene: &Scene,
) -> Result<(Session<'static>, SceneEdits, Frame, Timing), ApiError> {
    let mut edits = SceneEdits::new();
    let t = Instant::now();
    let list = edits.edits(scene, db)?;
    let edits_time = t.elapsed();
    let mut session = Session::new(
        db,
        SceneEdits::params(scene),
        scene.width,
        scene.height,
        scene.seed,
    )
    .map_err(|e| ApiError::invalid("$", e.to_string()))?;
    let frame = session
        .apply(list)
        .map_err(|e| ApiError::invalid("$", e.to_string()))?;
    let timing = Timing {
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

fn union(a: Option<[usize; 4]>, b: Option<[usize; 4]>) -> Option<[usize; 4]> {
    match (a, b) {
        (Some(a), Some(b)) => Some([
            a[0].min(b[0]),
            a[1].min(b[1]),
            a[2].max(b[2]),
            a[3].max(b[3]),
        ]),
        (a, None) => a,
        (None, b) => b,
    }
}

/// Pixels that differ between two heightfields (all when sizes differ).
fn change_of(old: &Heightfield, new: &Heightfield) -> (usize, Option<[usize; 4]>) {
    if (old.width(), old.height()) != (new.width(), new.height()) {
        return (new.len(), Some([0, 0, new.width(), new.height()]));
    }
    let n = old
        .data()
        .iter()
        .zip(new.data())
        .filter(|(a, b)| a.to_bits() != b.to_bits())
        .count();
    (n, (n > 0).then_some([0, 0, new.width(), new.height()]))
}
