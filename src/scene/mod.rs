//! Scene files: a terrain design as JSON — the database, the output size
//! and seed, and every user control (paper §3, §5): point and curve
//! constraints, junction heights, painted types, frozen regions and pastes.
//!
//! # Format (version 2)
//!
//! Positions are output pixels `[x, y]` (x right, y down; pixel (i, j)
//! covers `[i, i+1) × [j, j+1)`), inside `[0, width] × [0, height]` unless
//! said otherwise. Lengths in pixels end in `_px`, heights in metres in
//! `_m`, angles in degrees in `_deg`. Unknown fields are errors, so a typo
//! never silently does nothing. Optional fields show their default.
//!
//! ```json
//! {
//!   "version": 2,                       // optional, 1 or 2 (absent = 1); 2 changed only the default of a paste's "lift"
//!   "database": "exemplars.tsdb",       // optional: path (relative to the scene file); absent or null = the embedded database
//!   "size": [1024, 1024],               // width, height: 1..=65535 each
//!   "seed": 7,                          // 0..=4294967295
//!   "jitter": 0.4,                      // optional, 0..=4 texels
//!   "passes": 2,                        // optional, 0..=16
//!   "start_exemplar": 0,                // optional, an exemplar index of the database; absent = every exemplar (synth::Params::start_exemplar)
//!   "points": [{
//!     "id": "peak",                     // optional, unique; default "points[i]"
//!     "at": [300, 200],
//!     "height_m": 2400,                 // -20000..=20000
//!     "slope_deg": 0,                   // optional, 0..=80: steepness of the target plane
//!     "slope_direction_deg": 0,         // optional, -360..=360: direction the plane descends, 0 = +x (east), 90 = +y (down the image)
//!     "radius_px": 40                   // 0 < r <= 4096
//!   }],
//!   "curves": [{
//!     "id": "canyon",                   // optional, unique; default "curves[i]"
//!     "points": [[10, 500], [400, 520], [900, 480]],   // >= 2, the sketched polyline
//!     "smoothing": 2,                   // optional, 0..=8 Chaikin iterations
//!     "widgets": [{                     // >= 1
//!       "at": 0.5,                      // 0..=1: fraction of the smoothed curve's arc length
//!       "height_m": 900,                // -20000..=20000
//!       "slope_deg": [30, 30],          // [left, right], -85..=85; > 0 rises away from the curve
//!       "reach_px": [60, 60]            // [left, right], 0 < r <= 4096
//!     }]
//!   }],
//!   "junctions": [{ "at": [412, 518], "height_m": 700 }],  // optional: set the height of the automatic junction within 4 px
//!   "types": { "image": "types.png" },  // optional: an 8-bit index image of the scene's size, names in types.json beside it (the `*_types.png/json` layout); 255 = unconstrained
//!   "types": { "strokes": [{ "type": "mountains", "points": [[100, 100], [300, 120]], "radius_px": 40 }] },  // or: painted strokes with database type names; later strokes paint over earlier ones
//!   "types": { "strokes": [{ "erase": true, "points": [[120, 110]], "radius_px": 10 }] },  // a stroke may erase instead (back to unconstrained; no "type" then)
//!   "freeze": { "mask": "freeze.png" },  // optional: an 8-bit image of the scene's size, non-zero = frozen
//!   "freeze": { "strokes": [{ "points": [[50, 50]], "radius_px": 30 }] },  // or: strokes ("erase": true unfreezes)
//!   "pastes": [{
//!     "id": "dome",                     // optional, unique; default "pastes[i]"
//!     "source": "exemplar",             // "terrain" (the synthesized result) or "exemplar"
//!     "exemplar": 2,                    // with "exemplar": its index in the database
//!     "lasso": [[10, 10], [80, 12], [60, 90]],  // >= 3 points: the region, in source pixels
//!     "to": [700, 300],                 // where the lasso's centroid goes, output pixels
//!     "delta_m": 0,                     // optional, -20000..=20000: height offset δ, metres
//!     "lift": "ground"                  // optional: "ground" (default in version 2) lifts the paste so that it meets the
//!                                       // terrain along its lasso (the median step there is 0, its floor not below the
//!                                       // ground's), then by δ, exactly to the
//!                                       // lasso, bending to the ground over 16 px beyond it; "source" (default in
//!                                       // version 1) keeps the source's own heights, δ rising
//!                                       // over 16 px inside the lasso (synth::control::Lift)
//!   }],
//!   "sculpt": [{                        // optional: sculpt brush strokes, painted in order (later over earlier)
//!     "brush": "raise",                 // "raise", "lower", "smooth", "flatten" or "erode"
//!     "points": [[300, 300], [340, 310]],  // >= 1, the stroke's polyline
//!     "radius_px": 40,                  // 0 < r <= 4096
//!     "strength": 150,                  // raise/lower: metres, 0 < s <= 20000; the others: 0 < s <= 1, the share of the way to the brush's aim
//!     "falloff": 0.5,                   // optional, 0..=1: the outer share of the radius over which the effect fades
//!     "targets": {                      // the target heights baked from the terrain the stroke was painted on (the editor writes them)
//!       "at": [260, 260],               // node (0, 0), output pixels; node (i, j) is at + step·(i, j)
//!       "step_px": 10,                  // 0 < step <= 256
//!       "size": [14, 10],               // nodes across, down (each >= 1, at most 1000000 in all)
//!       "heights_m": [812.5, 813.1]     // size[0]·size[1] heights, row by row, -20000..=20000
//!     }
//!   }]
//! }
//! ```
//! (`//` comments are for this page only; JSON has none, and `types` /
//! `freeze` take one of the two forms.)
//!
//! Left and right of a curve are as seen walking from its first point to
//! its last on the map (y down): heading east, left is north. See
//! [`crate::synth::control::curve`] for how widgets, junctions, caps and
//! the reach envelope are interpreted.
//!
//! Parsing ([`Scene::parse`]) touches no file; [`Scene::type_raster`] and
//! [`Scene::freeze_raster`] read the referenced images and check them
//! against the scene and the database.

pub mod bake;
mod controls;
mod error;
pub mod overlay;
mod parse;
mod raster;
mod sculpt;
mod window;

pub use controls::{SceneEdits, polygon_centroid};
pub use error::{SceneError, SceneErrorKind};
pub use raster::stroke_mask;
pub use sculpt::targets_json;
pub use window::WindowedScene;

use crate::synth::control::Lift;
use crate::synth::control::curve::{CurveSpec, JunctionHeight};
use crate::synth::control::sculpt::{BrushStroke, TargetGrid};
use glam::DVec2;
use std::path::{Path, PathBuf};

/// Height limits of every `*_m` height, metres.
pub const MAX_ABS_HEIGHT_M: f64 = 20000.0;

/// A parsed, validated scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// The file it came from (for error messages and relative paths).
    pub file: PathBuf,
    /// Database path, resolved against the scene's folder; `None` = the
    /// embedded default.
    pub database: Option<PathBuf>,
    pub width: usize,
    pub height: usize,
    pub seed: u32,
    pub jitter: f64,
    pub passes: u32,
    pub start_exemplar: Option<usize>,
    pub points: Vec<PointSpec>,
    pub curves: Vec<CurveItem>,
    pub junctions: Vec<JunctionHeight>,
    pub types: Option<TypePaint>,
    pub freeze: Option<Freeze>,
    pub pastes: Vec<PasteSpec>,
    /// Sculpt brush strokes, in order (later ones paint over earlier ones).
    pub sculpt: Vec<SculptSpec>,
}

/// A sculpt stroke as written in the scene: the brush as painted and the
/// target heights it was baked into ([`crate::synth::control::sculpt`]).
/// `targets` is None only for a stroke an editor has yet to bake: the
/// synthesis refuses it, naming it.
#[derive(Debug, Clone, PartialEq)]
pub struct SculptSpec {
    pub stroke: BrushStroke,
    pub targets: Option<TargetGrid>,
}

/// A point constraint as written in the scene.
#[derive(Debug, Clone, PartialEq)]
pub struct PointSpec {
    pub id: String,
    pub at: DVec2,
    pub height_m: f64,
    pub slope_deg: f64,
    pub slope_direction_deg: f64,
    pub radius_px: f64,
}

/// A curve constraint as written in the scene.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveItem {
    pub id: String,
    pub spec: CurveSpec,
}

/// A painted stroke: a polyline (or one point) with a radius.
#[derive(Debug, Clone, PartialEq)]
pub struct Stroke {
    pub points: Vec<DVec2>,
    pub radius_px: f64,
}

/// Type paint.
#[derive(Debug, Clone, PartialEq)]
pub enum TypePaint {
    /// An index image (resolved path) with names beside it.
    Image(PathBuf),
    /// Strokes with type names, painted in order; `None` is an eraser
    /// (paints "unconstrained"), so an editor's brush and eraser both stay
    /// a list of strokes that later ones paint over.
    Strokes(Vec<(Option<String>, Stroke)>),
}

/// Frozen regions.
#[derive(Debug, Clone, PartialEq)]
pub enum Freeze {
    /// A mask image (resolved path); non-zero = frozen.
    Mask(PathBuf),
    /// Strokes painted in order: `true` freezes, `false` (an eraser) thaws.
    Strokes(Vec<(bool, Stroke)>),
}

/// Where a paste copies from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PasteSource {
    /// The synthesized terrain (the previous frame of a session).
    Terrain,
    /// An exemplar of the database, by index.
    Exemplar(usize),
}

/// A copy-paste.
#[derive(Debug, Clone, PartialEq)]
pub struct PasteSpec {
    pub id: String,
    pub source: PasteSource,
    /// The lasso, in source pixels.
    pub lasso: Vec<DVec2>,
    /// Where the lasso's centroid is pasted, output pixels.
    pub to: DVec2,
    pub delta_m: f64,
    /// What δ is added to (version 2's default: the ground).
    pub lift: Lift,
}

impl Scene {
    /// Reads and parses a scene file.
    pub fn read(path: &Path) -> Result<Scene, SceneError> {
        let bytes = std::fs::read(path).map_err(|e| {
            SceneError::new(
                path,
                "$",
                SceneErrorKind::Io(crate::io::IoError::os(path, e)),
            )
        })?;
        Scene::parse(&bytes, path)
    }

    /// Parses scene JSON; `file` names it in errors and anchors relative
    /// paths. Reads no files.
    pub fn parse(bytes: &[u8], file: &Path) -> Result<Scene, SceneError> {
        parse::scene(bytes, file)
    }

    fn err(&self, path: impl Into<String>, kind: SceneErrorKind) -> SceneError {
        SceneError::new(&self.file, path, kind)
    }

    /// The curve constraints' specs, in scene order.
    pub fn curve_specs(&self) -> Vec<CurveSpec> {
        self.curves.iter().map(|c| c.spec.clone()).collect()
    }
}
