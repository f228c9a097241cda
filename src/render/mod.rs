//! Preview rendering: a PNG that shows a heightfield's shape at a glance and
//! lets a person judge its scale (seed 003, end of §3).
//!
//! ```text
//! Heightfield ─► prepare (CPU, floats: resize, quantize, palette, params)
//!             ─► shade   (the stage `stages::shade`: integer per-pixel kernel, GPU-mirrorable)
//!             ─► overlay (CPU: points, curves, regions, markers) ─► PNG
//! ```
//!
//! What the picture carries: a soft multi-directional hillshade computed with
//! the true cell size (so slopes are right in metres), a hypsometric tint
//! (with water below sea level when the data crosses it), contour lines at a
//! "nice" interval with an index contour every fifth, an optional grid,
//! red where heights leave a given range (the paper marks heights outside the
//! exemplars' range this way), an optional type-colour overlay, and hatched
//! grey where there is no data.

pub mod compose;
pub mod contours;
pub mod coords;
mod error;
pub mod font;
pub mod overlay;
pub mod prepare;
pub mod preview_size;
pub mod tint;
pub mod types;

pub use compose::side_by_side;
pub use contours::Contours;
pub use coords::coords_preview;
pub use error::RenderError;
pub use overlay::{Canvas, Marker};
pub use prepare::{Prepared, RenderInfo, prepare};
pub use tint::Palette;
pub use types::TypeOverlay;

use crate::backend::BackendError;
use crate::backend::engine::Engine;
use crate::heightfield::Heightfield;
use image::RgbaImage;
use std::path::Path;

/// The largest preview side `max_size` may ask for.
pub const MAX_PREVIEW_SIDE: usize = 16384;

/// How to render. `Default` gives a ≤ 2048 px preview with automatic
/// contours, sea and tint.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderOptions {
    /// Larger inputs are box-filtered so the long side is at most this.
    pub max_size: usize,
    /// Smaller inputs are enlarged (bilinear, whole factor) toward this
    /// (capped by `max_size`).
    pub min_size: usize,
    /// Vertical exaggeration of the hillshade (contours and tint keep true heights).
    pub exaggeration: f64,
    pub contours: Contours,
    pub grid: Grid,
    /// Heights outside `[min, max]` metres are painted red.
    pub range: Option<(f64, f64)>,
    pub sea: Sea,
    /// Heights the land palette runs over, metres; `None` = from the data
    /// (see [`tint::MIN_SPAN_M`]).
    pub tint_range: Option<(f64, f64)>,
    pub palette: Palette,
    pub lighting: Lighting,
    pub types: Option<TypeOverlay>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            max_size: 2048,
            min_size: 512,
            exaggeration: 1.0,
            contours: Contours::Auto,
            grid: Grid::Off,
            range: None,
            sea: Sea::Auto,
            tint_range: None,
            palette: Palette::natural(),
            lighting: Lighting::default(),
            types: None,
        }
    }
}

/// Grid lines.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Grid {
    Off,
    /// Every this many input cells.
    Cells(f64),
    /// Every this many metres.
    Metres(f64),
}

/// Whether to show water.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sea {
    /// Sea level 0 m when the heights cross it (some below, some above).
    Auto,
    /// Water below this level, metres.
    Level(f64),
    /// No water: the land palette everywhere.
    Off,
}

/// One light; azimuth clockwise from north, altitude above the horizon.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Light {
    pub azimuth_deg: f64,
    pub altitude_deg: f64,
    /// Relative weight, 0..=1.
    pub weight: f64,
}

/// The hillshade's lights and how strongly they shade.
#[derive(Debug, Clone, PartialEq)]
pub struct Lighting {
    /// 1 to 4 lights.
    pub lights: Vec<Light>,
    /// Weight each light by sin²(aspect − azimuth), the USGS multidirectional
    /// rule (Mark 1992), instead of by its fixed weight alone.
    pub aspect_weighted: bool,
    /// Brightness of a slope facing away from every light (0..=1; flat = 1).
    pub shadow: f64,
    /// How far a slope facing the light brightens toward white (0..=1).
    pub highlight: f64,
}

impl Default for Lighting {
    /// A soft multi-directional set: a key light from the north-west (the
    /// cartographic convention, so valleys read as valleys), half-weight
    /// fills from the west and north that open up slopes the key grazes, and
    /// a half-weight light from straight above that darkens steep ground in
    /// every direction. All at 45° except the zenith light. Compared on the
    /// shared DEMs with the USGS aspect-weighted set ([`Lighting::usgs`]),
    /// this keeps the relief's modelling without single-light banding,
    /// where the USGS set came out flat.
    fn default() -> Self {
        let light = |azimuth_deg, altitude_deg, weight| Light {
            azimuth_deg,
            altitude_deg,
            weight,
        };
        Lighting {
            lights: vec![
                light(315.0, 45.0, 1.0),
                light(270.0, 45.0, 0.5),
                light(360.0, 45.0, 0.5),
                light(0.0, 90.0, 0.5),
            ],
            aspect_weighted: false,
            shadow: 0.35,
            highlight: 0.3,
        }
    }
}

impl Lighting {
    /// The USGS multi-directional oblique set (Mark 1992; GDAL
    /// `-multidirectional`): lights from 225°, 270°, 315° and 360° at 45°,
    /// each weighted by sin²(aspect − azimuth).
    pub fn usgs() -> Lighting {
        let light = |azimuth_deg| Light {
            azimuth_deg,
            altitude_deg: 45.0,
            weight: 1.0,
        };
        Lighting {
            lights: vec![light(225.0), light(270.0), light(315.0), light(360.0)],
            aspect_weighted: true,
            ..Lighting::default()
        }
    }
}

/// A rendered preview and what was chosen for it.
#[derive(Debug, Clone)]
pub struct Preview {
    pub image: RgbaImage,
    pub info: RenderInfo,
}

impl Preview {
    /// A drawing surface in heightfield cell coordinates.
    pub fn canvas(&mut self) -> Canvas<'_> {
        Canvas::new(
            &mut self.image,
            self.info.px_per_cell_x,
            self.info.px_per_cell_y,
        )
    }
}

/// Renders a preview: [`prepare`](fn@prepare), then the `shade` stage on the CPU.
pub fn render(hf: &Heightfield, opts: &RenderOptions) -> Result<Preview, RenderError> {
    render_on(&Engine::default(), hf, opts)
}

/// [`render`] with the `shade` stage on `engine` (a synthesis's own, so
/// that its preview is shaded where it ran): the same bytes on every one.
pub fn render_on(
    engine: &Engine,
    hf: &Heightfield,
    opts: &RenderOptions,
) -> Result<Preview, RenderError> {
    let prep = prepare(hf, opts)?;
    let pixels = engine
        .shade(&prep.params, &prep.buffers())
        .map_err(|e| match e {
            BackendError::Shade(e) => RenderError::Params(e),
            e => RenderError::Backend(e),
        })?;
    Ok(Preview::from_pixels(prep.info, &pixels))
}

impl Preview {
    /// The preview from the `shade` stage's packed RGBA pixels (of
    /// `info.width × info.height`), whichever backend shaded them.
    pub fn from_pixels(info: RenderInfo, pixels: &[u32]) -> Preview {
        let bytes: Vec<u8> = pixels.iter().flat_map(|p| p.to_le_bytes()).collect();
        let image = RgbaImage::from_raw(info.width as u32, info.height as u32, bytes)
            .expect("buffer holds width × height pixels");
        Preview { image, info }
    }
}

/// Encodes an image as PNG (deterministic bytes). Fast compression: on a
/// 1024² preview it takes ~16 ms instead of ~640 ms at the default level
/// for files only ~6 % larger, and previews are made far more often than
/// they are archived.
pub fn encode_png(image: &RgbaImage) -> Result<Vec<u8>, RenderError> {
    use image::ImageEncoder;
    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
    let mut out = Vec::new();
    PngEncoder::new_with_quality(&mut out, CompressionType::Fast, FilterType::Adaptive)
        .write_image(
            image.as_raw(),
            image.width(),
            image.height(),
            image::ExtendedColorType::Rgba8,
        )
        .map_err(|e| RenderError::Encode(e.to_string()))?;
    Ok(out)
}

/// Writes an image as PNG atomically (temporary file, then rename).
pub fn write_png(path: &Path, image: &RgbaImage) -> Result<(), RenderError> {
    crate::io::write_atomic(path, &encode_png(image)?)?;
    Ok(())
}
