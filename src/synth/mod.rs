//! Coarse-to-fine parallel synthesis (paper §4, DESIGN §3, §5, §6).
//!
//! Levels top..0 of any output size: the top level is the coarse start
//! ([`coarse`]: exemplar pieces laid by an altitude guide, or the start exemplar's centre
//! without jitter); each finer level is `upsample_jitter` of the one
//! above and, at levels ≤ L (the database's coarsest), `passes` correction
//! passes of four interleaved subpasses; `reconstruct` turns level 0 into
//! metres. Every stage is integer arithmetic and every random choice a hash,
//! so the output bytes depend only on the database, the parameters and the
//! seed — never on the thread count.
//!
//! One loop ([`Synthesizer::run`] and, under user control,
//! [`Synthesizer::run_with`]) drives whichever [`Backend`] was chosen, so
//! plain synthesis, scenes and editing sessions run on the CPU or the GPU
//! with the same bytes.

pub mod coarse;
pub mod cone;
pub mod control;
mod drive;
mod params;
mod restricted;
pub mod session;
pub mod source_map;
mod window;
mod windowed;

use crate::backend::engine::Engine;
use crate::backend::{Backend, Choice, cpu::Cpu};
use crate::database::Database;
use crate::heightfield::Heightfield;
use crate::isa::Isa;
use crate::level::atlas::AtlasLevel;
use crate::level::fixed::FRAC_BITS;
use crate::level::state::{State, level_size, top_level};
use crate::stages::correct::CorrectParams;
use crate::stages::upsample_jitter::{Step, UpsampleParams};
use coarse::Start;
use cone::{Cone, Rect};
use std::cell::RefCell;
use std::sync::OnceLock;

pub use params::{
    Guides, LevelGuide, LevelMaps, LevelTiming, PIECE_SIZES, Params, SynthError, Synthesis, Timings,
};
pub(crate) use window::union;
pub use window::{Frames, PassResult};
pub use windowed::{Paint, WindowControls, WindowError, check_window};

/// The control side of one run: per-level guides, the previous frame, and
/// whether to record this one.
struct Control<'a> {
    guides: &'a Guides,
    /// The previous frame's results. Owned: restricted re-synthesis patches
    /// each level's results in place as the level is corrected (the window
    /// replaced), instead of copying every pass of the whole level.
    prev: Option<RefCell<Frames>>,
    record: bool,
}

/// Synthesizes terrain from one database, on the CPU unless
/// [`Synthesizer::use_backend`] moved it to the GPU.
pub struct Synthesizer<'db> {
    db: &'db Database,
    params: Params,
    atlas: Vec<AtlasLevel<'db>>,
    jitter: i32,
    /// The coarse start's pool, built by the first synthesis that starts
    /// from pieces (it ranks every interior texel of level L).
    pool: OnceLock<coarse::Pool>,
    /// The start level's factor of passes (`coarse::seams`), measured by
    /// the first synthesis that starts from pieces.
    start_factor: OnceLock<u32>,
    /// The CPU stages' instruction-set level (when no GPU runs them).
    isa: Isa,
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
        if !crate::stages::correct::PRIORS.contains(&params.prior) {
            return Err(SynthError::Prior(params.prior));
        }
        let count = db.meta().exemplars.len();
        if let Some(index) = params.start_exemplar.filter(|&i| i >= count) {
            return Err(SynthError::StartExemplar { index, count });
        }
        if !PIECE_SIZES.contains(&params.piece_size) {
            return Err(SynthError::PieceSize(params.piece_size));
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
            pool: OnceLock::new(),
            start_factor: OnceLock::new(),
            isa: Isa::default(),
            #[cfg(feature = "gpu")]
            gpu: None,
        })
    }

    /// Moves the stages to the backend `choice` names. Returns a one-line
    /// notice when [`Choice::Auto`] found no GPU and stays on the CPU.
    pub fn use_backend(&mut self, choice: Choice) -> Result<Option<String>, SynthError> {
        let (engine, notice) = Engine::choose(choice)?;
        self.use_engine(engine)?;
        Ok(notice)
    }

    /// Runs the stages on `engine` (a GPU: uploads the database once).
    pub fn use_engine(&mut self, engine: Engine) -> Result<(), SynthError> {
        match engine {
            Engine::Cpu(isa) => {
                self.isa = isa;
                #[cfg(feature = "gpu")]
                {
                    self.gpu = None;
                }
            }
            #[cfg(feature = "gpu")]
            Engine::Gpu(ctx) => self.use_gpu(ctx)?,
        }
        Ok(())
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

    /// The engine the stages run on (e.g. to shade a preview there too).
    pub fn engine(&self) -> Engine {
        #[cfg(feature = "gpu")]
        if let Some(g) = &self.gpu {
            return Engine::Gpu(g.context().clone());
        }
        Engine::Cpu(self.isa)
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
            isa: self.isa,
        }
    }

    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The coarsest level L synthesis corrects: the database's coarsest,
    /// at most [`coarse::MAX_START_LEVEL`].
    pub(crate) fn coarsest(&self) -> usize {
        (self.db.level_count() - 1).min(coarse::MAX_START_LEVEL)
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
        let cone = self.whole(width, height)?;
        Ok(self.dispatch(&cone, seed, None)?.0)
    }

    /// Synthesis under control inputs (paper §5), on the backend chosen by
    /// [`Synthesizer::use_backend`]. `prev` is the previous frame's per-pass
    /// results (the coherence candidates, and what pixels outside a level's
    /// window keep), consumed: its buffers become this frame's; with
    /// `record`, this frame's are returned for the next one.
    pub fn run_with(
        &self,
        width: usize,
        height: usize,
        seed: u32,
        guides: &Guides,
        prev: Option<Frames>,
        record: bool,
    ) -> Result<(Synthesis, Option<Frames>), SynthError> {
        let cone = self.whole(width, height)?;
        self.run_cone(&cone, seed, guides, prev, record)
    }

    /// [`Synthesizer::run_with`] over a cone ([`Synthesizer::cone`]): the
    /// guides and the previous frame cover the cone's regions.
    pub(crate) fn run_cone(
        &self,
        cone: &Cone,
        seed: u32,
        guides: &Guides,
        prev: Option<Frames>,
        record: bool,
    ) -> Result<(Synthesis, Option<Frames>), SynthError> {
        let control = Control {
            guides,
            prev: prev.map(RefCell::new),
            record,
        };
        self.dispatch(cone, seed, Some(&control))
    }

    /// [`Synthesizer::drive`] on the chosen backend.
    fn dispatch(
        &self,
        cone: &Cone,
        seed: u32,
        control: Option<&Control<'_>>,
    ) -> Result<(Synthesis, Option<Frames>), SynthError> {
        #[cfg(feature = "gpu")]
        if let Some(g) = &self.gpu {
            return self.drive(g, cone, seed, control);
        }
        self.drive(&self.cpu(), cone, seed, control)
    }

    /// The database this synthesizer draws from.
    pub fn database(&self) -> &'db Database {
        self.db
    }

    /// Output cell size, metres (the start exemplar's).
    pub fn cell_size_m(&self) -> f64 {
        self.db.meta().exemplars[self.start()].cell_size_m
    }

    /// The start exemplar, or exemplar 0 (see [`Params::start_exemplar`]).
    fn start(&self) -> usize {
        self.params.start_exemplar.unwrap_or(0)
    }

    /// The levels a `width × height` world runs: how it starts, the
    /// coarsest synthesized level `top` and the database's coarsest level L.
    fn levels(&self, width: usize, height: usize) -> (Start, usize, usize) {
        let m = top_level(width, height);
        let l = self.coarsest();
        let start = Start::choose(self.jitter > 0, m, l, self.params.piece_size);
        (start, start.top(m, l), l)
    }

    /// The cone of a whole `width × height` synthesis: every level whole.
    fn whole(&self, width: usize, height: usize) -> Result<Cone, SynthError> {
        crate::size::check_dims(width, height)?;
        Ok(self.cone((width, height), Rect::new(0, 0, width, height), &[]))
    }

    /// The cone of `window` in a `world` (see [`Cone::plan`]; `needs`: more
    /// rectangles per level that must come out right).
    pub(crate) fn cone(&self, world: (usize, usize), window: Rect, needs: &[Option<Rect>]) -> Cone {
        let (_, top, l) = self.levels(world.0, world.1);
        let passes = self.level_passes(world.0, world.1);
        Cone::plan(world, window, (top, l, &passes), needs)
    }

    /// The correction passes of each level of a `width × height` synthesis
    /// (index = level, up to its coarsest): [`Params::passes`], times a
    /// factor of 1–4 at the level a jittered start's pieces are laid at,
    /// more for exemplars smooth at the pixel scale (`synth/coarse/seams.rs`:
    /// the pieces' seams are healed there).
    pub fn level_passes(&self, width: usize, height: usize) -> Vec<u32> {
        let (start, top, l) = self.levels(width, height);
        (0..=top)
            .map(|i| match start {
                Start::Pieces { .. } if i == l => self.params.passes * self.start_factor(),
                _ => self.params.passes,
            })
            .collect()
    }

    /// The start level's factor of passes for this synthesizer's
    /// exemplars, measured once.
    fn start_factor(&self) -> u32 {
        *self
            .start_factor
            .get_or_init(|| coarse::seams::factor(self.db, self.params.start_exemplar))
    }

    /// Parameters of the upsampling into level `level` over `region`. Above
    /// L (only the centre start has levels there) the levels only spread
    /// the start; jitter begins at L.
    fn upsample_params(&self, seed: u32, level: usize, region: Rect) -> UpsampleParams {
        let l = self.coarsest();
        UpsampleParams {
            seed,
            level: level as u32,
            jitter: if level > l { 0 } else { self.jitter },
            step: self.step(level, l),
            origin: [region.x0 as u32, region.y0 as u32],
        }
    }

    /// The settings of subpass `(px, py)` of a correction at `level`.
    fn correct_params(&self, level: usize, (px, py): (u32, u32)) -> CorrectParams {
        CorrectParams {
            px,
            py,
            prior: self.params.prior,
            similar: level >= self.params.similar_from,
        }
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
            let r = self.atlas[l].level.layout.rects[self.start()];
            let col = c[r.x0 as usize];
            Step::Wrap {
                min_x: col.min_x,
                max_x: col.max_x,
                min_y: crate::database::layout::MARGIN as i32,
                max_y: col.max_y,
            }
        }
    }

    /// The coarsest synthesized level `top` (see [`coarse`]) over the
    /// cone's top region.
    fn initial(
        &self,
        cone: &Cone,
        start: Start,
        seed: u32,
        control: Option<&Control<'_>>,
    ) -> State {
        let (width, height) = cone.world();
        let (m, l) = (top_level(width, height), self.coarsest());
        let region = cone.region(cone.top());
        match start {
            Start::Pieces { side } => {
                let atlas = &self.atlas[l];
                // Built outside the lock and then set, not in `get_or_init`:
                // the pool is built by rayon, and a rayon thread blocked on
                // the lock while another initializes it can starve that
                // initialization of threads (a deadlock with 2 threads).
                // Two syntheses starting at once may both build it; the
                // first kept is the same pool.
                let pool = match self.pool.get() {
                    Some(pool) => pool,
                    None => {
                        let built = coarse::Pool::new(atlas, self.params.start_exemplar);
                        self.pool.get_or_init(|| built)
                    }
                };
                let src = coarse::Source { atlas, pool };
                // Painted types choose the pieces they start from (issue 40).
                let allowed = control
                    .and_then(|c| c.guides.levels.get(l))
                    .and_then(|g| g.allowed.as_deref());
                coarse::pieces(
                    src,
                    region,
                    (width, height),
                    (l, side),
                    seed,
                    self.jitter,
                    allowed,
                )
            }
            Start::Centre => {
                let top = start.top(m, l);
                let a = &self.atlas[top.min(l)];
                coarse::centre(a, self.start(), (width, height), region, top, l)
            }
        }
    }

    /// Synthesis memory per output pixel: the finest level's state, the
    /// level above it (alive during upsampling and correction, where its
    /// offsets anchor the height prior), the fixed-point heights and the
    /// output heightfield.
    pub fn bytes_per_pixel(width: usize, height: usize) -> f64 {
        let (w0, h0) = level_size(width, height, 0);
        let (w1, h1) = level_size(width, height, 1);
        let bytes = (w0 * h0 + w1 * h1) * State::BYTES_PER_PIXEL + w0 * h0 * 4 + width * height * 4;
        bytes as f64 / (width * height) as f64
    }
}
