//! Water on a heightfield: depressions filled, flow routed, lakes, the sea
//! and rivers (`terrasynth water`, issue 41).
//!
//! ```text
//! heights ─► sea (optional) ─► fill (priority-flood) ─► flats (drainage gradient)
//!         ─► d8 (receivers) ─► accumulation ─► lakes (water depth) ─► rivers (Strahler, lines)
//! ```
//!
//! Every stage is exact and deterministic (no floating-point sums decide
//! anything; the fill copies heights; the optional MFD accumulation adds
//! in one fixed order), so the same input gives the same rasters on any
//! thread count. The whole chain is O(n) but for the fill's queues, radix
//! heaps ([`fill`]). The fill runs in strips side by side, accumulation
//! beside lakes: see the README's `water` section for the times.
//!
//! [`valleys`] is water's view for synthesis: the valley network a
//! synthesized terrain is given as curve constraints (`synth --valleys`).
//!
//! [`tiled`] computes the same rasters on a world cut into tiles, bit for
//! bit, holding a few tiles at a time (`terrasynth tiles --water`).
//!
//! Every cell drains: the fill leaves no pit, [`flats`] gives every level
//! cell a way down to its flat's outlet, and D8 ([`d8`]) follows heights
//! then that gradient, so following receivers from any cell ends at a
//! border outlet or the sea.

pub mod d8;
pub mod fill;
pub mod flats;
pub mod geojson;
pub mod lakes;
pub mod mfd;
pub mod preview;
pub mod rivers;
pub mod sea;
mod summary;
pub mod tiled;
pub mod valleys;

pub use lakes::{Lake, Thresholds};
pub use summary::Summary;

use crate::heightfield::{FirstNodata, Heightfield};
use std::time::{Duration, Instant};
use thiserror::Error;

/// Why water could not be computed.
#[non_exhaustive]
#[derive(Debug, Error)]
pub enum WaterError {
    #[error(
        "{count} nodata samples (the first at pixel ({x}, {y})): water needs every height; fill them first (terrasynth convert --fill-nodata IN OUT)"
    )]
    Nodata { count: usize, x: usize, y: usize },
    #[error("{name} {value} is invalid: expected {expected}")]
    Param {
        name: &'static str,
        value: f64,
        expected: &'static str,
    },
    #[error(transparent)]
    Io(#[from] crate::io::IoError),
}

/// What to compute.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Params {
    /// Cells joined to the border at or below this level (metres) are sea.
    pub sea_level: Option<f32>,
    /// What makes a filled depression a lake.
    pub lakes: Thresholds,
    /// A river drains at least this upstream area, km².
    pub river_area_km2: f64,
}

impl Default for Params {
    /// No sea; lakes at least 2 m deep and 0.1 km² (about 12 SRTM3 cells,
    /// so the metre-scale dimples of SRTM noise are not lakes); rivers from
    /// 5 km² of upstream area (about 580 cells of 92.6 m: a map's blue
    /// lines, not every gully).
    fn default() -> Self {
        Params {
            sea_level: None,
            lakes: Thresholds {
                min_depth_m: 2.0,
                min_area_km2: 0.1,
            },
            river_area_km2: 5.0,
        }
    }
}

impl Params {
    /// Refuses a non-finite sea level, negative or non-finite lake
    /// thresholds and a river area that is not positive.
    pub fn check(&self) -> Result<(), WaterError> {
        let bad = |name, value: f64, expected| WaterError::Param {
            name,
            value,
            expected,
        };
        if let Some(s) = self.sea_level.filter(|s| !s.is_finite()) {
            return Err(bad("sea level", s as f64, "a finite height in metres"));
        }
        for (name, v) in [
            ("minimum lake depth", self.lakes.min_depth_m),
            ("minimum lake area", self.lakes.min_area_km2),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(bad(name, v, "a finite value >= 0"));
            }
        }
        let r = self.river_area_km2;
        if !(r.is_finite() && r > 0.0) {
            return Err(bad("river area (km²)", r, "a finite value > 0"));
        }
        Ok(())
    }
}

/// How `flow.tif`'s accumulation is routed ([`compute_with`]). Rivers,
/// their Strahler orders and [`Water::receivers`] are D8 whichever it is.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Routing {
    /// All of a cell's flow to its steepest neighbour ([`d8`]).
    #[default]
    D8,
    /// Shared among its lower neighbours by slope ([`mfd`]).
    Mfd,
}

/// Bytes per cell [`compute`] holds at its peak (heights excluded): the
/// filled surface, receivers, accumulation, the flats' gradient, labels
/// and classes, depths, and the rivers' orders.
pub const BYTES_PER_CELL: u64 = 40;

/// Wall time of each stage of [`compute`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Timings {
    pub fill: Duration,
    pub flats: Duration,
    pub d8: Duration,
    /// Accumulation and lakes run side by side (each is one sequential
    /// walk, and neither needs the other): each one's own time.
    pub accumulate: Duration,
    pub lakes: Duration,
    pub rivers: Duration,
    /// The whole of [`compute`]: less than the stages' sum.
    pub wall: Duration,
}

impl Timings {
    /// The wall time of the whole computation.
    pub fn total(&self) -> Duration {
        self.wall
    }
}

/// The water of one heightfield, every raster row-major in its grid.
#[derive(Debug, Clone)]
pub struct Water {
    pub width: usize,
    pub height: usize,
    pub cell_size: f64,
    pub params: Params,
    /// The water surface: depressions filled to their spill level, the
    /// sea at sea level, elsewhere the ground.
    pub filled: Vec<f32>,
    /// D8 receiver of every cell on the filled surface, or [`d8::OUTLET`].
    pub receivers: Vec<u32>,
    /// D8 upstream area of every cell, in cells (itself included).
    pub accumulation: Vec<u32>,
    /// MFD upstream area of every cell in cells, with [`Routing::Mfd`].
    pub mfd_accumulation: Option<Vec<f32>>,
    /// Lakes, sea and water depth.
    pub bodies: lakes::Bodies,
    pub rivers: rivers::Rivers,
    /// Cells the fill raised (lakes and fills too small to be lakes).
    pub filled_cells: usize,
    pub timings: Timings,
}

/// The filled surface, D8 receivers and accumulation of `heights` (no NaN)
/// with flats resolved: what `masks` shows as flow.
pub struct Routed {
    pub filled: Vec<f32>,
    pub receivers: Vec<u32>,
    pub accumulation: Vec<u32>,
}

fn check_heights(hf: &Heightfield) -> Result<(), WaterError> {
    match hf.first_nodata() {
        Some(FirstNodata { count, x, y }) => Err(WaterError::Nodata { count, x, y }),
        None => Ok(()),
    }
}

/// Fills and routes a heightfield (no sea): the filled surface, receivers
/// and accumulation.
pub fn route(hf: &Heightfield) -> Result<Routed, WaterError> {
    check_heights(hf)?;
    let (w, h) = (hf.width(), hf.height());
    let filled = fill::priority_flood(hf.data(), w, h, None);
    let grad = flats::gradient(&filled, w, h, None);
    let receivers = d8::receivers(
        &surface(&filled, w, h, grad.as_deref(), None),
        d8::Edges::Inside,
    );
    let accumulation = d8::accumulate(&receivers);
    Ok(Routed {
        filled,
        receivers,
        accumulation,
    })
}

fn surface<'a>(
    filled: &'a [f32],
    width: usize,
    height: usize,
    gradient: Option<&'a [u32]>,
    sinks: Option<&'a [bool]>,
) -> d8::Surface<'a> {
    d8::Surface {
        heights: filled,
        width,
        height,
        gradient,
        sinks,
    }
}

/// Cells of `cell_size` metres making `area_km2` (at least one).
fn threshold_cells(area_km2: f64, cell_size: f64) -> u32 {
    (area_km2 * 1e6 / (cell_size * cell_size))
        .ceil()
        .clamp(1.0, u32::MAX as f64) as u32
}

/// `f`'s result and how long it took.
fn timed<T>(f: impl FnOnce() -> T) -> (T, Duration) {
    let clock = Instant::now();
    let v = f();
    (v, clock.elapsed())
}

/// Computes the water of a heightfield with D8 routing. Refuses nodata,
/// invalid parameters, and grids whose working memory exceeds what is
/// available.
pub fn compute(hf: &Heightfield, params: &Params) -> Result<Water, WaterError> {
    compute_with(hf, params, Routing::D8)
}

/// [`compute`], with the accumulation also routed by `routing`
/// ([`Water::mfd_accumulation`]).
pub fn compute_with(
    hf: &Heightfield,
    params: &Params,
    routing: Routing,
) -> Result<Water, WaterError> {
    params.check()?;
    check_heights(hf)?;
    let (w, h, cell) = (hf.width(), hf.height(), hf.cell_size());
    let per_cell = match routing {
        Routing::D8 => BYTES_PER_CELL,
        Routing::Mfd => BYTES_PER_CELL + mfd::BYTES_PER_CELL,
    };
    crate::io::check_memory(
        &format!("water on a {w}x{h} heightfield"),
        per_cell * (w * h) as u64,
    )?;
    let data = hf.data();
    let start = Instant::now();
    let (filled, fill_time) = timed(|| {
        let sea = params.sea_level.map(|l| sea::mask(data, w, h, l));
        let filled = fill::priority_flood(data, w, h, sea.as_deref().zip(params.sea_level));
        (filled, sea)
    });
    let (filled, sea) = filled;
    let sea = sea.as_deref();
    let (grad, flats_time) = timed(|| flats::gradient(&filled, w, h, sea));
    let routed = surface(&filled, w, h, grad.as_deref(), sea);
    let (receivers, d8_time) = timed(|| d8::receivers(&routed, d8::Edges::Inside));
    // MFD's time counts as accumulation's.
    let (mfd_accumulation, mfd_time) =
        timed(|| (routing == Routing::Mfd).then(|| mfd::accumulate(&routed)));
    drop(grad);
    let ((accumulation, accumulate_time), ((bodies, filled_cells), lakes_time)) = rayon::join(
        || timed(|| d8::accumulate(&receivers)),
        || {
            timed(|| {
                let bodies = lakes::find(data, &filled, (w, h, cell), sea, params.lakes);
                let filled_cells = filled
                    .iter()
                    .zip(data)
                    .zip(&bodies.class)
                    .filter(|((f, z), c)| f > z && **c != lakes::SEA)
                    .count();
                (bodies, filled_cells)
            })
        },
    );
    let threshold = threshold_cells(params.river_area_km2, cell);
    let (rivers, rivers_time) =
        timed(|| rivers::trace(&receivers, &accumulation, &bodies.class, threshold));
    let t = Timings {
        fill: fill_time,
        flats: flats_time,
        d8: d8_time,
        accumulate: accumulate_time + mfd_time,
        lakes: lakes_time,
        rivers: rivers_time,
        wall: start.elapsed(),
    };
    Ok(Water {
        width: w,
        height: h,
        cell_size: cell,
        params: *params,
        filled,
        receivers,
        accumulation,
        mfd_accumulation,
        bodies,
        rivers,
        filled_cells,
        timings: t,
    })
}

impl Water {
    /// What `flow.tif` holds: the MFD accumulation when it was asked for,
    /// else D8's, in cells.
    pub fn flow(&self) -> Vec<f32> {
        match &self.mfd_accumulation {
            Some(m) => m.clone(),
            None => self.accumulation.iter().map(|&a| a as f32).collect(),
        }
    }

    /// The rivers' threshold in cells.
    pub fn river_threshold_cells(&self) -> u32 {
        threshold_cells(self.params.river_area_km2, self.cell_size)
    }

    /// A raster of this grid as a heightfield with `hf`'s cell size and
    /// georeference (for writing beside it).
    pub fn raster(&self, like: &Heightfield, values: Vec<f32>) -> Heightfield {
        let mut out = Heightfield::from_vec(self.width, self.height, self.cell_size, values)
            .expect("a raster of the input's size and cell size");
        out.set_georef(like.georef().cloned());
        out
    }
}
