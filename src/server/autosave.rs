//! Autosave and recovery (issue 43: "never lose work"). A tab's document
//! lives in the page and in its session; a crashed browser, a killed server
//! or a closed laptop lose whatever was not saved. So, while any tab's
//! committed document differs from the scene file as last saved, a
//! background thread writes the unsaved work to a side file beside the
//! scene, `<scene>.autosave.json` ([`side_file`]),
//! [`Config::autosave_delay`] after the last edit (debounced: a drag or a
//! burst of strokes is one write, and never on the request path),
//! atomically. The scene file itself is only ever written by Save.
//!
//! Every tab's work is in it: the side file is one scene document, the
//! saved scene with each tab's changes since its base replayed on top
//! (oldest edit first, as a stale save's Merge does, `merge.rs`). So two
//! tabs' unsaved points are both there, a tab closed unsaved keeps its
//! work in it, and a tab's Save leaves the others' work in it.
//!
//! At the next start, a side file newer than the scene file and different
//! from it is offered for recovery ([`find`]): the page shows a banner and
//! the artist keeps it (it becomes the session's document, unsaved) or
//! discards it (the file is deleted). Until then autosave leaves the side
//! file alone, so an edit made before deciding cannot overwrite the work
//! found. A side file that does not parse is reported and left on disk.
//!
//! [`Config::autosave_delay`]: super::Config::autosave_delay

use super::App;
use super::editor::Handle;
use crate::io;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, Weak};
use std::time::{Duration, Instant, SystemTime};

/// The autosave file of a scene file: its name plus `.autosave.json`.
pub fn side_file(scene: &Path) -> PathBuf {
    let mut name = scene.file_name().unwrap_or_default().to_os_string();
    name.push(".autosave.json");
    scene.with_file_name(name)
}

/// Unsaved work found at start, waiting for the artist's decision.
#[derive(Clone)]
pub struct Recovery {
    pub doc: Value,
    pub modified: SystemTime,
}

pub struct Autosave {
    pub path: PathBuf,
    delay: Duration,
    state: Mutex<State>,
    wake: Condvar,
}

/// A tab with work that may be unsaved: its session while it is open, and
/// its work as last read (a closed tab's stays).
struct Tab {
    handle: Weak<Handle>,
    work: Option<Work>,
}

/// A session's design and the saved document it stands on.
struct Work {
    base: Arc<Value>,
    doc: Value,
}

#[derive(Default)]
struct State {
    /// When the last edit came: the next write is due the delay after.
    pending: Option<Instant>,
    /// Tabs edited since they last saved, oldest edit first.
    tabs: Vec<Tab>,
    recovery: Option<Recovery>,
    /// The document the side file holds, when this server wrote it (the
    /// same document is not written twice).
    written: Option<Value>,
    stopped: bool,
}

impl Autosave {
    pub fn new(path: PathBuf, delay: Duration, recovery: Option<Recovery>) -> Autosave {
        Autosave {
            path,
            delay,
            state: Mutex::new(State {
                recovery,
                ..State::default()
            }),
            wake: Condvar::new(),
        }
    }

    fn state(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// `h`'s document may have changed: the side file is rewritten after
    /// the delay, `h`'s work on top.
    pub fn changed(&self, h: &Arc<Handle>) {
        let mut s = self.state();
        let work = take_tab(&mut s.tabs, h).and_then(|t| t.work);
        s.tabs.push(Tab {
            handle: Arc::downgrade(h),
            work,
        });
        s.pending = Some(Instant::now());
        self.wake.notify_all();
    }

    pub fn recovery(&self) -> Option<Recovery> {
        self.state().recovery.clone()
    }

    /// The artist kept or discarded the recovered work: autosave resumes.
    pub fn resolved(&self) {
        let mut s = self.state();
        s.recovery = None;
        s.written = None;
        self.wake.notify_all();
    }

    /// Deletes the side file (Discard). A file already gone is no error.
    pub fn remove(&self) -> Result<(), io::IoError> {
        match std::fs::remove_file(&self.path) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                Err(io::IoError::os(&self.path, e))
            }
            _ => Ok(()),
        }
    }

    /// Session `h` just saved the scene file (its lock held): its work is
    /// saved, so the side file goes, unless it holds recovered work nobody
    /// has decided on yet. Other tabs' unsaved work is written again at
    /// once (on the thread: their merge needs that lock).
    pub fn saved(&self, h: &Arc<Handle>) {
        let mut s = self.state();
        take_tab(&mut s.tabs, h);
        if s.recovery.is_none() {
            s.written = None;
            if let Err(e) = self.remove() {
                eprintln!("warning: {e}");
            }
        }
        if !s.tabs.is_empty() {
            s.pending = Some(
                Instant::now()
                    .checked_sub(self.delay)
                    .unwrap_or_else(Instant::now),
            );
            self.wake.notify_all();
        }
    }

    /// Writes what is pending now and stops the thread (the server stops).
    pub fn stop(&self) {
        self.state().stopped = true;
        self.wake.notify_all();
    }
}

/// The autosave thread: waits for an edit, then for the delay without a
/// newer one, then writes. On stop it writes what is still pending at once.
pub fn spawn(app: Arc<App>) -> std::io::Result<std::thread::JoinHandle<()>> {
    std::thread::Builder::new()
        .name("terrasynth-autosave".into())
        .spawn(move || {
            let Some(a) = &app.autosave else { return };
            loop {
                let (due, stopped) = {
                    let mut s = a.state();
                    loop {
                        let due = match &s.pending {
                            _ if s.recovery.is_some() && !s.stopped => None,
                            Some(at) => Some(a.delay.saturating_sub(at.elapsed())),
                            None => None,
                        };
                        match due {
                            Some(d) if d.is_zero() || s.stopped => break,
                            _ if s.stopped => return,
                            Some(d) => {
                                s = a
                                    .wake
                                    .wait_timeout(s, d)
                                    .unwrap_or_else(|e| e.into_inner())
                                    .0
                            }
                            None => s = a.wake.wait(s).unwrap_or_else(|e| e.into_inner()),
                        }
                    }
                    (s.pending.take().is_some(), s.stopped)
                };
                if due {
                    write(&app, a);
                }
                if stopped {
                    return;
                }
            }
        })
}

/// Removes `h`'s tab from `tabs`, if there.
fn take_tab(tabs: &mut Vec<Tab>, h: &Arc<Handle>) -> Option<Tab> {
    let i = tabs
        .iter()
        .position(|t| std::ptr::eq(t.handle.as_ptr(), Arc::as_ptr(h)))?;
    Some(tabs.remove(i))
}

/// Every tab's unsaved work on top of the saved scene: each open tab's
/// work is read again, a closed one's stays as last read, and tabs with
/// nothing unsaved drop out.
fn unsaved(tabs: &mut Vec<Tab>, saved: &Arc<Value>) -> Value {
    for t in tabs.iter_mut() {
        if let Some(h) = t.handle.upgrade().filter(|h| !h.is_closed())
            && let Some(doc) = h.committed()
        {
            t.work = Some(Work {
                base: h.base().1,
                doc,
            });
        }
    }
    tabs.retain(|t| t.work.as_ref().is_some_and(|w| w.doc != *w.base));
    tabs.iter()
        .filter_map(|t| t.work.as_ref())
        .fold((**saved).clone(), |doc, w| {
            super::document::merge::merge(&w.base, &w.doc, &doc)
        })
}

/// Writes every tab's unsaved work to the side file; removes the side
/// file when there is none (undone back to the saved state).
fn write(app: &App, a: &Autosave) {
    // Held while writing: a save in between would leave a stale side file.
    let saved = app.saved.blocking_lock();
    let mut s = a.state();
    if s.recovery.is_some() {
        // Stopping with a decision still open: the side file is that work.
        return;
    }
    let doc = unsaved(&mut s.tabs, &saved.doc);
    if doc == *saved.doc {
        if s.written.take().is_some()
            && let Err(e) = a.remove()
        {
            eprintln!("warning: {e}");
        }
        return;
    }
    if s.written.as_ref() == Some(&doc) {
        return;
    }
    let text = match serde_json::to_string_pretty(&doc) {
        Ok(t) => t,
        Err(e) => return eprintln!("warning: autosave: {e}"),
    };
    // The cache dir of a server without a scene file may not exist yet.
    if let Some(dir) = a.path.parent().filter(|d| !d.as_os_str().is_empty()) {
        let _ = std::fs::create_dir_all(dir);
    }
    match io::write_atomic(&a.path, text.as_bytes()) {
        Ok(()) => s.written = Some(doc),
        Err(e) => eprintln!("warning: autosave failed: {e}"),
    }
}

/// The unsaved work at `side`, if it is worth offering: newer than the
/// scene file (when there is one) and different from `saved`, the scene's
/// document. Says on stderr what it found; a side file that is unreadable
/// or not JSON is named with the reason and left as it is.
pub fn find(side: &Path, scene: Option<&Path>, saved: &Value) -> Option<Recovery> {
    let modified = std::fs::metadata(side).and_then(|m| m.modified()).ok()?;
    let doc = std::fs::read(side)
        .map_err(|e| e.to_string())
        .and_then(|b| serde_json::from_slice::<Value>(&b).map_err(|e| e.to_string()));
    let doc = match doc {
        Ok(d) => d,
        Err(e) => {
            eprintln!(
                "warning: the autosaved work {} cannot be read ({e}): it is left as it is and not offered for recovery",
                side.display()
            );
            return None;
        }
    };
    let scene_modified = scene.and_then(|p| std::fs::metadata(p).and_then(|m| m.modified()).ok());
    if scene_modified.is_some_and(|t| t >= modified) {
        eprintln!(
            "note: {} is older than its scene file, so it is not offered for recovery (the next autosave replaces it)",
            side.display()
        );
        return None;
    }
    if doc == *saved {
        // Nothing unsaved in it.
        let _ = std::fs::remove_file(side);
        return None;
    }
    eprintln!(
        "unsaved work autosaved {} ago was found in {}: the editor page offers to keep or discard it",
        ago(modified),
        side.display()
    );
    Some(Recovery { doc, modified })
}

/// "12 s", "5 min", "3 h", "2 days": how long ago `t` was.
fn ago(t: SystemTime) -> String {
    let s = t.elapsed().unwrap_or_default().as_secs();
    match s {
        0..120 => format!("{s} s"),
        120..7200 => format!("{} min", s / 60),
        7200..172800 => format!("{} h", s / 3600),
        _ => format!("{} days", s / 86400),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn side_file_is_beside_the_scene() {
        assert_eq!(
            side_file(Path::new("dir/my scene.json")),
            Path::new("dir/my scene.json.autosave.json")
        );
        assert_eq!(ago(SystemTime::now()), "0 s");
    }
}
