//! GeoTIFF georeferencing (GeoTIFF 1.1, OGC 19-008r4) and GDAL's sample
//! metadata, between TIFF tags and [`Georef`].
//!
//! Read:
//! - the GeoKeyDirectory (34735) with its ASCII (34737) and double (34736)
//!   parameters: model type (projected / geographic), raster type
//!   (area / point), EPSG codes (`ProjectedCSTypeGeoKey`,
//!   `GeographicTypeGeoKey`, `VerticalCSTypeGeoKey`), linear and vertical
//!   units, citations, and an `ESRI PE String = <WKT>` citation (how GDAL
//!   stores a CRS without an EPSG code);
//! - `ModelPixelScale` (33550) + `ModelTiepoint` (33922), or a
//!   `ModelTransformation` (34264) without rotation; point rasters are moved
//!   half a cell to their outer corner, as GDAL does;
//! - `GDAL_METADATA` (42112): per-band `scale` / `offset` (physical value =
//!   raw × scale + offset) and `unittype` (m, ft, US survey foot).
//!
//! Written: pixel scale, tiepoint and keys for the heightfield's georeference
//! (EPSG code, or the WKT as an ESRI PE string, or the local grid of a
//! synthesized terrain with its citation), `VerticalUnitsGeoKey` = metre.

use crate::georef::{Crs, Georef, LOCAL_CRS_NAME, PixelIs, Units};
use crate::io::FormatError;
use crate::io::place::wkt;
use std::collections::HashMap;

pub(super) const KEY_MODEL_TYPE: u16 = 1024;
const KEY_RASTER_TYPE: u16 = 1025;
const KEY_CITATION: u16 = 1026;
const KEY_GEOGRAPHIC_TYPE: u16 = 2048;
const KEY_GEOG_CITATION: u16 = 2049;
const KEY_ANGULAR_UNITS: u16 = 2054;
const KEY_PROJECTED_TYPE: u16 = 3072;
const KEY_PCS_CITATION: u16 = 3073;
const KEY_LINEAR_UNITS: u16 = 3076;
const KEY_LINEAR_UNIT_SIZE: u16 = 3077;
const KEY_VERTICAL_TYPE: u16 = 4096;
const KEY_VERTICAL_UNITS: u16 = 4099;
const MODEL_PROJECTED: u16 = 1;
const MODEL_GEOGRAPHIC: u16 = 2;
const RASTER_PIXEL_IS_POINT: u16 = 2;
const USER_DEFINED: u16 = 32767;
const UNIT_METRE: u16 = 9001;
const UNIT_DEGREE: u16 = 9102;
const ESRI_PE: &str = "ESRI PE String = ";

/// A GeoKey's value.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum KeyValue {
    Short(u16),
    Ascii(String),
    Double(Vec<f64>),
}

/// The GeoKeys of a file.
#[derive(Debug, Default)]
pub(super) struct GeoKeys(pub HashMap<u16, KeyValue>);

impl GeoKeys {
    /// Parses the directory; `ascii` and `doubles` are the parameter tags.
    pub fn parse(dir: &[u16], ascii: &str, doubles: &[f64]) -> Result<GeoKeys, FormatError> {
        let bad = |m: String| FormatError::Metadata(format!("GeoKeyDirectory (tag 34735) {m}"));
        if dir.len() < 4 {
            return Err(bad("is shorter than its 4-value header".into()));
        }
        let n = dir[3] as usize;
        if dir.len() < 4 + 4 * n {
            return Err(bad(format!(
                "declares {n} keys but holds {}",
                (dir.len() - 4) / 4
            )));
        }
        let mut keys = HashMap::new();
        for k in dir[4..4 + 4 * n].chunks_exact(4) {
            let (id, loc, count, off) = (k[0], k[1], k[2] as usize, k[3] as usize);
            let value = match loc {
                0 => KeyValue::Short(k[3]),
                34737 => {
                    // Strings end with '|' (counted); take them by characters.
                    let s: String = ascii.chars().skip(off).take(count).collect();
                    KeyValue::Ascii(s.trim_end_matches(['|', '\0']).to_string())
                }
                34736 => match doubles.get(off..off.saturating_add(count)) {
                    Some(d) => KeyValue::Double(d.to_vec()),
                    None => {
                        return Err(bad(format!(
                            "key {id} points past the {} double parameters",
                            doubles.len()
                        )));
                    }
                },
                // Keys stored in other tags are not ones we read.
                _ => continue,
            };
            keys.insert(id, value);
        }
        Ok(GeoKeys(keys))
    }

    fn short(&self, id: u16) -> Option<u16> {
        match self.0.get(&id) {
            Some(KeyValue::Short(v)) => Some(*v),
            _ => None,
        }
    }
    fn text(&self, id: u16) -> Option<&str> {
        match self.0.get(&id) {
            Some(KeyValue::Ascii(s)) if !s.is_empty() => Some(s),
            _ => None,
        }
    }
    fn double(&self, id: u16) -> Option<f64> {
        match self.0.get(&id) {
            Some(KeyValue::Double(d)) => d.first().copied(),
            _ => None,
        }
    }

    /// The CRS the keys describe, `None` without a model type.
    pub fn crs(&self) -> Result<Option<Crs>, FormatError> {
        let unsupported = |what, found: String, supported| FormatError::Unsupported {
            what,
            found,
            supported,
        };
        let model = match self.short(KEY_MODEL_TYPE) {
            Some(m) => m,
            // No model type but projected keys: projected, as GDAL reads it.
            None if self.short(KEY_PROJECTED_TYPE).is_some()
                || self.short(KEY_LINEAR_UNITS).is_some() =>
            {
                MODEL_PROJECTED
            }
            None => return Ok(None),
        };
        let pe = [KEY_CITATION, KEY_PCS_CITATION, KEY_GEOG_CITATION]
            .iter()
            .find_map(|&k| self.text(k)?.strip_prefix(ESRI_PE));
        let mut crs = match model {
            MODEL_GEOGRAPHIC => {
                let unit = self.short(KEY_ANGULAR_UNITS).unwrap_or(UNIT_DEGREE);
                if unit != UNIT_DEGREE {
                    return Err(unsupported(
                        "GeoTIFF angular unit",
                        format!("EPSG {unit}"),
                        "degrees (EPSG 9102)",
                    ));
                }
                let mut c = Crs::epsg(0, Units::Degrees);
                c.epsg = self
                    .short(KEY_GEOGRAPHIC_TYPE)
                    .filter(|&v| v != USER_DEFINED && v != 0)
                    .map(u32::from);
                c.name = self.text(KEY_GEOG_CITATION).map(str::to_string);
                c
            }
            MODEL_PROJECTED => {
                let epsg = self
                    .short(KEY_PROJECTED_TYPE)
                    .filter(|&v| v != USER_DEFINED && v != 0)
                    .map(u32::from);
                let metres = match self.short(KEY_LINEAR_UNITS) {
                    Some(UNIT_METRE) => 1.0,
                    Some(9002) => 0.3048,
                    Some(9003) => 1200.0 / 3937.0,
                    Some(USER_DEFINED) => self.double(KEY_LINEAR_UNIT_SIZE).unwrap_or(f64::NAN),
                    None => epsg
                        .and_then(wkt::units_of)
                        .and_then(|u| match u {
                            Units::Linear { metres_per_unit } => Some(metres_per_unit),
                            Units::Degrees => None,
                        })
                        .unwrap_or(1.0),
                    Some(other) => {
                        return Err(unsupported(
                            "GeoTIFF linear unit",
                            format!("EPSG {other}"),
                            "metre (9001), foot (9002), US survey foot (9003) or a user-defined size",
                        ));
                    }
                };
                if !(metres.is_finite() && metres > 0.0) {
                    return Err(FormatError::Metadata(
                        "ProjLinearUnitSizeGeoKey (3077) must give a unit size > 0 m".into(),
                    ));
                }
                let mut c = Crs::epsg(
                    0,
                    Units::Linear {
                        metres_per_unit: metres,
                    },
                );
                c.epsg = epsg;
                c.name = self
                    .text(KEY_PCS_CITATION)
                    .or(self.text(KEY_CITATION))
                    .map(str::to_string);
                c
            }
            other => {
                return Err(unsupported(
                    "GeoTIFF model type",
                    format!("{other}"),
                    "projected (1) or geographic (2)",
                ));
            }
        };
        if let Some(w) = pe {
            // GDAL's way of storing a CRS that has no EPSG code.
            if let Ok(parsed) = wkt::parse(w.as_bytes()) {
                crs.epsg = crs.epsg.or(parsed.epsg);
                crs.name = parsed.name;
                crs.wkt = parsed.wkt;
            }
        }
        crs.vertical_epsg = self
            .short(KEY_VERTICAL_TYPE)
            .filter(|&v| v != USER_DEFINED && v != 0)
            .map(u32::from);
        Ok(Some(crs))
    }

    /// Metres per vertical unit of the samples (1 when not given).
    pub fn vertical_metres(&self) -> Result<f64, FormatError> {
        match self.short(KEY_VERTICAL_UNITS) {
            None | Some(UNIT_METRE) | Some(USER_DEFINED) => Ok(1.0),
            Some(9002) => Ok(0.3048),
            Some(9003) => Ok(1200.0 / 3937.0),
            Some(other) => Err(FormatError::Unsupported {
                what: "GeoTIFF vertical unit",
                found: format!("EPSG {other}"),
                supported: "metre (9001), foot (9002), US survey foot (9003)",
            }),
        }
    }

    pub fn pixel_is(&self) -> PixelIs {
        if self.short(KEY_RASTER_TYPE) == Some(RASTER_PIXEL_IS_POINT) {
            PixelIs::Point
        } else {
            PixelIs::Area
        }
    }
}

/// The georeference from the placement tags. `scale` = ModelPixelScale,
/// `tie` = ModelTiepoint, `matrix` = ModelTransformation.
pub(super) fn placement(
    keys: &GeoKeys,
    scale: Option<&[f64]>,
    tie: Option<&[f64]>,
    matrix: Option<&[f64]>,
) -> Result<Option<Georef>, FormatError> {
    let pixel_is = keys.pixel_is();
    let (px, py, ox, oy) = match (scale, tie, matrix) {
        (Some(s), Some(t), _) => {
            let (px, py) = (s[0], s[1]);
            (px, py, t[3] - t[0] * px, t[4] + t[1] * py)
        }
        (_, _, Some(m)) => {
            if m[1] != 0.0 || m[4] != 0.0 {
                return Err(FormatError::Unsupported {
                    what: "GeoTIFF geometry",
                    found: "a rotated or sheared ModelTransformation".into(),
                    supported: "north-up grids (gdalwarp the file to a north-up grid first)",
                });
            }
            (m[0], -m[5], m[3], m[7])
        }
        _ => return Ok(None),
    };
    if !(px.is_finite() && py.is_finite() && px > 0.0 && py > 0.0) {
        return Err(FormatError::Metadata(format!(
            "the pixel size is {px} x {py}: expected finite values > 0 (north-up grids only)"
        )));
    }
    // A point raster's tiepoint names a sample; its cell's corner is half a cell out.
    let half = if pixel_is == PixelIs::Point { 0.5 } else { 0.0 };
    let g = Georef {
        crs: keys.crs()?,
        origin_x: ox - half * px,
        origin_y: oy + half * py,
        pixel_x: px,
        pixel_y: py,
        pixel_is,
    };
    if !g.is_valid() {
        return Err(FormatError::Metadata(format!(
            "the geotransform places the origin at {}, {}: expected finite coordinates",
            g.origin_x, g.origin_y
        )));
    }
    Ok(Some(g))
}

/// Tags that place a georeference in a GeoTIFF.
pub(super) struct Tags {
    pub pixel_scale: [f64; 3],
    pub tiepoint: [f64; 6],
    pub keys: Vec<u16>,
    pub ascii: String,
}

/// The tags for `g`, with a note when its CRS cannot be written.
pub(super) fn tags(g: &Georef) -> Tags {
    let (px, py) = (g.pixel_x, g.pixel_y);
    let point = g.pixel_is == PixelIs::Point;
    let half = if point { 0.5 } else { 0.0 };
    let mut keys: Vec<(u16, u16, u16, u16)> = Vec::new();
    let mut ascii = String::new();
    let mut text = |keys: &mut Vec<_>, id: u16, s: &str| {
        let s = s.replace('|', "/");
        keys.push((
            id,
            34737,
            s.chars().count() as u16 + 1,
            ascii.chars().count() as u16,
        ));
        ascii.push_str(&s);
        ascii.push('|');
    };
    let crs = g.crs.as_ref();
    let geographic = crs.is_some_and(Crs::is_geographic);
    let model = if geographic {
        MODEL_GEOGRAPHIC
    } else {
        MODEL_PROJECTED
    };
    keys.push((KEY_MODEL_TYPE, 0, 1, model));
    keys.push((KEY_RASTER_TYPE, 0, 1, if point { 2 } else { 1 }));
    match crs {
        Some(c) if c.epsg.is_some_and(|e| e <= u16::MAX as u32) => {
            let code = c.epsg.unwrap_or(0) as u16;
            if let Some(n) = &c.name {
                text(&mut keys, KEY_CITATION, n);
            }
            if geographic {
                keys.push((KEY_GEOGRAPHIC_TYPE, 0, 1, code));
                keys.push((KEY_ANGULAR_UNITS, 0, 1, UNIT_DEGREE));
            } else {
                keys.push((KEY_PROJECTED_TYPE, 0, 1, code));
            }
        }
        Some(c) if c.wkt.is_some() => {
            // GDAL reads a CRS without EPSG code from an ESRI PE string in
            // the PCS (or geographic) citation of a user-defined CRS.
            let pe = format!("{ESRI_PE}{}", compact(c.wkt.as_deref().unwrap_or_default()));
            if geographic {
                text(&mut keys, KEY_GEOG_CITATION, &pe);
                keys.push((KEY_GEOGRAPHIC_TYPE, 0, 1, USER_DEFINED));
            } else {
                text(&mut keys, KEY_PCS_CITATION, &pe);
                keys.push((KEY_PROJECTED_TYPE, 0, 1, USER_DEFINED));
            }
        }
        Some(c) => {
            text(
                &mut keys,
                KEY_CITATION,
                c.name.as_deref().unwrap_or(LOCAL_CRS_NAME),
            );
        }
        None => text(
            &mut keys,
            KEY_CITATION,
            "unknown CRS (grid placed in metres)",
        ),
    }
    if !geographic {
        let unit = match crs.map(|c| c.units) {
            Some(Units::Linear { metres_per_unit }) if (metres_per_unit - 0.3048).abs() < 1e-12 => {
                9002
            }
            Some(Units::Linear { metres_per_unit })
                if (metres_per_unit - 1200.0 / 3937.0).abs() < 1e-12 =>
            {
                9003
            }
            _ => UNIT_METRE,
        };
        keys.push((KEY_LINEAR_UNITS, 0, 1, unit));
    }
    if let Some(v) = crs
        .and_then(|c| c.vertical_epsg)
        .filter(|&v| v <= u16::MAX as u32)
    {
        keys.push((KEY_VERTICAL_TYPE, 0, 1, v as u16));
    }
    keys.push((KEY_VERTICAL_UNITS, 0, 1, UNIT_METRE));
    keys.sort_by_key(|k| k.0);
    let mut dir = vec![1, 1, 0, keys.len() as u16];
    for (a, b, c, d) in keys {
        dir.extend([a, b, c, d]);
    }
    Tags {
        pixel_scale: [px, py, 0.0],
        tiepoint: [
            0.0,
            0.0,
            0.0,
            g.origin_x + half * px,
            g.origin_y - half * py,
            0.0,
        ],
        keys: dir,
        ascii,
    }
}

/// WKT without the line breaks and indentation outside quoted names.
fn compact(wkt: &str) -> String {
    let mut out = String::with_capacity(wkt.len());
    let mut quoted = false;
    for ch in wkt.chars() {
        if ch == '"' {
            quoted = !quoted;
        }
        if quoted || !ch.is_whitespace() {
            out.push(ch);
        }
    }
    out
}

/// Per-band value mapping from GDAL's metadata XML.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct BandMapping {
    pub scale: f64,
    pub offset: f64,
    /// Metres per unit of the band's `unittype`.
    pub unit_m: f64,
}

/// Reads `scale`, `offset` and `unittype` of band `sample` (0-based) from
/// GDAL_METADATA, e.g. `<Item name="SCALE" sample="0" role="scale">0.1</Item>`.
pub(super) fn band_mapping(xml: &str, sample: usize) -> Result<BandMapping, FormatError> {
    let mut m = BandMapping {
        scale: 1.0,
        offset: 0.0,
        unit_m: 1.0,
    };
    let attr = |tag: &str, name: &str| -> Option<String> {
        let at = tag.find(&format!("{name}=\""))? + name.len() + 2;
        Some(tag[at..].split('"').next()?.to_string())
    };
    for item in xml.split("<Item").skip(1) {
        let Some((tag, rest)) = item.split_once('>') else {
            continue;
        };
        let Some(value) = rest.split("</Item").next() else {
            continue;
        };
        if attr(tag, "sample").and_then(|s| s.parse::<usize>().ok()) != Some(sample) {
            continue;
        }
        let value = value.trim();
        let number = |what: &str| {
            value.parse::<f64>().ok().filter(|v| v.is_finite()).ok_or_else(|| {
                FormatError::Metadata(format!(
                    "GDAL_METADATA (tag 42112) gives band {} the {what} {value:?}: expected a finite number",
                    sample + 1
                ))
            })
        };
        match attr(tag, "role").as_deref() {
            Some("scale") => m.scale = number("scale")?,
            Some("offset") => m.offset = number("offset")?,
            Some("unittype") => {
                m.unit_m = match value.to_ascii_lowercase().as_str() {
                    "" | "m" | "metre" | "meter" | "metres" | "meters" => 1.0,
                    "ft" | "foot" | "feet" | "international foot" => 0.3048,
                    "us-ft" | "ftus" | "us survey foot" | "us_survey_foot" => 1200.0 / 3937.0,
                    _ => {
                        return Err(FormatError::Unsupported {
                            what: "band unit (GDAL unittype)",
                            found: value.into(),
                            supported: "m, ft, US survey foot",
                        });
                    }
                }
            }
            _ => {}
        }
    }
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_round_trip_through_tags() {
        let mut crs = Crs::epsg(
            32633,
            Units::Linear {
                metres_per_unit: 1.0,
            },
        );
        crs.name = Some("WGS 84 / UTM zone 33N".into());
        let g = Georef {
            crs: Some(crs),
            origin_x: 500_000.0,
            origin_y: 4_650_000.0,
            pixel_x: 10.0,
            pixel_y: 10.0,
            pixel_is: PixelIs::Point,
        };
        let t = tags(&g);
        let keys = GeoKeys::parse(&t.keys, &t.ascii, &[]).unwrap();
        let back = placement(&keys, Some(&t.pixel_scale), Some(&t.tiepoint), None)
            .unwrap()
            .unwrap();
        assert_eq!(back, g);
        // The local grid keeps its name and metres.
        let local = Georef::local(5, 2.5);
        let t = tags(&local);
        let keys = GeoKeys::parse(&t.keys, &t.ascii, &[]).unwrap();
        let back = placement(&keys, Some(&t.pixel_scale), Some(&t.tiepoint), None)
            .unwrap()
            .unwrap();
        assert!(back.is_local(), "{back:?}");
        assert_eq!(back, local);
    }

    #[test]
    fn gdal_metadata_scale_offset_and_units() {
        let xml = r#"<GDALMetadata>
  <Item name="OFFSET" sample="0" role="offset">-100</Item>
  <Item name="SCALE" sample="0" role="scale">0.1</Item>
  <Item name="SCALE" sample="1" role="scale">7</Item>
  <Item name="UNITTYPE" sample="0" role="unittype">ft</Item>
</GDALMetadata>"#;
        let m = band_mapping(xml, 0).unwrap();
        assert_eq!((m.scale, m.offset, m.unit_m), (0.1, -100.0, 0.3048));
        assert_eq!(band_mapping(xml, 1).unwrap().scale, 7.0);
        let bad = r#"<Item sample="0" role="scale">x</Item>"#;
        assert!(
            band_mapping(bad, 0)
                .unwrap_err()
                .to_string()
                .contains("band 1")
        );
    }
}
