//! GeoTIFF / TIFF heightfields: greyscale int16, uint16 or float32 (read,
//! strips or tiles, any compression the `tiff` crate decodes), float32 (write).
//!
//! Metadata read:
//! - `GDAL_NODATA` (tag 42113, ASCII): samples equal to it become NaN; NaN
//!   float samples are nodata regardless.
//! - `ModelPixelScaleTag` (33550): the cell size. Projected units are
//!   converted to metres from `ProjLinearUnitsGeoKey` (metre, foot, US survey
//!   foot). Geographic rasters (`GTModelTypeGeoKey` = 2) have scales in
//!   degrees: the cell size becomes the north–south spacing,
//!   `scale_y × 111 319.49 m` (one degree on the WGS84 equator), and the
//!   georeference is dropped because [`Georef`] is in metres.
//! - `ModelTiepointTag` (33922): the map position of the top-left corner
//!   ([`Georef`]), shifted by half a cell for `RasterPixelIsPoint`.
//!
//! Written: float32, uncompressed strips (every GeoTIFF reader opens them),
//! NaN for nodata with `GDAL_NODATA = "nan"`, the pixel scale, the tiepoint
//! when the heightfield has a georeference, and a minimal GeoKeyDirectory
//! (projected model, pixel-is-area, metres) so that the scale is never
//! mistaken for degrees. No CRS is claimed: we do not know one.

use super::limits::{DEFLATE_RATIO, LZW_RATIO, PACKBITS_RATIO, check_justified};
use super::sidecar::DEFAULT_CELL_SIZE_M;
use super::{Encoded, FormatError};
use crate::heightfield::{Georef, Heightfield, check_dims};
use std::collections::HashMap;
use std::io::Cursor;
use tiff::ColorType;
use tiff::decoder::{Decoder, DecodingResult, Limits};
use tiff::encoder::{TiffEncoder, colortype::Gray32Float};
use tiff::tags::{SampleFormat, Tag};

/// Metres per degree on the WGS84 equator (40 075 016.686 m / 360).
pub const METRES_PER_DEGREE: f64 = 111_319.490_793;

const KEY_MODEL_TYPE: u16 = 1024;
const KEY_RASTER_TYPE: u16 = 1025;
const KEY_ANGULAR_UNITS: u16 = 2054;
const KEY_LINEAR_UNITS: u16 = 3076;
const MODEL_PROJECTED: u16 = 1;
const MODEL_GEOGRAPHIC: u16 = 2;
const RASTER_PIXEL_IS_AREA: u16 = 1;
const RASTER_PIXEL_IS_POINT: u16 = 2;
const UNIT_METRE: u16 = 9001;
const UNIT_DEGREE: u16 = 9102;

pub(super) fn decode(bytes: &[u8]) -> Result<Heightfield, FormatError> {
    prescan(bytes)?;
    let mut dec = Decoder::new(Cursor::new(bytes)).map_err(tiff_error)?;
    let (w, h) = dec.dimensions().map_err(tiff_error)?;
    let (w, h) = (w as usize, h as usize);
    check_dims(w, h)?;
    let bits = match dec.colortype().map_err(tiff_error)? {
        ColorType::Gray(b @ (16 | 32)) => b,
        other => {
            return Err(FormatError::Unsupported {
                what: "TIFF sample layout",
                found: format!("{other:?}"),
                supported: "one greyscale sample of int16, uint16 or float32",
            });
        }
    };
    let format = match dec.find_tag_unsigned_vec::<u16>(Tag::SampleFormat) {
        Ok(Some(v)) => v
            .first()
            .copied()
            .map_or(SampleFormat::Uint, SampleFormat::from_u16_exhaustive),
        Ok(None) => SampleFormat::Uint,
        Err(e) => return Err(tiff_error(e)),
    };
    match (bits, format) {
        (16, SampleFormat::Int | SampleFormat::Uint) | (32, SampleFormat::IEEEFP) => {}
        _ => {
            return Err(FormatError::Unsupported {
                what: "TIFF sample format",
                found: format!("{bits}-bit {format:?}"),
                supported: "int16, uint16 or float32",
            });
        }
    }
    let ratio = match dec
        .find_tag_unsigned::<u16>(Tag::Compression)
        .map_err(tiff_error)?
    {
        None | Some(1) => 1,
        Some(32773) => PACKBITS_RATIO,
        Some(8 | 32946) => DEFLATE_RATIO,
        // LZW, and whatever else the decoder accepts: the loosest bound.
        Some(_) => LZW_RATIO,
    };
    let bytes_per_sample = bits as u64 / 8;
    check_justified(w, h, bytes_per_sample, bytes.len(), ratio)?;
    // The decoder's limits, as a second line of defence: the image buffer
    // (checked above) or tag values expanded to the decoder's 32-byte value
    // type, compressed chunks no larger than the file.
    let mut limits = Limits::default();
    limits.decoding_buffer_size = (w * h * bytes_per_sample as usize).max(32 * bytes.len());
    limits.intermediate_buffer_size = bytes.len();
    limits.ifd_value_size = bytes.len();
    let mut dec = dec.with_limits(limits);

    let nodata = gdal_nodata(&mut dec)?;
    let geo = geo_keys(&mut dec)?;
    let (cell, georef) = placement(&mut dec, &geo)?;

    let is_void = |v: f64| v.is_nan() || nodata == Some(v);
    let mut data: Vec<f32> = match dec.read_image().map_err(tiff_error)? {
        DecodingResult::I16(v) => v.iter().map(|&s| void_or(s as f64, is_void)).collect(),
        DecodingResult::U16(v) => v.iter().map(|&s| void_or(s as f64, is_void)).collect(),
        DecodingResult::F32(v) => {
            let nodata = nodata.map(|n| n as f32);
            v.iter()
                .map(|&s| {
                    if s.is_nan() || Some(s) == nodata {
                        f32::NAN
                    } else {
                        s
                    }
                })
                .collect()
        }
        _ => {
            return Err(FormatError::Corrupt(
                "TIFF decoded to an unexpected sample type".into(),
            ));
        }
    };
    if data.len() < w * h {
        return Err(FormatError::EndsEarly("TIFF image data"));
    }
    data.truncate(w * h);
    let mut hf = Heightfield::from_vec(w, h, cell, data)?;
    hf.set_georef(georef);
    Ok(hf)
}

fn void_or(v: f64, is_void: impl Fn(f64) -> bool) -> f32 {
    if is_void(v) { f32::NAN } else { v as f32 }
}

type Dec<'a> = Decoder<Cursor<&'a [u8]>>;

fn gdal_nodata(dec: &mut Dec) -> Result<Option<f64>, FormatError> {
    let Some(value) = dec.find_tag(Tag::GdalNodata).map_err(tiff_error)? else {
        return Ok(None);
    };
    let text = value
        .into_string()
        .map_err(|_| FormatError::Metadata("GDAL_NODATA (tag 42113) must be ASCII text".into()))?;
    let t = text.trim_matches(|c: char| c == '\0' || c.is_whitespace());
    t.parse::<f64>().map(Some).map_err(|_| {
        FormatError::Metadata(format!(
            "GDAL_NODATA (tag 42113) is {t:?}: expected a number or nan"
        ))
    })
}

/// The GeoKeyDirectory's short values (keys stored in the directory itself).
fn geo_keys(dec: &mut Dec) -> Result<HashMap<u16, u16>, FormatError> {
    let Some(value) = dec.find_tag(Tag::GeoKeyDirectoryTag).map_err(tiff_error)? else {
        return Ok(HashMap::new());
    };
    let bad = |m: &str| FormatError::Metadata(format!("GeoKeyDirectory (tag 34735) {m}"));
    let v = value
        .into_u16_vec()
        .map_err(|_| bad("must hold SHORT values"))?;
    if v.len() < 4 {
        return Err(bad("is shorter than its 4-value header"));
    }
    let n = v[3] as usize;
    if v.len() < 4 + 4 * n {
        return Err(bad(&format!(
            "declares {n} keys but holds {}",
            (v.len() - 4) / 4
        )));
    }
    Ok(v[4..4 + 4 * n]
        .chunks_exact(4)
        .filter(|k| k[1] == 0)
        .map(|k| (k[0], k[3]))
        .collect())
}

/// Cell size in metres and georeference from the GeoTIFF tags.
fn placement(dec: &mut Dec, geo: &HashMap<u16, u16>) -> Result<(f64, Option<Georef>), FormatError> {
    let Some(scale) = f64_tag(
        dec,
        Tag::ModelPixelScaleTag,
        2,
        "ModelPixelScale (tag 33550)",
    )?
    else {
        return Ok((DEFAULT_CELL_SIZE_M, None));
    };
    let (sx, sy) = (scale[0], scale[1]);
    if !(sx.is_finite() && sy.is_finite() && sx > 0.0 && sy > 0.0) {
        return Err(FormatError::Metadata(format!(
            "ModelPixelScale (tag 33550) is {sx} x {sy}: expected finite values > 0"
        )));
    }
    if geo.get(&KEY_MODEL_TYPE) == Some(&MODEL_GEOGRAPHIC) {
        let unit = geo.get(&KEY_ANGULAR_UNITS).copied().unwrap_or(UNIT_DEGREE);
        if unit != UNIT_DEGREE {
            return Err(FormatError::Unsupported {
                what: "GeoTIFF angular unit",
                found: format!("EPSG {unit}"),
                supported: "degrees (EPSG 9102)",
            });
        }
        return Ok((sy * METRES_PER_DEGREE, None));
    }
    let unit = match geo.get(&KEY_LINEAR_UNITS).copied().unwrap_or(UNIT_METRE) {
        UNIT_METRE => 1.0,
        9002 => 0.3048,
        9003 => 1200.0 / 3937.0,
        other => {
            return Err(FormatError::Unsupported {
                what: "GeoTIFF linear unit",
                found: format!("EPSG {other}"),
                supported: "metre (9001), foot (9002), US survey foot (9003)",
            });
        }
    };
    if (sx - sy).abs() > 1e-9 * sx.max(sy) {
        return Err(FormatError::Unsupported {
            what: "GeoTIFF cell shape",
            found: format!("{sx} x {sy} map units"),
            supported: "square cells (resample first)",
        });
    }
    let georef = match f64_tag(dec, Tag::ModelTiepointTag, 6, "ModelTiepoint (tag 33922)")? {
        None => None,
        Some(t) => {
            let half = if geo.get(&KEY_RASTER_TYPE) == Some(&RASTER_PIXEL_IS_POINT) {
                0.5
            } else {
                0.0
            };
            let x = (t[3] - (t[0] + half) * sx) * unit;
            let y = (t[4] + (t[1] + half) * sy) * unit;
            if !(x.is_finite() && y.is_finite()) {
                return Err(FormatError::Metadata(format!(
                    "ModelTiepoint (tag 33922) places the origin at {x}, {y}: expected finite coordinates"
                )));
            }
            Some(Georef {
                origin_x: x,
                origin_y: y,
            })
        }
    };
    Ok((sx * unit, georef))
}

fn f64_tag(
    dec: &mut Dec,
    tag: Tag,
    min_len: usize,
    name: &str,
) -> Result<Option<Vec<f64>>, FormatError> {
    let Some(value) = dec.find_tag(tag).map_err(tiff_error)? else {
        return Ok(None);
    };
    let v = value
        .into_f64_vec()
        .map_err(|_| FormatError::Metadata(format!("{name} must hold DOUBLE values")))?;
    if v.len() < min_len {
        return Err(FormatError::Metadata(format!(
            "{name} holds {} values, expected at least {min_len}",
            v.len()
        )));
    }
    Ok(Some(v))
}

/// Checks the header and that every value of the first IFD lies inside the
/// file, so that no count in a corrupt directory can make the decoder
/// reserve memory the file cannot fill.
fn prescan(bytes: &[u8]) -> Result<(), FormatError> {
    const MAGIC: &str = "TIFF header II*\\0 or MM\\0* (or BigTIFF +)";
    let le = match bytes.get(..2) {
        Some(b"II") => true,
        Some(b"MM") => false,
        _ => return Err(FormatError::bad_magic(MAGIC, bytes)),
    };
    // Offsets come from the file: any of them may point past its end.
    let u16_at = |o: usize| -> Option<u64> {
        let b: [u8; 2] = bytes.get(o..o.checked_add(2)?)?.try_into().ok()?;
        Some(if le {
            u16::from_le_bytes(b)
        } else {
            u16::from_be_bytes(b)
        } as u64)
    };
    let u32_at = |o: usize| -> Option<u64> {
        let b: [u8; 4] = bytes.get(o..o.checked_add(4)?)?.try_into().ok()?;
        Some(if le {
            u32::from_le_bytes(b)
        } else {
            u32::from_be_bytes(b)
        } as u64)
    };
    let u64_at = |o: usize| -> Option<u64> {
        let b: [u8; 8] = bytes.get(o..o.checked_add(8)?)?.try_into().ok()?;
        Some(if le {
            u64::from_le_bytes(b)
        } else {
            u64::from_be_bytes(b)
        })
    };
    let len = bytes.len() as u64;
    let short = |what| FormatError::Truncated {
        what,
        expected: 16,
        found: len,
    };
    let big = match u16_at(2) {
        Some(42) => false,
        Some(43) => true,
        None => return Err(short("the TIFF header")),
        Some(_) => return Err(FormatError::bad_magic(MAGIC, bytes)),
    };
    // Classic: u16 entry count, 12-byte entries, u32 offsets. BigTIFF: u64
    // count, 20-byte entries, u64 offsets.
    let (ifd, count_len, entry_len, inline) = if big {
        (
            u64_at(8).ok_or_else(|| short("the BigTIFF header"))?,
            8u64,
            20u64,
            8u64,
        )
    } else {
        (u32_at(4).ok_or_else(|| short("the TIFF header"))?, 2, 12, 4)
    };
    let at = usize::try_from(ifd).unwrap_or(usize::MAX);
    let n = if big { u64_at(at) } else { u16_at(at) }.ok_or(FormatError::Truncated {
        what: "the first TIFF directory",
        expected: ifd.saturating_add(count_len),
        found: len,
    })?;
    let end = ifd
        .saturating_add(count_len)
        .saturating_add(n.saturating_mul(entry_len));
    if end > len {
        return Err(FormatError::Truncated {
            what: "the first TIFF directory",
            expected: end,
            found: len,
        });
    }
    for i in 0..n {
        let e = (ifd + count_len + i * entry_len) as usize;
        let (tag, ty) = (u16_at(e).unwrap_or(0), u16_at(e + 2).unwrap_or(0));
        let count = if big { u64_at(e + 4) } else { u32_at(e + 4) }.unwrap_or(0);
        let size: u64 = match ty {
            1 | 2 | 6 | 7 => 1,
            3 | 8 => 2,
            4 | 9 | 11 | 13 => 4,
            5 | 10 | 12 | 16 | 17 | 18 => 8,
            // Unknown types are skipped by the decoder, never read.
            _ => continue,
        };
        let total = count.saturating_mul(size);
        if total > inline {
            let at = if big { u64_at(e + 12) } else { u32_at(e + 8) }.unwrap_or(u64::MAX);
            let stop = at.saturating_add(total);
            if stop > len {
                return Err(FormatError::Metadata(format!(
                    "TIFF tag {tag} declares {count} values at byte {at}, past the end of the {len}-byte file"
                )));
            }
        }
    }
    Ok(())
}

pub(super) fn encode(hf: &Heightfield) -> Result<Encoded, FormatError> {
    let (w, h) = (hf.width(), hf.height());
    if w > u32::MAX as usize || h > u32::MAX as usize {
        return Err(FormatError::Unwritable(format!(
            "{w}x{h} exceeds TIFF's 32-bit sizes"
        )));
    }
    let unwritable = |e: tiff::TiffError| FormatError::Unwritable(format!("TIFF: {e}"));
    let mut out = Cursor::new(Vec::new());
    {
        let mut enc = TiffEncoder::new(&mut out).map_err(unwritable)?;
        let mut image = enc
            .new_image::<Gray32Float>(w as u32, h as u32)
            .map_err(unwritable)?;
        let dir = image.encoder();
        let c = hf.cell_size();
        dir.write_tag(Tag::ModelPixelScaleTag, &[c, c, 0.0][..])
            .map_err(unwritable)?;
        if let Some(g) = hf.georef() {
            dir.write_tag(
                Tag::ModelTiepointTag,
                &[0.0, 0.0, 0.0, g.origin_x, g.origin_y, 0.0][..],
            )
            .map_err(unwritable)?;
        }
        #[rustfmt::skip]
        let keys: [u16; 16] = [
            1, 1, 0, 3, // version 1.1.0, three keys
            KEY_MODEL_TYPE, 0, 1, MODEL_PROJECTED,
            KEY_RASTER_TYPE, 0, 1, RASTER_PIXEL_IS_AREA,
            KEY_LINEAR_UNITS, 0, 1, UNIT_METRE,
        ];
        dir.write_tag(Tag::GeoKeyDirectoryTag, &keys[..])
            .map_err(unwritable)?;
        if hf.nodata_count() > 0 {
            dir.write_tag(Tag::GdalNodata, "nan").map_err(unwritable)?;
        }
        image.write_data(hf.data()).map_err(unwritable)?;
    }
    Ok(Encoded {
        bytes: out.into_inner(),
        sidecar: None,
    })
}

fn tiff_error(e: tiff::TiffError) -> FormatError {
    use tiff::TiffError as E;
    match e {
        E::IoError(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => {
            FormatError::EndsEarly("TIFF data")
        }
        E::UnsupportedError(u) => FormatError::Unsupported {
            what: "TIFF feature",
            found: u.to_string(),
            supported: "baseline greyscale strips or tiles, uncompressed, LZW, Deflate or PackBits",
        },
        E::LimitsExceeded => FormatError::Corrupt(
            "TIFF strips or tiles decode to more data than the image size".into(),
        ),
        other => FormatError::Corrupt(format!("TIFF: {other}")),
    }
}
