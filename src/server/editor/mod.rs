//! One editor session: a thread that owns a [`Session`](crate::synth::session::Session) (paper §5.3:
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
//!
//! Its parts: the state the thread owns and how a task becomes a frame
//! (`frame.rs`), the session states kept around pastes (`checkpoints.rs`),
//! and what the page shows of a frame (`view.rs`).

mod checkpoints;
mod frame;
pub(super) mod view;

use crate::backend::engine::Engine;
use crate::database::Database;
use crate::heightfield::Heightfield;
use crate::scene::Scene;
use crate::server::api::error::ApiError;
use crate::server::document::Policy;
use frame::Editor;
use image::RgbaImage;
use serde_json::{Value, json};
use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex, RwLock};
use std::time::{Duration, Instant};
use tokio::sync::oneshot;
use view::{Style, View};

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
    /// What the undo history holds (estimated bytes; `GET` of a session).
    pub history_bytes: usize,
    /// What the states kept around pastes hold (estimated bytes).
    pub checkpoint_bytes: usize,
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

/// What every editor of a server shares: the database, the policy that
/// checks documents, the preview style, and the engine that synthesizes
/// and shades. Cloned into each session's thread.
#[derive(Clone)]
pub struct Shared {
    pub db: &'static Database,
    pub policy: Arc<Policy>,
    pub style: Arc<Style>,
    pub engine: Engine,
}

/// The part of a session that request handlers hold.
pub struct Handle {
    queue: Mutex<Queue>,
    wake: Condvar,
    latest: RwLock<Option<Latest>>,
    tiles: Mutex<VecDeque<Tile>>,
    /// The whole preview's PNG, encoded on demand, by revision.
    full_png: Mutex<Option<(u64, Arc<Vec<u8>>)>>,
    last_used: Mutex<Instant>,
    /// Making a frame (the first included): never idle then, however long
    /// the synthesis takes.
    working: AtomicBool,
    /// The revision of the scene file this session's document stands on
    /// (`App::saved`), and that document: a save from a session whose base
    /// is older would overwrite another tab's save, and a merge needs to
    /// know what this tab changed since (`document/merge.rs`).
    base: Mutex<(u64, Arc<Value>)>,
}

impl Handle {
    /// The saved revision this session's document stands on, and its
    /// document.
    pub fn base(&self) -> (u64, Arc<Value>) {
        self.base.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }

    /// After this session saved, reloaded or merged: its document stands
    /// on the saved `revision`, whose document is `doc`.
    pub fn set_base(&self, revision: u64, doc: Arc<Value>) {
        *self.base.lock().unwrap_or_else(|e| e.into_inner()) = (revision, doc);
    }

    /// Starts a session's thread on `doc` (already checked by `policy`);
    /// the receiver gets the first frame, or why there is none (then the
    /// session is closed).
    pub fn spawn(
        shared: Shared,
        doc: Value,
        scene: Scene,
        base: (u64, Arc<Value>),
    ) -> (Arc<Handle>, oneshot::Receiver<Reply>) {
        let handle = Arc::new(Handle {
            queue: Mutex::new(Queue::default()),
            wake: Condvar::new(),
            latest: RwLock::new(None),
            tiles: Mutex::new(VecDeque::new()),
            full_png: Mutex::new(None),
            last_used: Mutex::new(Instant::now()),
            working: AtomicBool::new(true),
            base: Mutex::new(base),
        });
        let (tx, rx) = oneshot::channel();
        let h = handle.clone();
        let spawned = std::thread::Builder::new()
            .name("terrasynth-editor".into())
            .spawn(move || {
                let t = Instant::now();
                let first = guarded(|| Editor::new(shared, doc, scene));
                match first {
                    Ok(mut ed) => {
                        let reply = ed.frame_reply(None, t.elapsed(), true);
                        h.publish(&ed);
                        h.finished();
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
            && matches!(
                q.jobs.back(),
                Some(Job {
                    task: Task::Scene { .. },
                    ..
                })
            )
            && let Some(Job {
                task: Task::Scene { commit: older, .. },
                reply,
                ..
            }) = q.jobs.pop_back()
        {
            // Latest wins; a commit it replaces is committed by it.
            *commit |= older;
            let _ = reply.send(Ok(json!({"superseded": true})));
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

    /// The last committed document, without marking the session used (the
    /// autosave reads it, not the page).
    pub fn committed(&self) -> Option<Value> {
        let latest = self.latest.read().unwrap_or_else(|e| e.into_inner());
        latest.as_ref().map(|l| l.committed.clone())
    }

    /// Marks the session used now (idle sessions may be closed for others).
    pub fn touch(&self) {
        *self.last_used.lock().unwrap_or_else(|e| e.into_inner()) = Instant::now();
    }

    /// How long since the page was last heard from (zero while a frame is
    /// being made).
    pub fn idle(&self) -> Duration {
        if self.working.load(Ordering::Relaxed) {
            return Duration::ZERO;
        }
        self.last_used
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .elapsed()
    }

    /// A frame is done: the idle time counts from now.
    fn finished(&self) {
        self.touch();
        self.working.store(false, Ordering::Relaxed);
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
            history_bytes: ed.history.bytes(),
            checkpoint_bytes: ed.checkpoints.bytes(),
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
            self.working.store(true, Ordering::Relaxed);
            let reply = guarded(|| ed.run(job.task, waited));
            self.finished();
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
