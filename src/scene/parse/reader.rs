//! The path-naming JSON reader under the scene parser: typed getters that
//! reject unknown fields and out-of-range values with an error naming the
//! JSON path and the allowed range.

use super::*;
use crate::synth::control::curve::{LEFT, RIGHT};

/// Largest array the format accepts anywhere (points of a curve, strokes…):
/// keeps a hostile file from asking for unbounded work after parsing.
const MAX_ITEMS: usize = 100_000;

/// The values a number may take, and how an error names them.
#[derive(Clone, Copy)]
pub(super) struct Range<'e> {
    lo: f64,
    hi: f64,
    /// `lo` itself is excluded (a radius or reach of 0 has no extent).
    lo_open: bool,
    expected: &'e str,
}

impl<'e> Range<'e> {
    /// `lo..=hi`.
    pub(super) fn closed(lo: f64, hi: f64, expected: &'e str) -> Self {
        Range {
            lo,
            hi,
            lo_open: false,
            expected,
        }
    }

    /// `lo < x <= hi`.
    pub(super) fn above(lo: f64, hi: f64, expected: &'e str) -> Self {
        Range {
            lo_open: true,
            ..Range::closed(lo, hi, expected)
        }
    }

    fn contains(&self, x: f64) -> bool {
        x.is_finite() && x <= self.hi && (x > self.lo || (!self.lo_open && x == self.lo))
    }
}

pub(super) struct Reader<'a> {
    pub(super) file: &'a Path,
}

pub(super) type R<T> = Result<T, SceneError>;

fn describe(v: &Value) -> String {
    let s = v.to_string();
    if s.chars().count() > 40 {
        s.chars().take(40).chain(std::iter::once('…')).collect()
    } else {
        s
    }
}

impl Reader<'_> {
    pub(super) fn invalid(&self, path: &str, v: &Value, expected: impl Into<String>) -> SceneError {
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
    pub(super) fn object<'v>(
        &self,
        v: &'v Value,
        path: &str,
        allowed: &[&str],
    ) -> R<&'v Map<String, Value>> {
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

    pub(super) fn required<'v>(
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

    /// [`Reader::required`] with the field's path (`path.key`), which the
    /// typed read of its value names in its errors.
    pub(super) fn field<'v>(
        &self,
        m: &'v Map<String, Value>,
        path: &str,
        key: &str,
        expected: &'static str,
    ) -> R<(&'v Value, String)> {
        Ok((self.required(m, path, key, expected)?, join(path, key)))
    }

    pub(super) fn array<'v>(
        &self,
        v: &'v Value,
        path: &str,
        min: usize,
        what: &str,
    ) -> R<&'v [Value]> {
        match v.as_array() {
            Some(a) if a.len() >= min && a.len() <= MAX_ITEMS => Ok(a),
            _ => Err(self.invalid(path, v, format!("an array of {min}..={MAX_ITEMS} {what}"))),
        }
    }

    /// The objects of the array `v` at `path` (none when `v` is absent, at
    /// least `min` otherwise), each with only `allowed` keys, read in order
    /// by `item` with its path.
    pub(super) fn items<T>(
        &self,
        v: Option<&Value>,
        path: &str,
        min: usize,
        what: &str,
        allowed: &[&str],
        mut item: impl FnMut(&str, &Map<String, Value>) -> R<T>,
    ) -> R<Vec<T>> {
        let Some(v) = v else {
            return Ok(Vec::new());
        };
        self.array(v, path, min, what)?
            .iter()
            .enumerate()
            .map(|(i, e)| {
                let path = format!("{path}[{i}]");
                item(&path, self.object(e, &path, allowed)?)
            })
            .collect()
    }

    /// The required array `m[key]` of at least `min` `[x, y]` points, each
    /// within `bound`; `expected` says what is missing when it is absent.
    pub(super) fn points(
        &self,
        m: &Map<String, Value>,
        path: &str,
        key: &str,
        min: usize,
        expected: &'static str,
        bound: (f64, f64),
    ) -> R<Vec<DVec2>> {
        let (v, kp) = self.field(m, path, key, expected)?;
        self.array(v, &kp, min, "[x, y] points")?
            .iter()
            .enumerate()
            .map(|(k, p)| self.xy(p, &format!("{kp}[{k}]"), bound))
            .collect()
    }

    /// An optional number of `m`: `default` when `key` is absent, else
    /// checked as [`Reader::number`] does. Every number a scene may leave
    /// out (jitter, a point's slopes, a stroke's falloff) reads this way.
    pub(super) fn number_or(
        &self,
        m: &Map<String, Value>,
        path: &str,
        key: &str,
        range: Range,
        default: f64,
    ) -> R<f64> {
        match m.get(key) {
            Some(v) => self.number(v, &join(path, key), range),
            None => Ok(default),
        }
    }

    pub(super) fn number(&self, v: &Value, path: &str, range: Range) -> R<f64> {
        match v.as_f64() {
            Some(x) if range.contains(x) => Ok(x),
            _ => Err(self.invalid(path, v, range.expected)),
        }
    }

    pub(super) fn integer(&self, v: &Value, path: &str, hi: u64) -> R<u64> {
        match v.as_u64() {
            Some(x) if x <= hi => Ok(x),
            _ => Err(self.invalid(path, v, format!("an integer in 0..={hi}"))),
        }
    }

    pub(super) fn string<'v>(&self, v: &'v Value, path: &str, expected: &str) -> R<&'v str> {
        match v.as_str() {
            Some(s) if !s.is_empty() && s.len() <= 4096 => Ok(s),
            _ => Err(self.invalid(path, v, expected)),
        }
    }

    /// `[x, y]` within `[lo, hi]` per axis.
    pub(super) fn xy(&self, v: &Value, path: &str, (w, h): (f64, f64)) -> R<DVec2> {
        let expected = || format!("[x, y] with x in 0..={w} and y in 0..={h} pixels");
        let a = match v.as_array() {
            Some(a) if a.len() == 2 => a,
            _ => return Err(self.invalid(path, v, expected())),
        };
        let x = self.number(
            &a[0],
            &format!("{path}[0]"),
            Range::closed(0.0, w, &format!("x in 0..={w} pixels")),
        )?;
        let y = self.number(
            &a[1],
            &format!("{path}[1]"),
            Range::closed(0.0, h, &format!("y in 0..={h} pixels")),
        )?;
        Ok(DVec2::new(x, y))
    }

    /// `[left, right]`.
    pub(super) fn pair(&self, v: &Value, path: &str, range: Range) -> R<[f64; 2]> {
        let a = match v.as_array() {
            Some(a) if a.len() == 2 => a,
            _ => {
                let expected = format!("[left, right], each {}", range.expected);
                return Err(self.invalid(path, v, expected));
            }
        };
        let mut out = [0.0; 2];
        for side in [LEFT, RIGHT] {
            out[side] = self.number(&a[side], &format!("{path}[{side}]"), range)?;
        }
        Ok(out)
    }

    pub(super) fn height(&self, v: &Value, path: &str) -> R<f64> {
        self.number(
            v,
            path,
            Range::closed(
                -MAX_ABS_HEIGHT_M,
                MAX_ABS_HEIGHT_M,
                "a height in -20000..=20000 m",
            ),
        )
    }

    pub(super) fn id(
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

    pub(super) fn path_value(&self, v: &Value, path: &str) -> R<PathBuf> {
        let p = PathBuf::from(self.string(v, path, "a file path")?);
        Ok(match self.file.parent() {
            Some(dir) if p.is_relative() => dir.join(p),
            _ => p,
        })
    }

    /// A stroke's optional `"erase"` flag (default false).
    pub(super) fn erase(&self, m: &Map<String, Value>, path: &str) -> R<bool> {
        match m.get("erase") {
            None => Ok(false),
            Some(Value::Bool(b)) => Ok(*b),
            Some(v) => Err(self.invalid(&join(path, "erase"), v, "true or false")),
        }
    }

    pub(super) fn stroke(&self, m: &Map<String, Value>, path: &str, size: (f64, f64)) -> R<Stroke> {
        let points = self.points(m, path, "points", 1, "an array of [x, y] points", size)?;
        let (v, vp) = self.field(m, path, "radius_px", "a brush radius in pixels")?;
        let radius_px = self.number(
            v,
            &vp,
            Range::above(0.0, 4096.0, "0 < radius <= 4096 pixels"),
        )?;
        Ok(Stroke { points, radius_px })
    }
}

pub(super) fn join(path: &str, key: &str) -> String {
    if path == "$" {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}
