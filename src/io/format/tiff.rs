//! GeoTIFF / TIFF heightfields: read any greyscale or multi-band image of
//! 8-, 16- or 32-bit integers or 32- or 64-bit floats, in strips or tiles,
//! uncompressed or LZW, Deflate, PackBits, ZSTD or LERC (with or without its
//! deflate or zstd layer, [`lerc`]); write float32.
//!
//! Read:
//! - one band: the only one, or `ReadOptions::band` (1-based, as GDAL's
//!   `-b`) of a multi-band file, which without it is refused with the band
//!   count; pixel- or band-interleaved (planar, GDAL's `INTERLEAVE=BAND`);
//! - `GDAL_NODATA` (tag 42113): samples equal to it become NaN; NaN float
//!   samples are nodata regardless;
//! - GDAL's per-band scale, offset and unit, and the vertical unit GeoKey:
//!   heights are `(raw × scale + offset) × metres per unit`;
//! - the georeference and CRS ([`geotiff`]). The cell size is the
//!   pixel size in metres for projected files; geographic files keep their
//!   degree geometry here and are resampled to square metric cells by
//!   [`crate::io::place::ground`];
//! - LERC (34887) chunks are decoded by [`lerc`] (the `tiff` crate has no
//!   LERC codec), its validity mask as nodata;
//! - LZMA (34925) is refused with the GDAL command that rewrites the file in
//!   a codec we read: no maintained pure-Rust decoder is wired into the
//!   `tiff` crate for it.
//!
//! Written: float32, uncompressed strips (every GeoTIFF reader opens them),
//! NaN for nodata with `GDAL_NODATA = "nan"`, and the georeference with its
//! CRS, or — for a terrain that has none — a local grid in metres with the
//! correct cell size and its lower-left corner at (0, 0), named as such
//! ([`Georef::local`]), never an invented EPSG code.

mod geotiff;
mod lerc;

use super::sidecar::DEFAULT_CELL_SIZE_M;
use crate::georef::Georef;
use crate::heightfield::Heightfield;
use crate::io::guard::limits::{
    DEFLATE_RATIO, LERC_RATIO, LZW_RATIO, PACKBITS_RATIO, ZSTD_RATIO, check_justified,
};
use crate::io::{Encoded, FormatError};
use crate::size::check_dims;
use geotiff::GeoKeys;
use std::io::Cursor;
use tiff::decoder::{Decoder, DecodingResult, Limits};
use tiff::encoder::{TiffEncoder, colortype::Gray32Float};
use tiff::tags::{SampleFormat, Tag};

/// Metres per degree on the WGS84 equator (40 075 016.686 m / 360).
pub const METRES_PER_DEGREE: f64 = 111_319.490_793;

pub(in crate::io) fn decode(bytes: &[u8], band: Option<usize>) -> Result<Heightfield, FormatError> {
    prescan(bytes)?;
    let mut dec = Decoder::new(Cursor::new(bytes)).map_err(tiff_error)?;
    let (w, h) = dec.dimensions().map_err(tiff_error)?;
    let (w, h) = (w as usize, h as usize);
    check_dims(w, h)?;
    let (ratio, is_lerc) = compression_ratio(&mut dec)?;
    let color = dec.colortype().map_err(tiff_error)?;
    let (bits, samples) = (color.bit_depth(), color.num_samples().max(1) as usize);
    let format = match dec.find_tag_unsigned_vec::<u16>(Tag::SampleFormat) {
        Ok(Some(v)) => v
            .first()
            .copied()
            .map_or(SampleFormat::Uint, SampleFormat::from_u16_exhaustive),
        Ok(None) => SampleFormat::Uint,
        Err(e) => return Err(tiff_error(e)),
    };
    match (bits, format) {
        (8 | 16 | 32, SampleFormat::Int | SampleFormat::Uint) | (32 | 64, SampleFormat::IEEEFP) => {
        }
        _ => {
            return Err(FormatError::Unsupported {
                what: "TIFF sample format",
                found: format!("{bits}-bit {format:?}"),
                supported: "int8/16/32, uint8/16/32, float32 or float64 (gdal_translate -ot Float32 converts the rest)",
            });
        }
    }
    let (band, planar) = pick_band(&mut dec, band, samples)?;
    let bytes_per_pixel = bits as u64 / 8 * samples as u64;
    check_justified(w, h, bytes_per_pixel, bytes.len(), ratio)?;
    // The decoder's limits, as a second line of defence: the image buffer
    // (checked above) or tag values expanded to the decoder's 32-byte value
    // type, compressed chunks no larger than the file.
    let mut limits = Limits::default();
    limits.decoding_buffer_size = (w * h * bytes_per_pixel as usize).max(32 * bytes.len());
    limits.intermediate_buffer_size = bytes.len();
    limits.ifd_value_size = bytes.len();
    let mut dec = dec.with_limits(limits);

    let nodata = gdal_nodata(&mut dec)?;
    let keys = geo_keys(&mut dec)?;
    // Checked even when nothing places the grid: a CRS we cannot read is
    // an error, never silently ignored.
    let crs = keys.crs()?;
    let scale = f64_tag(
        &mut dec,
        Tag::ModelPixelScaleTag,
        2,
        "ModelPixelScale (tag 33550)",
    )?;
    if let Some(s) = &scale
        && !(s[0].is_finite() && s[1].is_finite() && s[0] > 0.0 && s[1] > 0.0)
    {
        return Err(FormatError::Metadata(format!(
            "ModelPixelScale (tag 33550) is {} x {}: expected finite values > 0",
            s[0], s[1]
        )));
    }
    let tie = f64_tag(
        &mut dec,
        Tag::ModelTiepointTag,
        6,
        "ModelTiepoint (tag 33922)",
    )?;
    let matrix = f64_tag(
        &mut dec,
        Tag::ModelTransformationTag,
        16,
        "ModelTransformation (tag 34264)",
    )?;
    let georef = geotiff::placement(&keys, scale.as_deref(), tie.as_deref(), matrix.as_deref())?;
    let cell = match (&georef, &scale) {
        (Some(g), _) => cell_size(g, h),
        // A scale without a position: metres if the keys say so, else as the
        // north–south size of degrees on the equator (no latitude known).
        (None, Some(s)) => match crs {
            Some(c) if c.is_geographic() => s[1] * METRES_PER_DEGREE,
            Some(c) => s[0] * georef_units(&c),
            None => s[0],
        },
        (None, None) => DEFAULT_CELL_SIZE_M,
    };
    let mapping = match dec.find_tag(Tag::Unknown(42112)).map_err(tiff_error)? {
        Some(v) => {
            let xml = v.into_string().map_err(|_| {
                FormatError::Metadata("GDAL_METADATA (tag 42112) must be ASCII text".into())
            })?;
            geotiff::band_mapping(&xml, band)?
        }
        None => geotiff::BandMapping {
            scale: 1.0,
            offset: 0.0,
            unit_m: 1.0,
        },
    };
    let unit = mapping.unit_m * keys.vertical_metres()?;
    let (scale_z, offset_z) = (mapping.scale * unit, mapping.offset * unit);
    let identity = scale_z == 1.0 && offset_z == 0.0;
    let convert = |raw: f64| -> f32 {
        if raw.is_nan() || nodata == Some(raw) {
            f32::NAN
        } else if identity {
            raw as f32
        } else {
            (raw * scale_z + offset_z) as f32
        }
    };
    let n = w * h;
    // Float32 samples compare with the nodata value in f32, as GDAL does.
    let nodata32 = nodata.map(|v| v as f32);
    let data = if is_lerc {
        let band = lerc::Band {
            index: band,
            samples,
            planar,
            bits,
            format,
            convert: &convert,
            nodata32,
        };
        lerc::read_band(&mut dec, bytes, &band, (w, h))?
    } else if planar {
        read_plane(&mut dec, band, samples, (w, h), &convert, nodata32)?
    } else {
        let image = dec.read_image().map_err(tiff_error)?;
        heights(&image, (band, samples, n), &convert, nodata32)?
    };
    if data.len() < n {
        return Err(FormatError::EndsEarly("TIFF image data"));
    }
    let mut hf = Heightfield::from_vec(w, h, cell, data)?;
    hf.set_georef(georef);
    Ok(hf)
}

/// Every `step`-th sample of `image` from `start`, `n` of them, as heights
/// (`convert`; Float32 samples equal to `nodata32` are nodata).
fn heights(
    image: &DecodingResult,
    (start, step, n): (usize, usize, usize),
    convert: &dyn Fn(f64) -> f32,
    nodata32: Option<f32>,
) -> Result<Vec<f32>, FormatError> {
    fn pick<T: Copy>(
        v: &[T],
        (start, step, n): (usize, usize, usize),
        f: impl Fn(T) -> f32,
    ) -> Vec<f32> {
        v.iter()
            .skip(start)
            .step_by(step)
            .take(n)
            .map(|&s| f(s))
            .collect()
    }
    let at = (start, step, n);
    Ok(match image {
        DecodingResult::U8(v) => pick(v, at, |s| convert(s as f64)),
        DecodingResult::I8(v) => pick(v, at, |s| convert(s as f64)),
        DecodingResult::U16(v) => pick(v, at, |s| convert(s as f64)),
        DecodingResult::I16(v) => pick(v, at, |s| convert(s as f64)),
        DecodingResult::U32(v) => pick(v, at, |s| convert(s as f64)),
        DecodingResult::I32(v) => pick(v, at, |s| convert(s as f64)),
        DecodingResult::F64(v) => pick(v, at, convert),
        DecodingResult::F32(v) => pick(v, at, |s| {
            if Some(s) == nodata32 {
                f32::NAN
            } else {
                convert(s as f64)
            }
        }),
        _ => {
            return Err(FormatError::Corrupt(
                "TIFF decoded to an unexpected sample type".into(),
            ));
        }
    })
}

/// Band `band` (0-based) of a band-interleaved (planar) file, decoded chunk
/// by chunk: the band's strips or tiles are the `band`-th run of the
/// file's chunks. Why not the decoder's whole-image read: it decodes the
/// first plane only, and its all-planes read panicked on striped planar
/// files (tiff 0.11.3).
fn read_plane(
    dec: &mut Dec,
    band: usize,
    samples: usize,
    (w, h): (usize, usize),
    convert: &dyn Fn(f64) -> f32,
    nodata32: Option<f32>,
) -> Result<Vec<f32>, FormatError> {
    let tiled = matches!(dec.get_chunk_type(), tiff::decoder::ChunkType::Tile);
    let chunks = if tiled {
        dec.tile_count()
    } else {
        dec.strip_count()
    }
    .map_err(tiff_error)? as usize;
    let per_plane = chunks / samples;
    let (cw, ch) = dec.chunk_dimensions();
    let (cw, ch) = (cw as usize, ch as usize);
    if per_plane == 0 || cw == 0 || ch == 0 {
        return Err(FormatError::Corrupt(
            "TIFF planar layout has no chunks".into(),
        ));
    }
    let across = if tiled { w.div_ceil(cw) } else { 1 };
    // Every sample of the band comes from a chunk: a file listing fewer
    // chunks than cover the image is corrupt, not partly nodata.
    let needed = across * h.div_ceil(ch);
    if per_plane < needed {
        return Err(FormatError::Corrupt(format!(
            "TIFF band {} has {per_plane} chunks of {cw}x{ch}: too few to cover the {w}x{h} image",
            band + 1
        )));
    }
    let mut out = vec![f32::NAN; w * h];
    for i in 0..needed {
        let (x0, y0) = ((i % across) * cw, (i / across) * ch);
        let index = (band * per_plane + i) as u32;
        // The decoded chunk is its data rectangle: edge tiles without their
        // padding, except that the decoder drops the bottom padding of the
        // first plane only, so rows past the image are cut here.
        let (stride, data_rows) = dec.chunk_data_dimensions(index);
        let (stride, rows) = (stride as usize, (data_rows as usize).min(h - y0));
        let chunk = dec.read_chunk(index).map_err(tiff_error)?;
        let v = heights(&chunk, (0, 1, stride * rows), convert, nodata32)?;
        if stride == 0 || v.len() < stride * rows {
            return Err(FormatError::EndsEarly("TIFF chunk"));
        }
        let cols = stride.min(w - x0);
        for (r, row) in v.chunks_exact(stride).enumerate() {
            let dst = (y0 + r) * w + x0;
            out[dst..dst + cols].copy_from_slice(&row[..cols]);
        }
    }
    Ok(out)
}

/// Metres per linear unit of a CRS (1 for degrees, which never get here).
fn georef_units(c: &crate::georef::Crs) -> f64 {
    match c.units {
        crate::georef::Units::Linear { metres_per_unit } => metres_per_unit,
        crate::georef::Units::Degrees => 1.0,
    }
}

/// The square cell size in metres: the north–south ground spacing (the
/// east–west one is checked, and geographic grids resampled, by
/// [`crate::io::place::ground`]).
fn cell_size(g: &Georef, rows: usize) -> f64 {
    g.ground_spacing(rows).1
}

/// The best compression ratio of the file's codec, and whether it is LERC
/// (decoded by [`lerc`], not the `tiff` crate); refuses codecs we cannot
/// decode with the command that rewrites the file.
fn compression_ratio(dec: &mut Dec) -> Result<(u64, bool), FormatError> {
    let code = dec
        .find_tag_unsigned::<u16>(Tag::Compression)
        .map_err(tiff_error)?;
    let refuse = |name: &'static str| FormatError::Unsupported {
        what: "TIFF compression",
        found: format!("{name} ({})", code.unwrap_or(0)),
        supported: "none, LZW, Deflate, PackBits, ZSTD or LERC; rewrite the file with gdal_translate -co COMPRESS=DEFLATE in.tif out.tif",
    };
    if code == Some(34887) {
        return Ok((LERC_RATIO, true));
    }
    let ratio = match code {
        None | Some(1) => 1,
        Some(32773) => PACKBITS_RATIO,
        Some(8 | 32946) => DEFLATE_RATIO,
        Some(5) => LZW_RATIO,
        Some(50000) => ZSTD_RATIO,
        Some(34925) => return Err(refuse("LZMA")),
        Some(7) => return Err(refuse("JPEG (lossy, not for heights)")),
        Some(50001) => return Err(refuse("WEBP (lossy, not for heights)")),
        // Whatever else the decoder accepts: the loosest bound.
        Some(_) => ZSTD_RATIO,
    };
    Ok((ratio, false))
}

/// The 0-based band to read, checked against the file's band count, and
/// whether the bands are interleaved by plane (`PlanarConfiguration` 2).
fn pick_band(
    dec: &mut Dec,
    band: Option<usize>,
    samples: usize,
) -> Result<(usize, bool), FormatError> {
    let b = match (band, samples) {
        (None, 1) => return Ok((0, false)),
        (None, n) => {
            return Err(FormatError::Unsupported {
                what: "TIFF band count",
                found: format!("{n} bands"),
                supported: "one band, or choose one with --band 1..=N",
            });
        }
        (Some(b), n) if (1..=n).contains(&b) => b - 1,
        (Some(b), n) => {
            return Err(FormatError::Metadata(format!(
                "band {b} does not exist: the file has {n} band{} (expected --band 1..={n})",
                if n == 1 { "" } else { "s" }
            )));
        }
    };
    let planar = dec
        .find_tag_unsigned::<u16>(Tag::PlanarConfiguration)
        .map_err(tiff_error)?;
    Ok((b, planar == Some(2)))
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

/// The GeoKeys with their ASCII and double parameters.
fn geo_keys(dec: &mut Dec) -> Result<GeoKeys, FormatError> {
    let Some(value) = dec.find_tag(Tag::GeoKeyDirectoryTag).map_err(tiff_error)? else {
        return Ok(GeoKeys::default());
    };
    let dir = value.into_u16_vec().map_err(|_| {
        FormatError::Metadata("GeoKeyDirectory (tag 34735) must hold SHORT values".into())
    })?;
    let ascii = match dec.find_tag(Tag::GeoAsciiParamsTag).map_err(tiff_error)? {
        Some(v) => v.into_string().map_err(|_| {
            FormatError::Metadata("GeoAsciiParams (tag 34737) must be ASCII text".into())
        })?,
        None => String::new(),
    };
    let doubles = f64_tag(
        dec,
        Tag::GeoDoubleParamsTag,
        0,
        "GeoDoubleParams (tag 34736)",
    )?
    .unwrap_or_default();
    GeoKeys::parse(&dir, &ascii, &doubles)
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
    // Offsets come from the file: any of them may point past its end. An
    // unsigned integer of `n` bytes in the file's byte order.
    let uint_at = |o: usize, n: usize| -> Option<u64> {
        let b = bytes.get(o..o.checked_add(n)?)?;
        let be = |v: u64, &x: &u8| v << 8 | x as u64;
        Some(if le {
            b.iter().rev().fold(0, be)
        } else {
            b.iter().fold(0, be)
        })
    };
    let u16_at = |o| uint_at(o, 2);
    let u32_at = |o| uint_at(o, 4);
    let u64_at = |o| uint_at(o, 8);
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

pub(in crate::io) fn encode(hf: &Heightfield) -> Result<Encoded, FormatError> {
    let (w, h) = (hf.width(), hf.height());
    if w > u32::MAX as usize || h > u32::MAX as usize {
        return Err(FormatError::Unwritable(format!(
            "{w}x{h} exceeds TIFF's 32-bit sizes"
        )));
    }
    let unwritable = |e: tiff::TiffError| FormatError::Unwritable(format!("TIFF: {e}"));
    let local;
    let g = match hf.georef() {
        Some(g) => g,
        None => {
            local = Georef::local(h, hf.cell_size());
            &local
        }
    };
    let tags = geotiff::tags(g);
    let mut out = Cursor::new(Vec::new());
    {
        let mut enc = TiffEncoder::new(&mut out).map_err(unwritable)?;
        let mut image = enc
            .new_image::<Gray32Float>(w as u32, h as u32)
            .map_err(unwritable)?;
        let dir = image.encoder();
        dir.write_tag(Tag::ModelPixelScaleTag, &tags.pixel_scale[..])
            .map_err(unwritable)?;
        dir.write_tag(Tag::ModelTiepointTag, &tags.tiepoint[..])
            .map_err(unwritable)?;
        dir.write_tag(Tag::GeoKeyDirectoryTag, &tags.keys[..])
            .map_err(unwritable)?;
        if !tags.ascii.is_empty() {
            dir.write_tag(Tag::GeoAsciiParamsTag, tags.ascii.as_str())
                .map_err(unwritable)?;
        }
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
            supported: "strips or tiles, uncompressed, LZW, Deflate, PackBits, ZSTD or LERC; rewrite other files with gdal_translate -co COMPRESS=DEFLATE in.tif out.tif",
        },
        E::LimitsExceeded => FormatError::Corrupt(
            "TIFF strips or tiles decode to more data than the image size".into(),
        ),
        other => FormatError::Corrupt(format!("TIFF: {other}")),
    }
}
