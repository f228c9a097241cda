//! Undo and redo (seed 002 §2.5: "a powerful multiple-undo function"): the
//! current committed document and, per step, the [`Patch`] between it and
//! the one before. Undo and redo apply a patch backwards or forwards and
//! hand back the document to apply, which goes through the session like
//! any edit, so only what the undone step touched is re-synthesized.
//! Intermediate states of a drag are not committed: one drag is one step.
//!
//! Why patches: a step costs what its edit changed (a moved point: a few
//! hundred bytes), where whole documents cost ~9× the scene's JSON each
//! (issue 43). Steps also fall off, oldest first, beyond [`MAX_BYTES`], so
//! a session's history stays bounded whatever its edits.

use super::patch::Patch;
use serde_json::Value;
use std::collections::VecDeque;

/// Most steps kept; the oldest fall off.
pub const MAX_STEPS: usize = 500;

/// Most bytes the steps may hold (estimated, [`Patch::bytes`]): 500
/// strokes of a few hundred points each.
pub const MAX_BYTES: usize = 32 << 20;

#[derive(Debug, Clone)]
pub struct History {
    /// The document at the cursor.
    current: Value,
    /// `steps[i]` turns state `i` into state `i + 1` (None: a commit of
    /// the same document, still a step as the page counts them), and its
    /// bytes.
    steps: VecDeque<(Option<Patch>, usize)>,
    /// The state shown: `0..=steps.len()`.
    cursor: usize,
    bytes: usize,
}

impl History {
    pub fn new(first: Value) -> History {
        History {
            current: first,
            steps: VecDeque::new(),
            cursor: 0,
            bytes: 0,
        }
    }

    /// The current committed document.
    pub fn current(&self) -> &Value {
        &self.current
    }

    /// Commits a document: it becomes current and the redo steps go.
    pub fn commit(&mut self, doc: Value) {
        let patch = Patch::between(&self.current, &doc);
        for (_, b) in self.steps.drain(self.cursor..) {
            self.bytes -= b;
        }
        let b = size_of::<(Option<Patch>, usize)>() + patch.as_ref().map_or(0, Patch::bytes);
        self.steps.push_back((patch, b));
        self.bytes += b;
        self.current = doc;
        self.cursor += 1;
        // At most MAX_STEPS states: the first and MAX_STEPS - 1 steps.
        while self.steps.len() >= MAX_STEPS || (self.bytes > MAX_BYTES && self.steps.len() > 1) {
            if let Some((_, b)) = self.steps.pop_front() {
                self.bytes -= b;
                self.cursor -= 1;
            }
        }
    }

    /// Steps back; the document to apply, or None at the first.
    pub fn undo(&mut self) -> Option<&Value> {
        self.cursor = self.cursor.checked_sub(1)?;
        if let Some(p) = &self.steps[self.cursor].0 {
            p.apply(&mut self.current, false);
        }
        Some(&self.current)
    }

    /// Steps forward; the document to apply, or None at the last.
    pub fn redo(&mut self) -> Option<&Value> {
        if let Some(p) = &self.steps.get(self.cursor)?.0 {
            p.apply(&mut self.current, true);
        }
        self.cursor += 1;
        Some(&self.current)
    }

    /// Steps that undo and redo can take.
    pub fn counts(&self) -> (usize, usize) {
        (self.cursor, self.steps.len() - self.cursor)
    }

    /// What the steps hold, estimated (bytes).
    pub fn bytes(&self) -> usize {
        self.bytes
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn undo_redo_and_a_new_commit_drops_the_redo_steps() {
        let mut h = History::new(json!(0));
        h.commit(json!(1));
        h.commit(json!(2));
        assert_eq!(h.counts(), (2, 0));
        assert_eq!(h.undo(), Some(&json!(1)));
        assert_eq!(h.undo(), Some(&json!(0)));
        assert_eq!(h.undo(), None);
        assert_eq!(h.current(), &json!(0));
        assert_eq!(h.redo(), Some(&json!(1)));
        assert_eq!(h.counts(), (1, 1));
        h.commit(json!(3));
        assert_eq!(h.redo(), None);
        assert_eq!(h.counts(), (2, 0));
        assert_eq!(h.undo(), Some(&json!(1)));
    }

    #[test]
    fn the_oldest_steps_fall_off() {
        let mut h = History::new(json!(0));
        for i in 1..=MAX_STEPS + 10 {
            h.commit(json!(i));
        }
        assert_eq!(h.counts(), (MAX_STEPS - 1, 0));
        while h.undo().is_some() {}
        assert_eq!(h.current(), &json!(11));
    }
}
