//! The open editor sessions, one per browser tab, by an unguessable id.
//!
//! A tab gets its own session (own synthesis state, own undo history) as
//! long as a slot is free and memory allows; otherwise a clear refusal
//! (503 naming the limit; the page retries). The page sends a heartbeat
//! (every quarter of the idle time) and closes its session when it is
//! hidden; a session not heard from for the idle time (a crashed browser,
//! a reload while its first frame was still being made, so the page never
//! learnt its id) gives its slot to the next tab that needs one. It is
//! reclaimed only then, not on a timer: browsers slow the timers of
//! background tabs to once a minute, and such a tab keeps its undo
//! history as long as no one needs the slot (its document is in the page:
//! it reopens a session from it if the slot was taken).

use super::api::error::ApiError;
use super::editor::Handle;
use std::collections::HashMap;
use std::hash::{BuildHasher, Hasher};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// Bytes per output pixel a session holds: the synthesis state, the
/// previous frame's per-pass results, guides, constraint sums, curve fields,
/// the heightfield and the preview. Measured as the server's resident size
/// at 1024²: +57 MiB for a new session, +117 MiB more once it has a point,
/// a curve and painted types (≈ 166 B/px); since then a session also keeps
/// each level's final state (`Frames::states`, 12 B/px at level 0, 16 with
/// the coarser levels: ≈ 182 B/px). Rounded up.
pub const SESSION_BYTES_PER_PIXEL: u64 = 200;

pub struct Registry {
    sessions: Mutex<HashMap<String, Arc<Handle>>>,
    pub limit: usize,
    pub idle: Duration,
}

impl Registry {
    pub fn new(limit: usize, idle: Duration) -> Registry {
        Registry {
            sessions: Mutex::new(HashMap::new()),
            limit,
            idle,
        }
    }

    fn map(&self) -> std::sync::MutexGuard<'_, HashMap<String, Arc<Handle>>> {
        self.sessions.lock().unwrap_or_else(|e| e.into_inner())
    }

    pub fn get(&self, id: &str) -> Result<Arc<Handle>, ApiError> {
        let mut map = self.map();
        match map.get(id) {
            Some(h) if !h.is_closed() => Ok(h.clone()),
            Some(_) => {
                map.remove(id);
                Err(ApiError::NoSession(id.into()))
            }
            None => Err(ApiError::NoSession(id.into())),
        }
    }

    pub fn open(&self) -> usize {
        let mut map = self.map();
        map.retain(|_, h| !h.is_closed());
        map.len()
    }

    /// Admits a `width × height` session started by `spawn`, under one
    /// lock so concurrent tabs cannot overshoot the limit: when every slot
    /// is taken, the longest-idle session past the idle time is closed, or
    /// the tab is refused; so is a session memory cannot hold.
    pub fn admit<R>(
        &self,
        width: usize,
        height: usize,
        spawn: impl FnOnce() -> (Arc<Handle>, R),
    ) -> Result<(String, R), ApiError> {
        let mut map = self.map();
        map.retain(|_, h| !h.is_closed());
        if map.len() >= self.limit {
            let idlest = map
                .iter()
                .map(|(id, h)| (id.clone(), h.idle()))
                .filter(|(_, idle)| *idle > self.idle)
                .max_by_key(|(_, idle)| *idle);
            match idlest.and_then(|(id, _)| map.remove(&id)) {
                Some(h) => h.close(),
                None => {
                    return Err(ApiError::Full {
                        open: map.len(),
                        idle_s: self.idle.as_secs(),
                    });
                }
            }
        }
        check_memory(width, height)?;
        let (handle, r) = spawn();
        let id = new_id();
        map.insert(id.clone(), handle);
        Ok((id, r))
    }

    /// Closes `id` unless `done`, when dropped: a session request
    /// abandoned (its connection closed) after the session was admitted
    /// would otherwise hold the slot until its heartbeat is missed.
    pub fn until_answered<'a>(&'a self, id: &'a str) -> Unanswered<'a> {
        Unanswered {
            registry: self,
            id,
            done: false,
        }
    }

    pub fn close(&self, id: &str) -> bool {
        match self.map().remove(id) {
            Some(h) => {
                h.close();
                true
            }
            None => false,
        }
    }

    pub fn close_all(&self) {
        for (_, h) in self.map().drain() {
            h.close();
        }
    }
}

/// See [`Registry::until_answered`].
pub struct Unanswered<'a> {
    registry: &'a Registry,
    id: &'a str,
    pub done: bool,
}

impl Drop for Unanswered<'_> {
    fn drop(&mut self) {
        if !self.done {
            self.registry.close(self.id);
        }
    }
}

/// Refuses a session that would not fit in the memory the system reports
/// available (Linux `MemAvailable`; elsewhere no check).
pub fn check_memory(width: usize, height: usize) -> Result<(), ApiError> {
    let needed = (width as u64 * height as u64).saturating_mul(SESSION_BYTES_PER_PIXEL);
    match crate::io::available_memory() {
        Some(avail) if needed > avail => Err(ApiError::Memory {
            width,
            height,
            needed_mib: needed >> 20,
            available_mib: avail >> 20,
        }),
        _ => Ok(()),
    }
}

/// 128 random bits as hex (from the standard library's randomly keyed
/// hasher: session ids need to be unguessable by other local pages, not
/// cryptographic keys).
pub fn new_id() -> String {
    let mut out = String::new();
    for k in 0..2u64 {
        let mut h = std::collections::hash_map::RandomState::new().build_hasher();
        h.write_u64(k);
        h.write_u128(
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map(|d| d.as_nanos())
                .unwrap_or(0),
        );
        out.push_str(&format!("{:016x}", h.finish()));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_differ() {
        let a: Vec<String> = (0..100).map(|_| new_id()).collect();
        let mut b = a.clone();
        b.sort();
        b.dedup();
        assert_eq!(b.len(), 100);
        assert!(a.iter().all(|id| id.len() == 32));
    }

    #[test]
    fn a_session_larger_than_memory_is_refused() {
        if crate::io::available_memory().is_none() {
            eprintln!("skipped: no /proc/meminfo here");
            return;
        }
        let e = check_memory(65535, 65535).unwrap_err();
        assert!(e.to_string().contains("MiB are available"), "{e}");
        assert!(check_memory(64, 64).is_ok());
    }
}
