//! The strict JSON reader behind [`Scene::parse`]: walks a `serde_json`
//! value, tracking the JSON path, rejecting unknown fields and checking
//! every value's range as it goes (serde's derive reports neither paths nor
//! ranges in this form).

mod constraints;
mod paint;
mod reader;
mod sculpt;

use super::*;
use reader::{R, Range, Reader, join};
use serde_json::{Map, Value};

pub fn scene(bytes: &[u8], file: &Path) -> R<Scene> {
    let r = Reader { file };
    let root: Value = serde_json::from_slice(bytes)
        .map_err(|e| SceneError::new(file, "$", SceneErrorKind::Json(e.to_string())))?;
    let m = r.object(
        &root,
        "$",
        &[
            "version",
            "database",
            "size",
            "seed",
            "jitter",
            "passes",
            "start_exemplar",
            "points",
            "curves",
            "junctions",
            "types",
            "freeze",
            "pastes",
            "sculpt",
        ],
    )?;
    let version = match m.get("version") {
        None => 1,
        Some(v) => match v.as_u64() {
            Some(n @ 1..=2) => n,
            _ => return Err(r.invalid("version", v, "1 or 2")),
        },
    };
    let database = match m.get("database") {
        None | Some(Value::Null) => None,
        Some(v) => Some(r.path_value(v, "database")?),
    };
    let size_v = r.required(m, "$", "size", "[width, height] in pixels")?;
    let size = match size_v.as_array().map(|a| a.as_slice()) {
        Some([w, h]) => {
            let side = |v: &Value, p: &str| match v.as_u64() {
                Some(x) if (1..=65535).contains(&x) => Ok(x as usize),
                _ => Err(r.invalid(p, v, "an integer in 1..=65535")),
            };
            (side(w, "size[0]")?, side(h, "size[1]")?)
        }
        _ => {
            return Err(r.invalid(
                "size",
                size_v,
                "[width, height], each an integer in 1..=65535",
            ));
        }
    };
    crate::size::check_dims(size.0, size.1).map_err(|e| {
        r.invalid(
            "size",
            size_v,
            format!("a size the synthesizer accepts ({e})"),
        )
    })?;
    let (fw, fh) = (size.0 as f64, size.1 as f64);
    let (v, vp) = r.field(m, "$", "seed", "an integer seed in 0..=4294967295")?;
    let seed = r.integer(v, &vp, u32::MAX as u64)? as u32;
    let jitter = r.number_or(
        m,
        "$",
        "jitter",
        Range::closed(0.0, 4.0, "0..=4 texels"),
        0.4,
    )?;
    let passes = match m.get("passes") {
        Some(v) => r.integer(v, "passes", 16)? as u32,
        None => 2,
    };
    let start_exemplar = match m.get("start_exemplar") {
        Some(v) => Some(r.integer(v, "start_exemplar", 65535)? as usize),
        None => None,
    };
    let mut ids = Vec::new();
    let d = Doc {
        r: &r,
        m,
        size: (fw, fh),
        version,
    };
    let points = constraints::points(&d, &mut ids)?;
    let curves = constraints::curves(&d, &mut ids)?;
    let junctions = constraints::junctions(&d)?;
    let types = paint::types(&d)?;
    let freeze = paint::freeze(&d)?;
    let pastes = paint::pastes(&d, &mut ids)?;
    let sculpt = sculpt::sculpt(&d)?;

    Ok(Scene {
        file: file.to_path_buf(),
        database,
        width: size.0,
        height: size.1,
        seed,
        jitter,
        passes,
        start_exemplar,
        points,
        curves,
        junctions,
        types,
        freeze,
        pastes,
        sculpt,
    })
}

/// What each section of a document is read with: the reader, the
/// document's top-level object, the terrain size in pixels (the bound
/// of every `[x, y]` on the terrain) and the format version.
struct Doc<'a> {
    r: &'a Reader<'a>,
    m: &'a Map<String, Value>,
    size: (f64, f64),
    /// The format version (1 when absent): it sets defaults that changed.
    version: u64,
}

impl Doc<'_> {
    /// The objects of the optional top-level array `key` (see
    /// [`Reader::items`]).
    fn items<T>(
        &self,
        key: &str,
        what: &str,
        allowed: &[&str],
        item: impl FnMut(&str, &Map<String, Value>) -> R<T>,
    ) -> R<Vec<T>> {
        self.r.items(self.m.get(key), key, 0, what, allowed, item)
    }

    /// The `"at"` pixel and `"height_m"` of an item that sets a height at a
    /// place (a point constraint, a junction height).
    fn height_at(&self, o: &Map<String, Value>, path: &str) -> R<(DVec2, f64)> {
        let r = self.r;
        let (v, vp) = r.field(o, path, "at", "[x, y] in pixels")?;
        let at = r.xy(v, &vp, self.size)?;
        let (v, vp) = r.field(o, path, "height_m", "a height in metres")?;
        let height_m = r.height(v, &vp)?;
        Ok((at, height_m))
    }
}
