//! `world.vrt`: a GDAL virtual raster that mosaics the tiles' cores, so
//! GIS tools (GDAL, QGIS) open a tile directory as one raster of the whole
//! world, in the same local grid the tiles are placed in.
//!
//! Each tile is a source whose `SrcRect` is its core inside its file (the
//! overlap left out) and whose `DstRect` is the core's place in the world:
//! the mosaic's pixels are exactly the synthesized world's. 16-bit PNG
//! tiles are scaled back to metres with the tiles' shared mapping
//! (`ScaleOffset`, `ScaleRatio`).

use super::grid::Grid;
use crate::georef::LOCAL_CRS_NAME;
use crate::io::{Format, HeightMapping};
use std::fmt::Write;

/// The file name of the mosaic in a tile directory.
pub const FILE: &str = "world.vrt";

/// Whether GDAL can read tiles of `format` as sources (Debian's GDAL has
/// no EXR driver; other builds do, so EXR mosaics are still written).
pub fn supported(format: Format) -> bool {
    matches!(format, Format::Tiff | Format::Exr | Format::Png16)
}

/// The VRT of a grid's tiles (`files` in [`Grid::tiles`] order).
/// `mapping`: the metres of 16-bit codes (PNG tiles).
pub fn vrt(
    grid: &Grid,
    cell_size_m: f64,
    format: Format,
    files: &[String],
    mapping: Option<HeightMapping>,
) -> String {
    let (w, h) = grid.world;
    let mut x = String::new();
    let _ = writeln!(x, r#"<VRTDataset rasterXSize="{w}" rasterYSize="{h}">"#);
    let _ = writeln!(
        x,
        r#"  <SRS dataAxisToSRSAxisMapping="1,2">LOCAL_CS["{LOCAL_CRS_NAME}",UNIT["metre",1],AXIS["Easting",EAST],AXIS["Northing",NORTH]]</SRS>"#
    );
    // Lower-left corner at (0, 0), rows running south (`Georef::local`).
    let top = h as f64 * cell_size_m;
    let _ = writeln!(
        x,
        "  <GeoTransform>0, {cell_size_m:?}, 0, {top:?}, 0, {:?}</GeoTransform>",
        -cell_size_m
    );
    let _ = writeln!(x, r#"  <VRTRasterBand dataType="Float32" band="1">"#);
    let data_type = if format == Format::Png16 {
        "UInt16"
    } else {
        "Float32"
    };
    for (t, file) in grid.tiles().zip(files) {
        let (e, c) = (t.extent, t.core);
        let kind = if mapping.is_some() {
            "ComplexSource"
        } else {
            "SimpleSource"
        };
        let _ = writeln!(x, "    <{kind}>");
        let _ = writeln!(
            x,
            r#"      <SourceFilename relativeToVRT="1">{}</SourceFilename>"#,
            escape(file)
        );
        let _ = writeln!(x, "      <SourceBand>1</SourceBand>");
        let _ = writeln!(
            x,
            r#"      <SourceProperties RasterXSize="{}" RasterYSize="{}" DataType="{data_type}"/>"#,
            e.width(),
            e.height()
        );
        let _ = writeln!(
            x,
            r#"      <SrcRect xOff="{}" yOff="{}" xSize="{}" ySize="{}"/>"#,
            c.x0 - e.x0,
            c.y0 - e.y0,
            c.width(),
            c.height()
        );
        let _ = writeln!(
            x,
            r#"      <DstRect xOff="{}" yOff="{}" xSize="{}" ySize="{}"/>"#,
            c.x0,
            c.y0,
            c.width(),
            c.height()
        );
        if let Some(m) = mapping {
            let _ = writeln!(x, "      <ScaleOffset>{:?}</ScaleOffset>", m.offset_m);
            let _ = writeln!(x, "      <ScaleRatio>{:?}</ScaleRatio>", m.scale_m);
        }
        let _ = writeln!(x, "    </{kind}>");
    }
    x.push_str("  </VRTRasterBand>\n</VRTDataset>\n");
    x
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}
