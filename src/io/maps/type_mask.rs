//! Terrain-type masks: one 8-bit type index per cell (paper §5.2: types are
//! painted on exemplars and on the synthesized terrain).
//!
//! On disk: an 8-bit greyscale PNG of the heightfield's size, and names in a
//! JSON beside it (`<stem>.json`) in the layout of `../shared/dem/*_types.json`:
//! `{"types": {"0": "sea", "1": "flat", …}, …}` (other keys are ignored on
//! read). Index 255 means "no type". This is the one reader of the format,
//! and the writer of every mask but a classification of a terrain by its own
//! heights ([`crate::procedural::types::TypeClassification`], a fixed set of
//! typed classes, which writes the same layout itself).

use crate::io::{FormatError, IoError, write_atomic};
use std::collections::BTreeMap;
use std::path::Path;

/// The PNG's colour type and depth.
const LAYOUT: (png::ColorType, png::BitDepth) = (png::ColorType::Grayscale, png::BitDepth::Eight);

/// Index meaning "no type".
pub const NO_TYPE: u8 = 255;

/// A type index per cell, row-major, and the names of the indices.
#[derive(Debug, Clone, PartialEq)]
pub struct TypeMask {
    pub width: usize,
    pub height: usize,
    pub indices: Vec<u8>,
    /// Index → name; indices without a name are called `type<index>`.
    pub names: BTreeMap<u8, String>,
}

impl TypeMask {
    pub fn new(width: usize, height: usize, indices: Vec<u8>) -> Result<TypeMask, FormatError> {
        FormatError::check_table(width, height, indices.len(), "type indices", "mask")?;
        Ok(TypeMask {
            width,
            height,
            indices,
            names: BTreeMap::new(),
        })
    }

    /// An owned copy of a window (names kept), e.g. the mask of a cropped
    /// exemplar; the window must lie inside the mask.
    pub fn crop(
        &self,
        x: usize,
        y: usize,
        w: usize,
        h: usize,
    ) -> Result<TypeMask, crate::size::SizeError> {
        crate::size::check_window(x, y, w, h, self.width, self.height)?;
        let indices = (y..y + h)
            .flat_map(|r| &self.indices[r * self.width + x..][..w])
            .copied()
            .collect();
        Ok(TypeMask {
            width: w,
            height: h,
            indices,
            names: self.names.clone(),
        })
    }

    /// The name of an index.
    pub fn name_of(&self, index: u8) -> String {
        self.names
            .get(&index)
            .cloned()
            .unwrap_or_else(|| format!("type{index}"))
    }

    /// The distinct indices present (excluding [`NO_TYPE`]), ascending.
    pub fn present(&self) -> Vec<u8> {
        let mut seen = [false; 256];
        for &i in &self.indices {
            seen[i as usize] = true;
        }
        (0..NO_TYPE).filter(|&i| seen[i as usize]).collect()
    }

    /// Decodes the PNG and, if given, the names JSON.
    pub fn decode(png_bytes: &[u8], names_json: Option<&[u8]>) -> Result<TypeMask, FormatError> {
        let (w, h, buf) = crate::io::format::png::decode_raw(
            png_bytes,
            LAYOUT,
            "type mask PNG",
            "8-bit greyscale, one type index per pixel",
        )?;
        let mut mask = TypeMask::new(w, h, buf)?;
        if let Some(json) = names_json {
            mask.names = parse_names(json)?;
        }
        Ok(mask)
    }

    /// Reads `path` and `<stem>.json` beside it when present.
    pub fn read(path: &Path) -> Result<TypeMask, IoError> {
        let bytes = std::fs::read(path).map_err(|e| IoError::os(path, e))?;
        let names_path = path.with_extension("json");
        let names = match std::fs::read(&names_path) {
            Ok(b) => Some(b),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
            Err(e) => return Err(IoError::os(&names_path, e)),
        };
        TypeMask::decode(&bytes, None)
            .map_err(|kind| IoError::Format {
                path: path.to_path_buf(),
                kind,
            })
            .and_then(|mut m| {
                if let Some(json) = names {
                    m.names = parse_names(&json).map_err(|kind| IoError::Format {
                        path: names_path.clone(),
                        kind,
                    })?;
                }
                Ok(m)
            })
    }

    /// The PNG bytes (8-bit greyscale).
    pub fn encode_png(&self) -> Vec<u8> {
        crate::io::format::png::encode_raw(self.width, self.height, LAYOUT, &self.indices)
    }

    /// The names JSON in the shared layout: `dem`, `types`, `present`,
    /// `fractions`, `method`.
    pub fn encode_json(&self, dem_file: &str, method: &str) -> Vec<u8> {
        let mut counts = [0u64; 256];
        for &i in &self.indices {
            counts[i as usize] += 1;
        }
        let total = self.indices.len() as f64;
        let present = self.present();
        let mut types = serde_json::Map::new();
        for (i, n) in &self.names {
            types.insert(i.to_string(), n.clone().into());
        }
        let mut pres = serde_json::Map::new();
        let mut fractions = serde_json::Map::new();
        for &i in &present {
            pres.insert(i.to_string(), self.name_of(i).into());
            let f = (counts[i as usize] as f64 / total * 1000.0).round() / 1000.0;
            fractions.insert(self.name_of(i), f.into());
        }
        let v = serde_json::json!({
            "dem": dem_file,
            "types": types,
            "present": pres,
            "fractions": fractions,
            "method": method,
        });
        let mut s = serde_json::to_vec_pretty(&v).expect("JSON values always serialize");
        s.push(b'\n');
        s
    }

    /// Writes the PNG and its names JSON (`<stem>.json`), atomically.
    pub fn write(&self, path: &Path, dem_file: &str, method: &str) -> Result<(), IoError> {
        write_atomic(
            &path.with_extension("json"),
            &self.encode_json(dem_file, method),
        )?;
        write_atomic(path, &self.encode_png())
    }
}

/// Parses `{"types": {"<index>": "<name>", …}}`; a file without `types` names nothing.
fn parse_names(json: &[u8]) -> Result<BTreeMap<u8, String>, FormatError> {
    let bad = |m: String| FormatError::Metadata(format!("type names: {m}"));
    let v: serde_json::Value =
        serde_json::from_slice(json).map_err(|e| bad(format!("not JSON: {e}")))?;
    let Some(types) = v.get("types") else {
        return Ok(BTreeMap::new());
    };
    let obj = types
        .as_object()
        .ok_or_else(|| bad("\"types\" must map indices to names".into()))?;
    let mut out = BTreeMap::new();
    for (k, name) in obj {
        let idx = k
            .parse::<u8>()
            .ok()
            .filter(|&i| i != NO_TYPE)
            .ok_or_else(|| bad(format!("index {k:?} is invalid: expected 0..=254")))?;
        let name = name
            .as_str()
            .ok_or_else(|| bad(format!("types.{k} must be a string")))?;
        out.insert(idx, name.to_string());
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crop_copies_the_window_and_refuses_one_outside() {
        let mut m = TypeMask::new(4, 3, (0..12).collect()).unwrap();
        m.names = [(5, "hills".into())].into();
        let c = m.crop(1, 1, 2, 2).unwrap();
        assert_eq!(
            (c.width, c.height, c.indices.clone()),
            (2, 2, vec![5, 6, 9, 10])
        );
        assert_eq!(c.name_of(5), "hills");
        assert!(m.crop(3, 0, 2, 1).is_err());
        assert!(m.crop(0, 0, 0, 1).is_err());
    }

    #[test]
    fn round_trips_and_reads_shared_masks() {
        let mut m = TypeMask::new(3, 2, vec![0, 1, 1, 2, 255, 0]).unwrap();
        m.names = [(0, "sea".into()), (1, "hills".into())].into();
        let json = m.encode_json("x.png", "test");
        let back = TypeMask::decode(&m.encode_png(), Some(&json)).unwrap();
        assert_eq!(back, m);
        assert_eq!(back.present(), vec![0, 1, 2]);
        let other = br#"{"types": {"0": "sea", "3": "mountains"}, "x": 1}"#;
        assert_eq!(
            TypeMask::decode(&m.encode_png(), Some(other))
                .unwrap()
                .name_of(3),
            "mountains"
        );
        assert_eq!(back.name_of(2), "type2");
        if let Some(p) = crate::shared_dem("riviera_coast_types.png") {
            let s = TypeMask::read(&p).unwrap();
            assert_eq!(
                (s.width, s.height, s.name_of(0).as_str()),
                (600, 600, "sea")
            );
        }
    }

    #[test]
    fn bad_masks_are_refused() {
        assert!(TypeMask::decode(b"not a png", None).is_err());
        assert!(matches!(
            TypeMask::new(2, 2, vec![0; 3]),
            Err(FormatError::DimensionMismatch(_))
        ));
        let m = TypeMask::new(1, 1, vec![0]).unwrap().encode_png();
        for json in [
            &br#"{"types": []}"#[..],
            br#"{"types": {"x": "a"}}"#,
            br#"{"types": {"255": "a"}}"#,
            b"{",
        ] {
            assert!(TypeMask::decode(&m, Some(json)).is_err());
        }
    }
}
