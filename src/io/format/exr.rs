//! OpenEXR heightfields: one 32-bit float channel, NaN = nodata.
//!
//! Reading takes the single layer's channel named `Y` (OpenEXR's luminance,
//! the usual name for greyscale data), or the only channel when there is
//! one, or `R` of an RGB(A) image — Houdini and other tools write heights
//! into the red channel of a colour EXR (with a notice, [`RED_NOTE`]); any
//! other layout is refused with the channel names listed, rather than
//! guessing which of several channels holds heights. F16 channels are
//! widened to f32 exactly; U32 channels are refused (heights are not counts,
//! and large u32 values do not fit f32). The data window's position is
//! ignored: the grid starts at its top-left sample.
//!
//! The cell size travels in a custom `double` layer attribute
//! [`CELL_SIZE_ATTRIBUTE`]; files without it get the default cell size.
//! Written files use lossless ZIP compression (16 scan lines per block),
//! each block at the level it pays for (see [`zip_block`]).

use super::sidecar::DEFAULT_CELL_SIZE_M;
use crate::heightfield::Heightfield;
use crate::io::guard::limits::{DEFLATE_RATIO, PACKBITS_RATIO, check_justified};
use crate::io::{Encoded, FormatError};
use crate::size::check_dims;
use exr::meta::MetaData;
use exr::prelude::*;
// The prelude exports its own `Result`; ours carries a `FormatError`.
use exr::block::chunk::{Chunk, CompressedBlock, CompressedScanLineBlock};
use exr::block::writer::ChunksWriter;
use exr::image::recursive::{NoneMore, Recursive};
use rayon::prelude::*;
use std::io::Cursor;
use std::result::Result;

/// Layer attribute holding the cell size in metres (OpenEXR type `double`).
pub const CELL_SIZE_ATTRIBUTE: &str = "cellSizeMetres";

const MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];

/// Blocks below which decompression runs on the calling thread.
const PARALLEL_MIN_BLOCKS: usize = 64;

/// Whether the header names the cell size attribute (else the cell size
/// read is the default). The header precedes the pixels and attribute
/// names are stored as plain text.
pub(in crate::io) fn has_cell_size(bytes: &[u8]) -> bool {
    let name = CELL_SIZE_ATTRIBUTE.as_bytes();
    bytes
        .windows(name.len() + 1)
        .any(|w| &w[..name.len()] == name && w[name.len()] == 0)
}

/// The notice of a height read from the `R` channel of an RGB(A) EXR.
pub const RED_NOTE: &str =
    "heights read from channel R of an RGB(A) EXR (as Houdini writes them); G, B and A are ignored";

/// Decodes the height channel; the notice says when it was R of RGB(A).
pub(in crate::io) fn decode(
    bytes: &[u8],
) -> Result<(Heightfield, Option<&'static str>), FormatError> {
    if bytes.len() < MAGIC.len() || bytes[..MAGIC.len()] != MAGIC {
        return Err(FormatError::bad_magic("OpenEXR magic 76 2F 31 01", bytes));
    }
    // Headers first: the declared size and channels are checked before any
    // pixel buffer exists.
    let meta = MetaData::read_from_buffered(Cursor::new(bytes), false).map_err(exr_error)?;
    let header = match meta.headers.as_slice() {
        [one] => one,
        many => {
            return Err(FormatError::Unsupported {
                what: "EXR part count",
                found: many.len().to_string(),
                supported: "a single-part image",
            });
        }
    };
    if header.deep {
        return Err(FormatError::Unsupported {
            what: "EXR data",
            found: "deep samples".into(),
            supported: "flat images",
        });
    }
    let (w, h) = (header.layer_size.width(), header.layer_size.height());
    check_dims(w, h)?;
    let channels = &header.channels.list;
    let bytes_per_pixel: u64 = channels
        .iter()
        .map(|c| match c.sample_type {
            SampleType::F16 => 2,
            SampleType::F32 | SampleType::U32 => 4,
        })
        .sum();
    check_justified(
        w,
        h,
        bytes_per_pixel,
        bytes.len(),
        max_ratio(header.compression),
    )?;
    // The offset table (8 bytes per block) precedes the pixels and is read
    // whole: it must fit in the file too.
    if (header.chunk_count as u64).saturating_mul(8) > bytes.len() as u64 {
        return Err(FormatError::not_justified(w, h, bytes.len()));
    }

    // A colour image: channels R, G, B and maybe A, nothing else.
    let rgb = channels.len() >= 3
        && channels
            .iter()
            .all(|c| ["R", "G", "B", "A"].iter().any(|n| c.name.eq(n)));
    let red = channels.iter().find(|c| c.name.eq("R")).filter(|_| rgb);
    let channel = match channels.iter().find(|c| c.name.eq("Y")) {
        Some(c) => c,
        None if channels.len() == 1 => &channels[0],
        None if red.is_some() => red.expect("checked"),
        None => {
            let names: Vec<String> = channels.iter().map(|c| c.name.to_string()).collect();
            return Err(FormatError::Unsupported {
                what: "EXR channels",
                found: names.join(", "),
                supported: "a channel named Y, exactly one channel, or R of an RGB(A) image",
            });
        }
    };
    if channel.sample_type == SampleType::U32 {
        return Err(FormatError::Unsupported {
            what: "EXR sample type",
            found: format!("u32 in channel {}", channel.name),
            supported: "f32 or f16",
        });
    }
    if channel.sampling != Vec2(1, 1) {
        return Err(FormatError::Unsupported {
            what: "EXR channel subsampling",
            found: format!("{:?} in channel {}", channel.sampling, channel.name),
            supported: "one sample per pixel",
        });
    }
    let cell = cell_size(header)?;

    let reader = read()
        .no_deep_data()
        .largest_resolution_level()
        .specific_channels()
        .required(channel.name.clone())
        .collect_pixels(
            |size, _| (size.width(), vec![0f32; size.area()]),
            |(width, data): &mut (usize, Vec<f32>), pos, (v,): (f32,)| {
                data[pos.y() * *width + pos.x()] = v
            },
        )
        .first_valid_layer()
        .all_attributes();
    // exr builds a thread pool per parallel read: worth it only for many blocks.
    let reader = if header.chunk_count >= PARALLEL_MIN_BLOCKS {
        reader
    } else {
        reader.non_parallel()
    };
    let image = reader
        .from_buffered(Cursor::new(bytes))
        .map_err(exr_error)?;
    let (width, data) = image.layer_data.channel_data.pixels;
    // The reader re-parses the headers; a file whose second parse disagrees
    // with the first is corrupt, not a different image.
    if width != w || data.len() != w * h {
        return Err(FormatError::Corrupt(format!(
            "EXR pixel count {} does not match the data window {w}x{h}",
            data.len()
        )));
    }
    let note = (red.is_some() && channel.name.eq("R")).then_some(RED_NOTE);
    Ok((Heightfield::from_vec(w, h, cell, data)?, note))
}

/// The most a block can expand when decompressed, by codec.
fn max_ratio(c: Compression) -> u64 {
    match c {
        Compression::Uncompressed => 1,
        // A 2-byte run emits at most 128 bytes.
        Compression::RLE => PACKBITS_RATIO,
        // Deflate of 24-bit values that expand back to 32-bit floats.
        Compression::PXR24 => DEFLATE_RATIO * 4 / 3,
        // Deflate, PIZ's Huffman run codes (~410x), B44's fixed blocks, DWA's
        // lossless fallbacks: deflate's bound covers them all.
        _ => DEFLATE_RATIO,
    }
}

fn cell_size(header: &exr::meta::header::Header) -> Result<f64, FormatError> {
    let value = match header
        .own_attributes
        .other
        .get(&Text::from(CELL_SIZE_ATTRIBUTE))
    {
        None => return Ok(DEFAULT_CELL_SIZE_M),
        Some(AttributeValue::F64(v)) => *v,
        Some(AttributeValue::F32(v)) => *v as f64,
        Some(other) => {
            return Err(FormatError::Metadata(format!(
                "EXR attribute {CELL_SIZE_ATTRIBUTE} must be a double, found {other:?}"
            )));
        }
    };
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(FormatError::Metadata(format!(
            "EXR attribute {CELL_SIZE_ATTRIBUTE} is {value}: expected a finite cell size > 0 m"
        )))
    }
}

/// The image `encode` writes: one layer, channel `Y`, ZIP16 scan lines,
/// the cell size attribute.
#[allow(clippy::type_complexity)]
fn image(
    hf: &Heightfield,
) -> Image<
    Layer<
        SpecificChannels<
            impl Fn(Vec2<usize>) -> (f32,) + '_,
            Recursive<NoneMore, ChannelDescription>,
        >,
    >,
> {
    let (w, h) = (hf.width(), hf.height());
    let data = hf.data();
    let mut attributes = LayerAttributes::default();
    attributes.other.insert(
        Text::from(CELL_SIZE_ATTRIBUTE),
        AttributeValue::F64(hf.cell_size()),
    );
    Image::from_layer(Layer::new(
        (w, h),
        attributes,
        Encoding {
            compression: Compression::ZIP16,
            blocks: Blocks::ScanLines,
            line_order: LineOrder::Increasing,
        },
        SpecificChannels::build()
            .with_channel("Y")
            .with_pixel_fn(move |pos: Vec2<usize>| (data[pos.y() * w + pos.x()],)),
    ))
}

pub(in crate::io) fn encode(hf: &Heightfield) -> Result<Encoded, FormatError> {
    let (w, data) = (hf.width(), hf.data());
    // The crate writes the header and the offset table; the blocks are
    // ours (see `zip_block`), compressed on the caller's pool.
    let headers = image(hf).write().infer_meta_data();
    let blocks: Vec<Vec<u8>> = data
        .par_chunks(w * LINES_PER_BLOCK)
        .map(zip_block)
        .collect();
    let mut out = Cursor::new(Vec::new());
    exr::block::write(&mut out, headers, true, |_, writer| {
        for (i, pixels) in blocks.into_iter().enumerate() {
            let block = CompressedScanLineBlock {
                y_coordinate: (i * LINES_PER_BLOCK) as i32,
                compressed_pixels_le: pixels,
            };
            let chunk = Chunk {
                layer_index: 0,
                compressed_block: CompressedBlock::ScanLine(block),
            };
            writer.write_chunk(i, chunk)?;
        }
        Ok(())
    })
    .map_err(|e| FormatError::Unwritable(format!("EXR: {e}")))?;
    Ok(Encoded {
        bytes: out.into_inner(),
        sidecar: None,
    })
}

/// Scan lines per ZIP16 block.
const LINES_PER_BLOCK: usize = 16;

/// A ZIP block at which the quick pass counts as compressible (compressed
/// to under 3/4 of its size), so it is compressed again at
/// [`ZIP_LEVEL`].
const WORTH_EFFORT: (usize, usize) = (3, 4);

/// OpenEXR's default ZIP level (and the `exr` crate's).
const ZIP_LEVEL: u8 = 4;

/// One ZIP block of the rows `lines`, as OpenEXR stores it: the samples'
/// little-endian bytes split into even and odd halves, byte differences
/// (+128), zlib; or the raw bytes where that is not smaller (the reader
/// tells them apart by the size).
///
/// Why not the `exr` crate's own compressor: it deflates every block at
/// level 4, which on a synthesized heightfield's floats (whose low
/// mantissa bytes are noise) spends ~135 ms of CPU per 1024² output to
/// save 4 % — a third of the synthesis itself, measured in the whole
/// `synth -o x.exr` process. Level 1 takes a quarter of the time; where
/// the data is regular (integer heights, plains, the sea) it falls well
/// short of level 4 (66 % of raw against 43 % on a DEM in whole metres),
/// so blocks that the quick pass finds compressible get level 4 too,
/// and those keep the crate's exact bytes.
fn zip_block(lines: &[f32]) -> Vec<u8> {
    let raw: Vec<u8> = lines.iter().flat_map(|v| v.to_le_bytes()).collect();
    let half = raw.len().div_ceil(2);
    let mut split = vec![0u8; raw.len()];
    for (i, &b) in raw.iter().enumerate() {
        split[(i % 2) * half + i / 2] = b;
    }
    let mut prev = split[0];
    for b in &mut split[1..] {
        let cur = *b;
        *b = cur.wrapping_sub(prev).wrapping_add(128);
        prev = cur;
    }
    let quick = miniz_oxide::deflate::compress_to_vec_zlib(&split, 1);
    let (num, den) = WORTH_EFFORT;
    let zipped = match quick.len() * den < raw.len() * num {
        true => miniz_oxide::deflate::compress_to_vec_zlib(&split, ZIP_LEVEL),
        false => quick,
    };
    match zipped.len() < raw.len() {
        true => zipped,
        false => raw,
    }
}

fn exr_error(e: exr::error::Error) -> FormatError {
    match e {
        // exr turns an unexpected end of file into this message.
        exr::error::Error::Invalid(m) if m == "reference to missing bytes" => {
            FormatError::EndsEarly("EXR data")
        }
        exr::error::Error::NotSupported(what) => FormatError::Unsupported {
            what: "EXR feature",
            found: what.into_owned(),
            supported: "flat scan-line or tiled images",
        },
        other => FormatError::Corrupt(format!("EXR: {other}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A smooth slope whose low mantissa bytes are noise (as a
    /// synthesis's are: interpolated heights), from a hash of the position.
    fn noisy(x: usize, y: usize) -> f32 {
        let k = (x as u32).wrapping_mul(0x9E37_79B9) ^ (y as u32).wrapping_mul(0x85EB_CA6B);
        let k = (k ^ k >> 15).wrapping_mul(0x2C1B_3C6D);
        800.0 + 0.31 * x as f32 + 0.17 * y as f32 + (k >> 16) as f32 / 65536.0
    }

    /// The crate's own writer, every block at level 4.
    fn crate_bytes(hf: &Heightfield) -> Vec<u8> {
        let mut out = Cursor::new(Vec::new());
        image(hf)
            .write()
            .non_parallel()
            .to_buffered(&mut out)
            .unwrap();
        out.into_inner()
    }

    fn same_bits(a: &Heightfield, b: &Heightfield) -> bool {
        let bits = |h: &Heightfield| h.data().iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        (a.width(), a.height(), a.cell_size()) == (b.width(), b.height(), b.cell_size())
            && bits(a) == bits(b)
    }

    #[test]
    fn compressible_blocks_are_the_crates_own_bytes() {
        // Whole and half metres with nodata: every block compresses well,
        // so every block takes level 4, as the crate writes it.
        let hf = Heightfield::from_fn(48, 1100, 2.5, |x, y| match (x * 31 + y) % 211 {
            0 => f32::NAN,
            _ => ((x * 7 + y) % 97) as f32 * 0.5,
        })
        .unwrap();
        let ours = encode(&hf).unwrap().bytes;
        assert!(
            ours == crate_bytes(&hf),
            "compressible EXR differs from exr's"
        );
        assert!(same_bits(&decode(&ours).unwrap().0, &hf));
    }

    #[test]
    fn noisy_blocks_take_the_quick_level_and_read_back_exactly() {
        let hf = Heightfield::from_fn(300, 70, 1.0, noisy).unwrap();
        let ours = encode(&hf).unwrap().bytes;
        let theirs = crate_bytes(&hf);
        assert!(
            ours != theirs,
            "the noisy blocks were not compressed at level 1"
        );
        // Level 1 on such data costs a few per cent of size at most.
        assert!(
            ours.len() < theirs.len() * 21 / 20,
            "{} vs {}",
            ours.len(),
            theirs.len()
        );
        assert!(ours.len() < 300 * 70 * 4, "not compressed at all");
        assert!(same_bits(&decode(&ours).unwrap().0, &hf));
    }

    #[test]
    fn incompressible_blocks_are_stored_raw_and_mixed_files_read_back() {
        // Every bit random (NaN payloads aside): deflate cannot shrink it,
        // so the block is its raw little-endian bytes.
        let lines: Vec<f32> = (0..64 * LINES_PER_BLOCK)
            .map(|i| {
                f32::from_bits((noisy(i, 7).to_bits() << 9) ^ (i as u32).wrapping_mul(0x9E37_79B9))
            })
            .map(|v| if v.is_nan() { 1.0 } else { v })
            .collect();
        let raw: Vec<u8> = lines.iter().flat_map(|v| v.to_le_bytes()).collect();
        assert_eq!(zip_block(&lines), raw);
        // Blocks of all three kinds in one file, and a last partial block.
        let hf = Heightfield::from_fn(64, 3 * LINES_PER_BLOCK + 5, 1.0, |x, y| {
            match y / LINES_PER_BLOCK {
                0 => lines[(y % LINES_PER_BLOCK) * 64 + x],
                1 => noisy(x, y),
                _ => (x / 8) as f32,
            }
        })
        .unwrap();
        assert!(same_bits(
            &decode(&encode(&hf).unwrap().bytes).unwrap().0,
            &hf
        ));
    }
}
