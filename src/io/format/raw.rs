//! Headerless raw heightfields: R16 (little-endian u16, the Unity / Unreal
//! convention) and R32 (little-endian f32 metres), rows north to south.
//!
//! Dimensions come from, in order: [`crate::io::ReadOptions::size`], the JSON
//! sidecar's `width` and `height`, or — when the sample count is a perfect
//! square, as engine heightmaps usually are — the square root. Anything else
//! is a dimension mismatch, never a guess.
//!
//! R16 samples get metres from the sidecar mapping, or the 16-bit default
//! (decimetres) without one; writing spreads the data's range over
//! 0..=65535 and records the mapping in the sidecar, like PNG16. R16 cannot
//! store nodata (engines read every code as a height), so writing refuses
//! NaN. R32 stores metres directly, NaN included (as is a sidecar
//! `nodata_value`); its sidecar carries the size and cell size with an
//! identity mapping.

use super::quantize::{dequantize, quantize16};
use super::sidecar::{DEFAULT_CELL_SIZE_M, HeightMapping, Sidecar};
use crate::heightfield::Heightfield;
use crate::io::{Encoded, Format, FormatError};
use crate::size::check_dims;

/// Decodes an R16 or R32 file (`format`): its grid size from `size`, the
/// sidecar or a square sample count (see the module docs), then its samples
/// as the format stores them.
pub(in crate::io) fn decode(
    format: Format,
    bytes: &[u8],
    sidecar: Option<&Sidecar>,
    size: Option<(usize, usize)>,
) -> Result<Heightfield, FormatError> {
    let r16 = format == Format::R16;
    let (sample_bytes, name) = if r16 { (2, "R16") } else { (4, "R32") };
    let (w, h) = dimensions(bytes.len(), sample_bytes, name, sidecar, size)?;
    if r16 {
        let codes = bytes
            .chunks_exact(2)
            .map(|c| u16::from_le_bytes([c[0], c[1]]));
        dequantize(w, h, codes, 16, sidecar)
    } else {
        metres32(w, h, bytes, sidecar)
    }
}

/// R32 samples: metres, through the sidecar's mapping when it has one.
fn metres32(
    w: usize,
    h: usize,
    bytes: &[u8],
    sidecar: Option<&Sidecar>,
) -> Result<Heightfield, FormatError> {
    let mapping = sidecar.map_or(
        HeightMapping {
            offset_m: 0.0,
            scale_m: 1.0,
        },
        |s| s.mapping,
    );
    let identity = mapping.offset_m == 0.0 && mapping.scale_m == 1.0;
    let nodata = sidecar.and_then(|s| s.nodata_value).map(|n| n as f32);
    let data = bytes
        .chunks_exact(4)
        .map(|c| {
            let v = f32::from_le_bytes([c[0], c[1], c[2], c[3]]);
            if v.is_nan() || Some(v) == nodata {
                f32::NAN
            } else if identity {
                v
            } else {
                mapping.to_metres(v as f64) as f32
            }
        })
        .collect();
    let cell = sidecar
        .and_then(|s| s.cell_size_m)
        .unwrap_or(DEFAULT_CELL_SIZE_M);
    Ok(Heightfield::from_vec(w, h, cell, data)?)
}

/// The grid size of a raw file of `len` bytes, checked against the byte count.
fn dimensions(
    len: usize,
    bytes_per_sample: usize,
    name: &str,
    sidecar: Option<&Sidecar>,
    size: Option<(usize, usize)>,
) -> Result<(usize, usize), FormatError> {
    let from_sidecar = sidecar.and_then(|s| s.width.zip(s.height));
    let (w, h, source) = match (size, from_sidecar) {
        (Some((w, h)), _) => (w, h, "the given size"),
        (None, Some((w, h))) => (w, h, "the sidecar"),
        (None, None) => {
            if len == 0 || len % bytes_per_sample != 0 {
                return Err(FormatError::DimensionMismatch(format!(
                    "{len} bytes is not a whole number of {bytes_per_sample}-byte {name} samples"
                )));
            }
            let n = len / bytes_per_sample;
            let side = n.isqrt();
            if side * side != n {
                return Err(FormatError::DimensionMismatch(format!(
                    "{n} {name} samples do not form a square; give the size (--in-size WxH) or a sidecar with width and height"
                )));
            }
            (side, side, "the square sample count")
        }
    };
    check_dims(w, h)?;
    if let Some(s) = sidecar {
        s.check_size(w, h)?;
    }
    let need = w * h * bytes_per_sample;
    if need != len {
        return Err(FormatError::DimensionMismatch(format!(
            "{w}x{h} from {source} needs {need} bytes of {name} ({bytes_per_sample} per sample), the file has {len}"
        )));
    }
    Ok((w, h))
}

pub(in crate::io) fn encode16(
    hf: &Heightfield,
    range: Option<(f64, f64)>,
    south_up: bool,
) -> Result<Encoded, FormatError> {
    FormatError::check_no_nodata(hf, Format::R16)?;
    let q = quantize16(hf, range, south_up)?;
    Ok(Encoded {
        bytes: q.bytes(u16::to_le_bytes),
        sidecar: Some(q.sidecar),
    })
}

pub(in crate::io) fn encode32(hf: &Heightfield) -> Result<Encoded, FormatError> {
    let sidecar = Sidecar {
        mapping: HeightMapping {
            offset_m: 0.0,
            scale_m: 1.0,
        },
        cell_size_m: Some(hf.cell_size()),
        width: Some(hf.width()),
        height: Some(hf.height()),
        nodata_value: None,
        georef: hf.georef().cloned(),
        south_up: false,
    };
    let (min, max) = hf
        .extent()
        .range
        .map_or((0.0, 0.0), |(lo, hi)| (lo as f64, hi as f64));
    Ok(Encoded {
        bytes: hf.data().iter().flat_map(|v| v.to_le_bytes()).collect(),
        sidecar: Some(sidecar.to_json(min, max)),
    })
}
