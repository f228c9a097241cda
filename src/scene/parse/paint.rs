//! Painted and pasted controls of a scene: type paint and frozen regions
//! (an image or strokes) and copy-pastes (paper §5).

use super::*;

/// `"types"`: an index image or type strokes.
pub(super) fn types(
    r: &Reader,
    m: &Map<String, Value>,
    (fw, fh): (f64, f64),
) -> R<Option<TypePaint>> {
    let types = match m.get("types") {
        None => None,
        Some(v) => {
            let o = r.object(v, "types", &["image", "strokes"])?;
            Some(match (o.get("image"), o.get("strokes")) {
                (Some(img), None) => TypePaint::Image(r.path_value(img, "types.image")?),
                (None, Some(s)) => {
                    let mut out = Vec::new();
                    for (i, st) in r
                        .array(s, "types.strokes", 1, "strokes")?
                        .iter()
                        .enumerate()
                    {
                        let path = format!("types.strokes[{i}]");
                        let o = r.object(st, &path, &["type", "erase", "points", "radius_px"])?;
                        let name = if r.erase(o, &path)? {
                            if let Some(t) = o.get("type") {
                                return Err(r.invalid(
                                    &join(&path, "type"),
                                    t,
                                    "no type on an eraser stroke (\"erase\": true)",
                                ));
                            }
                            None
                        } else {
                            let name = r.string(
                                r.required(o, &path, "type", "a type name of the database")?,
                                &join(&path, "type"),
                                "a type name",
                            )?;
                            Some(name.to_string())
                        };
                        out.push((name, r.stroke(o, &path, (fw, fh))?));
                    }
                    TypePaint::Strokes(out)
                }
                _ => {
                    return Err(r.invalid(
                        "types",
                        v,
                        "an object with exactly one of \"image\" or \"strokes\"",
                    ));
                }
            })
        }
    };
    Ok(types)
}

/// `"freeze"`: a mask image or freeze/thaw strokes.
pub(super) fn freeze(
    r: &Reader,
    m: &Map<String, Value>,
    (fw, fh): (f64, f64),
) -> R<Option<Freeze>> {
    let freeze = match m.get("freeze") {
        None => None,
        Some(v) => {
            let o = r.object(v, "freeze", &["mask", "strokes"])?;
            Some(match (o.get("mask"), o.get("strokes")) {
                (Some(mask), None) => Freeze::Mask(r.path_value(mask, "freeze.mask")?),
                (None, Some(s)) => {
                    let mut out = Vec::new();
                    for (i, st) in r
                        .array(s, "freeze.strokes", 1, "strokes")?
                        .iter()
                        .enumerate()
                    {
                        let path = format!("freeze.strokes[{i}]");
                        let o = r.object(st, &path, &["erase", "points", "radius_px"])?;
                        out.push((!r.erase(o, &path)?, r.stroke(o, &path, (fw, fh))?));
                    }
                    Freeze::Strokes(out)
                }
                _ => {
                    return Err(r.invalid(
                        "freeze",
                        v,
                        "an object with exactly one of \"mask\" or \"strokes\"",
                    ));
                }
            })
        }
    };
    Ok(freeze)
}

/// `"pastes"`: copy-pastes from the terrain or an exemplar; their ids join `ids`.
pub(super) fn pastes(
    r: &Reader,
    m: &Map<String, Value>,
    (fw, fh): (f64, f64),
    ids: &mut Vec<String>,
) -> R<Vec<PasteSpec>> {
    let mut pastes = Vec::new();
    if let Some(v) = m.get("pastes") {
        for (i, p) in r.array(v, "pastes", 0, "pastes")?.iter().enumerate() {
            let path = format!("pastes[{i}]");
            let o = r.object(
                p,
                &path,
                &["id", "source", "exemplar", "lasso", "to", "delta_m"],
            )?;
            let id = r.id(o, &path, path.clone(), ids)?;
            let sp = join(&path, "source");
            let sv = r.required(o, &path, "source", "\"terrain\" or \"exemplar\"")?;
            let source = match (sv.as_str(), o.get("exemplar")) {
                (Some("terrain"), None) => PasteSource::Terrain,
                (Some("terrain"), Some(e)) => {
                    return Err(r.invalid(
                        &join(&path, "exemplar"),
                        e,
                        "no exemplar index when the source is \"terrain\"",
                    ));
                }
                (Some("exemplar"), Some(e)) => {
                    PasteSource::Exemplar(r.integer(e, &join(&path, "exemplar"), 65535)? as usize)
                }
                (Some("exemplar"), None) => {
                    return Err(SceneError::new(
                        r.file,
                        join(&path, "exemplar"),
                        SceneErrorKind::Missing("an exemplar index of the database"),
                    ));
                }
                _ => return Err(r.invalid(&sp, sv, "\"terrain\" or \"exemplar\"")),
            };
            // Exemplar lassos are checked against the exemplar's size when
            // the database is known; here only against the largest side.
            let bound = match source {
                PasteSource::Terrain => (fw, fh),
                PasteSource::Exemplar(_) => (65535.0, 65535.0),
            };
            let lp = join(&path, "lasso");
            let lasso = r
                .array(
                    r.required(o, &path, "lasso", "an array of >= 3 [x, y] points")?,
                    &lp,
                    3,
                    "[x, y] points",
                )?
                .iter()
                .enumerate()
                .map(|(k, q)| r.xy(q, &format!("{lp}[{k}]"), bound))
                .collect::<R<Vec<_>>>()?;
            let to = r.xy(
                r.required(o, &path, "to", "[x, y] in pixels")?,
                &join(&path, "to"),
                (fw, fh),
            )?;
            let delta_m = match o.get("delta_m") {
                Some(v) => r.height(v, &join(&path, "delta_m"))?,
                None => 0.0,
            };
            pastes.push(PasteSpec {
                id,
                source,
                lasso,
                to,
                delta_m,
            });
        }
    }
    Ok(pastes)
}
