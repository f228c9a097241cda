//! Sketch-driven patch synthesis (seeds 001 and 004): a ridge/valley sketch
//! becomes a terrain assembled from patches of many real DEMs.
//!
//! Pipeline ([`synthesize`]), one module per stage:
//! 1. [`sketch`] → signed field; [`ppa`] ridges and valleys on it (and, once
//!    per source, on every DEM: [`candidates::PreparedSource`]);
//! 2. [`graph`]: key nodes and paths; breadth-first patch centres along
//!    the sketch's features, control points on a circle of radius patch/4;
//! 3. [`candidates`] × [`costs`]: per user patch, round one scores every
//!    source feature node of the same kind and degree under 10 transforms
//!    (integer feature-profile + angle cost, data-parallel) and keeps the best
//!    5 per source; round two warps those by a thin-plate spline onto the
//!    sketch's control points and adds bending energy, SSD against what is
//!    already placed, noise-variance difference and a repetition penalty;
//!    the best 5 of that get a graph-cut seam cost, and the cheapest wins;
//! 4. [`merge`]: graph-cut seam ([`graphcut`]; finalists ranked by a
//!    half-resolution cut, the winner cut coarse to fine in bands),
//!    Shepard-interpolated gradient correction and a multigrid-preconditioned
//!    Poisson solve;
//! 5. [`hole_fill`]: the rest, by priority order, from non-feature candidates
//!    under 6 transforms (integer SSD + noise on an 8× reduced grid through
//!    an explicit-SIMD kernel, then the same second round and merge);
//! 6. the broad drift of the merge is removed ([`remove_drift`]), the
//!    sketch's broad shape added ([`deform_by_sketch`]), the pits the joins
//!    between patches made raised ([`join_pits`]) and the lowest point put
//!    at the sources' typical lowest level.
//!
//! Only the sources whose relief fits the library's take part
//! ([`Library`], `input::library::MAX_STRETCH`).
//!
//! [`sketch`]: input::sketch
//! [`ppa`]: input::ppa
//! [`candidates::PreparedSource`]: place::candidates::PreparedSource
//! [`graph`]: input::graph
//! [`candidates`]: place::candidates
//! [`costs`]: place::costs
//! [`graphcut`]: merge::graphcut
//! [`hole_fill`]: fill::hole_fill
//! [`join_pits`]: merge::join_pits
//! [`cache`]: input::cache
//!
//! Sources are prepared once per [`Library`] and their features kept on
//! disk between processes ([`cache`]).
//!
//! Everything is deterministic: no randomness; parallel loops write
//! per-candidate results that are reduced in index order with ties broken
//! by index, so the bytes do not depend on the thread count.

pub mod fill;
pub mod input;
pub mod merge;
pub mod place;

mod driver;
mod params;
mod report;

pub(crate) use driver::solve_opts;
pub use driver::{synthesize, synthesize_with};
pub use input::library::Library;
pub use merge::broad_shape::{deform_by_sketch, remove_drift};
pub use params::{Params, PatchError, Weights};
pub use place::placement::{
    UserPatch, sketch_field, sketch_graph, sketch_merge_len, sketch_ppa_params, user_patches,
};
pub(crate) use place::round2::{Scored, round2_cost, select, user_window};
pub use place::warp::{detrend, feature_warp, sample_warped};
pub use report::adherence::adherence;
pub use report::{Stats, Synthesis, Timings};
