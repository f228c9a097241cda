//! The JSON sidecar that gives integer samples a meaning in metres.
//!
//! Read: the sidecars of `../shared/dem` (`height_mapping.offset_m`,
//! `height_mapping.scale_m`, `cell_size_m`, `width`, `height`) and the same
//! keys at the top level. Other keys are ignored, so richer provenance
//! sidecars load as they are. Written: the same shape, so a file we write
//! reads back in any tool that reads the shared DEMs.
//!
//! Without a sidecar, [`HeightMapping::default_for_bits`] applies: 16-bit
//! samples are decimetres (0–6553.5 m), 8-bit samples are 10 m steps
//! (0–2550 m), and cells are 10 m (the paper's scale). These defaults are a
//! convention, not a guess about the file; `info` reports when they were used.

use super::FormatError;
use serde_json::{Map, Value, json};

/// Metres of an integer sample `v`: `offset_m + scale_m * v`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeightMapping {
    pub offset_m: f64,
    pub scale_m: f64,
}

impl HeightMapping {
    /// The mapping used when a file has no sidecar.
    pub fn default_for_bits(bits: u8) -> HeightMapping {
        HeightMapping {
            offset_m: 0.0,
            scale_m: if bits <= 8 { 10.0 } else { 0.1 },
        }
    }

    /// The mapping that spreads `[min, max]` over `0..=max_code` (a flat
    /// field gets scale 0, as the shared DEM sidecars do).
    pub fn spanning(min: f64, max: f64, max_code: u32) -> HeightMapping {
        HeightMapping {
            offset_m: min,
            scale_m: if max > min {
                (max - min) / max_code as f64
            } else {
                0.0
            },
        }
    }

    pub fn to_metres(&self, v: f64) -> f64 {
        self.offset_m + self.scale_m * v
    }
}

/// Cell size used when neither the file nor a sidecar gives one.
pub const DEFAULT_CELL_SIZE_M: f64 = 10.0;

/// The parsed sidecar.
#[derive(Debug, Clone, PartialEq)]
pub struct Sidecar {
    pub mapping: HeightMapping,
    pub cell_size_m: Option<f64>,
    pub width: Option<usize>,
    pub height: Option<usize>,
    /// Integer sample value that marks nodata, if any.
    pub nodata_value: Option<f64>,
}

impl Sidecar {
    pub fn parse(bytes: &[u8]) -> Result<Sidecar, FormatError> {
        let bad = |m: String| FormatError::InvalidSidecar(m);
        let v: Value = serde_json::from_slice(bytes).map_err(|e| {
            bad(format!(
                "not JSON (line {}, column {}): {e}",
                e.line(),
                e.column()
            ))
        })?;
        let top = v
            .as_object()
            .ok_or_else(|| bad("expected a JSON object at the top level".into()))?;
        let hm = match top.get("height_mapping") {
            Some(Value::Object(m)) => m,
            Some(_) => return Err(bad("height_mapping must be an object".into())),
            None => top,
        };
        let field = if std::ptr::eq(hm, top) {
            ""
        } else {
            "height_mapping."
        };
        let offset_m = number(hm, "offset_m", field)?.unwrap_or(0.0);
        let scale_m = number(hm, "scale_m", field)?
            .ok_or_else(|| bad(format!("missing {field}scale_m (metres per sample unit)")))?;
        if scale_m < 0.0 {
            return Err(bad(format!("{field}scale_m is {scale_m}: expected >= 0")));
        }
        let cell_size_m = number(top, "cell_size_m", "")?;
        if let Some(c) = cell_size_m
            && c <= 0.0
        {
            return Err(bad(format!("cell_size_m is {c}: expected > 0")));
        }
        Ok(Sidecar {
            mapping: HeightMapping { offset_m, scale_m },
            cell_size_m,
            width: dimension(top, "width")?,
            height: dimension(top, "height")?,
            nodata_value: number(top, "nodata_value", "")?,
        })
    }

    /// Checks the sidecar against the dimensions found in the data file.
    pub fn check_size(&self, width: usize, height: usize) -> Result<(), FormatError> {
        for (name, declared, actual) in [
            ("width", self.width, width),
            ("height", self.height, height),
        ] {
            if let Some(d) = declared
                && d != actual
            {
                return Err(FormatError::InvalidSidecar(format!(
                    "{name} is {d} but the data file is {actual}"
                )));
            }
        }
        Ok(())
    }

    /// The sidecar we write next to quantized outputs.
    pub fn to_json(&self, min_m: f64, max_m: f64) -> Vec<u8> {
        let mut v = json!({
            "generator": concat!("terrasynth ", env!("CARGO_PKG_VERSION")),
            "width": self.width,
            "height": self.height,
            "cell_size_m": self.cell_size_m,
            "elevation_min_m": min_m,
            "elevation_max_m": max_m,
            "height_mapping": {
                "formula": "h_m = offset_m + scale_m * v",
                "offset_m": self.mapping.offset_m,
                "scale_m": self.mapping.scale_m,
            },
        });
        if let Some(n) = self.nodata_value {
            v["nodata_value"] = json!(n);
        }
        let mut s = serde_json::to_vec_pretty(&v).expect("JSON values always serialize");
        s.push(b'\n');
        s
    }
}

fn number(obj: &Map<String, Value>, key: &str, prefix: &str) -> Result<Option<f64>, FormatError> {
    match obj.get(key) {
        None | Some(Value::Null) => Ok(None),
        Some(Value::Number(n)) => match n.as_f64() {
            Some(f) if f.is_finite() => Ok(Some(f)),
            _ => Err(FormatError::InvalidSidecar(format!(
                "{prefix}{key} is not a finite number"
            ))),
        },
        Some(other) => Err(FormatError::InvalidSidecar(format!(
            "{prefix}{key} must be a number, found {other}"
        ))),
    }
}

fn dimension(obj: &Map<String, Value>, key: &str) -> Result<Option<usize>, FormatError> {
    match obj.get(key) {
        None | Some(Value::Null) => Ok(None),
        Some(v) => v
            .as_u64()
            .filter(|&n| n >= 1 && n <= crate::heightfield::MAX_SIDE as u64)
            .map(|n| Some(n as usize))
            .ok_or_else(|| {
                FormatError::InvalidSidecar(format!(
                    "{key} is {v}: expected an integer in 1..={}",
                    crate::heightfield::MAX_SIDE
                ))
            }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_nested_and_flat_mappings() {
        let s = Sidecar::parse(br#"{"cell_size_m": 30.5, "width": 4, "height_mapping": {"offset_m": -5, "scale_m": 0.5}}"#).unwrap();
        assert_eq!(
            s.mapping,
            HeightMapping {
                offset_m: -5.0,
                scale_m: 0.5
            }
        );
        assert_eq!(
            (s.cell_size_m, s.width, s.height),
            (Some(30.5), Some(4), None)
        );
        let s = Sidecar::parse(br#"{"offset_m": 1, "scale_m": 2}"#).unwrap();
        assert_eq!(
            s.mapping,
            HeightMapping {
                offset_m: 1.0,
                scale_m: 2.0
            }
        );
    }

    #[test]
    fn rejects_bad_sidecars_with_the_field_name() {
        for (text, needle) in [
            (&b"[1]"[..], "object"),
            (b"{", "not JSON"),
            (
                br#"{"height_mapping": {"offset_m": 0}}"#,
                "height_mapping.scale_m",
            ),
            (br#"{"scale_m": "x"}"#, "scale_m must be a number"),
            (br#"{"scale_m": -1}"#, "expected >= 0"),
            (br#"{"scale_m": 1, "cell_size_m": 0}"#, "cell_size_m"),
            (br#"{"scale_m": 1, "width": 0}"#, "width"),
        ] {
            let e = Sidecar::parse(text).unwrap_err().to_string();
            assert!(e.contains(needle), "{e} should mention {needle}");
        }
    }

    #[test]
    fn written_sidecar_parses_back() {
        let s = Sidecar {
            mapping: HeightMapping::spanning(-17.0, 1206.0, 65535),
            cell_size_m: Some(92.55),
            width: Some(900),
            height: Some(900),
            nodata_value: None,
        };
        assert_eq!(Sidecar::parse(&s.to_json(-17.0, 1206.0)).unwrap(), s);
    }
}
