//! terrasynth against GDAL (Debian's `gdal-bin` and `python3-gdal`): the
//! file variants GIS users have, the GIS corner cases of issue 44 and
//! LERC-compressed GeoTIFFs, each written by one side and read by the
//! other. Without GDAL every test says so and skips
//! (`TERRASYNTH_REQUIRE_GDAL` turns that into a failure).

#[path = "../common/mod.rs"]
mod common;

mod formats;
mod grids;
mod lerc;
