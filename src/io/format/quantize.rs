//! Integer samples ↔ metres for the quantized formats (PNG16, PNG8, R16).
//!
//! Writing maps the data's own `[min, max]` (or a requested range) onto the
//! full 16-bit code range, so no precision is wasted; the sidecar records the
//! mapping. With nodata, code 0 is reserved for it and heights use
//! 1..=65535 — only for formats whose consumers read the sidecar (PNG16);
//! R16 refuses nodata before calling this.

use super::sidecar::{DEFAULT_CELL_SIZE_M, HeightMapping, Sidecar};
use crate::heightfield::Heightfield;
use crate::io::FormatError;
use rayon::prelude::*;

/// Codes in row-major order plus the sidecar that gives them metres.
pub(super) struct Quantized {
    pub codes: Vec<u16>,
    pub sidecar: Vec<u8>,
}

impl Quantized {
    /// The codes as bytes, each by `order` (`u16::to_be_bytes` for PNG,
    /// `to_le_bytes` for R16), converted in parallel like the codes.
    pub fn bytes(&self, order: fn(u16) -> [u8; 2]) -> Vec<u8> {
        let mut bytes = vec![0u8; self.codes.len() * 2];
        bytes
            .par_chunks_mut(1 << 16)
            .zip(self.codes.par_chunks(1 << 15))
            .for_each(|(out, codes)| {
                for (o, &c) in out.chunks_exact_mut(2).zip(codes) {
                    o.copy_from_slice(&order(c));
                }
            });
        bytes
    }
}

pub(super) fn quantize16(
    hf: &Heightfield,
    range: Option<(f64, f64)>,
    south_up: bool,
) -> Result<Quantized, FormatError> {
    let extent = hf.extent();
    let has_nodata = extent.nodata > 0;
    let (min, max) = match (range, extent.range) {
        (Some(r), _) => r,
        (None, Some((lo, hi))) => (lo as f64, hi as f64),
        (None, None) => (0.0, 0.0),
    };
    if !(min.is_finite() && max.is_finite() && min <= max) {
        return Err(FormatError::Unwritable(format!(
            "height range {min}..{max} is invalid: expected finite min <= max"
        )));
    }
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
    let code = |v: f32| {
        let code = if v.is_nan() {
            0
        } else if m.scale_m > 0.0 {
            let c = ((v as f64 - m.offset_m) / m.scale_m).round();
            lo + c.clamp(0.0, max_code as f64) as u32
        } else {
            lo
        };
        code as u16
    };
    // Row by row in parallel (each code depends on its sample only): on
    // one core this was most of the time a `synth` process spent after
    // its synthesis.
    let (w, h) = (hf.width(), hf.height());
    let mut codes = vec![0u16; w * h];
    codes.par_chunks_mut(w).enumerate().for_each(|(y, out)| {
        let src = hf.row(if south_up { h - 1 - y } else { y });
        for (c, &v) in out.iter_mut().zip(src) {
            *c = code(v);
        }
    });
    let sidecar = Sidecar {
        mapping,
        cell_size_m: Some(hf.cell_size()),
        width: Some(hf.width()),
        height: Some(hf.height()),
        nodata_value: has_nodata.then_some(0.0),
        georef: hf.georef().cloned(),
        south_up,
    };
    Ok(Quantized {
        codes,
        sidecar: sidecar.to_json(min, max),
    })
}

/// Builds a heightfield from integer codes of `bits` bits, using the
/// sidecar's mapping, nodata code and cell size, or the documented defaults.
pub(super) fn dequantize(
    width: usize,
    height: usize,
    codes: impl Iterator<Item = u16>,
    bits: u8,
    sidecar: Option<&Sidecar>,
) -> Result<Heightfield, FormatError> {
    let mapping = sidecar
        .map(|s| s.mapping)
        .unwrap_or_else(|| HeightMapping::default_for_bits(bits));
    let nodata = sidecar.and_then(|s| s.nodata_value);
    let cell = sidecar
        .and_then(|s| s.cell_size_m)
        .unwrap_or(DEFAULT_CELL_SIZE_M);
    let mut data: Vec<f32> = codes
        .take(width * height)
        .map(|v| {
            if nodata == Some(v as f64) {
                f32::NAN
            } else {
                mapping.to_metres(v as f64) as f32
            }
        })
        .collect();
    if sidecar.is_some_and(|s| s.south_up) && data.len() == width * height {
        // Rows stored south to north (Unity's order): back to north-up.
        let flipped: Vec<f32> = data.chunks_exact(width).rev().flatten().copied().collect();
        data = flipped;
    }
    Ok(Heightfield::from_vec(width, height, cell, data)?)
}
