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

/// One control list, merged as the module docs say.
fn lists(base: &Value, mine: &Value, theirs: &Value) -> Value {
    let Some(m) = mine.as_array().cloned() else {
        return mine.clone();
    };
    let mut out = theirs.as_array().cloned().unwrap_or_default();
    let empty = Vec::new();
    let b = base.as_array().unwrap_or(&empty);
    let find = |list: &[Value], k: &str| list.iter().position(|e| key(e) == k);
    // What I removed since the base goes, unless they changed it.
    for e in b {
        let k = key(e);
        if find(&m, &k).is_none()
            && let Some(i) = find(&out, &k)
            && out[i] == *e
        {
            out.remove(i);
        }
    }
    for e in m {
        let k = key(&e);
        match (find(b, &k).map(|i| &b[i]), find(&out, &k)) {
            // Unchanged by me: theirs stands (or their removal).
            (Some(was), _) if *was == e => {}
            // Changed by me: mine replaces theirs.
            (Some(_), Some(i)) => out[i] = e,
            // Changed by me, removed by them; or added by me.
            (Some(_), None) | (None, None) => out.push(e),
            // Added by me, and they added the same.
            (None, Some(i)) if out[i] == e => {}
            // Added by me under an id they used for something else.
            (None, Some(_)) => {
                let fresh = fresh_id(&k, &out);
                let mut e = e;
                e["id"] = Value::String(fresh);
                out.push(e);
            }
        }
    }
    Value::Array(out)
}

/// An element's identity: its `id`, else its whole value.
fn key(e: &Value) -> String {
    match e.get("id").and_then(Value::as_str) {
        Some(id) => format!("id:{id}"),
        None => format!("value:{e}"),
    }
}

/// `id` (a key `id:…`) with a suffix no element of `list` uses.
fn fresh_id(key: &str, list: &[Value]) -> String {
    let id = key.strip_prefix("id:").unwrap_or(key);
    let used = |c: &str| {
        list.iter()
            .any(|e| e.get("id").and_then(Value::as_str) == Some(c))
    };
    (2..)
        .map(|n| format!("{id}-{n}"))
        .find(|c| !used(c))
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
