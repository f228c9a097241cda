//! The strict JSON reader behind [`Scene::parse`]: walks a `serde_json`
//! value, tracking the JSON path, rejecting unknown fields and checking
//! every value's range as it goes (serde's derive reports neither paths nor
//! ranges in this form).

mod constraints;
mod paint;
mod reader;

use super::*;
use reader::{R, Reader, join};
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
        ],
    )?;
    if let Some(v) = m.get("version")
        && v.as_u64() != Some(1)
    {
        return Err(r.invalid("version", v, "1"));
    }
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
    let seed = r.integer(
        r.required(m, "$", "seed", "an integer seed in 0..=4294967295")?,
        "seed",
        u32::MAX as u64,
    )? as u32;
    let jitter = match m.get("jitter") {
        Some(v) => r.number(v, "jitter", 0.0, 4.0, false, "0..=4 texels")?,
        None => 0.4,
    };
    let passes = match m.get("passes") {
        Some(v) => r.integer(v, "passes", 16)? as u32,
        None => 2,
    };
    let start_exemplar = match m.get("start_exemplar") {
        Some(v) => Some(r.integer(v, "start_exemplar", 65535)? as usize),
        None => None,
    };
    let mut ids = Vec::new();
    let bounds = (fw, fh);
    let points = constraints::points(&r, m, bounds, &mut ids)?;
    let curves = constraints::curves(&r, m, bounds, &mut ids)?;
    let junctions = constraints::junctions(&r, m, bounds)?;
    let types = paint::types(&r, m, bounds)?;
    let freeze = paint::freeze(&r, m, bounds)?;
    let pastes = paint::pastes(&r, m, bounds, &mut ids)?;

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
    })
}
