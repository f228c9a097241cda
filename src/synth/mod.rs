//! Coarse-to-fine parallel synthesis (paper §4, DESIGN §3, §5, §6).
//!
//! Levels M..0 of any output size: level M is 2×2, initialised at the centre
//! of the start exemplar; each finer level is `upsample_jitter` of the one
//! above and, at levels ≤ L (the database's coarsest), `passes` correction
//! passes of four interleaved subpasses; `reconstruct` turns level 0 into
//! metres. Every stage is integer arithmetic and every random choice a hash,
//! so the output bytes depend only on the database, the parameters and the
//! seed — never on the thread count.

pub mod atlas;
pub mod control;
pub mod fixed;
pub mod stages;
pub mod state;

use crate::backend::{Backend, BackendError, Choice, cpu::Cpu};
use crate::database::Database;
use crate::heightfield::Heightfield;
use atlas::AtlasLevel;
use fixed::{Coord, FRAC_BITS};
use stages::correct::{CorrectParams, SUBPASSES};
use stages::reconstruct::HEIGHT_FRAC_BITS;
use stages::upsample_jitter::{Step, UpsampleParams};
use state::{State, level_size, top_level};
use std::time::{Duration, Instant};
use thiserror::Error;

/// With jitter, synthesis starts this many levels above the database's
/// coarsest level L, from hash-chosen exemplar positions (see
/// `Synthesizer::initial`): level L starts as a mosaic of 2^b × 2^b blocks.
pub const COARSE_BLOCK_BITS: usize = 2;

/// Hash salt of the coarse start positions (kept apart from the jitter's
/// `hash4(seed, level, x, y)`, whose level is always < 2^16).
const COARSE_SALT: u32 = 0xC0A5_0000;

/// Synthesis settings (paper defaults).
#[derive(Debug, Clone)]
pub struct Params {
    /// Jitter amplitude r of eq. 1, in texels (0 = none; paper: 0.4).
    pub jitter: f64,
    /// Correction passes per level (paper: 2), each of four subpasses.
    pub passes: u32,
    /// Exemplar whose centre initialises the coarsest level.
    pub start_exemplar: usize,
    /// Keep every level's S and V in the result, for inspection.
    pub keep_levels: bool,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            jitter: 0.4,
            passes: 2,
            start_exemplar: 0,
            keep_levels: false,
        }
    }
}

/// Invalid synthesis requests.
#[non_exhaustive]
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SynthError {
    #[error("jitter {0} is invalid: expected 0..=4 texels")]
    Jitter(f64),
    #[error("passes {0} is invalid: expected 0..=16")]
    Passes(u32),
    #[error("start exemplar {index} does not exist: the database has {count} (0..={max})", max = count - 1)]
    StartExemplar { index: usize, count: usize },
    #[error(transparent)]
    Size(#[from] crate::error::SizeError),
    #[error(transparent)]
    Backend(#[from] BackendError),
}

/// One level's final state, kept when [`Params::keep_levels`] is set.
#[derive(Debug, Clone)]
pub struct LevelMaps {
    pub level: usize,
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

/// Synthesizes terrain from one database, on the CPU unless
/// [`Synthesizer::use_backend`] moved it to the GPU.
pub struct Synthesizer<'db> {
    db: &'db Database,
    params: Params,
    atlas: Vec<AtlasLevel<'db>>,
    jitter: i32,
    #[cfg(feature = "gpu")]
    gpu: Option<crate::backend::gpu::Gpu>,
}

impl<'db> Synthesizer<'db> {
    pub fn new(db: &'db Database, params: Params) -> Result<Self, SynthError> {
        if !(0.0..=4.0).contains(&params.jitter) {
            return Err(SynthError::Jitter(params.jitter));
        }
        if params.passes > 16 {
            return Err(SynthError::Passes(params.passes));
        }
        let count = db.meta().exemplars.len();
        if params.start_exemplar >= count {
            return Err(SynthError::StartExemplar {
                index: params.start_exemplar,
                count,
            });
        }
        let atlas = (0..db.level_count())
            .map(|i| AtlasLevel::new(db, i))
            .collect();
        let jitter = (params.jitter * (1 << FRAC_BITS) as f64).round() as i32;
        Ok(Synthesizer {
            db,
            params,
            atlas,
            jitter,
            #[cfg(feature = "gpu")]
            gpu: None,
        })
    }

    /// Moves the stages to the backend `choice` names. Returns a one-line
    /// notice when [`Choice::Auto`] found no GPU and stays on the CPU.
    pub fn use_backend(&mut self, choice: Choice) -> Result<Option<String>, SynthError> {
        #[cfg(feature = "gpu")]
        {
            let ctx = match choice {
                Choice::Cpu => {
                    self.gpu = None;
                    return Ok(None);
                }
                Choice::Gpu => crate::backend::gpu::Context::new()?,
                Choice::Auto => match crate::backend::gpu::Context::new() {
                    Ok(ctx) => ctx,
                    Err(e) => {
                        self.gpu = None;
                        return Ok(Some(format!("{e}; using the CPU")));
                    }
                },
            };
            self.use_gpu(ctx)?;
            Ok(None)
        }
        #[cfg(not(feature = "gpu"))]
        match choice {
            Choice::Cpu => Ok(None),
            Choice::Gpu => Err(BackendError::NotCompiled.into()),
            Choice::Auto => Ok(Some(format!(
                "{}; using the CPU",
                BackendError::NotCompiled
            ))),
        }
    }

    /// Runs the stages on the GPU of `ctx` (uploads the database once).
    #[cfg(feature = "gpu")]
    pub fn use_gpu(
        &mut self,
        ctx: std::sync::Arc<crate::backend::gpu::Context>,
    ) -> Result<(), SynthError> {
        self.gpu = Some(crate::backend::gpu::Gpu::new(
            ctx,
            &self.atlas,
            self.db.heights(),
        )?);
        Ok(())
    }

    /// Where the stages run: `"cpu"` or `"gpu"`.
    pub fn backend_name(&self) -> &'static str {
        #[cfg(feature = "gpu")]
        if let Some(g) = &self.gpu {
            return g.name();
        }
        self.cpu().name()
    }

    /// The CPU backend over this synthesizer's database.
    fn cpu(&self) -> Cpu<'_, 'db> {
        Cpu {
            atlas: &self.atlas,
            heights: self.db.heights(),
        }
    }

    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The coarsest database level L.
    fn coarsest(&self) -> usize {
        self.db.level_count() - 1
    }

    /// Synthesizes a `width × height` heightfield.
    pub fn synthesize(
        &self,
        width: usize,
        height: usize,
        seed: u32,
    ) -> Result<Heightfield, SynthError> {
        Ok(self.run(width, height, seed)?.heightfield)
    }

    /// Synthesizes and returns timings (and levels, if kept), on the
    /// backend chosen by [`Synthesizer::use_backend`].
    pub fn run(&self, width: usize, height: usize, seed: u32) -> Result<Synthesis, SynthError> {
        #[cfg(feature = "gpu")]
        if let Some(g) = &self.gpu {
            return self.run_on(g, width, height, seed);
        }
        self.run_on(&self.cpu(), width, height, seed)
    }

    /// The synthesis loop on any backend: the same stage calls in the same
    /// order, so every backend yields the same bytes. Stage timings are wall
    /// clock up to [`Backend::finish`], i.e. including the device's work.
    pub fn run_on<B: Backend>(
        &self,
        b: &B,
        width: usize,
        height: usize,
        seed: u32,
    ) -> Result<Synthesis, SynthError> {
        crate::heightfield::check_dims(width, height)?;
        let t0 = Instant::now();
        let m = top_level(width, height);
        let l = self.coarsest();
        let mut timings = Timings {
            levels: vec![LevelTiming::default(); m + 1],
            ..Default::default()
        };
        let mut kept = Vec::new();
        // With jitter, levels above `top` would only be a spread-out copy of
        // the start exemplar; they are skipped (see `initial`).
        let top = if self.jitter > 0 {
            m.min(l + COARSE_BLOCK_BITS)
        } else {
            m
        };
        let mut state = b.upload(self.initial(width, height, top, seed))?;
        for level in (0..=top).rev() {
            let (w, h) = level_size(width, height, level);
            if level < top {
                let t = Instant::now();
                let child = b.alloc(w, h)?;
                let params = UpsampleParams {
                    seed,
                    level: level as u32,
                    jitter: self.jitter,
                    step: self.step(level, l),
                };
                b.upsample_jitter(&state, &child, level, &params);
                b.finish()?;
                state = child;
                timings.levels[level].upsample = t.elapsed();
            }
            if level <= l {
                let t = Instant::now();
                for _pass in 0..self.params.passes {
                    for &(px, py) in &SUBPASSES {
                        b.correct(&state, level, &CorrectParams { px, py });
                    }
                }
                b.finish()?;
                timings.levels[level].correct = t.elapsed();
            }
            if self.params.keep_levels {
                let (coords, offsets) = b.download(&state)?;
                kept.push(LevelMaps {
                    level,
                    width: w,
                    height: h,
                    coords,
                    offsets,
                });
            }
        }
        kept.reverse();
        let t = Instant::now();
        let fixed = b.reconstruct(&state)?;
        let stride = level_size(width, height, 0).0;
        let heightfield = self.to_metres(&fixed, stride, width, height)?;
        timings.reconstruct = t.elapsed();
        timings.total = t0.elapsed();
        Ok(Synthesis {
            heightfield,
            levels: kept,
            timings,
        })
    }

    /// How level `level` is made from the one above.
    fn step(&self, level: usize, l: usize) -> Step {
        if level < l {
            Step::Pyramid
        } else if level > l {
            Step::Virtual {
                shift: (level - l) as u32,
            }
        } else {
            let c = &self.atlas[l].columns;
            let r = self.atlas[l].level.layout.rects[self.params.start_exemplar];
            let col = c[r.x0 as usize];
            Step::Wrap {
                min_x: col.min_x,
                max_x: col.max_x,
                min_y: crate::database::layout::MARGIN as i32,
                max_y: col.max_y,
            }
        }
    }

    /// The coarsest synthesized level, `top`.
    ///
    /// Without jitter (the reproduction property): level M holds the start
    /// exemplar's centre, spread so that each level halves the spacing — at
    /// level ≤ L an exact copy of the centre, tiled toroidally when the
    /// output is larger than the exemplar.
    ///
    /// With jitter, an output larger than the exemplars would otherwise be
    /// that tiled copy plus sub-texel jitter: above level L there is no data
    /// to correct with, so the paper's jitter cannot create variety there and
    /// the tiles stay visible as a repeating pattern. Instead each pixel of
    /// level `top = L + COARSE_BLOCK_BITS` starts at a hash-chosen position
    /// of the start exemplar (the fully jittered coarse level of Lefebvre &
    /// Hoppe 2005), so level L begins as a mosaic of small exemplar blocks
    /// that its correction passes assemble into exemplar-like patches.
    fn initial(&self, width: usize, height: usize, top: usize, seed: u32) -> State {
        let l = self.coarsest();
        let at = top.min(l);
        let r = self.atlas[at].level.layout.rects[self.params.start_exemplar];
        let (w, h) = level_size(width, height, top);
        let st = State::new(w, h);
        if self.jitter > 0 && top > l {
            // Level-L texel ranges whose whole 2^b block stays inside the
            // exemplar interior (b = top − L).
            let span = (1i32 << (top - l)) - 1;
            let col = self.atlas[l].columns[r.x0 as usize];
            let (x0, y0) = (col.min_x, crate::database::layout::MARGIN as i32);
            let nx = (col.max_x - span - x0 + 1).max(1) as u32;
            let ny = (col.max_y - span - y0 + 1).max(1) as u32;
            for y in 0..h {
                for x in 0..w {
                    let hash = crate::hash::hash4(seed, COARSE_SALT, x as u32, y as u32);
                    let tx = x0 + crate::hash::below(hash, nx) as i32;
                    let ty = y0 + crate::hash::below(crate::hash::pcg(hash), ny) as i32;
                    st.set(y * w + x, Coord::from_texel(tx, ty), 0);
                }
            }
            return st;
        }
        let m = top;
        let (cx, cy) = ((r.x0 + r.width / 2) as i32, (r.height / 2) as i32);
        for y in 0..h {
            for x in 0..w {
                // Offset from the level's centre, in half texels of level m.
                let (hx, hy) = (2 * x as i32 + 1 - w as i32, 2 * y as i32 + 1 - h as i32);
                let to_fixed = |half: i32| -> i32 {
                    if m > l {
                        // In level-L units: a level-m texel is 2^(m−L) of them.
                        (half << FRAC_BITS) << (m - l - 1)
                    } else {
                        half << (FRAC_BITS - 1)
                    }
                };
                let s = Coord {
                    x: (cx << FRAC_BITS) + to_fixed(hx),
                    y: (cy << FRAC_BITS) + to_fixed(hy),
                };
                st.set(y * w + x, s, 0);
            }
        }
        st
    }

    /// Level-0 fixed-point heights → metres, cropped to the requested size
    /// (levels are at least 2×2).
    fn to_metres(
        &self,
        fixed: &[i32],
        stride: usize,
        width: usize,
        height: usize,
    ) -> Result<Heightfield, SynthError> {
        let q = self.db.quantization();
        let cell = self.db.meta().exemplars[self.params.start_exemplar].cell_size_m;
        let scale = q.scale_m / (1 << HEIGHT_FRAC_BITS) as f64;
        Ok(Heightfield::from_fn(width, height, cell, |x, y| {
            (q.offset_m + scale * fixed[y * stride + x] as f64) as f32
        })?)
    }

    /// Synthesis memory per output pixel: the finest level's state, the
    /// level above it (alive during upsampling), the fixed-point heights and
    /// the output heightfield.
    pub fn bytes_per_pixel(width: usize, height: usize) -> f64 {
        let (w0, h0) = level_size(width, height, 0);
        let (w1, h1) = level_size(width, height, 1);
        let bytes = (w0 * h0 + w1 * h1) * State::BYTES_PER_PIXEL + w0 * h0 * 4 + width * height * 4;
        bytes as f64 / (width * height) as f64
    }
}
