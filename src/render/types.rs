//! Terrain-type masks (one 8-bit type index per cell, as painted on
//! exemplars, seed 003 §5.2) and the colours the preview shows them in.
//!
//! On disk a mask is an 8-bit greyscale PNG of the heightfield's size, with
//! optional names in a JSON file beside it (`<stem>.json`,
//! `{"types": {"0": "sea", "1": "flat", …}}`), like the shared DEMs' masks.

use super::RenderError;
use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::Path;

/// Index meaning "no type": such cells are not coloured.
pub const NO_TYPE: u8 = 255;
/// Default opacity of type colours over the terrain tint.
pub const DEFAULT_OPACITY: u8 = 150;

/// A type index per cell, row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct TypeMask {
    width: usize,
    height: usize,
    indices: Vec<u8>,
    names: BTreeMap<u8, String>,
}

impl TypeMask {
    pub fn new(width: usize, height: usize, indices: Vec<u8>) -> Result<TypeMask, RenderError> {
        crate::heightfield::check_dims(width, height)?;
        if indices.len() != width * height {
            return Err(RenderError::Option {
                option: "types",
                value: format!("{} indices", indices.len()),
                allowed: format!("exactly {} for a {width}x{height} mask", width * height),
            });
        }
        Ok(TypeMask {
            width,
            height,
            indices,
            names: BTreeMap::new(),
        })
    }

    /// Names types, for legends.
    pub fn with_names(mut self, names: BTreeMap<u8, String>) -> TypeMask {
        self.names = names;
        self
    }

    pub fn width(&self) -> usize {
        self.width
    }
    pub fn height(&self) -> usize {
        self.height
    }
    pub fn indices(&self) -> &[u8] {
        &self.indices
    }
    pub fn names(&self) -> &BTreeMap<u8, String> {
        &self.names
    }
    /// The distinct indices present (excluding [`NO_TYPE`]), ascending.
    pub fn present(&self) -> Vec<u8> {
        let mut seen = [false; 256];
        for &i in &self.indices {
            seen[i as usize] = true;
        }
        (0..255u8).filter(|&i| seen[i as usize]).collect()
    }

    /// Reads an 8-bit greyscale PNG mask, and `<stem>.json` names if present.
    pub fn read_png(path: &Path) -> Result<TypeMask, RenderError> {
        let fail = |message: String| RenderError::TypesFile {
            path: path.to_path_buf(),
            message,
        };
        let bytes = std::fs::read(path).map_err(|e| fail(e.to_string()))?;
        let mut mask = decode_png(&bytes).map_err(fail)?;
        let names_path = path.with_extension("json");
        match std::fs::read(&names_path) {
            Ok(json) => {
                mask.names = parse_names(&json).map_err(|message| RenderError::TypesFile {
                    path: names_path,
                    message,
                })?
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => {
                return Err(RenderError::TypesFile {
                    path: names_path,
                    message: e.to_string(),
                });
            }
        }
        Ok(mask)
    }
}

/// Decodes an 8-bit single-channel PNG into a mask (no names).
pub fn decode_png(bytes: &[u8]) -> Result<TypeMask, String> {
    let mut decoder = png::Decoder::new(Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::IDENTITY);
    let mut reader = decoder
        .read_info()
        .map_err(|e| format!("not a readable PNG: {e}"))?;
    let info = reader.info();
    let (w, h) = (info.width as usize, info.height as usize);
    if info.color_type != png::ColorType::Grayscale || info.bit_depth != png::BitDepth::Eight {
        return Err(format!(
            "unsupported PNG {:?} {}-bit: a type mask is 8-bit greyscale (one index per pixel)",
            info.color_type, info.bit_depth as u8
        ));
    }
    crate::heightfield::check_dims(w, h).map_err(|e| e.to_string())?;
    // Deflate cannot compress better than ~1032:1; refuse sizes the file cannot hold.
    if (w as u64) * (h as u64) > bytes.len() as u64 * 1032 + 4096 {
        return Err(format!(
            "declared size {w}x{h} needs more data than a {}-byte file can hold",
            bytes.len()
        ));
    }
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| "PNG output size overflows".to_string())?;
    let mut buf = vec![0u8; size];
    reader
        .next_frame(&mut buf)
        .map_err(|e| format!("corrupt PNG data: {e}"))?;
    buf.truncate(w * h);
    TypeMask::new(w, h, buf).map_err(|e| e.to_string())
}

/// Parses `{"types": {"<index>": "<name>", …}}`.
fn parse_names(json: &[u8]) -> Result<BTreeMap<u8, String>, String> {
    #[derive(serde::Deserialize)]
    struct Names {
        types: BTreeMap<String, String>,
    }
    let n: Names = serde_json::from_slice(json).map_err(|e| format!("invalid type names: {e}"))?;
    n.types
        .into_iter()
        .map(|(k, v)| {
            k.parse::<u8>()
                .ok()
                .filter(|&i| i != NO_TYPE)
                .map(|i| (i, v))
                .ok_or_else(|| format!("type index {k:?} is invalid: expected 0..=254"))
        })
        .collect()
}

/// Distinct colours for type indices (Tableau-10 order, without red, which
/// means "out of range"); indices beyond the list reuse it.
pub const TYPE_COLOURS: [[u8; 3]; 9] = [
    [78, 121, 167],  // blue
    [242, 142, 43],  // orange
    [89, 161, 79],   // green
    [176, 122, 161], // purple
    [237, 201, 72],  // yellow
    [118, 183, 178], // teal
    [156, 117, 95],  // brown
    [255, 157, 167], // pink
    [186, 176, 172], // grey
];

/// The colour of type `index` (sRGB).
pub fn type_colour(index: u8) -> [u8; 3] {
    TYPE_COLOURS[index as usize % TYPE_COLOURS.len()]
}

/// A type mask and how to show it.
#[derive(Debug, Clone, PartialEq)]
pub struct TypeOverlay {
    pub mask: TypeMask,
    /// Colour and opacity per index; [`NO_TYPE`] is never drawn.
    pub colours: Box<[[u8; 4]; 256]>,
}

impl TypeOverlay {
    /// The mask in the default colours at [`DEFAULT_OPACITY`].
    pub fn new(mask: TypeMask) -> TypeOverlay {
        let colours = Box::new(std::array::from_fn(|i| {
            let [r, g, b] = type_colour(i as u8);
            [
                r,
                g,
                b,
                if i == NO_TYPE as usize {
                    0
                } else {
                    DEFAULT_OPACITY
                },
            ]
        }));
        TypeOverlay { mask, colours }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_and_refuse_bad_indices() {
        let n = parse_names(br#"{"types": {"0": "sea", "3": "mountains"}, "x": 1}"#).unwrap();
        assert_eq!(n[&3], "mountains");
        assert!(parse_names(br#"{"types": {"255": "none"}}"#).is_err());
        assert!(parse_names(br#"{"types": {"a": "b"}}"#).is_err());
        assert!(parse_names(b"[]").is_err());
    }

    #[test]
    fn present_lists_indices() {
        let m = TypeMask::new(2, 2, vec![3, 255, 0, 3]).unwrap();
        assert_eq!(m.present(), vec![0, 3]);
        assert!(TypeMask::new(2, 2, vec![0; 3]).is_err());
    }
}
