//! Rivers as GeoJSON: one LineString per segment ([`super::rivers`]), its
//! vertices at cell centres, with `strahler`, `upstream_area_km2`,
//! `length_m` and `end` (confluence, lake, sea, border) as properties.
//!
//! Coordinates are in the CRS of the rasters written beside it: the
//! heightfield's georeference when it has one (a `crs` member names its
//! EPSG code, which GDAL reads), otherwise terrasynth's local grid in
//! metres ([`Georef::local`]: lower-left corner at (0, 0), no place on
//! Earth), the grid every GeoTIFF of a synthesized terrain is written on —
//! so the lines lie on the rasters in any GIS. RFC 7946 asks for WGS84
//! longitude/latitude; only a heightfield in EPSG:4326 gives that, and the
//! others are GeoJSON "by prior arrangement", as GDAL writes them.

use super::Water;
use crate::georef::Georef;
use serde_json::{Value, json};

impl Water {
    /// The rivers as a GeoJSON FeatureCollection (UTF-8 bytes, ending in a
    /// newline). `georef`: the heightfield's.
    pub fn rivers_geojson(&self, georef: Option<&Georef>) -> Vec<u8> {
        let local;
        let g = match georef {
            Some(g) => g,
            None => {
                local = Georef::local(self.height, self.cell_size);
                &local
            }
        };
        let w = self.width;
        let point = |i: u32| {
            let (x, y) = ((i as usize % w) as f64, (i as usize / w) as f64);
            json!([
                g.origin_x + (x + 0.5) * g.pixel_x,
                g.origin_y - (y + 0.5) * g.pixel_y
            ])
        };
        let cell_km2 = self.cell_size * self.cell_size / 1e6;
        let features: Vec<Value> = self
            .rivers
            .segments
            .iter()
            .map(|s| {
                json!({
                    "type": "Feature",
                    "properties": {
                        "strahler": s.order,
                        "upstream_area_km2": s.upstream_cells as f64 * cell_km2,
                        "length_m": s.length_cells(w) * self.cell_size,
                        "end": s.end,
                    },
                    "geometry": {
                        "type": "LineString",
                        "coordinates": s.cells.iter().map(|&i| point(i)).collect::<Vec<_>>(),
                    },
                })
            })
            .collect();
        let mut fc = json!({
            "type": "FeatureCollection",
            "name": "rivers",
            "features": features,
        });
        if let Some(code) = g.crs.as_ref().and_then(|c| c.epsg) {
            fc["crs"] = json!({
                "type": "name",
                "properties": { "name": format!("urn:ogc:def:crs:EPSG::{code}") },
            });
        }
        let mut out = serde_json::to_vec(&fc).expect("JSON values always serialize");
        out.push(b'\n');
        out
    }
}
