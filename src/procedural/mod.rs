//! The procedural toolbox (seed 002 ch. 4–5 and §7.3) and the terrain
//! styles of `terrasynth generate` made with it.
//!
//! Building blocks, each usable on its own:
//! - [`noise`]: gradient noise from a stateless integer hash;
//! - [`fbm`]: fractal sums (fBm, ridged, billowy) and a heterogeneous multifractal;
//! - [`warp`]: domain warping; [`remap`]: bias, gain, terracing;
//! - [`thermal`] and [`hydraulic`]: erosion as Jacobi iterations;
//! - [`fluvial`]: stream-power incision along the drainage network;
//! - [`mod@creep`]: linear hillslope diffusion;
//! - [`types`]: terrain-type masks derived from a heightfield.
//!
//! [`styles`] combines them into evolved landscapes (alpine, canyon, hills).
//!
//! Everything here is deterministic: the same parameters give the same bits
//! on every machine and at every thread count. Only `+ − × ÷` and `sqrt` are
//! used on floats (exactly rounded by IEEE 754; see [`math`]), every random
//! choice is a hash of (seed, position), and every parallel pass computes
//! each cell from the previous pass's buffers only.

pub mod creep;
pub mod error;
pub mod fbm;
pub mod fluvial;
pub(crate) mod grid;
pub mod hydraulic;
pub mod math;
pub mod noise;
pub mod remap;
pub mod styles;
pub mod thermal;
pub mod types;
pub mod warp;

pub use creep::creep;
pub use error::ProceduralError;
pub use fbm::{Fractal, Multifractal, Shape};
pub use fluvial::{FluvialParams, fluvial_erode};
pub use hydraulic::{Boundary, Budget, Hydraulic, HydraulicParams, hydraulic_erode};
pub use noise::gradient_noise;
pub use styles::Style;
pub use thermal::{ThermalParams, thermal_erode};
pub use types::TypeClassification;
pub use warp::Warp;
