//! Realism measured (issue 14; the method of `../shared/REALISM.md`):
//! how far a synthesized terrain is from a real one, in units of how far
//! the real one is from itself.
//!
//! Descriptors, each computed on a heightfield in metres with its true cell
//! size (one line each; [`DESCRIPTORS`] holds the same lines for `eval --help`):
//!
//! | id | kind | what |
//! |---|---|---|
//! | `slope` | distribution | Horn slope of every interior cell, degrees — steepness |
//! | `laplacian` | distribution | 5-point Laplacian (N+S+E+W−4h)/cell², 1/m — sharpness of ridges (−) and valleys (+) |
//! | `tpi` | distribution | topographic position index: height minus the 11×11 mean, m — local prominence |
//! | `roughness` | distribution | standard deviation of the 3×3 heights, m — fine texture |
//! | `drainage` | distribution | log₁₀ D8 drainage area (cells) of every cell, raw surface — the channel network |
//! | `pits` | scalar | fraction of interior cells lower than all 8 neighbours — undrained dimples |
//! | `olsen` | scalar | Olsen's erosion score ε = std / mean of the slope — eroded (high) vs noise (low) |
//! | `beta` | scalar | spectral slope β of P(f) ∝ f^−β, fitted over wavelengths 4–64 cells — balance of scales |
//! | `hypsometric` | scalar | hypsometric integral (mean − min) / (max − min) of the heights — how much stands high |
//!
//! Reported beside them, not in the ratio: **relief** (the 1st–99th
//! percentile height range, m: robust to single spikes), the **median
//! slope** (degrees) and the share of the area in **closed** depressions
//! ([`drainage::closed_share`]: the area more than
//! [`drainage::CLOSED_DEPTH_M`] below its spill level — water with no
//! valley out).
//!
//! Distances ([`distance`]): distributions by the Wasserstein-1 distance of
//! 199 quantiles over the pooled 10–90 % range; scalars by |a−b|/(|a|+|b|).
//! The **realism ratio** ([`compare`](fn@compare)) is the mean over the nine
//! descriptors of d(synthesis, reference) / max(d(left half, right half),
//! [`compare::FLOOR`]) of the reference: 1.0 = as different as the real
//! terrain is from itself. Type usage ([`types`]) reads a coordinates map.

pub mod compare;
pub mod curvature;
pub mod distance;
pub mod drainage;
pub mod elevation;
mod error;
pub mod fft;
pub mod novelty;
pub mod plot;
pub mod roughness;
pub mod slope;
pub mod spectrum;
pub mod types;

pub use compare::{Comparison, Reference, compare};
pub use distance::Sample;
pub use error::EvalError;
pub use spectrum::Spectrum;
pub use types::{TypeUsage, type_usage};

use crate::heightfield::{FirstNodata, Heightfield};
use rayon::prelude::*;

/// Whether a descriptor is a distribution over cells or one number.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    Distribution,
    Scalar,
}

/// What a descriptor is, for tables, plots and `--help`.
#[derive(Debug, Clone, Copy)]
pub struct Info {
    pub id: &'static str,
    /// Unit of its values ("" when unit-free).
    pub unit: &'static str,
    pub kind: Kind,
    /// One line: what it measures.
    pub doc: &'static str,
}

const fn info(id: &'static str, unit: &'static str, kind: Kind, doc: &'static str) -> Info {
    Info {
        id,
        unit,
        kind,
        doc,
    }
}

/// The descriptors of the realism ratio, in report order: five
/// distributions, then four scalars.
pub const DESCRIPTORS: [Info; 9] = [
    info(
        "slope",
        "deg",
        Kind::Distribution,
        "Horn slope of every interior cell, degrees: steepness",
    ),
    info(
        "laplacian",
        "1/m",
        Kind::Distribution,
        "5-point Laplacian (N+S+E+W-4h)/cell^2: sharpness of ridges (-) and valleys (+)",
    ),
    info(
        "tpi",
        "m",
        Kind::Distribution,
        "topographic position index, height minus the 11x11 mean: local prominence",
    ),
    info(
        "roughness",
        "m",
        Kind::Distribution,
        "standard deviation of the 3x3 heights: fine texture",
    ),
    info(
        "drainage",
        "log10 cells",
        Kind::Distribution,
        "log10 D8 drainage area of every cell, on the raw surface: the channel network",
    ),
    info(
        "pits",
        "fraction",
        Kind::Scalar,
        "fraction of interior cells lower than all 8 neighbours: undrained dimples",
    ),
    info(
        "olsen",
        "",
        Kind::Scalar,
        "Olsen's erosion score, std / mean of the slope: eroded (high) vs noise (low)",
    ),
    info(
        "beta",
        "",
        Kind::Scalar,
        "spectral slope beta of P(f) ~ f^-beta, fitted over wavelengths 4-64 cells: balance of scales",
    ),
    info(
        "hypsometric",
        "",
        Kind::Scalar,
        "hypsometric integral (mean - min) / (max - min) of the heights: how much stands high",
    ),
];

/// Index of a descriptor in [`DESCRIPTORS`] (and in [`Descriptors::values`]).
pub mod id {
    pub const SLOPE: usize = 0;
    pub const LAPLACIAN: usize = 1;
    pub const TPI: usize = 2;
    pub const ROUGHNESS: usize = 3;
    pub const DRAINAGE: usize = 4;
    pub const PITS: usize = 5;
    pub const OLSEN: usize = 6;
    pub const BETA: usize = 7;
    pub const HYPSOMETRIC: usize = 8;
}

/// The descriptor lines of `eval --help`, with the extras and distances.
pub fn help_text() -> String {
    let mut s = String::from("Descriptors (each compared between the terrains):\n");
    for d in &DESCRIPTORS {
        let kind = match d.kind {
            Kind::Distribution => "distribution",
            Kind::Scalar => "scalar",
        };
        s += &format!("  {} ({kind}):\n      {}\n", d.id, d.doc);
    }
    s += &format!(
        "Also reported, not in the ratio: relief (1st-99th percentile height range, m), the \
         median slope (deg) and the closed share (the area more than {} m below its spill level, \
         water with no valley out).\n\
         Distances: distributions by the Wasserstein-1 distance of 199 quantiles over the pooled \
         10-90 % range; scalars by |a-b|/(|a|+|b|). Realism ratio: the mean over descriptors of \
         d(synthesis, reference) / max(d(reference left half, right half), {}); 1.0 = as \
         different as the real terrain is from itself.\n",
        drainage::CLOSED_DEPTH_M,
        compare::FLOOR
    );
    s
}

/// One descriptor's value on one terrain.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    Distribution(Sample),
    Scalar(f64),
}

impl Value {
    /// The number a table shows: the median of a distribution, or the scalar.
    pub fn summary(&self) -> f64 {
        match self {
            Value::Distribution(s) => s.median(),
            Value::Scalar(v) => *v,
        }
    }
}

/// Every descriptor of one terrain.
#[derive(Debug, Clone, PartialEq)]
pub struct Descriptors {
    pub width: usize,
    pub height: usize,
    pub cell_size: f64,
    /// In [`DESCRIPTORS`] order.
    pub values: Vec<Value>,
    pub spectrum: Spectrum,
    /// The 1st–99th percentile height range, metres.
    pub relief: f64,
    /// [`drainage::closed_share`], a fraction of the area.
    pub closed: f64,
}

impl Descriptors {
    pub fn median_slope(&self) -> f64 {
        self.values[id::SLOPE].summary()
    }
    pub fn pits(&self) -> f64 {
        self.values[id::PITS].summary()
    }
}

/// Smallest side [`describe`] accepts: room for the 11×11 TPI window and a
/// spectrum with a few bins in its band.
pub const MIN_SIDE: usize = 16;

/// Computes every descriptor of a terrain (in parallel; ~0.5 s for 1024² on
/// 2 cores). Nodata is refused: no descriptor is defined across a hole.
pub fn describe(hf: &Heightfield) -> Result<Descriptors, EvalError> {
    let (w, h) = (hf.width(), hf.height());
    if w < MIN_SIDE || h < MIN_SIDE {
        return Err(EvalError::TooSmall {
            width: w,
            height: h,
            min: MIN_SIDE,
        });
    }
    check_nodata(hf)?;
    let ((spectrum, (drainage, closed)), (slope, rest)) = rayon::join(
        || {
            rayon::join(
                || spectrum::spectrum(hf),
                || {
                    rayon::join(
                        || Sample::new(drainage::log_area(hf)),
                        || drainage::closed_share(hf),
                    )
                },
            )
        },
        || {
            let slope = Sample::new(slope::slope_degrees(hf));
            let rest = [
                curvature::laplacian as fn(&Heightfield) -> Vec<f32>,
                curvature::tpi,
                roughness::roughness,
            ]
            .par_iter()
            .map(|f| Sample::new(f(hf)))
            .collect::<Vec<_>>();
            (slope, rest)
        },
    );
    let heights = Sample::new(hf.data().to_vec());
    let olsen = slope::olsen_epsilon(&slope);
    let [laplacian, tpi, roughness]: [Sample; 3] = rest.try_into().expect("three descriptors");
    let values = vec![
        Value::Distribution(slope),
        Value::Distribution(laplacian),
        Value::Distribution(tpi),
        Value::Distribution(roughness),
        Value::Distribution(drainage),
        Value::Scalar(drainage::pit_fraction(hf)),
        Value::Scalar(olsen),
        Value::Scalar(spectrum.beta),
        Value::Scalar(elevation::hypsometric_integral(&heights)),
    ];
    Ok(Descriptors {
        width: w,
        height: h,
        cell_size: hf.cell_size(),
        values,
        spectrum,
        relief: elevation::relief(&heights),
        closed,
    })
}

/// Refuses a terrain with nodata, naming its first hole.
pub(crate) fn check_nodata(hf: &Heightfield) -> Result<(), EvalError> {
    match hf.first_nodata() {
        Some(FirstNodata { count, x, y }) => Err(EvalError::Nodata { count, x, y }),
        None => Ok(()),
    }
}

/// A cell's neighbourhood, read by offset.
pub(crate) struct Nbhd<'a> {
    data: &'a [f32],
    width: usize,
    index: usize,
}

impl Nbhd<'_> {
    /// The height at offset (dx, dy), metres.
    #[inline(always)]
    pub fn at(&self, dx: isize, dy: isize) -> f64 {
        self.data[(self.index as isize + dy * self.width as isize + dx) as usize] as f64
    }
}

/// `f` of every cell at least `margin` cells from each edge, row-major
/// (`(w − 2·margin) × (h − 2·margin)` values; none if the terrain is
/// narrower), rows in parallel.
pub(crate) fn interior(
    hf: &Heightfield,
    margin: usize,
    f: impl Fn(&Nbhd) -> f32 + Sync,
) -> Vec<f32> {
    let (w, h) = (hf.width(), hf.height());
    if w <= 2 * margin || h <= 2 * margin {
        return Vec::new();
    }
    let iw = w - 2 * margin;
    let mut out = vec![0.0f32; iw * (h - 2 * margin)];
    out.par_chunks_mut(iw).enumerate().for_each(|(j, row)| {
        let y = j + margin;
        for (i, o) in row.iter_mut().enumerate() {
            *o = f(&Nbhd {
                data: hf.data(),
                width: w,
                index: y * w + i + margin,
            });
        }
    });
    out
}
