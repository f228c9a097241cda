//! `tiles --water`: the water of a tiled world beside its height tiles —
//! per tile `tile_<col>_<row>.filled.tif`, `.lakes.tif`, `.flow.tif` and
//! `.rivers.tif` (float32 GeoTIFFs of the tile's core, in the world's local
//! grid), a mosaic per raster (`filled.vrt`, …) and a `water` entry in the
//! manifest. The rasters are bit for bit those `terrasynth water` computes
//! on the whole world the tiles' cores make up
//! ([`crate::water::tiled`]), with memory for a few tiles and the rings.
//!
//! The heights are read back from the tile files, so the water is that of
//! the tiles as written (16-bit tiles: their decoded heights). It is
//! computed again on every run (a lake's level depends on the whole
//! world), while the height tiles of an earlier run are kept as usual.

use super::grid::Grid;
use super::manifest::{Manifest, WaterEntry};
use super::{TilesError, Tiling, vrt};
use crate::georef::Georef;
use crate::heightfield::Heightfield;
use crate::io::{self, Format, IoError};
use crate::progress::Progress;
use crate::water::tiled::{self, Core, Io, Layout, Report, TileWater};
use crate::water::{Params, WaterError};
use std::path::Path;

/// The rasters' suffixes: the water surface (depressions filled to their
/// spill level), water depth of lakes and sea (metres), D8 flow
/// accumulation (cells), Strahler order of river cells.
pub const RASTERS: [&str; 4] = ["filled", "lakes", "flow", "rivers"];

/// Writes the water of the world whose tiles [`super::write`] put in `dir`
/// (every tile must be there); `progress` counts tiles written.
pub fn write(
    t: &Tiling,
    dir: &Path,
    params: &Params,
    progress: &dyn Progress,
) -> Result<Report, TilesError> {
    let manifest_error = |reason: String| TilesError::Manifest {
        path: dir.join(super::manifest::FILE),
        reason,
    };
    let mut m = Manifest::read(dir)?.ok_or_else(|| manifest_error("missing".into()))?;
    let grid = t.grid;
    let cores = Grid { overlap: 0, ..grid };
    let layout = Layout {
        world: grid.world,
        tile: grid.tile,
    };
    if m.tiles.len() != layout.count() {
        return Err(manifest_error(format!(
            "{} of {} tiles finished: water needs them all",
            m.tiles.len(),
            layout.count()
        )));
    }
    let tiles: Vec<_> = grid.tiles().collect();
    let heights = |c: Core| -> Result<Vec<f32>, WaterError> {
        let k = layout.tile_of(c.x0, c.y0);
        let path = dir.join(&m.tiles[k].file);
        let hf = io::read(&path, &io::ReadOptions::default())?;
        let e = tiles[k].extent;
        let ok = (hf.width(), hf.height()) == (e.width(), e.height());
        let core = ok
            .then(|| hf.crop(c.x0 - e.x0, c.y0 - e.y0, c.w, c.h).ok())
            .flatten()
            .ok_or_else(|| {
                IoError::os(
                    &path,
                    std::io::Error::other(format!(
                        "{}x{} pixels: the manifest says {}x{}",
                        hf.width(),
                        hf.height(),
                        e.width(),
                        e.height()
                    )),
                )
            })?;
        Ok(core.into_vec())
    };
    let cell = t.cell_size_m;
    let world_grid = Georef::local(grid.world.1, cell);
    progress.start("water tiles", layout.count() as u64);
    let sink = |w: TileWater| -> Result<(), WaterError> {
        let c = w.core;
        let tile = &tiles[layout.tile_of(c.x0, c.y0)];
        let acc = w.accumulation.iter().map(|&a| a as f32).collect();
        let rivers = w.rivers.iter().map(|&o| o as f32).collect();
        for (suffix, values) in RASTERS.iter().zip([w.filled, w.depth, acc, rivers]) {
            let mut hf =
                Heightfield::from_vec(c.w, c.h, cell, values).expect("a raster of the core's size");
            hf.set_georef(Some(world_grid.shifted(c.x0, c.y0)));
            let path = dir.join(grid.file_name(tile, &format!("{suffix}.tif")));
            io::write(&hf, &path, &io::WriteOptions::default())?;
        }
        progress.advance(1);
        Ok(())
    };
    let io = Io {
        heights: &heights,
        sink: &sink,
        scratch: &dir.join(".water-scratch"),
    };
    let report = tiled::compute(&layout, cell, params, &io);
    progress.finish();
    let report = report?;
    let mut vrts = Vec::new();
    for suffix in RASTERS {
        let files: Vec<String> = tiles
            .iter()
            .map(|x| grid.file_name(x, &format!("{suffix}.tif")))
            .collect();
        let name = format!("{suffix}.vrt");
        let x = vrt::vrt(&cores, cell, Format::Tiff, &files, None);
        io::write_atomic(&dir.join(&name), x.as_bytes())?;
        vrts.push(name);
    }
    m.water = Some(WaterEntry {
        sea_level_m: params.sea_level,
        river_area_km2: params.river_area_km2,
        lake_min_depth_m: params.lakes.min_depth_m,
        lake_min_area_km2: params.lakes.min_area_km2,
        tile_files: "tile_<col>_<row>.<raster>.tif (the tile's core)".into(),
        rasters: RASTERS.map(String::from).to_vec(),
        vrts,
        lakes: report.lakes,
    });
    m.write(dir)?;
    Ok(report)
}
