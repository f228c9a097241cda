//! Painted and pasted controls of a scene: type paint and frozen regions
//! (an image or strokes) and copy-pastes (paper §5).

use super::*;

/// What `"types"` and `"freeze"` hold: an image file or strokes.
enum Painted<T> {
    Image(PathBuf),
    Strokes(Vec<T>),
}

/// The optional object `m[key]` with exactly one of an image file at
/// `image` or at least one stroke at `"strokes"` (each with only
/// `stroke_keys`, read by `stroke` with its path).
fn image_or_strokes<T>(
    d: &Doc,
    key: &str,
    image: &str,
    stroke_keys: &[&str],
    stroke: impl FnMut(&str, &Map<String, Value>) -> R<T>,
) -> R<Option<Painted<T>>> {
    let r = d.r;
    let Some(v) = d.m.get(key) else {
        return Ok(None);
    };
    let o = r.object(v, key, &[image, "strokes"])?;
    Ok(Some(match (o.get(image), o.get("strokes")) {
        (Some(img), None) => Painted::Image(r.path_value(img, &join(key, image))?),
        (None, Some(s)) => Painted::Strokes(r.items(
            Some(s),
            &join(key, "strokes"),
            1,
            "strokes",
            stroke_keys,
            stroke,
        )?),
        _ => {
            return Err(r.invalid(
                key,
                v,
                format!("an object with exactly one of \"{image}\" or \"strokes\""),
            ));
        }
    }))
}

/// `"types"`: an index image or type strokes.
pub(super) fn types(d: &Doc) -> R<Option<TypePaint>> {
    let r = d.r;
    let keys = ["type", "erase", "points", "radius_px"];
    let painted = image_or_strokes(d, "types", "image", &keys, |path, o| {
        let name = if r.erase(o, path)? {
            if let Some(t) = o.get("type") {
                return Err(r.invalid(
                    &join(path, "type"),
                    t,
                    "no type on an eraser stroke (\"erase\": true)",
                ));
            }
            None
        } else {
            let (v, vp) = r.field(o, path, "type", "a type name of the database")?;
            let name = r.string(v, &vp, "a type name")?;
            Some(name.to_string())
        };
        Ok((name, r.stroke(o, path, d.size)?))
    })?;
    Ok(painted.map(|p| match p {
        Painted::Image(file) => TypePaint::Image(file),
        Painted::Strokes(strokes) => TypePaint::Strokes(strokes),
    }))
}

/// `"freeze"`: a mask image or freeze/thaw strokes.
pub(super) fn freeze(d: &Doc) -> R<Option<Freeze>> {
    let r = d.r;
    let keys = ["erase", "points", "radius_px"];
    let painted = image_or_strokes(d, "freeze", "mask", &keys, |path, o| {
        Ok((!r.erase(o, path)?, r.stroke(o, path, d.size)?))
    })?;
    Ok(painted.map(|p| match p {
        Painted::Image(file) => Freeze::Mask(file),
        Painted::Strokes(strokes) => Freeze::Strokes(strokes),
    }))
}

/// `"pastes"`: copy-pastes from the terrain or an exemplar; their ids join `ids`.
pub(super) fn pastes(d: &Doc, ids: &mut Vec<String>) -> R<Vec<PasteSpec>> {
    let r = d.r;
    d.items(
        "pastes",
        "pastes",
        &["id", "source", "exemplar", "lasso", "to", "delta_m", "lift"],
        |path, o| {
            let id = r.id(o, path, path.to_string(), ids)?;
            let (sv, sp) = r.field(o, path, "source", "\"terrain\" or \"exemplar\"")?;
            let source = match (sv.as_str(), o.get("exemplar")) {
                (Some("terrain"), None) => PasteSource::Terrain,
                (Some("terrain"), Some(e)) => {
                    return Err(r.invalid(
                        &join(path, "exemplar"),
                        e,
                        "no exemplar index when the source is \"terrain\"",
                    ));
                }
                (Some("exemplar"), Some(e)) => {
                    PasteSource::Exemplar(r.integer(e, &join(path, "exemplar"), 65535)? as usize)
                }
                (Some("exemplar"), None) => {
                    return Err(SceneError::new(
                        r.file,
                        join(path, "exemplar"),
                        SceneErrorKind::Missing("an exemplar index of the database"),
                    ));
                }
                _ => return Err(r.invalid(&sp, sv, "\"terrain\" or \"exemplar\"")),
            };
            // Exemplar lassos are checked against the exemplar's size when
            // the database is known; here only against the largest side.
            let bound = match source {
                PasteSource::Terrain => d.size,
                PasteSource::Exemplar(_) => (65535.0, 65535.0),
            };
            let lasso = r.points(o, path, "lasso", 3, "an array of >= 3 [x, y] points", bound)?;
            let (v, vp) = r.field(o, path, "to", "[x, y] in pixels")?;
            let to = r.xy(v, &vp, d.size)?;
            let delta_m = match o.get("delta_m") {
                Some(v) => r.height(v, &join(path, "delta_m"))?,
                None => 0.0,
            };
            // Version 1 had only the source's own heights.
            let lift = match (o.get("lift"), d.version) {
                (None, 1) => Lift::Source,
                (None, _) => Lift::Ground,
                (Some(v), _) => match v.as_str() {
                    Some("ground") => Lift::Ground,
                    Some("source") => Lift::Source,
                    _ => return Err(r.invalid(&join(path, "lift"), v, "\"ground\" or \"source\"")),
                },
            };
            Ok(PasteSpec {
                id,
                source,
                lasso,
                to,
                delta_m,
                lift,
            })
        },
    )
}
