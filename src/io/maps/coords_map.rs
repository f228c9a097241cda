//! Source-coordinate maps: for every synthesized pixel, the exemplar texel
//! it was drawn from (`synth --coords`, read back by `eval --coords`).
//!
//! On disk: a **16-bit RGB PNG** of the output's size, channels big-endian
//! as PNG stores them: **R = x** and **G = y** of the source texel within its
//! exemplar (level-0 texels; 0 = the exemplar's west / north edge), **B = the
//! exemplar's index** in the database (`db info` order), [`NO_EXEMPLAR`] =
//! none. Sixteen bits hold any exemplar a database accepts (its atlas is
//! < 65536 texels across), so the map is exact; a person reads the
//! 8-bit picture `synth --coords-preview` writes instead.

use crate::io::{FormatError, IoError, write_atomic};
use std::path::Path;

/// The PNG's colour type and depth.
const LAYOUT: (png::ColorType, png::BitDepth) = (png::ColorType::Rgb, png::BitDepth::Sixteen);

/// Exemplar index meaning "drawn from no exemplar".
pub const NO_EXEMPLAR: u16 = u16::MAX;

/// Where one output pixel came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Source {
    pub x: u16,
    pub y: u16,
    pub exemplar: u16,
}

/// A source per output pixel, row-major.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CoordsMap {
    pub width: usize,
    pub height: usize,
    pub sources: Vec<Source>,
}

impl CoordsMap {
    pub fn new(width: usize, height: usize, sources: Vec<Source>) -> Result<Self, FormatError> {
        FormatError::check_table(width, height, sources.len(), "sources", "map")?;
        Ok(CoordsMap {
            width,
            height,
            sources,
        })
    }

    /// The PNG bytes (see the module docs).
    pub fn encode_png(&self) -> Vec<u8> {
        let mut raw = Vec::with_capacity(self.sources.len() * 6);
        for s in &self.sources {
            for v in [s.x, s.y, s.exemplar] {
                raw.extend_from_slice(&v.to_be_bytes());
            }
        }
        crate::io::format::png::encode_raw(self.width, self.height, LAYOUT, &raw)
    }

    /// Decodes a map; anything but a 16-bit RGB PNG is refused.
    pub fn decode(bytes: &[u8]) -> Result<CoordsMap, FormatError> {
        let (w, h, buf) = crate::io::format::png::decode_raw(
            bytes,
            LAYOUT,
            "coordinates map PNG",
            "16-bit RGB (R = x, G = y, B = exemplar), as `synth --coords` writes",
        )?;
        let word = |c: &[u8], k: usize| u16::from_be_bytes([c[2 * k], c[2 * k + 1]]);
        let sources = buf
            .chunks_exact(6)
            .take(w * h)
            .map(|c| Source {
                x: word(c, 0),
                y: word(c, 1),
                exemplar: word(c, 2),
            })
            .collect();
        CoordsMap::new(w, h, sources)
    }

    pub fn read(path: &Path) -> Result<CoordsMap, IoError> {
        let bytes = std::fs::read(path).map_err(|e| IoError::os(path, e))?;
        CoordsMap::decode(&bytes).map_err(|kind| IoError::Format {
            path: path.to_path_buf(),
            kind,
        })
    }

    /// Writes the PNG atomically.
    pub fn write(&self, path: &Path) -> Result<(), IoError> {
        write_atomic(path, &self.encode_png())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_every_bit_and_refuses_other_pngs() {
        let sources = (0..12u16)
            .map(|i| Source {
                x: i.wrapping_mul(40_961),
                y: 65_535 - i * 3,
                exemplar: if i == 5 { NO_EXEMPLAR } else { i % 3 },
            })
            .collect();
        let m = CoordsMap::new(4, 3, sources).unwrap();
        assert_eq!(CoordsMap::decode(&m.encode_png()).unwrap(), m);
        let grey = crate::io::TypeMask::new(2, 2, vec![0; 4])
            .unwrap()
            .encode_png();
        assert!(matches!(
            CoordsMap::decode(&grey),
            Err(FormatError::Unsupported { .. })
        ));
        assert!(CoordsMap::decode(b"junk").is_err());
        assert!(CoordsMap::new(2, 2, vec![Source::default(); 3]).is_err());
    }
}
