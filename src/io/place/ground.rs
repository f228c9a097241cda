//! From a file's grid to the square metric cells every stage assumes.
//!
//! A georeferenced grid knows its true ground spacing on both axes
//! ([`Georef::ground_spacing`]). When the two differ — every geographic DEM
//! away from the equator (SRTM, Copernicus GLO-30/90, NASADEM, 3DEP are in
//! degrees: at 49.5° N a 3″ cell is 92.7 m north–south but 60.4 m
//! east–west), or an ESRI grid with `dx` ≠ `dy` — taking one of them as the
//! cell size would stretch the terrain. Instead the grid is **resampled** to
//! square cells (one notice line says so):
//!
//! - cell size: `--cell-size` when given, else the north–south spacing, so
//!   rows are kept and only columns change;
//! - method: [`crate::resample::resample`], separable tent filter —
//!   area-weighted when reducing (no aliasing), bilinear when enlarging;
//!   nodata carries no weight;
//! - geometry: the georeference keeps its CRS and extent, with the new pixel
//!   size in CRS units (a geographic grid stays geographic, GDAL sees the
//!   same footprint); the east–west spacing is exact at the centre row and
//!   varies with cos(latitude) across the grid (±1.3 % over a 1° tile);
//! - sizes round to whole cells, so the spacing differs from the requested
//!   cell by at most half a cell over the grid's width (0.06 % at 800 px).
//!
//! Grids whose spacings agree within [`SQUARE_TOLERANCE`] are kept as they
//! are. A georeferenced square grid given another `--cell-size` is
//! resampled to it (its ground spacing is known); a grid without CRS has its
//! cell size relabelled, and its placement, now meaningless, dropped.
//!
//! SRTM `.hgt` files get their georeference from the tile name here.

use crate::georef::{Crs, Georef, PixelIs, Units};
use crate::heightfield::Heightfield;
use crate::io::FormatError;
use crate::size::check_dims;

/// Relative difference of the two spacings below which cells count as
/// square (well under the variation of E–W spacing across a 1° tile).
pub const SQUARE_TOLERANCE: f64 = 0.01;

/// What [`square_cells`] did, for the user.
#[derive(Debug, Clone, PartialEq)]
pub struct GridReport {
    /// East–west and north–south spacing in metres as read, when known.
    pub native_spacing: Option<(f64, f64)>,
    /// One-line notices (resampling, dropped placement; the reader adds the
    /// EXR channel read and a normalised 0..1 range).
    pub notes: Vec<String>,
}

/// Brings a decoded grid to square metric cells (see the module docs).
pub fn square_cells(
    mut hf: Heightfield,
    cell: Option<f64>,
) -> Result<(Heightfield, GridReport), FormatError> {
    let mut report = GridReport {
        native_spacing: None,
        notes: Vec::new(),
    };
    let Some(g) = hf.georef().cloned() else {
        if let Some(c) = cell {
            hf.set_cell_size(c)?;
        }
        return Ok((hf, report));
    };
    let (w, h) = (hf.width(), hf.height());
    let (dx, dy) = g.ground_spacing(h);
    if !(dx.is_finite() && dy.is_finite() && dx > 0.0 && dy > 0.0) {
        return Err(FormatError::Metadata(format!(
            "the georeference gives cells of {dx} x {dy} m: expected finite sizes > 0 (is the grid beyond a pole?)"
        )));
    }
    report.native_spacing = Some((dx, dy));
    if g.crs.is_none()
        && cell.is_none()
        && dx.max(dy) < 0.01
        && g.origin_x.abs() <= 360.0
        && g.origin_y.abs() <= 90.0
    {
        return Err(FormatError::Metadata(format!(
            "cells of {} x {} map units at ({}, {}) look like degrees, but no .prj says which CRS the grid is in: add one beside it (gdalsrsinfo -o wkt_esri EPSG:4326 > NAME.prj) or give --cell-size in metres",
            g.pixel_x, g.pixel_y, g.origin_x, g.origin_y
        )));
    }
    let square = (dx - dy).abs() <= SQUARE_TOLERANCE * dx.max(dy);
    if g.crs.is_none() && cell.is_some_and(|c| c != hf.cell_size()) {
        // No CRS: the file's units were a guess; the user's cell size wins.
        hf.set_cell_size(cell.unwrap_or(dy))?;
        hf.set_georef(None);
        report.notes.push(format!(
            "--cell-size {} m relabels a grid without a CRS; its map placement no longer applies and is dropped",
            hf.cell_size()
        ));
        return Ok((hf, report));
    }
    if square && cell.is_none_or(|c| (c - hf.cell_size()).abs() <= 1e-9 * c) {
        return Ok((hf, report));
    }
    let target = cell.unwrap_or(dy);
    let nw = ((w as f64 * dx / target).round() as usize).max(1);
    let nh = ((h as f64 * dy / target).round() as usize).max(1);
    check_dims(nw, nh)?;
    let mut out = crate::resample::resample(&hf, nw, nh)?;
    out.set_cell_size(target)?;
    out.set_georef(Some(g.resized((w, h), (nw, nh))));
    let what = match (&g.crs, g.centre_latitude(h)) {
        (Some(c), Some(lat)) => format!(
            "geographic grid ({}) at {:.2}° {}",
            c.label(),
            lat.abs(),
            if lat >= 0.0 { "N" } else { "S" }
        ),
        _ => "grid".to_string(),
    };
    report.notes.push(format!(
        "{what} has {dx:.2} m (E-W) x {dy:.2} m (N-S) cells: resampled to square {target:.2} m cells, {w}x{h} -> {nw}x{nh} (tent filter; --cell-size chooses the cell)"
    ));
    Ok((out, report))
}

/// The georeference of an SRTM tile from its name (`N41E001`, `s12w077`,
/// any suffix): samples lie on whole-degree lines (pixel-is-point), the
/// tile's south-west sample at the named corner. `None` for other names.
pub fn hgt_georef(name: &str, side: usize) -> Option<Georef> {
    let b = name.as_bytes();
    let sign = |c: u8, pos: u8, neg: u8| match c.to_ascii_uppercase() {
        c if c == pos => Some(1.0),
        c if c == neg => Some(-1.0),
        _ => None,
    };
    let digits = |s: &[u8]| -> Option<f64> {
        s.iter()
            .all(u8::is_ascii_digit)
            .then(|| std::str::from_utf8(s).ok()?.parse().ok())?
    };
    let lat = sign(*b.first()?, b'N', b'S')? * digits(b.get(1..3)?)?;
    let lon = sign(*b.get(3)?, b'E', b'W')? * digits(b.get(4..7)?)?;
    if !(-90.0..90.0).contains(&lat) || !(-180.0..180.0).contains(&lon) || side < 2 {
        return None;
    }
    let res = 1.0 / (side - 1) as f64;
    let mut crs = Crs::epsg(4326, Units::Degrees);
    crs.name = Some("WGS 84".into());
    Some(Georef {
        crs: Some(crs),
        origin_x: lon - res / 2.0,
        origin_y: lat + 1.0 + res / 2.0,
        pixel_x: res,
        pixel_y: res,
        pixel_is: PixelIs::Point,
    })
}

/// What the `georef` fuzz target (and its replay test) runs on one input:
/// an SRTM tile name on the first line, a `.prj` WKT after it, parsed
/// alone and as the companion of a small geographic ESRI grid.
#[doc(hidden)]
pub fn fuzz_georef(data: &[u8]) -> Result<crate::io::Loaded, FormatError> {
    const GRID: &[u8] =
        b"ncols 3\nnrows 2\nxllcorner 1\nyllcorner 41\ndx 0.001\ndy 0.0008\n1 2 3\n4 5 6\n";
    let split = data.iter().position(|&b| b == b'\n').unwrap_or(data.len());
    let _ = hgt_georef(&String::from_utf8_lossy(&data[..split]), 1201);
    let prj = data.get(split + 1..).unwrap_or_default();
    let _ = super::wkt::parse(prj);
    let companions = crate::io::Companions {
        prj: Some(prj),
        ..Default::default()
    };
    crate::io::load_bytes(
        GRID,
        crate::io::Format::Asc,
        &companions,
        &Default::default(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srtm_names() {
        let g = hgt_georef("N49E011.hgt", 1201).unwrap();
        assert!((g.origin_x - (11.0 - 0.5 / 1200.0)).abs() < 1e-12);
        assert!((g.origin_y - (50.0 + 0.5 / 1200.0)).abs() < 1e-12);
        let g = hgt_georef("s12w077", 3601).unwrap();
        assert_eq!(g.origin_x, -77.0 - 0.5 / 3600.0);
        assert_eq!(g.origin_y, -11.0 + 0.5 / 3600.0);
        for bad in ["", "N4", "X49E011", "N49E01", "N95E011", "N49E1x1"] {
            assert!(hgt_georef(bad, 1201).is_none(), "{bad}");
        }
    }

    #[test]
    fn geographic_grid_becomes_square_without_stretch() {
        // A 3″ grid at 49.5° N: columns shrink by cos(49.5°) ≈ 0.651.
        let mut hf = Heightfield::from_fn(300, 120, 1.0, |x, _| x as f32).unwrap();
        let mut g = hgt_georef("N49E011", 1201).unwrap();
        g.origin_y = 49.55;
        hf.set_georef(Some(g.clone()));
        let (out, rep) = square_cells(hf, None).unwrap();
        let (dx, dy) = rep.native_spacing.unwrap();
        assert!(
            (dy - 92.68).abs() < 0.05 && (dx - 60.36).abs() < 0.1,
            "{dx} {dy}"
        );
        assert_eq!((out.width(), out.height()), (195, 120));
        assert!((out.cell_size() - dy).abs() < 1e-9);
        // Same extent in degrees; the ramp spans the same range.
        let og = out.georef().unwrap();
        assert!((og.pixel_x * 195.0 - g.pixel_x * 300.0).abs() < 1e-12);
        assert!(
            rep.notes[0].contains("300x120 -> 195x120"),
            "{:?}",
            rep.notes
        );
        let (ndx, ndy) = og.ground_spacing(120);
        assert!((ndx / ndy - 1.0).abs() < 0.005, "{ndx} vs {ndy}");
    }
}
