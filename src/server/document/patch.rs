//! The difference between two JSON documents, kept by the undo history
//! instead of whole documents: an edit changes one control of a scene
//! (a point moved, a stroke added), so a step costs what that control
//! costs, not what the scene costs (issue 43: whole documents cost ~9× a
//! scene's JSON per step, 6.8 MiB for a 0.74 MB scene).

use serde_json::{Map, Value};

/// Turns one value into another, and back.
#[derive(Debug, Clone, PartialEq)]
pub enum Patch {
    /// Replaced whole: (before, after).
    Replace(Box<Value>, Box<Value>),
    /// Members of an object: each changed, added or removed member.
    Object(Vec<(String, Member)>),
    /// Elements `at..at + before.len()` of an array became `after` (the
    /// arrays' common beginning and end are not kept).
    Splice {
        at: usize,
        before: Vec<Value>,
        after: Vec<Value>,
    },
    /// One element of an array changed (a dragged point, a reshaped curve).
    Element(usize, Box<Patch>),
}

/// One member's change.
#[derive(Debug, Clone, PartialEq)]
pub enum Member {
    Added(Value),
    Removed(Value),
    Changed(Patch),
}

impl Patch {
    /// What turns `a` into `b`; None when they are equal.
    pub fn between(a: &Value, b: &Value) -> Option<Patch> {
        if a == b {
            return None;
        }
        Some(match (a, b) {
            (Value::Object(x), Value::Object(y)) => Patch::Object(members(x, y)),
            (Value::Array(x), Value::Array(y)) => {
                let head = x.iter().zip(y).take_while(|(p, q)| p == q).count();
                let tail = x[head..]
                    .iter()
                    .rev()
                    .zip(y[head..].iter().rev())
                    .take_while(|(p, q)| p == q)
                    .count();
                let (old, new) = (&x[head..x.len() - tail], &y[head..y.len() - tail]);
                match (old, new) {
                    ([p], [q]) => Patch::Element(head, Box::new(Patch::between(p, q)?)),
                    _ => Patch::Splice {
                        at: head,
                        before: old.to_vec(),
                        after: new.to_vec(),
                    },
                }
            }
            _ => Patch::Replace(Box::new(a.clone()), Box::new(b.clone())),
        })
    }

    /// Applies the patch to the value it was made from (`forward`) or
    /// undoes it on the value it made. A value the patch does not fit is
    /// left as far as it fits: history only applies its own patches to
    /// the documents they were made from.
    pub fn apply(&self, v: &mut Value, forward: bool) {
        let pick = |a: &Value, b: &Value| if forward { b.clone() } else { a.clone() };
        match (self, v) {
            (Patch::Replace(a, b), v) => *v = pick(a, b),
            (Patch::Object(list), Value::Object(map)) => {
                for (key, m) in list {
                    match (m, forward) {
                        (Member::Added(x), true) | (Member::Removed(x), false) => {
                            map.insert(key.clone(), x.clone());
                        }
                        (Member::Added(_), false) | (Member::Removed(_), true) => {
                            map.remove(key);
                        }
                        (Member::Changed(p), _) => {
                            if let Some(x) = map.get_mut(key) {
                                p.apply(x, forward);
                            }
                        }
                    }
                }
            }
            (Patch::Splice { at, before, after }, Value::Array(arr)) => {
                let (out, put) = if forward {
                    (before, after)
                } else {
                    (after, before)
                };
                let end = (at + out.len()).min(arr.len());
                let at = (*at).min(end);
                arr.splice(at..end, put.iter().cloned());
            }
            (Patch::Element(i, p), Value::Array(arr)) => {
                if let Some(x) = arr.get_mut(*i) {
                    p.apply(x, forward);
                }
            }
            _ => {}
        }
    }

    /// Approximate heap bytes this patch holds (see [`value_bytes`]).
    pub fn bytes(&self) -> usize {
        size_of::<Patch>()
            + match self {
                Patch::Replace(a, b) => value_bytes(a) + value_bytes(b),
                Patch::Object(list) => list
                    .iter()
                    .map(|(k, m)| {
                        k.capacity()
                            + size_of::<(String, Member)>()
                            + match m {
                                Member::Added(x) | Member::Removed(x) => value_bytes(x),
                                Member::Changed(p) => p.bytes(),
                            }
                    })
                    .sum(),
                Patch::Splice { before, after, .. } => {
                    before.iter().chain(after).map(value_bytes).sum()
                }
                Patch::Element(_, p) => p.bytes(),
            }
    }
}

fn members(x: &Map<String, Value>, y: &Map<String, Value>) -> Vec<(String, Member)> {
    let mut out = Vec::new();
    for (k, a) in x {
        match y.get(k) {
            None => out.push((k.clone(), Member::Removed(a.clone()))),
            Some(b) => {
                if let Some(p) = Patch::between(a, b) {
                    out.push((k.clone(), Member::Changed(p)));
                }
            }
        }
    }
    for (k, b) in y {
        if !x.contains_key(k) {
            out.push((k.clone(), Member::Added(b.clone())));
        }
    }
    out
}

/// Approximate heap bytes of a JSON value as serde_json holds it: the
/// value itself, string and array capacity, and per object member its key
/// and a B-tree node's share (~2 words). An estimate for the history's
/// memory bound, not an allocator's count.
pub fn value_bytes(v: &Value) -> usize {
    size_of::<Value>()
        + match v {
            Value::String(s) => s.capacity(),
            Value::Array(a) => {
                a.iter().map(value_bytes).sum::<usize>()
                    + (a.capacity() - a.len()) * size_of::<Value>()
            }
            Value::Object(m) => m
                .iter()
                .map(|(k, x)| size_of::<String>() + k.capacity() + 16 + value_bytes(x))
                .sum(),
            _ => 0,
        }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn round_trip(a: Value, b: Value) {
        let p = Patch::between(&a, &b).expect("they differ");
        let mut v = a.clone();
        p.apply(&mut v, true);
        assert_eq!(v, b, "{p:?}");
        p.apply(&mut v, false);
        assert_eq!(v, a, "{p:?}");
    }

    #[test]
    fn patches_go_both_ways() {
        let doc = json!({"size": [64, 64], "points": [{"at": [1, 2]}, {"at": [3, 4]}], "seed": 3});
        let mut moved = doc.clone();
        moved["points"][1]["at"] = json!([5, 6]);
        round_trip(doc.clone(), moved);
        let mut added = doc.clone();
        added["points"]
            .as_array_mut()
            .unwrap()
            .insert(1, json!({"at": [9, 9]}));
        added["curves"] = json!([]);
        round_trip(doc.clone(), added.clone());
        let mut removed = doc.clone();
        removed.as_object_mut().unwrap().remove("seed");
        removed["points"] = json!([]);
        round_trip(doc.clone(), removed);
        round_trip(doc, json!(null));
        assert_eq!(Patch::between(&added, &added), None);
    }

    #[test]
    fn a_moved_point_costs_the_point_not_the_document() {
        let strokes: Vec<Value> = (0..2000)
            .map(|i| json!({"type": "rock", "points": [[i, 1], [i, 2], [i, 3]], "radius_px": 4}))
            .collect();
        let doc =
            json!({"points": [{"at": [1, 2], "height_m": 900}], "types": {"strokes": strokes}});
        let mut moved = doc.clone();
        moved["points"][0]["at"] = json!([3, 4]);
        let p = Patch::between(&doc, &moved).unwrap();
        assert!(p.bytes() < 1024, "{} bytes", p.bytes());
        assert!(value_bytes(&doc) > 500_000, "{}", value_bytes(&doc));
    }
}
