//! The strict JSON reader behind [`Scene::parse`]: walks a `serde_json`
//! value, tracking the JSON path, rejecting unknown fields and checking
//! every value's range as it goes (serde's derive reports neither paths nor
//! ranges in this form).

use super::*;
use crate::synth::control::curve::{LEFT, MAX_REACH_PX, MAX_SLOPE_DEG, RIGHT, Widget};
use serde_json::{Map, Value};

/// Largest array the format accepts anywhere (points of a curve, strokes…):
/// keeps a hostile file from asking for unbounded work after parsing.
const MAX_ITEMS: usize = 100_000;

struct Reader<'a> {
    file: &'a Path,
}

type R<T> = Result<T, SceneError>;

fn describe(v: &Value) -> String {
    let s = v.to_string();
    if s.chars().count() > 40 {
        s.chars().take(40).chain(std::iter::once('…')).collect()
    } else {
        s
    }
}

impl Reader<'_> {
    fn invalid(&self, path: &str, v: &Value, expected: impl Into<String>) -> SceneError {
        SceneError::new(
            self.file,
            path,
            SceneErrorKind::Invalid {
                found: describe(v),
                expected: expected.into(),
            },
        )
    }

    /// An object with only `allowed` keys.
    fn object<'v>(&self, v: &'v Value, path: &str, allowed: &[&str]) -> R<&'v Map<String, Value>> {
        let m = v
            .as_object()
            .ok_or_else(|| self.invalid(path, v, "an object"))?;
        if let Some(k) = m.keys().find(|k| !allowed.contains(&k.as_str())) {
            return Err(SceneError::new(
                self.file,
                join(path, k),
                SceneErrorKind::Unknown(allowed.join(", ")),
            ));
        }
        Ok(m)
    }

    fn required<'v>(
        &self,
        m: &'v Map<String, Value>,
        path: &str,
        key: &str,
        expected: &'static str,
    ) -> R<&'v Value> {
        m.get(key).ok_or_else(|| {
            SceneError::new(
                self.file,
                join(path, key),
                SceneErrorKind::Missing(expected),
            )
        })
    }

    fn array<'v>(&self, v: &'v Value, path: &str, min: usize, what: &str) -> R<&'v [Value]> {
        match v.as_array() {
            Some(a) if a.len() >= min && a.len() <= MAX_ITEMS => Ok(a),
            _ => Err(self.invalid(path, v, format!("an array of {min}..={MAX_ITEMS} {what}"))),
        }
    }

    fn number(
        &self,
        v: &Value,
        path: &str,
        lo: f64,
        hi: f64,
        lo_open: bool,
        expected: &str,
    ) -> R<f64> {
        match v.as_f64() {
            Some(x) if x.is_finite() && x <= hi && (x > lo || (!lo_open && x == lo)) => Ok(x),
            _ => Err(self.invalid(path, v, expected)),
        }
    }

    fn integer(&self, v: &Value, path: &str, hi: u64) -> R<u64> {
        match v.as_u64() {
            Some(x) if x <= hi => Ok(x),
            _ => Err(self.invalid(path, v, format!("an integer in 0..={hi}"))),
        }
    }

    fn string<'v>(&self, v: &'v Value, path: &str, expected: &str) -> R<&'v str> {
        match v.as_str() {
            Some(s) if !s.is_empty() && s.len() <= 4096 => Ok(s),
            _ => Err(self.invalid(path, v, expected)),
        }
    }

    /// `[x, y]` within `[lo, hi]` per axis.
    fn xy(&self, v: &Value, path: &str, (w, h): (f64, f64)) -> R<DVec2> {
        let expected = || format!("[x, y] with x in 0..={w} and y in 0..={h} pixels");
        let a = match v.as_array() {
            Some(a) if a.len() == 2 => a,
            _ => return Err(self.invalid(path, v, expected())),
        };
        let x = self.number(
            &a[0],
            &format!("{path}[0]"),
            0.0,
            w,
            false,
            &format!("x in 0..={w} pixels"),
        )?;
        let y = self.number(
            &a[1],
            &format!("{path}[1]"),
            0.0,
            h,
            false,
            &format!("y in 0..={h} pixels"),
        )?;
        Ok(DVec2::new(x, y))
    }

    /// `[left, right]`.
    fn pair(
        &self,
        v: &Value,
        path: &str,
        lo: f64,
        hi: f64,
        lo_open: bool,
        expected: &str,
    ) -> R<[f64; 2]> {
        let a = match v.as_array() {
            Some(a) if a.len() == 2 => a,
            _ => return Err(self.invalid(path, v, format!("[left, right], each {expected}"))),
        };
        let mut out = [0.0; 2];
        for side in [LEFT, RIGHT] {
            out[side] = self.number(
                &a[side],
                &format!("{path}[{side}]"),
                lo,
                hi,
                lo_open,
                expected,
            )?;
        }
        Ok(out)
    }

    fn height(&self, v: &Value, path: &str) -> R<f64> {
        self.number(
            v,
            path,
            -MAX_ABS_HEIGHT_M,
            MAX_ABS_HEIGHT_M,
            false,
            "a height in -20000..=20000 m",
        )
    }

    fn id(
        &self,
        m: &Map<String, Value>,
        path: &str,
        default: String,
        seen: &mut Vec<String>,
    ) -> R<String> {
        let id = match m.get("id") {
            Some(v) => self
                .string(v, &join(path, "id"), "a non-empty string")?
                .to_string(),
            None => default,
        };
        if seen.contains(&id) {
            return Err(self.invalid(
                &join(path, "id"),
                &Value::String(id),
                "an id no other item of the scene has",
            ));
        }
        seen.push(id.clone());
        Ok(id)
    }

    fn path_value(&self, v: &Value, path: &str) -> R<PathBuf> {
        let p = PathBuf::from(self.string(v, path, "a file path")?);
        Ok(match self.file.parent() {
            Some(dir) if p.is_relative() => dir.join(p),
            _ => p,
        })
    }

    /// A stroke's optional `"erase"` flag (default false).
    fn erase(&self, m: &Map<String, Value>, path: &str) -> R<bool> {
        match m.get("erase") {
            None => Ok(false),
            Some(Value::Bool(b)) => Ok(*b),
            Some(v) => Err(self.invalid(&join(path, "erase"), v, "true or false")),
        }
    }

    fn stroke(&self, m: &Map<String, Value>, path: &str, size: (f64, f64)) -> R<Stroke> {
        let pts = self.array(
            self.required(m, path, "points", "an array of [x, y] points")?,
            &join(path, "points"),
            1,
            "[x, y] points",
        )?;
        let points = pts
            .iter()
            .enumerate()
            .map(|(k, p)| self.xy(p, &format!("{}[{k}]", join(path, "points")), size))
            .collect::<R<Vec<_>>>()?;
        let radius_px = self.number(
            self.required(m, path, "radius_px", "a brush radius in pixels")?,
            &join(path, "radius_px"),
            0.0,
            4096.0,
            true,
            "0 < radius <= 4096 pixels",
        )?;
        Ok(Stroke { points, radius_px })
    }
}

fn join(path: &str, key: &str) -> String {
    if path == "$" {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

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
    crate::heightfield::check_dims(size.0, size.1).map_err(|e| {
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

    let mut points = Vec::new();
    if let Some(v) = m.get("points") {
        for (i, p) in r
            .array(v, "points", 0, "point constraints")?
            .iter()
            .enumerate()
        {
            let path = format!("points[{i}]");
            let o = r.object(
                p,
                &path,
                &[
                    "id",
                    "at",
                    "height_m",
                    "slope_deg",
                    "slope_direction_deg",
                    "radius_px",
                ],
            )?;
            let id = r.id(o, &path, path.clone(), &mut ids)?;
            let at = r.xy(
                r.required(o, &path, "at", "[x, y] in pixels")?,
                &join(&path, "at"),
                (fw, fh),
            )?;
            let height_m = r.height(
                r.required(o, &path, "height_m", "a height in metres")?,
                &join(&path, "height_m"),
            )?;
            let slope_deg = match o.get("slope_deg") {
                Some(v) => r.number(
                    v,
                    &join(&path, "slope_deg"),
                    0.0,
                    80.0,
                    false,
                    "0..=80 degrees",
                )?,
                None => 0.0,
            };
            let slope_direction_deg = match o.get("slope_direction_deg") {
                Some(v) => r.number(
                    v,
                    &join(&path, "slope_direction_deg"),
                    -360.0,
                    360.0,
                    false,
                    "-360..=360 degrees",
                )?,
                None => 0.0,
            };
            let radius_px = r.number(
                r.required(o, &path, "radius_px", "a radius in pixels")?,
                &join(&path, "radius_px"),
                0.0,
                MAX_REACH_PX,
                true,
                "0 < radius <= 4096 pixels",
            )?;
            points.push(PointSpec {
                id,
                at,
                height_m,
                slope_deg,
                slope_direction_deg,
                radius_px,
            });
        }
    }

    let mut curves = Vec::new();
    if let Some(v) = m.get("curves") {
        for (i, c) in r
            .array(v, "curves", 0, "curve constraints")?
            .iter()
            .enumerate()
        {
            let path = format!("curves[{i}]");
            let o = r.object(c, &path, &["id", "points", "smoothing", "widgets"])?;
            let id = r.id(o, &path, path.clone(), &mut ids)?;
            let pp = join(&path, "points");
            let pts = r.array(
                r.required(o, &path, "points", "an array of >= 2 [x, y] points")?,
                &pp,
                2,
                "[x, y] points",
            )?;
            let points = pts
                .iter()
                .enumerate()
                .map(|(k, p)| r.xy(p, &format!("{pp}[{k}]"), (fw, fh)))
                .collect::<R<Vec<_>>>()?;
            let smoothing = match o.get("smoothing") {
                Some(v) => r.integer(v, &join(&path, "smoothing"), 8)? as u32,
                None => 2,
            };
            let wp = join(&path, "widgets");
            let ws = r.array(
                r.required(o, &path, "widgets", "an array of >= 1 widgets")?,
                &wp,
                1,
                "widgets",
            )?;
            let mut widgets = Vec::with_capacity(ws.len());
            for (k, w) in ws.iter().enumerate() {
                let path = format!("{wp}[{k}]");
                let o = r.object(w, &path, &["at", "height_m", "slope_deg", "reach_px"])?;
                let at = r.number(
                    r.required(o, &path, "at", "a fraction of the arc length")?,
                    &join(&path, "at"),
                    0.0,
                    1.0,
                    false,
                    "0..=1 (fraction of the curve's arc length)",
                )?;
                let height_m = r.height(
                    r.required(o, &path, "height_m", "a height in metres")?,
                    &join(&path, "height_m"),
                )?;
                let slope_deg = r.pair(
                    r.required(o, &path, "slope_deg", "[left, right] slopes in degrees")?,
                    &join(&path, "slope_deg"),
                    -MAX_SLOPE_DEG,
                    MAX_SLOPE_DEG,
                    false,
                    "-85..=85 degrees",
                )?;
                let reach_px = r.pair(
                    r.required(o, &path, "reach_px", "[left, right] reaches in pixels")?,
                    &join(&path, "reach_px"),
                    0.0,
                    MAX_REACH_PX,
                    true,
                    "0 < reach <= 4096 pixels",
                )?;
                widgets.push(Widget {
                    at,
                    height_m,
                    slope_deg,
                    reach_px,
                });
            }
            if points.windows(2).all(|w| w[0] == w[1]) {
                return Err(r.invalid(
                    &pp,
                    o.get("points").expect("checked"),
                    "points that are not all the same (a curve needs length)",
                ));
            }
            curves.push(CurveItem {
                id,
                spec: CurveSpec {
                    points,
                    widgets,
                    smoothing,
                },
            });
        }
    }

    let mut junctions = Vec::new();
    if let Some(v) = m.get("junctions") {
        for (i, j) in r
            .array(v, "junctions", 0, "junction heights")?
            .iter()
            .enumerate()
        {
            let path = format!("junctions[{i}]");
            let o = r.object(j, &path, &["at", "height_m"])?;
            let at = r.xy(
                r.required(o, &path, "at", "[x, y] in pixels")?,
                &join(&path, "at"),
                (fw, fh),
            )?;
            let height_m = r.height(
                r.required(o, &path, "height_m", "a height in metres")?,
                &join(&path, "height_m"),
            )?;
            junctions.push(JunctionHeight { at, height_m });
        }
    }

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

    let mut pastes = Vec::new();
    if let Some(v) = m.get("pastes") {
        for (i, p) in r.array(v, "pastes", 0, "pastes")?.iter().enumerate() {
            let path = format!("pastes[{i}]");
            let o = r.object(
                p,
                &path,
                &["id", "source", "exemplar", "lasso", "to", "delta_m"],
            )?;
            let id = r.id(o, &path, path.clone(), &mut ids)?;
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
                        file,
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
