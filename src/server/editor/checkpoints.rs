//! Session states kept around pastes, so that undoing, redoing or deleting
//! a paste swaps a state in instead of re-synthesizing the terrain.
//!
//! Why: a paste is permanent in a session (paper §5.3), so a document with
//! fewer pastes than the session's could only be shown by a new session: a
//! whole synthesis, 1.5–2.2 s at 1024² on 2 cores (issue 43), against
//! ~100–300 ms for other edits. So before a paste the editor keeps the
//! session's state (a [`Snapshot`] and the [`SceneEdits`] that go with it);
//! undo swaps it back (no synthesis: the same bytes as before the paste)
//! and keeps the state it leaves, which redo swaps in again. From a kept
//! state, a document that differs in more than its pastes takes the usual
//! edits (restricted re-synthesis).
//!
//! A state costs 42–84 B per output pixel (44–88 MB at 1024², 11–22 MB at
//! 512²; more with constraints), so at most [`MAX_KEPT`] states and [`MAX_BYTES`] are kept, the
//! oldest dropped first; a paste whose state was dropped is undone as
//! before, by a new session.

use crate::heightfield::Heightfield;
use crate::scene::{Scene, SceneEdits};
use crate::synth::session::Snapshot;
use std::collections::VecDeque;
use std::sync::Arc;

/// Most states kept per session.
pub const MAX_KEPT: usize = 8;

/// Most bytes the kept states may hold per session (estimated,
/// [`Snapshot::bytes`]): two or more 1024² states, [`MAX_KEPT`] 512² ones.
pub const MAX_BYTES: usize = 256 << 20;

/// A session's state and the scene it shows.
pub struct Checkpoint {
    pub scene: Scene,
    pub edits: SceneEdits,
    pub state: Snapshot,
    pub heightfield: Arc<Heightfield>,
    bytes: usize,
}

impl Checkpoint {
    pub fn new(
        scene: Scene,
        edits: SceneEdits,
        state: Snapshot,
        heightfield: Arc<Heightfield>,
    ) -> Checkpoint {
        Checkpoint {
            bytes: Checkpoint::bytes_for(state.bytes(), &edits),
            scene,
            edits,
            state,
            heightfield,
        }
    }

    /// What [`Checkpoints`] counts for a checkpoint whose state holds
    /// `state` bytes ([`Snapshot::bytes`]).
    pub fn bytes_for(state: usize, edits: &SceneEdits) -> usize {
        state + edits.type_raster().map_or(0, <[u8]>::len) + size_of::<Checkpoint>()
    }
}

/// The states kept, oldest first.
#[derive(Default)]
pub struct Checkpoints {
    kept: VecDeque<Checkpoint>,
    bytes: usize,
}

impl Checkpoints {
    /// Keeps a state (the newest); the oldest go beyond the bounds, and a
    /// state larger than [`MAX_BYTES`] is not kept at all.
    pub fn push(&mut self, c: Checkpoint) {
        if c.bytes > MAX_BYTES {
            return;
        }
        self.bytes += c.bytes;
        self.kept.push_back(c);
        while self.kept.len() > MAX_KEPT || self.bytes > MAX_BYTES {
            if let Some(old) = self.kept.pop_front() {
                self.bytes -= old.bytes;
            }
        }
    }

    /// Takes the oldest state when keeping one more of `bytes` (as
    /// [`Checkpoint::bytes_for`] counts) would drop it: its buffers can take
    /// the new state's copy ([`crate::synth::session::Session::snapshot_into`]).
    pub fn recycle(&mut self, bytes: usize) -> Option<Snapshot> {
        let full = self.kept.len() >= MAX_KEPT || self.bytes + bytes > MAX_BYTES;
        if !full || bytes > MAX_BYTES {
            return None;
        }
        let old = self.kept.pop_front()?;
        self.bytes -= old.bytes;
        Some(old.state)
    }

    /// Takes the newest state that has exactly `scene`'s pastes and of
    /// which `scene` can be an edit (see
    /// [`crate::server::document::rebuild_reason`]); else, with `prefix`,
    /// the state that has most of `scene`'s first pastes (newest among
    /// equals), from which the rest are applied again as edits.
    ///
    /// Why `prefix`: deleting a paste that is not the last one left no
    /// state with the document's pastes, so the session was built anew (a
    /// whole synthesis, 1.5–2.2 s at 1024²); the state before the deleted
    /// paste and the later pastes pasted again cost a paste's edit each.
    /// The caller asks for it only when the shown state cannot take the
    /// document's pastes itself (it has one the document lacks).
    pub fn take(&mut self, scene: &Scene, prefix: bool) -> Option<Checkpoint> {
        // A state `scene` can be an edit of has a prefix of its pastes, so
        // the most pastes are all of them where such a state is kept.
        let fits =
            |c: &Checkpoint| crate::server::document::rebuild_reason(&c.scene, scene).is_none();
        let k = (0..self.kept.len())
            .filter(|&k| fits(&self.kept[k]))
            .max_by_key(|&k| (self.kept[k].scene.pastes.len(), k))?;
        if !prefix && self.kept[k].scene.pastes != scene.pastes {
            return None;
        }
        let c = self.kept.remove(k)?;
        self.bytes -= c.bytes;
        Some(c)
    }

    /// Takes the newest state.
    pub fn take_newest(&mut self) -> Option<Checkpoint> {
        let c = self.kept.pop_back()?;
        self.bytes -= c.bytes;
        Some(c)
    }

    /// Drops every state (a new session cannot take them).
    pub fn clear(&mut self) {
        self.kept.clear();
        self.bytes = 0;
    }

    /// What the kept states hold (estimated bytes).
    pub fn bytes(&self) -> usize {
        self.bytes
    }
}
