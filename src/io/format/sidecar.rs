//! The JSON sidecar that gives integer samples a meaning in metres.
//!
//! Read: the sidecars of `../shared/dem` (`height_mapping.offset_m`,
//! `height_mapping.scale_m`, `cell_size_m`, `width`, `height`) and the same
//! keys at the top level. Other keys are ignored, so richer provenance
//! sidecars load as they are. Written: the same shape, so a file we write
//! reads back in any tool that reads the shared DEMs.
//!
//! The georeference travels as `georeference.geotransform` (GDAL's six
//! numbers, north-up), `pixel_is` (`area` / `point`) and the CRS
//! (`crs_epsg`, `crs_wkt`, `crs_name`, `crs_units` = `degree` or
//! `metres_per_unit`). The shared DEMs' descriptive `georeference` (corner
//! latitudes and longitudes of an already resampled grid) has no
//! geotransform and is not read as one.
//!
//! Without a sidecar, [`HeightMapping::default_for_bits`] applies: 16-bit
//! samples are decimetres (0–6553.5 m), 8-bit samples are 10 m steps
//! (0–2550 m), and cells are 10 m (the paper's scale). These defaults are a
//! convention, not a guess about the file; `info` reports when they were used.

use crate::georef::{Crs, Georef, PixelIs, Units};
use crate::io::FormatError;
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
    /// Where the grid lies, when known.
    pub georef: Option<Georef>,
    /// Rows are stored south to north (`"row_order": "south_to_north"`,
    /// written for Unity); default north to south.
    pub south_up: bool,
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
            south_up: match top.get("row_order") {
                None | Some(Value::Null) => false,
                Some(Value::String(s)) if s == "south_to_north" => true,
                Some(Value::String(s)) if s == "north_to_south" => false,
                Some(other) => {
                    return Err(bad(format!(
                        "row_order is {other}: expected \"north_to_south\" or \"south_to_north\""
                    )));
                }
            },
            georef: match top.get("georeference") {
                Some(Value::Object(g)) if g.contains_key("geotransform") => Some(georef(g)?),
                _ => None,
            },
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
        if self.south_up {
            v["row_order"] = json!("south_to_north");
        }
        if let Some(g) = &self.georef {
            let c = g.crs.as_ref();
            v["georeference"] = json!({
                "geotransform": [g.origin_x, g.pixel_x, 0.0, g.origin_y, 0.0, -g.pixel_y],
                "pixel_is": if g.pixel_is == PixelIs::Point { "point" } else { "area" },
                "crs_epsg": c.and_then(|c| c.epsg),
                "crs_name": c.and_then(|c| c.name.clone()),
                "crs_wkt": c.and_then(|c| c.wkt.clone()),
                "crs_units": match c.map(|c| c.units) {
                    None => json!(null),
                    Some(Units::Degrees) => json!("degree"),
                    Some(Units::Linear { metres_per_unit }) => json!({ "metres_per_unit": metres_per_unit }),
                },
                "crs_vertical_epsg": c.and_then(|c| c.vertical_epsg),
            });
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

/// Our own `georeference` object (see the module docs).
fn georef(g: &Map<String, Value>) -> Result<Georef, FormatError> {
    let bad = |m: &str| FormatError::InvalidSidecar(format!("georeference.{m}"));
    let t: Vec<f64> = g
        .get("geotransform")
        .and_then(Value::as_array)
        .filter(|a| a.len() == 6)
        .and_then(|a| a.iter().map(Value::as_f64).collect())
        .ok_or_else(|| bad("geotransform must be an array of 6 numbers"))?;
    if t[2] != 0.0 || t[4] != 0.0 {
        return Err(bad(
            "geotransform is rotated: expected a north-up grid (terms 2 and 4 = 0)",
        ));
    }
    let code = |k: &str| -> Result<Option<u32>, FormatError> {
        match g.get(k) {
            None | Some(Value::Null) => Ok(None),
            Some(v) => v
                .as_u64()
                .and_then(|c| u32::try_from(c).ok())
                .map(Some)
                .ok_or_else(|| bad(&format!("{k} must be an EPSG code"))),
        }
    };
    let text = |k: &str| g.get(k).and_then(Value::as_str).map(str::to_string);
    let units = match g.get("crs_units") {
        None | Some(Value::Null) => None,
        Some(Value::String(s)) if s == "degree" => Some(Units::Degrees),
        Some(Value::Object(o)) => match o.get("metres_per_unit").and_then(Value::as_f64) {
            Some(m) if m.is_finite() && m > 0.0 => Some(Units::Linear { metres_per_unit: m }),
            _ => return Err(bad("crs_units.metres_per_unit must be a number > 0")),
        },
        Some(_) => {
            return Err(bad(
                "crs_units must be \"degree\" or {\"metres_per_unit\": m}",
            ));
        }
    };
    let crs = units.map(|units| -> Result<Crs, FormatError> {
        Ok(Crs {
            epsg: code("crs_epsg")?,
            wkt: text("crs_wkt"),
            name: text("crs_name"),
            units,
            vertical_epsg: code("crs_vertical_epsg")?,
        })
    });
    let out = Georef {
        crs: crs.transpose()?,
        origin_x: t[0],
        origin_y: t[3],
        pixel_x: t[1],
        pixel_y: -t[5],
        pixel_is: match g.get("pixel_is").and_then(Value::as_str) {
            Some("point") => PixelIs::Point,
            None | Some("area") => PixelIs::Area,
            Some(_) => return Err(bad("pixel_is must be \"area\" or \"point\"")),
        },
    };
    if !out.is_valid() {
        return Err(bad(
            "geotransform must be finite with cell sizes > 0 (term 1 > 0, term 5 < 0)",
        ));
    }
    Ok(out)
}

fn dimension(obj: &Map<String, Value>, key: &str) -> Result<Option<usize>, FormatError> {
    match obj.get(key) {
        None | Some(Value::Null) => Ok(None),
        Some(v) => v
            .as_u64()
            .filter(|&n| n >= 1 && n <= crate::size::MAX_SIDE as u64)
            .map(|n| Some(n as usize))
            .ok_or_else(|| {
                FormatError::InvalidSidecar(format!(
                    "{key} is {v}: expected an integer in 1..={}",
                    crate::size::MAX_SIDE
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
            georef: None,
            south_up: false,
        };
        assert_eq!(Sidecar::parse(&s.to_json(-17.0, 1206.0)).unwrap(), s);
        let mut crs = Crs::epsg(4326, Units::Degrees);
        crs.name = Some("WGS 84".into());
        let s = Sidecar {
            georef: Some(Georef {
                crs: Some(crs),
                origin_x: 1.0,
                origin_y: 41.75,
                pixel_x: 0.001,
                pixel_y: 1.0 / 1200.0,
                pixel_is: PixelIs::Point,
            }),
            ..s
        };
        assert_eq!(Sidecar::parse(&s.to_json(-17.0, 1206.0)).unwrap(), s);
        let local = Sidecar {
            georef: Some(Georef::local(900, 92.55)),
            south_up: true,
            ..s
        };
        assert_eq!(
            Sidecar::parse(&local.to_json(-17.0, 1206.0)).unwrap(),
            local
        );
    }
}
