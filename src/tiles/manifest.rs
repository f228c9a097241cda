//! `manifest.json` of a tile directory: what world the tiles are cut from
//! (size, cell size, how it was made: database, seed, parameters, scene),
//! the grid, and one record per finished tile with its CRC-32 — so that a
//! resumed run knows which tiles it can keep, and anyone can check them.

use super::TilesError;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Version of the manifest layout.
pub const VERSION: u32 = 1;

/// The manifest's file name in a tile directory.
pub const FILE: &str = "manifest.json";

/// Everything that decides the tiles' contents: a resumed run keeps the
/// tiles of a directory only when this is equal.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Identity {
    /// Output pixels.
    pub world: [usize; 2],
    pub cell_size_m: f64,
    /// How the world was made (database and its CRC-32, seed, synthesis
    /// parameters, scene), as the caller describes it.
    pub source: serde_json::Value,
    /// `tiff`, `exr`, `png16` or `r16` (`io::Format::name`).
    pub format: String,
    pub tile_size: usize,
    pub overlap: usize,
    /// The height range mapped onto 16-bit codes (png16, r16), metres.
    pub height_range_m: Option<[f64; 2]>,
    /// The game engine the tiles are laid out for (`tiles --for`), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub engine: Option<String>,
}

/// One finished tile.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Record {
    pub col: usize,
    pub row: usize,
    /// The tile's file, relative to the directory.
    pub file: String,
    /// Pixels of the world it stands for in the mosaic: [x, y, w, h].
    pub core: [usize; 4],
    /// Pixels its file holds (core and overlap): [x, y, w, h].
    pub extent: [usize; 4],
    /// CRC-32 of the file's bytes followed by its sidecar's, if it has one
    /// (`0x` and 8 hex digits).
    pub crc32: String,
}

/// The whole manifest.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    pub version: u32,
    #[serde(flatten)]
    pub identity: Identity,
    /// Columns and rows.
    pub grid: [usize; 2],
    /// The GDAL mosaic (`world.vrt`), once every tile is written; none for
    /// formats GDAL cannot open (r16).
    pub vrt: Option<String>,
    /// The water rasters beside the tiles (`tiles --water`), when made.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub water: Option<WaterEntry>,
    /// Finished tiles, row by row.
    pub tiles: Vec<Record>,
}

/// The water of a tile directory (`tiles --water`, [`super::water`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WaterEntry {
    pub sea_level_m: Option<f32>,
    pub river_area_km2: f64,
    pub lake_min_depth_m: f64,
    pub lake_min_area_km2: f64,
    /// How the tiles' water files are named.
    pub tile_files: String,
    /// The rasters' suffixes in those names.
    pub rasters: Vec<String>,
    /// One GDAL mosaic per raster.
    pub vrts: Vec<String>,
    /// Lakes in the whole world.
    pub lakes: usize,
}

impl Manifest {
    /// Reads a directory's manifest; `None` when it has none.
    pub fn read(dir: &Path) -> Result<Option<Manifest>, TilesError> {
        let path = dir.join(FILE);
        let bytes = match std::fs::read(&path) {
            Ok(b) => b,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(crate::io::IoError::os(&path, e).into()),
        };
        let m: Manifest = serde_json::from_slice(&bytes).map_err(|e| TilesError::Manifest {
            path: path.clone(),
            reason: e.to_string(),
        })?;
        if m.version != VERSION {
            return Err(TilesError::Manifest {
                path,
                reason: format!("version {} is not {VERSION}", m.version),
            });
        }
        Ok(Some(m))
    }

    /// Writes it atomically (temporary file, then rename): indented, with
    /// one line per tile (a 64 × 64 grid stays a 4100-line file).
    pub fn write(&self, dir: &Path) -> Result<(), TilesError> {
        let head = Manifest {
            tiles: Vec::new(),
            ..self.clone()
        };
        let head = serde_json::to_string_pretty(&head).expect("a manifest serializes");
        let head = head
            .strip_suffix("\"tiles\": []\n}")
            .expect("tiles are the last field");
        let lines: Vec<String> = self
            .tiles
            .iter()
            .map(|r| {
                format!(
                    "    {}",
                    serde_json::to_string(r).expect("a record serializes")
                )
            })
            .collect();
        let json = format!("{head}\"tiles\": [\n{}\n  ]\n}}\n", lines.join(",\n"));
        Ok(crate::io::write_atomic(&dir.join(FILE), json.as_bytes())?)
    }
}

/// The CRC-32 of a tile's file and sidecar, as a manifest writes it.
pub fn crc32(file: &[u8], sidecar: Option<&[u8]>) -> String {
    let mut h = crc32fast::Hasher::new();
    h.update(file);
    if let Some(s) = sidecar {
        h.update(s);
    }
    format!("0x{:08x}", h.finalize())
}
