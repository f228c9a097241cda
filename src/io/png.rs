//! Greyscale PNG heightmaps: 16-bit (read/write) and 8-bit (read), with the
//! JSON sidecar giving metres ([`super::sidecar`]).
//!
//! Writing maps the data's own `[min, max]` onto the full code range (or a
//! requested range), like the shared DEMs. Nodata survives the round trip:
//! when present it gets code 0, recorded as `nodata_value` in the sidecar,
//! and valid heights use codes 1..=65535.

use super::sidecar::{DEFAULT_CELL_SIZE_M, HeightMapping, Sidecar};
use super::{Encoded, FormatError};
use crate::heightfield::{Heightfield, check_dims};
use std::io::Cursor;

/// Upper bound of deflate's compression ratio (RFC 1951: a 258-byte match
/// per ~2 bits); a file shorter than size/1032 cannot hold the image.
const MAX_DEFLATE_RATIO: u64 = 1032;

/// The bit depth of a greyscale PNG, to choose between 8- and 16-bit decoding.
pub(super) fn sniff_depth(bytes: &[u8]) -> Option<super::Format> {
    // IHDR is always first: signature (8) + length (4) + "IHDR" (4) + w, h (8) + depth (1).
    let depth = *bytes.get(24)?;
    (bytes.get(12..16)? == b"IHDR").then_some(if depth == 16 {
        super::Format::Png16
    } else {
        super::Format::Png8
    })
}

pub(super) fn decode(bytes: &[u8], sidecar: Option<&Sidecar>) -> Result<Heightfield, FormatError> {
    const SIG: &[u8] = b"\x89PNG\r\n\x1a\n";
    if bytes.len() < SIG.len() || &bytes[..SIG.len()] != SIG {
        return Err(FormatError::BadMagic {
            expected: "PNG signature 89 50 4E 47 0D 0A 1A 0A",
            found: hex_prefix(bytes),
        });
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
    let raw = (w as u64) * (h as u64) * (bits as u64 / 8);
    if raw > bytes.len() as u64 * MAX_DEFLATE_RATIO + 4096 {
        return Err(FormatError::SizeNotJustified {
            width: w as u64,
            height: h as u64,
            file_len: bytes.len() as u64,
        });
    }
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

    let mapping = sidecar
        .map(|s| s.mapping)
        .unwrap_or_else(|| HeightMapping::default_for_bits(bits));
    let nodata = sidecar.and_then(|s| s.nodata_value);
    let cell = sidecar
        .and_then(|s| s.cell_size_m)
        .unwrap_or(DEFAULT_CELL_SIZE_M);
    let to_m = |v: u16| -> f32 {
        if nodata == Some(v as f64) {
            f32::NAN
        } else {
            mapping.to_metres(v as f64) as f32
        }
    };
    let data: Vec<f32> = if bits == 16 {
        buf.chunks_exact(2)
            .take(w * h)
            .map(|c| to_m(u16::from_be_bytes([c[0], c[1]])))
            .collect()
    } else {
        buf.iter().take(w * h).map(|&v| to_m(v as u16)).collect()
    };
    Ok(Heightfield::from_vec(w, h, cell, data)?)
}

pub(super) fn encode16(
    hf: &Heightfield,
    range: Option<(f64, f64)>,
) -> Result<Encoded, FormatError> {
    let has_nodata = hf.nodata_count() > 0;
    let (min, max) = match (range, hf.stats()) {
        (Some(r), _) => r,
        (None, Some(s)) => (s.min as f64, s.max as f64),
        (None, None) => (0.0, 0.0),
    };
    if !(min.is_finite() && max.is_finite() && min <= max) {
        return Err(FormatError::Unwritable(format!(
            "height range {min}..{max} is invalid: expected finite min <= max"
        )));
    }
    // With nodata, code 0 is reserved for it and heights use 1..=65535.
    let (lo, max_code) = if has_nodata {
        (1u32, 65534u32)
    } else {
        (0, 65535)
    };
    let m = HeightMapping::spanning(min, max, max_code);
    let mapping = HeightMapping {
        offset_m: m.offset_m - lo as f64 * m.scale_m,
        scale_m: m.scale_m,
    };
    let mut bytes = Vec::with_capacity(hf.len() * 2);
    for &v in hf.data() {
        let code = if v.is_nan() {
            0
        } else if m.scale_m > 0.0 {
            let c = ((v as f64 - m.offset_m) / m.scale_m).round();
            lo + c.clamp(0.0, max_code as f64) as u32
        } else {
            lo
        };
        bytes.extend_from_slice(&(code as u16).to_be_bytes());
    }
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, hf.width() as u32, hf.height() as u32);
        enc.set_color(png::ColorType::Grayscale);
        enc.set_depth(png::BitDepth::Sixteen);
        let mut w = enc
            .write_header()
            .map_err(|e| FormatError::Unwritable(e.to_string()))?;
        w.write_image_data(&bytes)
            .map_err(|e| FormatError::Unwritable(e.to_string()))?;
    }
    let sidecar = Sidecar {
        mapping,
        cell_size_m: Some(hf.cell_size()),
        width: Some(hf.width()),
        height: Some(hf.height()),
        nodata_value: has_nodata.then_some(0.0),
    };
    Ok(Encoded {
        bytes: out,
        sidecar: Some(sidecar.to_json(min, max)),
    })
}

fn png_error(e: png::DecodingError) -> FormatError {
    match e {
        png::DecodingError::IoError(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => {
            FormatError::EndsEarly("PNG stream")
        }
        other => FormatError::Corrupt(format!("PNG: {other}")),
    }
}

fn hex_prefix(bytes: &[u8]) -> String {
    let s: Vec<String> = bytes.iter().take(8).map(|b| format!("{b:02X}")).collect();
    if s.is_empty() {
        "an empty file".into()
    } else {
        s.join(" ")
    }
}
