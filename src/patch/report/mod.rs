//! What a finished synthesis hands back: the heightfield and sketch graphs
//! ([`Synthesis`]) with the wall time per stage and the counts of the run.

pub(crate) mod adherence;

use crate::Heightfield;
use crate::patch::input::graph::FeatureGraph;
use std::time::Duration;

/// Wall time per stage.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Timings {
    /// Sketch rasterisation, PPA and feature graph.
    pub sketch: Duration,
    /// Round one of feature candidates (integer, data-parallel).
    pub feature_round1: Duration,
    /// Round two: TPS warp, SSD, noise, graph-cut costs.
    pub feature_round2: Duration,
    /// Seams, Shepard and Poisson for feature patches.
    pub feature_merge: Duration,
    /// Priority and round one of hole filling.
    pub fill_round1: Duration,
    pub fill_round2: Duration,
    pub fill_merge: Duration,
    pub total: Duration,
}

/// Counts that describe a run.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Stats {
    pub user_patches: usize,
    pub feature_patches: usize,
    pub fill_patches: usize,
    /// Candidates scored in round one (feature, fill).
    pub round1_feature: u64,
    pub round1_fill: u64,
    /// Worst relative residual of the Poisson solves.
    pub worst_residual: f64,
    /// Pits on the joins between patches raised to their lowest neighbour
    /// ([`crate::patch::merge::join_pits`]).
    pub join_pits: usize,
}

/// A finished synthesis.
#[derive(Debug, Clone)]
pub struct Synthesis {
    pub heightfield: Heightfield,
    pub ridges: FeatureGraph,
    pub valleys: FeatureGraph,
    pub timings: Timings,
    pub stats: Stats,
    /// Which of the library's sources each output pixel was cut from
    /// (row-major, an index into [`Library::sources`]), for measuring a
    /// result against the DEMs it is made of.
    ///
    /// [`Library::sources`]: crate::patch::Library::sources
    pub sources: Vec<u32>,
}
