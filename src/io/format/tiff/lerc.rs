//! LERC-compressed GeoTIFF chunks (compression 34887: GDAL's `LERC`,
//! `LERC_DEFLATE` and `LERC_ZSTD`, what Copernicus GLO-30 COG mirrors use).
//!
//! The `tiff` crate cannot decode LERC, so the band is read here chunk by
//! chunk, as libtiff's `tif_lerc.c` writes it: each strip or tile is one
//! Lerc2 blob — or, for pixel-interleaved floats with NaNs in some bands
//! only, one blob per band, concatenated — optionally wrapped in a zlib or
//! zstd stream (`LercParameters`, tag 50674 = [LERC version, additional
//! compression 0 none / 1 deflate / 2 zstd]). A strip's blob holds the
//! strip's rows (the last one short); a tile's holds the whole tile,
//! padding included. A Lerc2 validity mask marks nodata: libtiff turns
//! masked float samples into NaN, and so do we for every sample type.
//!
//! Every size comes from the file, so each is checked before it is used:
//! chunk bytes inside the file, the unwrapped blob no larger than libtiff's
//! own buffer for it, and each blob's declared size and sample type equal
//! to the chunk's before the Lerc2 decoder allocates anything.

use super::{Dec, heights, tiff_error};
use crate::io::FormatError;
use lerc_core::{DataType, PixelData};
use std::io::Read;
use tiff::decoder::{ChunkType, DecodingResult};
use tiff::tags::{SampleFormat, Tag};

/// What the caller's band is made of and how its samples become heights.
pub(in crate::io) struct Band<'a> {
    /// 0-based band to read.
    pub index: usize,
    /// Bands in the file.
    pub samples: usize,
    /// Band-interleaved (`PlanarConfiguration` 2).
    pub planar: bool,
    /// Bits per sample and their format, from the file's tags.
    pub bits: u8,
    pub format: SampleFormat,
    pub convert: &'a dyn Fn(f64) -> f32,
    /// Float32 samples equal to this are nodata (GDAL compares in f32).
    pub nodata32: Option<f32>,
}

/// The layer around each Lerc2 blob (`LercParameters`' second value).
#[derive(Clone, Copy)]
enum Wrap {
    None,
    Deflate,
    Zstd,
}

/// The `w × h` band of a LERC-compressed file, row-major, nodata as NaN.
pub(in crate::io) fn read_band(
    dec: &mut Dec,
    file: &[u8],
    band: &Band,
    (w, h): (usize, usize),
) -> Result<Vec<f32>, FormatError> {
    let wrap = wrap(dec)?;
    let want = data_type(band.bits, band.format)?;
    let tiled = matches!(dec.get_chunk_type(), ChunkType::Tile);
    let (offsets, counts) = if tiled {
        (Tag::TileOffsets, Tag::TileByteCounts)
    } else {
        (Tag::StripOffsets, Tag::StripByteCounts)
    };
    let offsets = chunk_table(dec, offsets)?;
    let counts = chunk_table(dec, counts)?;
    let (cw, ch) = dec.chunk_dimensions();
    let (cw, ch) = (cw as usize, ch as usize);
    // A strip spans the image's width whatever TileWidth says.
    let cw = if tiled { cw } else { w };
    if cw == 0 || ch == 0 {
        return Err(FormatError::Corrupt("TIFF LERC chunks of zero size".into()));
    }
    let across = w.div_ceil(cw);
    let needed = across * h.div_ceil(ch);
    let planes = if band.planar { band.samples } else { 1 };
    if offsets.len() != counts.len() || offsets.len() < needed * planes {
        return Err(FormatError::Corrupt(format!(
            "TIFF lists {} chunk offsets and {} byte counts: {} chunks of {cw}x{ch} cover the {w}x{h} image{}",
            offsets.len(),
            counts.len(),
            needed * planes,
            if planes > 1 { " in every band" } else { "" }
        )));
    }
    // Bands in each blob: all of them for pixel-interleaved files.
    let depth = if band.planar { 1 } else { band.samples };
    let (first, sample) = if band.planar {
        (band.index * needed, 0)
    } else {
        (0, band.index)
    };
    let mut out = vec![f32::NAN; w * h];
    for i in 0..needed {
        let (x0, y0) = ((i % across) * cw, (i / across) * ch);
        // Strips stop at the image's last row; tiles keep their padding.
        let rows = if tiled { ch } else { ch.min(h - y0) };
        let index = first + i;
        let name = Chunk {
            tiled,
            index,
            band: band.planar.then_some(band.index + 1),
        };
        let raw = chunk_bytes(file, offsets[index], counts[index], &name)?;
        let size = (cw * rows * depth).saturating_mul(band.bits as usize / 8);
        let blob = unwrap(raw, wrap, size, &name)?;
        let (values, mask) = decode_chunk(&blob, (cw, rows, depth), want, sample, &name)?;
        let v = heights(&values, (0, 1, cw * rows), band.convert, band.nodata32)?;
        let (cols, data_rows) = (cw.min(w - x0), rows.min(h - y0));
        for r in 0..data_rows {
            let dst = (y0 + r) * w + x0;
            let src = r * cw;
            for c in 0..cols {
                let valid = mask.as_ref().is_none_or(|m| m[src + c] != 0);
                out[dst + c] = if valid { v[src + c] } else { f32::NAN };
            }
        }
    }
    Ok(out)
}

/// A chunk as error messages name it: "LERC tile 12 (band 2)".
struct Chunk {
    tiled: bool,
    index: usize,
    band: Option<usize>,
}

impl std::fmt::Display for Chunk {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let kind = if self.tiled { "tile" } else { "strip" };
        write!(f, "LERC {kind} {}", self.index)?;
        match self.band {
            Some(b) => write!(f, " (band {b})"),
            None => Ok(()),
        }
    }
}

impl Chunk {
    fn corrupt(&self, what: impl std::fmt::Display) -> FormatError {
        FormatError::Corrupt(format!("TIFF {self}: {what}"))
    }
}

/// `LercParameters` (tag 50674); without it libtiff assumes no wrapping.
fn wrap(dec: &mut Dec) -> Result<Wrap, FormatError> {
    let params = dec
        .find_tag_unsigned_vec::<u32>(Tag::Unknown(50674))
        .map_err(tiff_error)?
        .unwrap_or_default();
    Ok(match params.get(1).copied().unwrap_or(0) {
        0 => Wrap::None,
        1 => Wrap::Deflate,
        2 => Wrap::Zstd,
        other => {
            return Err(FormatError::Unsupported {
                what: "TIFF LERC additional compression",
                found: format!("{other} (LercParameters, tag 50674)"),
                supported: "0 none, 1 deflate or 2 zstd (GDAL's LERC, LERC_DEFLATE, LERC_ZSTD)",
            });
        }
    })
}

/// The Lerc2 sample type libtiff writes for the file's sample format.
fn data_type(bits: u8, format: SampleFormat) -> Result<DataType, FormatError> {
    Ok(match (bits, format) {
        (8, SampleFormat::Int) => DataType::I8,
        (8, _) => DataType::U8,
        (16, SampleFormat::Int) => DataType::I16,
        (16, _) => DataType::U16,
        (32, SampleFormat::Int) => DataType::I32,
        (32, SampleFormat::IEEEFP) => DataType::F32,
        (32, _) => DataType::U32,
        (64, SampleFormat::IEEEFP) => DataType::F64,
        _ => {
            return Err(FormatError::Unsupported {
                what: "TIFF LERC sample format",
                found: format!("{bits}-bit {format:?}"),
                supported: "8-, 16- or 32-bit integers, float32 or float64",
            });
        }
    })
}

fn chunk_table(dec: &mut Dec, tag: Tag) -> Result<Vec<u64>, FormatError> {
    dec.find_tag_unsigned_vec::<u64>(tag)
        .map_err(tiff_error)?
        .ok_or_else(|| FormatError::Metadata(format!("TIFF LERC file without {tag:?}")))
}

/// The chunk's stored bytes, which must lie inside the file.
fn chunk_bytes<'f>(
    file: &'f [u8],
    offset: u64,
    count: u64,
    name: &Chunk,
) -> Result<&'f [u8], FormatError> {
    let end = offset.saturating_add(count);
    usize::try_from(offset)
        .ok()
        .zip(usize::try_from(end).ok())
        .and_then(|(a, b)| file.get(a..b))
        .ok_or_else(|| {
            name.corrupt(format_args!(
                "bytes {offset}..{end} lie past the end of the {}-byte file",
                file.len()
            ))
        })
}

/// The Lerc2 blob inside the chunk's deflate or zstd layer. A blob of
/// `size` decoded bytes fits libtiff's buffer of 256 + 4/3 × `size` bytes
/// (header, mask, incompressible blocks); a longer one is corrupt, and
/// nothing longer is ever held.
fn unwrap<'r>(
    raw: &'r [u8],
    wrap: Wrap,
    size: usize,
    name: &Chunk,
) -> Result<std::borrow::Cow<'r, [u8]>, FormatError> {
    let limit = size.saturating_add(size / 3).saturating_add(256);
    let blob = match wrap {
        Wrap::None => return Ok(raw.into()),
        Wrap::Deflate => miniz_oxide::inflate::decompress_to_vec_zlib_with_limit(raw, limit)
            .map_err(|e| name.corrupt(format_args!("its deflate layer: {e}")))?,
        Wrap::Zstd => {
            let mut blob = Vec::new();
            zstd::stream::read::Decoder::new(raw)
                .and_then(|d| d.take(limit as u64 + 1).read_to_end(&mut blob))
                .map_err(|e| name.corrupt(format_args!("its zstd layer: {e}")))?;
            if blob.len() > limit {
                return Err(name.corrupt(format_args!(
                    "its zstd layer holds more than the {limit} bytes a {size}-byte chunk can need"
                )));
            }
            blob
        }
    };
    Ok(blob.into())
}

/// Sample `sample` of every pixel of a `cols × rows` chunk of `depth`
/// bands, with the validity mask (0 = nodata) when the blob has one.
fn decode_chunk(
    blob: &[u8],
    (cols, rows, depth): (usize, usize, usize),
    want: DataType,
    sample: usize,
    name: &Chunk,
) -> Result<(DecodingResult, Option<Vec<u8>>), FormatError> {
    let blobs = check_headers(blob, (cols, rows, depth), name)?;
    let decoded =
        lerc_reader::decode_band_set(blob).map_err(|e| name.corrupt(format_args!("Lerc2: {e}")))?;
    let (_, mut bands, mut masks) = decoded.into_parts();
    // One blob of `depth` interleaved bands, or one blob per band.
    let (values, mask, stride, at) = if blobs == 1 {
        (bands.swap_remove(0), masks.swap_remove(0), depth, sample)
    } else {
        (bands.swap_remove(sample), masks.swap_remove(sample), 1, 0)
    };
    if values.data_type() != want {
        return Err(name.corrupt(format_args!(
            "Lerc2 samples are {:?}, the file's are {want:?}",
            values.data_type()
        )));
    }
    let n = cols * rows;
    let values = match values {
        PixelData::I8(v) => DecodingResult::I8(pick(v, at, stride, n)),
        PixelData::U8(v) => DecodingResult::U8(pick(v, at, stride, n)),
        PixelData::I16(v) => DecodingResult::I16(pick(v, at, stride, n)),
        PixelData::U16(v) => DecodingResult::U16(pick(v, at, stride, n)),
        PixelData::I32(v) => DecodingResult::I32(pick(v, at, stride, n)),
        PixelData::U32(v) => DecodingResult::U32(pick(v, at, stride, n)),
        PixelData::F32(v) => DecodingResult::F32(pick(v, at, stride, n)),
        PixelData::F64(v) => DecodingResult::F64(pick(v, at, stride, n)),
    };
    if mask.as_ref().is_some_and(|m| m.len() != n) {
        return Err(name.corrupt("the Lerc2 mask does not cover the chunk"));
    }
    Ok((values, mask))
}

/// Every `stride`-th of `n` samples from `at` (all of them when `stride` is 1).
fn pick<T: Copy>(v: Vec<T>, at: usize, stride: usize, n: usize) -> Vec<T> {
    if stride == 1 {
        v
    } else {
        v.into_iter().skip(at).step_by(stride).take(n).collect()
    }
}

/// Reads the header of each concatenated Lerc2 blob without decoding it:
/// every blob must have the chunk's size, and either one blob carries all
/// `depth` bands or there is one single-band blob per band. Returns the
/// blob count. Why by hand: the decoder reserves its buffers from these
/// header fields, so they are checked against the chunk first.
fn check_headers(
    blob: &[u8],
    (cols, rows, depth): (usize, usize, usize),
    name: &Chunk,
) -> Result<usize, FormatError> {
    let mut at = 0;
    let mut count = 0;
    while at < blob.len() {
        let h = Header::read(&blob[at..]).ok_or_else(|| {
            name.corrupt(format_args!(
                "blob {} is not a complete Lerc2 header ({} bytes left)",
                count + 1,
                blob.len() - at
            ))
        })?;
        if (h.cols, h.rows) != (cols, rows) {
            return Err(name.corrupt(format_args!(
                "its Lerc2 blob is {}x{}, the chunk {cols}x{rows}",
                h.cols, h.rows
            )));
        }
        count += 1;
        let fits = match count {
            1 => h.depth == depth || h.depth == 1,
            _ => h.depth == 1 && count <= depth,
        };
        if !fits {
            return Err(name.corrupt(format_args!(
                "its Lerc2 blob {count} has depth {} for a chunk of {depth} band{}",
                h.depth,
                if depth == 1 { "" } else { "s" }
            )));
        }
        if h.size == 0 {
            return Err(name.corrupt("a Lerc2 blob declares zero bytes"));
        }
        at = at.saturating_add(h.size);
    }
    if count == 0 || (count > 1 && count != depth) {
        return Err(name.corrupt(format_args!(
            "{count} Lerc2 blobs for a chunk of {depth} band{}",
            if depth == 1 { "" } else { "s" }
        )));
    }
    Ok(count)
}

/// The fields of a Lerc2 header that size the decoder's buffers.
struct Header {
    rows: usize,
    cols: usize,
    depth: usize,
    /// The blob's length in bytes, header included.
    size: usize,
}

impl Header {
    /// `Lerc2 `, version, checksum (v3+), rows, cols, depth (v4+), valid
    /// pixels, micro-block size, blob size — little-endian.
    fn read(b: &[u8]) -> Option<Header> {
        let int = |o: usize| -> Option<u32> {
            Some(u32::from_le_bytes(b.get(o..o + 4)?.try_into().ok()?))
        };
        if b.get(..6)? != b"Lerc2 " {
            return None;
        }
        let version = int(6)?;
        let mut o = if version >= 3 { 14 } else { 10 };
        let rows = int(o)? as usize;
        let cols = int(o + 4)? as usize;
        o += 8;
        let depth = if version >= 4 {
            o += 4;
            int(o - 4)? as usize
        } else {
            1
        };
        let size = int(o + 8)? as usize;
        Some(Header {
            rows,
            cols,
            depth,
            size,
        })
    }
}
