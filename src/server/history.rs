//! Undo and redo (seed 002 §2.5: "a powerful multiple-undo function"): a
//! list of committed scene documents and a cursor. Undo and redo move the
//! cursor and hand back the document to apply, which goes through the
//! session like any edit, so only what the undone step touched is
//! re-synthesized. Intermediate states of a drag are not committed: one
//! drag is one step.

use serde_json::Value;

/// Most steps kept; the oldest fall off (documents are small, but a long
/// painting session adds a stroke per step).
pub const MAX_STEPS: usize = 500;

#[derive(Debug, Clone)]
pub struct History {
    docs: Vec<Value>,
    /// Index of the current document in `docs`.
    cursor: usize,
}

impl History {
    pub fn new(first: Value) -> History {
        History {
            docs: vec![first],
            cursor: 0,
        }
    }

    /// The current committed document.
    pub fn current(&self) -> &Value {
        &self.docs[self.cursor]
    }

    /// Commits a document: it becomes current and the redo steps go.
    pub fn commit(&mut self, doc: Value) {
        self.docs.truncate(self.cursor + 1);
        self.docs.push(doc);
        if self.docs.len() > MAX_STEPS {
            self.docs.remove(0);
        }
        self.cursor = self.docs.len() - 1;
    }

    /// Steps back; the document to apply, or None at the first.
    pub fn undo(&mut self) -> Option<&Value> {
        self.cursor = self.cursor.checked_sub(1)?;
        Some(&self.docs[self.cursor])
    }

    /// Steps forward; the document to apply, or None at the last.
    pub fn redo(&mut self) -> Option<&Value> {
        if self.cursor + 1 >= self.docs.len() {
            return None;
        }
        self.cursor += 1;
        Some(&self.docs[self.cursor])
    }

    /// Steps that undo and redo can take.
    pub fn counts(&self) -> (usize, usize) {
        (self.cursor, self.docs.len() - 1 - self.cursor)
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
