//! Merging a tab's document into a scene file another tab saved since
//! (issue 43: a stale save is refused, and the page offers to reload the
//! file's version or to merge, "mine on top of theirs").
//!
//! A three-way merge against the saved document the tab started from
//! (its *base*): with the base, "I deleted this point" and "they added
//! this point" can be told apart, which a two-way union cannot. What the
//! tab changed since its base is replayed on the file's version:
//!
//! - the control lists (`points`, `curves`, `junctions`, `pastes`,
//!   `sculpt`, and the `strokes` of `types` and `freeze`) merge element by
//!   element, keyed by `id` where the element has one, else by its whole
//!   value. Mine added → appended (on top: strokes paint over theirs);
//!   mine changed → replaces theirs, or is appended when they removed it;
//!   mine removed → removed, unless they changed it meanwhile. An added
//!   element whose `id` they also used for something else gets a fresh id
//!   (two tabs both name their first point `p1`);
//! - any other field (size, seed, parameters): mine where I changed it,
//!   else theirs.

use serde_json::Value;
use std::collections::{HashMap, HashSet};

/// The fields that hold control lists (a field name, or `field.strokes`).
const LISTS: [&str; 5] = ["points", "curves", "junctions", "pastes", "sculpt"];
const STROKE_LAYERS: [&str; 2] = ["types", "freeze"];

/// `mine` on top of `theirs`; both descend from `base`.
pub fn merge(base: &Value, mine: &Value, theirs: &Value) -> Value {
    let (Some(b), Some(m), Some(t)) = (base.as_object(), mine.as_object(), theirs.as_object())
    else {
        return mine.clone();
    };
    let mut out = t.clone();
    let keys: std::collections::BTreeSet<&String> = m.keys().chain(b.keys()).collect();
    for key in keys {
        let (bv, mv) = (b.get(key), m.get(key));
        if bv == mv {
            continue;
        }
        let merged = match (key.as_str(), bv, mv, t.get(key)) {
            (k, _, Some(mv), tv) if LISTS.contains(&k) => Some(lists(
                bv.unwrap_or(&Value::Null),
                mv,
                tv.unwrap_or(&Value::Null),
            )),
            (k, _, Some(mv), Some(tv)) if STROKE_LAYERS.contains(&k) => {
                Some(layer(bv.unwrap_or(&Value::Null), mv, tv))
            }
            (_, _, mv, _) => mv.cloned(),
        };
        match merged {
            Some(v) => out.insert(key.clone(), v),
            None => out.remove(key),
        };
    }
    Value::Object(out)
}

/// A `types` or `freeze` layer: strokes merged when all three hold
/// strokes (an image layer is not merged: mine wins).
fn layer(base: &Value, mine: &Value, theirs: &Value) -> Value {
    let strokes = |v: &Value| v.get("strokes").cloned();
    match (strokes(mine), strokes(theirs), mine.as_object()) {
        (Some(ms), Some(ts), Some(m)) => {
            let mut out = m.clone();
            let bs = strokes(base).unwrap_or(Value::Null);
            out.insert("strokes".into(), lists(&bs, &ms, &ts));
            Value::Object(out)
        }
        _ => mine.clone(),
    }
}

/// One control list, merged as the module docs say. Elements are found
/// by key through hash maps: a 0.7 MB scene has thousands of strokes.
fn lists(base: &Value, mine: &Value, theirs: &Value) -> Value {
    if !mine.is_array() {
        return mine.clone();
    }
    let keyed = |v: &Value| -> Vec<(String, Value)> {
        v.as_array()
            .map(|a| a.iter().map(|e| (key(e), e.clone())).collect())
            .unwrap_or_default()
    };
    let b: HashMap<String, Value> = keyed(base).into_iter().collect();
    let m = keyed(mine);
    let mine_keys: HashSet<&str> = m.iter().map(|(k, _)| k.as_str()).collect();
    let mut out: Vec<Option<(String, Value)>> = keyed(theirs).into_iter().map(Some).collect();
    let mut at: HashMap<String, usize> = HashMap::new();
    for (i, e) in out.iter().enumerate().rev() {
        if let Some((k, _)) = e {
            at.insert(k.clone(), i);
        }
    }
    let holds = |out: &[Option<(String, Value)>], i: usize, v: &Value| {
        out[i].as_ref().is_some_and(|(_, e)| e == v)
    };
    // What I removed since the base goes, unless they changed it.
    for (k, was) in &b {
        if !mine_keys.contains(k.as_str())
            && let Some(&i) = at.get(k)
            && holds(&out, i, was)
        {
            out[i] = None;
            at.remove(k);
        }
    }
    for (k, e) in m {
        match (b.get(&k), at.get(&k).copied()) {
            // Unchanged by me: theirs stands (or their removal).
            (Some(was), _) if *was == e => {}
            // Changed by me: mine replaces theirs.
            (Some(_), Some(i)) => out[i] = Some((k, e)),
            // Added by me, and they added the same.
            (None, Some(i)) if holds(&out, i, &e) => {}
            // Added by me under an id they used for something else (only
            // elements with an id get here: a value key means equal).
            (None, Some(_)) => {
                let mut e = e;
                e["id"] = Value::String(fresh_id(&k, &at));
                let k = key(&e);
                at.insert(k.clone(), out.len());
                out.push(Some((k, e)));
            }
            // Changed by me, removed by them; or added by me.
            (_, None) => {
                at.insert(k.clone(), out.len());
                out.push(Some((k, e)));
            }
        }
    }
    Value::Array(out.into_iter().flatten().map(|(_, e)| e).collect())
}

/// An element's identity: its `id`, else its whole value.
fn key(e: &Value) -> String {
    match e.get("id").and_then(Value::as_str) {
        Some(id) => format!("id:{id}"),
        None => format!("value:{e}"),
    }
}

/// The id of `key` (`id:…`) with a suffix no key in `taken` has.
fn fresh_id(key: &str, taken: &HashMap<String, usize>) -> String {
    let id = key.strip_prefix("id:").unwrap_or(key);
    (2..)
        .map(|n| format!("{id}-{n}"))
        .find(|c| !taken.contains_key(&format!("id:{c}")))
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::{Map, json};

    fn merged(base: Value, mine: Value, theirs: Value) -> Map<String, Value> {
        merge(&base, &mine, &theirs).as_object().cloned().unwrap()
    }

    fn p(id: &str, x: u32) -> Value {
        json!({"id": id, "at": [x, 10], "height_m": 100, "radius_px": 4})
    }

    #[test]
    fn two_tabs_first_points_both_named_p1_are_both_kept() {
        let base = json!({"size": [64, 64], "seed": 1, "points": []});
        let theirs = json!({"size": [64, 64], "seed": 1, "points": [p("p1", 10)]});
        let mine = json!({"size": [64, 64], "seed": 2, "points": [p("p1", 40)]});
        let m = merged(base, mine, theirs);
        let mut renamed = p("p1", 40);
        renamed["id"] = json!("p1-2");
        assert_eq!(m["points"], json!([p("p1", 10), renamed]));
        assert_eq!(m["seed"], 2, "mine where I changed it");
    }

    #[test]
    fn changes_removals_and_their_edits() {
        let base = json!({"seed": 1, "points": [p("a", 1), p("b", 2), p("c", 3)]});
        // I move a, remove b and c; they move c, add d, change the seed.
        let mine = json!({"seed": 1, "points": [p("a", 9)]});
        let theirs = json!({"seed": 5, "points": [p("a", 1), p("b", 2), p("c", 7), p("d", 4)]});
        let m = merged(base, mine, theirs);
        assert_eq!(m["points"], json!([p("a", 9), p("c", 7), p("d", 4)]));
        assert_eq!(m["seed"], 5, "theirs where I did not change it");
    }

    #[test]
    fn strokes_go_on_top_and_fields_only_i_have_stay() {
        let s = |x: u32| json!({"points": [[x, 1]], "radius_px": 2});
        let base = json!({"freeze": {"strokes": [s(1)]}});
        let theirs = json!({"freeze": {"strokes": [s(1), s(2)]}});
        let mine = json!({"freeze": {"strokes": [s(1), s(3)]}, "sculpt": [s(9)]});
        let m = merged(base, mine, theirs);
        assert_eq!(m["freeze"], json!({"strokes": [s(1), s(2), s(3)]}));
        assert_eq!(m["sculpt"], json!([s(9)]));
        // Only they painted a layer: it stays.
        let m = merged(json!({}), json!({}), json!({"types": {"strokes": [s(4)]}}));
        assert_eq!(m["types"], json!({"strokes": [s(4)]}));
    }
}
