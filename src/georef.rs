//! Where a heightfield lies on Earth, when its file said so.
//!
//! A [`Georef`] is GDAL's north-up geotransform (origin of the outer corner of
//! the top-left cell, cell width and height in CRS units) plus the CRS it is
//! expressed in, and whether the samples were declared as cell areas or
//! points. It is only ever *read* from a file (GeoTIFF keys, `.prj`, an SRTM
//! tile's name, a sidecar) or carried from one; nothing here invents a
//! location. A synthesized terrain has none: writers give it
//! [`Georef::local`], a local (engineering) grid in metres with the correct
//! cell size and its lower-left corner at (0, 0), and no EPSG code.
//!
//! The heightfield's own `cell_size` stays the one square cell in metres that
//! every stage uses; the georeference keeps the map geometry. For a projected
//! CRS the two agree (`pixel × metres_per_unit = cell_size`). For a
//! geographic CRS the pixel is in degrees: [`Georef::ground_spacing`] gives
//! its true size on the ground, which [`crate::io`] uses to resample
//! east–west until cells are square.

/// How samples relate to cells (GeoTIFF `GTRasterTypeGeoKey`). The origin is
/// always the outer corner, as in GDAL; `Point` only records that the source
/// declared sample positions, so a writer can declare them the same way.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PixelIs {
    #[default]
    Area,
    Point,
}

/// The units of a CRS's horizontal axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Units {
    /// Geographic: latitude and longitude in degrees.
    Degrees,
    /// Projected or local: a linear unit of this many metres.
    Linear { metres_per_unit: f64 },
}

/// A coordinate reference system, as far as the file named it.
#[derive(Debug, Clone, PartialEq)]
pub struct Crs {
    /// EPSG code of the horizontal CRS, when the file gave one.
    pub epsg: Option<u32>,
    /// WKT as the file gave it (`.prj`, or GeoTIFF's ESRI PE string).
    pub wkt: Option<String>,
    /// A human-readable name (GeoTIFF citation, WKT name).
    pub name: Option<String>,
    pub units: Units,
    /// EPSG code of the vertical CRS (e.g. 5773 EGM96 height), when given.
    pub vertical_epsg: Option<u32>,
}

impl Crs {
    /// A CRS known only by its EPSG code and units.
    pub fn epsg(code: u32, units: Units) -> Crs {
        Crs {
            epsg: Some(code),
            wkt: None,
            name: None,
            units,
            vertical_epsg: None,
        }
    }

    pub fn is_geographic(&self) -> bool {
        self.units == Units::Degrees
    }

    /// `EPSG:32633`, the name, or "a local grid in metres".
    pub fn label(&self) -> String {
        match (&self.epsg, &self.name) {
            (Some(c), Some(n)) => format!("EPSG:{c} ({n})"),
            (Some(c), None) => format!("EPSG:{c}"),
            (None, Some(n)) => n.clone(),
            (None, None) if self.is_geographic() => "geographic (no EPSG code)".into(),
            (None, None) => "projected (no EPSG code)".into(),
        }
    }
}

/// The geometry of a grid on a map.
#[derive(Debug, Clone, PartialEq)]
pub struct Georef {
    /// `None`: the file placed the grid (ESRI ASCII without `.prj`) but did
    /// not say in which CRS; coordinates are taken to be metres.
    pub crs: Option<Crs>,
    /// Map coordinates of the outer corner of the top-left cell.
    pub origin_x: f64,
    pub origin_y: f64,
    /// Cell width and height in CRS units, both > 0 (rows run south).
    pub pixel_x: f64,
    pub pixel_y: f64,
    pub pixel_is: PixelIs,
}

/// The name written for [`Georef::local`] grids.
pub const LOCAL_CRS_NAME: &str = "terrasynth local grid (metres, no geographic location)";

/// WGS84 semi-major axis (m) and first eccentricity squared.
const WGS84_A: f64 = 6_378_137.0;
const WGS84_E2: f64 = 0.006_694_379_990_141_317;

/// Metres per degree of latitude and of longitude at latitude `lat_deg` on
/// the WGS84 ellipsoid (meridional and prime-vertical radii of curvature).
/// Other datums' ellipsoids differ by < 0.01 %, far below a DEM's accuracy.
pub fn metres_per_degree(lat_deg: f64) -> (f64, f64) {
    let phi = lat_deg.to_radians();
    let s2 = phi.sin().powi(2);
    let w = (1.0 - WGS84_E2 * s2).sqrt();
    let rad = std::f64::consts::PI / 180.0;
    (
        rad * WGS84_A * (1.0 - WGS84_E2) / (w * w * w),
        rad * WGS84_A * phi.cos() / w,
    )
}

impl Georef {
    /// A synthesized terrain's grid: local metres, lower-left corner at the
    /// origin, square `cell` metres, no EPSG code (it is nowhere on Earth).
    pub fn local(height: usize, cell: f64) -> Georef {
        Georef {
            crs: Some(Crs {
                epsg: None,
                wkt: None,
                name: Some(LOCAL_CRS_NAME.into()),
                units: Units::Linear {
                    metres_per_unit: 1.0,
                },
                vertical_epsg: None,
            }),
            origin_x: 0.0,
            origin_y: height as f64 * cell,
            pixel_x: cell,
            pixel_y: cell,
            pixel_is: PixelIs::Area,
        }
    }

    pub fn is_geographic(&self) -> bool {
        self.crs.as_ref().is_some_and(Crs::is_geographic)
    }

    /// Whether this is a [`Georef::local`] grid (no place on Earth).
    pub fn is_local(&self) -> bool {
        self.crs
            .as_ref()
            .is_some_and(|c| c.epsg.is_none() && c.name.as_deref() == Some(LOCAL_CRS_NAME))
    }

    /// Metres per CRS unit for linear CRSs (1 when the CRS is unknown).
    pub fn metres_per_unit(&self) -> Option<f64> {
        match self.crs.as_ref().map(|c| c.units) {
            Some(Units::Degrees) => None,
            Some(Units::Linear { metres_per_unit }) => Some(metres_per_unit),
            None => Some(1.0),
        }
    }

    /// Latitude of the grid's centre row, for geographic grids.
    pub fn centre_latitude(&self, rows: usize) -> Option<f64> {
        self.is_geographic()
            .then(|| self.origin_y - self.pixel_y * rows as f64 / 2.0)
    }

    /// True east–west and north–south spacing in metres (at the centre row
    /// for geographic grids, where east–west shrinks with the latitude).
    pub fn ground_spacing(&self, rows: usize) -> (f64, f64) {
        match self.centre_latitude(rows) {
            Some(lat) => {
                let (m_lat, m_lon) = metres_per_degree(lat.clamp(-90.0, 90.0));
                (self.pixel_x * m_lon, self.pixel_y * m_lat)
            }
            None => {
                let m = self.metres_per_unit().unwrap_or(1.0);
                (self.pixel_x * m, self.pixel_y * m)
            }
        }
    }

    /// The georeference of the window whose top-left cell is (x0, y0).
    pub fn shifted(&self, x0: usize, y0: usize) -> Georef {
        Georef {
            origin_x: self.origin_x + x0 as f64 * self.pixel_x,
            origin_y: self.origin_y - y0 as f64 * self.pixel_y,
            ..self.clone()
        }
    }

    /// The same extent covered by `width × height` cells instead of
    /// `from_width × from_height` (what resampling does to the geometry).
    pub fn resized(
        &self,
        (from_width, from_height): (usize, usize),
        (width, height): (usize, usize),
    ) -> Georef {
        Georef {
            pixel_x: self.pixel_x * from_width as f64 / width as f64,
            pixel_y: self.pixel_y * from_height as f64 / height as f64,
            ..self.clone()
        }
    }

    /// Checks that every number is usable (finite, cells > 0).
    pub fn is_valid(&self) -> bool {
        [self.origin_x, self.origin_y, self.pixel_x, self.pixel_y]
            .iter()
            .all(|v| v.is_finite())
            && self.pixel_x > 0.0
            && self.pixel_y > 0.0
            && self
                .metres_per_unit()
                .is_none_or(|m| m.is_finite() && m > 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metres_per_degree_matches_published_values() {
        // Standard tables (WGS84): 110 574 m / 111 320 m at 0°,
        // 111 132 m / 78 847 m at 45°, 111 694 m / 0 m at 90°.
        for (lat, want_lat, want_lon) in [
            (0.0, 110_574.0, 111_320.0),
            (45.0, 111_132.0, 78_847.0),
            (90.0, 111_694.0, 0.0),
        ] {
            let (a, b) = metres_per_degree(lat);
            assert!((a - want_lat).abs() < 1.0, "{lat}: {a}");
            assert!((b - want_lon).abs() < 1.0, "{lat}: {b}");
        }
    }

    #[test]
    fn geographic_spacing_shrinks_east_west() {
        // SRTM3 at 49.5° N, the franconian_jura tile: 92.68 m x 60.36 m
        // (its sidecar's native spacing).
        let g = Georef {
            crs: Some(Crs::epsg(4326, Units::Degrees)),
            origin_x: 11.0,
            origin_y: 50.0,
            pixel_x: 1.0 / 1200.0,
            pixel_y: 1.0 / 1200.0,
            pixel_is: PixelIs::Point,
        };
        let (dx, dy) = g.ground_spacing(1200);
        assert!((dy - 92.68).abs() < 0.05, "{dy}");
        assert!((dx - 60.36).abs() < 0.05, "{dx}");
        let s = g.shifted(10, 20);
        assert!((s.origin_y - (50.0 - 20.0 / 1200.0)).abs() < 1e-12);
        let r = g.resized((1200, 1200), (800, 1200));
        assert!((r.pixel_x - 1.5 / 1200.0).abs() < 1e-15);
    }
}
