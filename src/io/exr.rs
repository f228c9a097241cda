//! OpenEXR heightfields: one 32-bit float channel, NaN = nodata.
//!
//! Reading takes the single layer's channel named `Y` (OpenEXR's luminance,
//! the usual name for greyscale data), or the only channel when there is
//! one; any other layout is refused with the channel names listed, rather
//! than guessing which of several channels holds heights. F16 channels are
//! widened to f32 exactly; U32 channels are refused (heights are not counts,
//! and large u32 values do not fit f32). The data window's position is
//! ignored: the grid starts at its top-left sample.
//!
//! The cell size travels in a custom `double` layer attribute
//! [`CELL_SIZE_ATTRIBUTE`]; files without it get the default cell size.
//! Written files use lossless ZIP compression (16 scan lines per block).

use super::limits::{DEFLATE_RATIO, PACKBITS_RATIO, check_justified};
use super::sidecar::DEFAULT_CELL_SIZE_M;
use super::{Encoded, FormatError};
use crate::heightfield::Heightfield;
use crate::size::check_dims;
use exr::meta::MetaData;
use exr::prelude::*;
// The prelude exports its own `Result`; ours carries a `FormatError`.
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
pub(super) fn has_cell_size(bytes: &[u8]) -> bool {
    let name = CELL_SIZE_ATTRIBUTE.as_bytes();
    bytes
        .windows(name.len() + 1)
        .any(|w| &w[..name.len()] == name && w[name.len()] == 0)
}

pub(super) fn decode(bytes: &[u8]) -> Result<Heightfield, FormatError> {
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

    let channel = match channels.iter().find(|c| c.name.eq("Y")) {
        Some(c) => c,
        None if channels.len() == 1 => &channels[0],
        None => {
            let names: Vec<String> = channels.iter().map(|c| c.name.to_string()).collect();
            return Err(FormatError::Unsupported {
                what: "EXR channels",
                found: names.join(", "),
                supported: "a channel named Y, or exactly one channel",
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
    Ok(Heightfield::from_vec(w, h, cell, data)?)
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

pub(super) fn encode(hf: &Heightfield) -> Result<Encoded, FormatError> {
    encode_with(
        hf,
        hf.height().div_ceil(LINES_PER_BLOCK) >= PARALLEL_MIN_BLOCKS,
    )
}

/// Scan lines per ZIP16 block.
const LINES_PER_BLOCK: usize = 16;

/// Parallel compression writes the same bytes: blocks are compressed
/// independently and, in increasing line order, written sorted.
fn encode_with(hf: &Heightfield, parallel: bool) -> Result<Encoded, FormatError> {
    let (w, h) = (hf.width(), hf.height());
    let data = hf.data();
    let mut attributes = LayerAttributes::default();
    attributes.other.insert(
        Text::from(CELL_SIZE_ATTRIBUTE),
        AttributeValue::F64(hf.cell_size()),
    );
    let layer = Layer::new(
        (w, h),
        attributes,
        Encoding {
            compression: Compression::ZIP16,
            blocks: Blocks::ScanLines,
            line_order: LineOrder::Increasing,
        },
        SpecificChannels::build()
            .with_channel("Y")
            .with_pixel_fn(|pos: Vec2<usize>| (data[pos.y() * w + pos.x()],)),
    );
    let mut out = Cursor::new(Vec::new());
    let image = Image::from_layer(layer);
    let writer = image.write();
    let writer = if parallel {
        writer
    } else {
        writer.non_parallel()
    };
    writer
        .to_buffered(&mut out)
        .map_err(|e| FormatError::Unwritable(format!("EXR: {e}")))?;
    Ok(Encoded {
        bytes: out.into_inner(),
        sidecar: None,
    })
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

    #[test]
    fn parallel_and_sequential_writes_are_identical() {
        let hf =
            Heightfield::from_fn(48, 1100, 1.0, |x, y| ((x * 7 + y) % 97) as f32 * 0.5).unwrap();
        let a = encode_with(&hf, true).unwrap().bytes;
        let b = encode_with(&hf, false).unwrap().bytes;
        assert!(a == b, "parallel EXR output differs from sequential");
        assert_eq!(decode(&a).unwrap(), hf);
    }
}
