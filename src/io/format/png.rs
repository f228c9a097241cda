//! Greyscale PNG heightmaps: 16-bit (read/write) and 8-bit (read), with the
//! JSON sidecar giving metres ([`super::sidecar`]).
//!
//! Writing maps the data's own `[min, max]` onto the full code range (or a
//! requested range), like the shared DEMs. Nodata survives the round trip:
//! when present it gets code 0, recorded as `nodata_value` in the sidecar,
//! and valid heights use codes 1..=65535.

use super::quantize::{dequantize, quantize16};
use super::sidecar::Sidecar;
use crate::heightfield::Heightfield;
use crate::io::guard::limits::{DEFLATE_RATIO, check_justified};
use crate::io::{Encoded, FormatError};
use crate::size::check_dims;
use std::io::Cursor;

/// The bit depth of a greyscale PNG, to choose between 8- and 16-bit decoding.
pub(in crate::io) fn sniff_depth(bytes: &[u8]) -> Option<crate::io::Format> {
    // IHDR is always first: signature (8) + length (4) + "IHDR" (4) + w, h (8) + depth (1).
    let depth = *bytes.get(24)?;
    (bytes.get(12..16)? == b"IHDR").then_some(if depth == 16 {
        crate::io::Format::Png16
    } else {
        crate::io::Format::Png8
    })
}

pub(in crate::io) fn decode(
    bytes: &[u8],
    sidecar: Option<&Sidecar>,
) -> Result<Heightfield, FormatError> {
    const SIG: &[u8] = b"\x89PNG\r\n\x1a\n";
    if bytes.len() < SIG.len() || &bytes[..SIG.len()] != SIG {
        return Err(FormatError::bad_magic(
            "PNG signature 89 50 4E 47 0D 0A 1A 0A",
            bytes,
        ));
    }
    let mut decoder = png::Decoder::new(Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::IDENTITY);
    let mut reader = decoder.read_info().map_err(png_error)?;
    let info = reader.info();
    let (w, h) = (info.width as usize, info.height as usize);
    let (color, depth) = (info.color_type, info.bit_depth);
    if color != png::ColorType::Grayscale {
        return Err(FormatError::Unsupported {
            what: "PNG colour type",
            found: format!("{color:?}"),
            supported: "single-channel greyscale",
        });
    }
    let bits: u8 = match depth {
        png::BitDepth::Eight => 8,
        png::BitDepth::Sixteen => 16,
        other => {
            return Err(FormatError::Unsupported {
                what: "PNG bit depth",
                found: format!("{} bits", other as u8),
                supported: "8 or 16 bits",
            });
        }
    };
    check_dims(w, h)?;
    check_justified(w, h, bits as u64 / 8, bytes.len(), DEFLATE_RATIO)?;
    if let Some(sc) = sidecar {
        sc.check_size(w, h)?;
    }
    let mut buf = vec![
        0u8;
        reader.output_buffer_size().ok_or_else(|| {
            FormatError::Corrupt("PNG output size overflows".into())
        })?
    ];
    reader.next_frame(&mut buf).map_err(png_error)?;

    if bits == 16 {
        let codes = buf
            .chunks_exact(2)
            .map(|c| u16::from_be_bytes([c[0], c[1]]));
        dequantize(w, h, codes, bits, sidecar)
    } else {
        dequantize(w, h, buf.iter().map(|&v| v as u16), bits, sidecar)
    }
}

pub(in crate::io) fn encode16(
    hf: &Heightfield,
    range: Option<(f64, f64)>,
    south_up: bool,
) -> Result<Encoded, FormatError> {
    let q = quantize16(hf, range, south_up)?;
    let bytes = q.bytes(u16::to_be_bytes);
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, hf.width() as u32, hf.height() as u32);
        enc.set_color(png::ColorType::Grayscale);
        enc.set_depth(png::BitDepth::Sixteen);
        // Fast (fdeflate) rather than the default zlib level: on one core
        // the default took 150 ms of a 0.52 s `synth --size 1024x1024 -o
        // x.png` (synthesis itself 0.36 s on two); Fast makes the whole
        // process 0.35 s for files 10 % larger, same samples.
        enc.set_compression(png::Compression::Fast);
        let mut w = enc
            .write_header()
            .map_err(|e| FormatError::Unwritable(e.to_string()))?;
        w.write_image_data(&bytes)
            .map_err(|e| FormatError::Unwritable(e.to_string()))?;
    }
    Ok(Encoded {
        bytes: out,
        sidecar: Some(q.sidecar),
    })
}

/// Decodes a PNG that must have one colour type and bit depth (the masks
/// and maps the project writes itself, read back): its raw samples as PNG
/// stores them (16-bit big-endian), `width × height × bytes per pixel`
/// bytes. Sizes are checked before the buffer is allocated; anything else
/// is refused as `what`, naming the `supported` layout.
pub(in crate::io) fn decode_raw(
    bytes: &[u8],
    (color, depth): (png::ColorType, png::BitDepth),
    what: &'static str,
    supported: &'static str,
) -> Result<(usize, usize, Vec<u8>), FormatError> {
    let mut decoder = png::Decoder::new(Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::IDENTITY);
    let mut reader = decoder
        .read_info()
        .map_err(|e| FormatError::Corrupt(format!("not a readable PNG: {e}")))?;
    let info = reader.info();
    let (w, h) = (info.width as usize, info.height as usize);
    if info.color_type != color || info.bit_depth != depth {
        return Err(FormatError::Unsupported {
            what,
            found: format!("{:?} {}-bit", info.color_type, info.bit_depth as u8),
            supported,
        });
    }
    check_dims(w, h)?;
    let pixel = color.samples() as u64 * depth as u64 / 8;
    check_justified(w, h, pixel, bytes.len(), DEFLATE_RATIO)?;
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| FormatError::Corrupt("PNG output size overflows".into()))?;
    let mut buf = vec![0u8; size];
    reader
        .next_frame(&mut buf)
        .map_err(|e| FormatError::Corrupt(format!("corrupt PNG data: {e}")))?;
    buf.truncate(w * h * pixel as usize);
    Ok((w, h, buf))
}

/// A PNG of raw samples laid out as [`decode_raw`] returns them.
pub(in crate::io) fn encode_raw(
    width: usize,
    height: usize,
    (color, depth): (png::ColorType, png::BitDepth),
    raw: &[u8],
) -> Vec<u8> {
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, width as u32, height as u32);
    enc.set_color(color);
    enc.set_depth(depth);
    enc.set_compression(png::Compression::Fast);
    let mut w = enc.write_header().expect("writing to a Vec cannot fail");
    w.write_image_data(raw)
        .expect("the buffer matches the header");
    drop(w);
    out
}

fn png_error(e: png::DecodingError) -> FormatError {
    match e {
        png::DecodingError::IoError(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => {
            FormatError::EndsEarly("PNG stream")
        }
        other => FormatError::Corrupt(format!("PNG: {other}")),
    }
}
