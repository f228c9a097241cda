//! What a synthesis takes and gives: its settings, the control inputs per
//! level, the errors it reports, and its result with per-level timings.

use crate::backend::BackendError;
use crate::heightfield::Heightfield;
use crate::level::fixed::Coord;
use crate::stages::correct::nudge::Target;
use std::time::Duration;
use thiserror::Error;

/// Synthesis settings (paper defaults).
#[derive(Debug, Clone)]
pub struct Params {
    /// Jitter amplitude r of eq. 1, in texels (0 = none; paper: 0.4).
    pub jitter: f64,
    /// Correction passes per level (paper: 2), each of four subpasses; the
    /// level a jittered start is laid at takes up to four times as many for
    /// exemplars smooth at the pixel scale
    /// ([`Synthesizer::level_passes`](super::Synthesizer::level_passes)).
    pub passes: u32,
    /// The exemplar synthesis starts from: its pieces make the coarse start
    /// (see [`super::coarse`]), or without jitter its centre; the output
    /// takes its cell size. `None`: pieces from every exemplar (each place
    /// by the altitude of its surroundings, so each exemplar and terrain
    /// type by its share of the database's altitudes), exemplar 0's centre
    /// without jitter, and exemplar 0's cell size.
    pub start_exemplar: Option<usize>,
    /// Side, in output pixels, of the exemplar pieces the coarse start lays
    /// (one of [`PIECE_SIZES`]; rounded to whole texels of the start
    /// level): the knob between new and faithful. Small pieces (the
    /// default, 32) make landforms the exemplars do not hold — no 64-px
    /// window is one piece; large ones keep the exemplars' own landforms,
    /// massifs and valley networks whole, and copy them (a world shows
    /// them again and again).
    pub piece_size: usize,
    /// Height prior weight P of the correction (one of
    /// `crate::stages::correct::PRIORS`; 0 is the paper's pure relative height
    /// matching). See the `correct` stage's module docs.
    pub prior: u32,
    /// The finest level at which each source u also offers its most
    /// similar texel C₂ as a candidate (the paper's k = 2); finer levels
    /// score C₁ alone (k = 1). 0: k = 2 everywhere, as in the paper.
    ///
    /// Why 1: at level 0, C₂ won 0.17 % of the pixels of a 1024²
    /// synthesis (0.15–0.22 % at every level: κ = 2 and the height prior
    /// rarely let it), yet scoring it took ~16 % of level 0's
    /// instructions and its texels were the level's farthest reads.
    /// Without it at level 0 the realism protocol (8 DEMs × 9 seeds) gave
    /// the same mean ratio, 0.520; without it at levels 0–1 too, 0.522
    /// (olympic 0.244 → 0.262), and at every level 0.532, so the coarse
    /// levels keep it: a C₂ there starts a patch from elsewhere in the
    /// exemplars.
    pub similar_from: usize,
    /// Keep every level's S and V in the result, for inspection.
    pub keep_levels: bool,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            jitter: 0.4,
            passes: 2,
            start_exemplar: None,
            piece_size: DEFAULT_PIECE_SIZE,
            prior: crate::stages::correct::DEFAULT_PRIOR,
            similar_from: 1,
            keep_levels: false,
        }
    }
}

/// The piece sizes of the coarse start (output pixels; see
/// [`Params::piece_size`]).
pub const PIECE_SIZES: std::ops::RangeInclusive<usize> = 8..=1024;

/// The default piece size: half the novelty measure's window.
pub const DEFAULT_PIECE_SIZE: usize = 32;

/// Invalid synthesis requests.
#[non_exhaustive]
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SynthError {
    #[error("jitter {0} is invalid: expected 0..=4 texels")]
    Jitter(f64),
    #[error("passes {0} is invalid: expected 0..=16")]
    Passes(u32),
    #[error("height prior {0} is invalid: expected one of {list:?}", list = crate::stages::correct::PRIORS)]
    Prior(u32),
    #[error("start exemplar {index} does not exist: the database has {count} (0..={max})", max = count - 1)]
    StartExemplar { index: usize, count: usize },
    #[error("piece size {0} is invalid: expected {min}..={max} pixels", min = PIECE_SIZES.start(), max = PIECE_SIZES.end())]
    PieceSize(usize),
    #[error(transparent)]
    Size(#[from] crate::size::SizeError),
    #[error(transparent)]
    Window(#[from] super::windowed::WindowError),
    #[error(transparent)]
    Backend(#[from] BackendError),
}

/// One level's final state, kept when [`Params::keep_levels`] is set.
#[derive(Debug, Clone)]
pub struct LevelMaps {
    pub level: usize,
    /// Absolute position of pixel (0, 0) in its level: (0, 0) for a whole
    /// level, a window's cone region's corner otherwise.
    pub origin: [usize; 2],
    pub width: usize,
    pub height: usize,
    /// Exemplar coordinates (fixed point; atlas units of this level, or of
    /// level L above it).
    pub coords: Vec<Coord>,
    /// Height offsets, in database units.
    pub offsets: Vec<i32>,
}

/// Where the time went.
#[derive(Debug, Clone, Default)]
pub struct Timings {
    /// Per level (index = level): upsample, correct, total.
    pub levels: Vec<LevelTiming>,
    pub reconstruct: Duration,
    pub total: Duration,
    /// Stage times are the device's own (GPU timestamp queries), not wall
    /// clock.
    pub device_clock: bool,
}

#[derive(Debug, Clone, Copy, Default)]
pub struct LevelTiming {
    pub upsample: Duration,
    pub correct: Duration,
}

/// The result of a synthesis.
#[derive(Debug, Clone)]
pub struct Synthesis {
    pub heightfield: Heightfield,
    /// Levels M..0 when kept (index = level).
    pub levels: Vec<LevelMaps>,
    pub timings: Timings,
}

/// Control inputs of one synthesis, per level (index = level; levels the
/// correction never visits are ignored).
#[derive(Debug, Default, PartialEq)]
pub struct Guides {
    pub levels: Vec<LevelGuide>,
    /// Re-synthesize only where this frame can differ from the previous
    /// one: at each level, the window around the pixels whose inputs
    /// changed and the children of the parent level's changed pixels,
    /// widened by how far 4·passes subpasses carry a change. Outside it
    /// every pixel's inputs equal the previous frame's (a weight may only
    /// have dropped to frozen, which keeps the previous result), so its
    /// previous per-pass results are what it would compute: restricted and
    /// full re-synthesis give the same bytes (tested).
    pub restrict: bool,
}

/// One level's control rasters (level-sized, row-major).
#[derive(Debug, Default, PartialEq)]
pub struct LevelGuide {
    /// Geometric targets (every level: see `control::blend`).
    pub targets: Option<Vec<Target>>,
    /// Type target sets R^i (levels ≥ 2).
    pub allowed: Option<Vec<u32>>,
    /// Coherence weights W^i in quarters (used when a previous frame exists).
    pub weights: Option<Vec<u8>>,
    /// Bounds `[x0, y0, x1, y1)` of the pixels whose own inputs (targets,
    /// type sets, raised weights, pasted candidates) differ from the
    /// previous frame's; None if none do. Used when [`Guides::restrict`].
    pub dirty: Option<[usize; 4]>,
}

/// Clones that can reuse the target's buffers (`clone_from`): an editor
/// refills a recycled [`crate::synth::session::Snapshot`] without
/// allocating or faulting in new pages.
impl Clone for Guides {
    fn clone(&self) -> Guides {
        Guides {
            levels: self.levels.clone(),
            restrict: self.restrict,
        }
    }

    fn clone_from(&mut self, source: &Guides) {
        self.levels.clone_from(&source.levels);
        self.restrict = source.restrict;
    }
}

impl Clone for LevelGuide {
    fn clone(&self) -> LevelGuide {
        LevelGuide {
            targets: self.targets.clone(),
            allowed: self.allowed.clone(),
            weights: self.weights.clone(),
            dirty: self.dirty,
        }
    }

    fn clone_from(&mut self, source: &LevelGuide) {
        self.targets.clone_from(&source.targets);
        self.allowed.clone_from(&source.allowed);
        self.weights.clone_from(&source.weights);
        self.dirty = source.dirty;
    }
}
