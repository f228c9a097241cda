//! Terragen terrain files (`.ter`, read/write).
//!
//! Layout (little-endian): `TERRAGEN` `TERRAIN ` then 4-byte-aligned chunks
//! without lengths: `SIZE` (u16 = shorter side − 1, 2 pad bytes), `XPTS` /
//! `YPTS` (u16 + 2 pad), `SCAL` (3 × f32 metres per terrain unit, default
//! 30), `CRAD` (f32), `CRVM` (u32), `ALTW` (i16 HeightScale, i16 BaseHeight,
//! then XPTS × YPTS i16 samples, rows **south to north**), `EOF `. A sample
//! `e` is `SCAL_z × (BaseHeight + e × HeightScale / 65536)` metres; the cell
//! size is `SCAL_x` (which must equal `SCAL_y`). Reading stops at `EOF ` or
//! at the end of the file (old writers omit `EOF `).
//!
//! Writing uses uniform scaling (`SCAL` = cell size on all axes, as
//! Terragen expects), centres BaseHeight on the data and picks the smallest
//! HeightScale that covers it, so the samples use nearly the whole i16
//! range: the step is about `(max − min + cell) / 65535` metres. Terragen
//! has no nodata, so writing refuses NaN.

use crate::heightfield::Heightfield;
use crate::io::{Encoded, Format, FormatError};
use crate::size::check_dims;

const MAGIC: &[u8; 16] = b"TERRAGENTERRAIN ";
const MARKERS: [&[u8; 4]; 8] = [
    b"SIZE", b"XPTS", b"YPTS", b"SCAL", b"CRAD", b"CRVM", b"ALTW", b"EOF ",
];

struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Cursor<'a> {
    fn take(&mut self, n: usize, what: &'static str) -> Result<&'a [u8], FormatError> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.bytes.len());
        let Some(end) = end else {
            return Err(FormatError::truncated(
                what,
                self.pos.saturating_add(n) as u64,
                self.bytes.len(),
            ));
        };
        let s = &self.bytes[self.pos..end];
        self.pos = end;
        Ok(s)
    }
    fn u16(&mut self, what: &'static str) -> Result<u16, FormatError> {
        let b = self.take(2, what)?;
        Ok(u16::from_le_bytes([b[0], b[1]]))
    }
    fn i16(&mut self, what: &'static str) -> Result<i16, FormatError> {
        Ok(self.u16(what)? as i16)
    }
    fn f32(&mut self, what: &'static str) -> Result<f32, FormatError> {
        let b = self.take(4, what)?;
        Ok(f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }
    fn at_marker(&self) -> bool {
        self.bytes
            .get(self.pos..self.pos + 4)
            .is_some_and(|m| MARKERS.iter().any(|k| &k[..] == m))
    }
}

pub(in crate::io) fn decode(bytes: &[u8]) -> Result<Heightfield, FormatError> {
    if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
        return Err(FormatError::bad_magic("\"TERRAGENTERRAIN \"", bytes));
    }
    let mut c = Cursor {
        bytes,
        pos: MAGIC.len(),
    };
    let (mut size, mut xpts, mut ypts) = (None, None, None);
    let mut scal = [30.0f32; 3];
    let mut heights = None;
    while c.pos < bytes.len() {
        let at = c.pos;
        let marker = c.take(4, "a Terragen chunk marker")?;
        match marker {
            b"SIZE" => {
                size = Some(c.u16("the SIZE chunk")? as usize + 1);
                c.take(2, "the SIZE chunk")?;
            }
            b"XPTS" => {
                xpts = Some(c.u16("the XPTS chunk")? as usize);
                c.take(2, "the XPTS chunk")?;
            }
            b"YPTS" => {
                ypts = Some(c.u16("the YPTS chunk")? as usize);
                c.take(2, "the YPTS chunk")?;
            }
            b"SCAL" => {
                for s in &mut scal {
                    *s = c.f32("the SCAL chunk")?;
                }
            }
            b"CRAD" | b"CRVM" => {
                c.take(4, "a CRAD or CRVM chunk")?;
            }
            b"ALTW" => {
                let side = size.ok_or_else(|| {
                    FormatError::Corrupt(format!(
                        "Terragen ALTW chunk at byte {at} comes before any SIZE chunk"
                    ))
                })?;
                let (w, h) = (xpts.unwrap_or(side), ypts.unwrap_or(side));
                check_dims(w, h)?;
                let scale = c.i16("the ALTW chunk")?;
                let base = c.i16("the ALTW chunk")?;
                // `take` checks the byte count before anything is allocated.
                let need = w * h * 2;
                let samples = c.take(need, "the ALTW samples")?;
                heights = Some((w, h, scale, base, samples));
                // Chunks are 4-byte aligned: an odd sample count leaves 2 pad bytes.
                if need % 4 != 0 && !c.at_marker() && c.pos + 2 <= bytes.len() {
                    c.pos += 2;
                }
            }
            b"EOF " => break,
            other => {
                return Err(FormatError::Corrupt(format!(
                    "unknown Terragen chunk {:?} at byte {at} (known: SIZE, XPTS, YPTS, SCAL, CRAD, CRVM, ALTW, EOF)",
                    String::from_utf8_lossy(other)
                )));
            }
        }
    }
    let (w, h, scale, base, samples) = heights
        .ok_or_else(|| FormatError::Corrupt("Terragen file has no ALTW (height) chunk".into()))?;
    let [sx, sy, sz] = scal;
    if !scal.iter().all(|s| s.is_finite() && *s > 0.0) {
        return Err(FormatError::Metadata(format!(
            "Terragen SCAL is {sx} x {sy} x {sz}: expected finite values > 0"
        )));
    }
    if sx != sy {
        return Err(FormatError::Unsupported {
            what: "Terragen cell shape",
            found: format!("SCAL {sx} x {sy} m"),
            supported: "square cells (SCAL x = y)",
        });
    }
    let (scale, base, sz) = (scale as f64, base as f64, sz as f64);
    let mut data = vec![0f32; w * h];
    for (y, row) in data.chunks_exact_mut(w).enumerate() {
        // Terragen rows run south to north; ours north to south.
        let src = &samples[(h - 1 - y) * w * 2..(h - y) * w * 2];
        for (v, s) in row.iter_mut().zip(src.chunks_exact(2)) {
            let e = i16::from_le_bytes([s[0], s[1]]) as f64;
            *v = (sz * (base + e * scale / 65536.0)) as f32;
        }
    }
    Ok(Heightfield::from_vec(w, h, sx as f64, data)?)
}

pub(in crate::io) fn encode(hf: &Heightfield) -> Result<Encoded, FormatError> {
    FormatError::check_no_nodata(hf, Format::Ter)?;
    let (w, h) = (hf.width(), hf.height());
    if w > u16::MAX as usize || h > u16::MAX as usize {
        return Err(FormatError::Unwritable(format!(
            "{w}x{h} exceeds Terragen's 16-bit sizes (at most 65535 per side)"
        )));
    }
    let cell = hf.cell_size();
    let stats = hf
        .stats()
        .ok_or_else(|| FormatError::Unwritable("no heights".into()))?;
    // Heights in terrain units (one unit = one cell). SCAL holds the cell
    // size as f32: quantize against the value readers will use.
    let unit = cell as f32 as f64;
    let (lo, hi) = (stats.min as f64 / unit, stats.max as f64 / unit);
    let base = ((lo + hi) / 2.0).round();
    let dev = (hi - base).max(base - lo);
    let scale = (dev * 65536.0 / 32767.0).ceil().max(1.0);
    if base.abs() > 32767.0 || scale > 32767.0 {
        return Err(FormatError::Unwritable(format!(
            "heights {} .. {} m do not fit Terragen's 16-bit base height and scale at a {cell} m cell size",
            stats.min, stats.max
        )));
    }
    let mut out = Vec::with_capacity(64 + w * h * 2);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(b"SIZE");
    out.extend_from_slice(&((w.min(h) - 1) as u16).to_le_bytes());
    out.extend_from_slice(&[0, 0]);
    for (marker, n) in [(b"XPTS", w), (b"YPTS", h)] {
        out.extend_from_slice(marker);
        out.extend_from_slice(&(n as u16).to_le_bytes());
        out.extend_from_slice(&[0, 0]);
    }
    out.extend_from_slice(b"SCAL");
    for _ in 0..3 {
        out.extend_from_slice(&(unit as f32).to_le_bytes());
    }
    out.extend_from_slice(b"ALTW");
    out.extend_from_slice(&(scale as i16).to_le_bytes());
    out.extend_from_slice(&(base as i16).to_le_bytes());
    for y in (0..h).rev() {
        for &v in hf.row(y) {
            let e = ((v as f64 / unit - base) * 65536.0 / scale).round();
            out.extend_from_slice(&(e.clamp(-32768.0, 32767.0) as i16).to_le_bytes());
        }
    }
    if out.len() % 4 != 0 {
        out.extend_from_slice(&[0, 0]);
    }
    out.extend_from_slice(b"EOF ");
    Ok(Encoded {
        bytes: out,
        sidecar: None,
    })
}
