//! Coarse-to-fine parallel synthesis (paper §4, DESIGN §3, §5, §6).
//!
//! Levels top..0 of any output size: the top level is the coarse start
//! ([`coarse`]: verbatim exemplar blocks, or the start exemplar's centre
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
mod params;
mod restricted;
pub mod session;
pub mod source_map;
mod window;
mod windowed;

pub use crate::level::{atlas, fixed, state};
pub use crate::stages;

use crate::backend::{Backend, Choice, Stage, cpu::Cpu};
use crate::database::Database;
use crate::heightfield::Heightfield;
use atlas::AtlasLevel;
use coarse::Start;
use cone::{Cone, Rect};
use fixed::FRAC_BITS;
use restricted::LevelBuffers;
use stages::correct::{CorrectParams, SUBPASSES};
use stages::reconstruct::{self, HEIGHT_FRAC_BITS};
use stages::upsample_jitter::{Step, UpsampleParams};
use state::{State, level_size, top_level};
use std::cell::RefCell;
use std::sync::OnceLock;
use std::time::{Duration, Instant};
use window::{REACH_PER_SUBPASS, widen};

pub use params::{
    Guides, LevelGuide, LevelMaps, LevelTiming, Params, SynthError, Synthesis, Timings,
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
    /// The coarse start's profile of the exemplars, built by the first
    /// synthesis that starts from blocks.
    profile: OnceLock<coarse::Profile>,
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
        if !stages::correct::PRIORS.contains(&params.prior) {
            return Err(SynthError::Prior(params.prior));
        }
        let count = db.meta().exemplars.len();
        if let Some(index) = params.start_exemplar.filter(|&i| i >= count) {
            return Err(SynthError::StartExemplar { index, count });
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
            profile: OnceLock::new(),
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
            Choice::Gpu => Err(crate::backend::BackendError::NotCompiled.into()),
            Choice::Auto => Ok(Some(format!(
                "{}; using the CPU",
                crate::backend::BackendError::NotCompiled
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

    /// The GPU the stages run on, if they do (e.g. to shade a preview
    /// there too).
    #[cfg(feature = "gpu")]
    pub fn gpu_context(&self) -> Option<&std::sync::Arc<crate::backend::gpu::Context>> {
        self.gpu.as_ref().map(|g| g.context())
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

    /// The synthesis loop, one for every backend, for plain and controlled
    /// synthesis and for whole worlds and windows: the same stage calls in
    /// the same order, so every backend yields the same bytes, and a
    /// window's pixels are those of the whole world (each level computes
    /// its [`Cone`] region; stages hash absolute coordinates). Stage
    /// timings are wall clock up to [`Backend::finish`], i.e. including the
    /// device's work, unless the backend has a device clock.
    fn drive<B: Backend>(
        &self,
        b: &B,
        cone: &Cone,
        seed: u32,
        control: Option<&Control<'_>>,
    ) -> Result<(Synthesis, Option<Frames>), SynthError> {
        let t0 = Instant::now();
        let (width, height) = cone.world();
        let (start, top, l) = self.levels(width, height);
        let mut timings = Timings {
            levels: vec![LevelTiming::default(); top_level(width, height) + 1],
            ..Default::default()
        };
        let mut kept = Vec::new();
        let mut frames = control.filter(|c| c.record).map(|_| Frames {
            levels: vec![Vec::new(); l.min(top_level(width, height)) + 1],
            ..Frames::default()
        });
        // A level's whole state, once nothing reads it any more: kept in the
        // recorded frame (`Frames::states`) where the backend has it on the
        // host, else dropped.
        let keep_state = |frames: &mut Option<Frames>, level: usize, st: B::State| {
            if let Some(f) = frames.as_mut() {
                f.keep_state(level, b.host_state(st));
            }
        };
        // Without a device clock, the loop waits after each stage so that
        // wall clock measures it; with one, stages queue back to back.
        let device_clock = b.has_device_clock();
        b.device_times()?; // forget times of earlier calls
        let mut state = b.upload(self.initial(cone, start, seed))?;
        // The level above, kept through this level's correction: its
        // offsets anchor the height prior (`correct` module docs).
        let mut parent: Option<B::State> = None;
        let mut parent_size = (0, 0);
        // Whether `parent` is its level's whole state (not a crop of it).
        let mut parent_whole = false;
        // Bounds of the pixels of the level above that differ from the
        // previous frame (restricted re-synthesis only).
        let mut changed_parent: Option<[usize; 4]> = None;
        // The window corrected at level 0 (restricted re-synthesis only).
        let mut window0 = None;
        for level in (0..=top).rev() {
            let region = cone.region(level);
            let (w, h) = (region.width(), region.height());
            let window = match control {
                Some(c) if level <= l => self.window(c, level, (w, h), changed_parent),
                _ => None,
            };
            if level < top {
                let t = Instant::now();
                let above = match cone.parent_crop(level) {
                    Some(c) => {
                        parent_size = (c.width(), c.height());
                        let crop = b.crop(&state, [c.x0, c.y0, c.x1, c.y1])?;
                        keep_state(&mut frames, level + 1, state);
                        crop
                    }
                    None => {
                        let r = cone.region(level + 1);
                        parent_size = (r.width(), r.height());
                        state
                    }
                };
                let whole = cone.parent_crop(level).is_none();
                let child = b.alloc(w, h)?;
                let p = self.upsample_params(seed, level, region);
                // Correcting a window with coherence reads the upsampled
                // pixels within a subpass's reach of it; the rest take the
                // previous frame's results before anything reads them.
                let coherent = control
                    .and_then(|c| c.guides.levels.get(level))
                    .is_some_and(|g| g.weights.is_some());
                match window.filter(|_| coherent) {
                    Some(win) => {
                        let read = widen(win, REACH_PER_SUBPASS, w, h);
                        b.upsample_jitter_rect(&above, &child, level, &p, read);
                    }
                    None => b.upsample_jitter(&above, &child, level, &p),
                }
                if !device_clock {
                    b.finish()?;
                }
                if let (Some(old), true) = (parent.replace(above), parent_whole) {
                    keep_state(&mut frames, level + 2, old);
                }
                parent_whole = whole;
                state = child;
                timings.levels[level].upsample = t.elapsed();
            }
            if level <= l {
                let t = Instant::now();
                match control {
                    None => {
                        for _pass in 0..self.params.passes {
                            for &sub in &SUBPASSES {
                                let p = self.correct_params(level, sub);
                                b.correct(&state, parent.as_ref(), level, &p);
                            }
                        }
                    }
                    Some(c) => {
                        changed_parent = match window.filter(|_| self.can_crop(c, level)) {
                            Some(win) => {
                                let buf = LevelBuffers {
                                    state: &state,
                                    parent: parent.as_ref().map(|p| (p, parent_size)),
                                    level,
                                    region,
                                };
                                let (changed, corrected) =
                                    self.correct_cropped(b, buf, c, win, frames.as_mut())?;
                                state = corrected;
                                changed
                            }
                            None => self.correct_level(
                                b,
                                (&state, parent.as_ref()),
                                (level, region),
                                c,
                                window,
                                frames.as_mut(),
                            )?,
                        };
                        window0 = window;
                    }
                }
                if !device_clock {
                    b.finish()?;
                }
                timings.levels[level].correct = t.elapsed();
            }
            if self.params.keep_levels {
                let (coords, offsets) = b.download(&state)?;
                kept.push(LevelMaps {
                    level,
                    origin: [region.x0, region.y0],
                    width: w,
                    height: h,
                    coords,
                    offsets,
                });
            }
        }
        kept.reverse();
        let t = Instant::now();
        // The previous frame's heights are taken: patched, they become
        // this frame's.
        let prev_heights = control
            .and_then(|c| c.prev.as_ref())
            .map(|p| std::mem::take(&mut p.borrow_mut().heights))
            .filter(|h| h.len() == cone.region(0).width() * cone.region(0).height());
        // The fixed-point heights are kept only for the next frame.
        let keep = frames.is_some();
        let (heightfield, fixed) = match (window0, prev_heights) {
            // Heights depend on the S and V within `reconstruct::REACH`,
            // which differ from the previous frame's only inside the window.
            (Some(win), Some(prev)) => {
                let r = cone.region(0);
                let read = widen(win, reconstruct::REACH, r.width(), r.height());
                let fixed = b.reconstruct_rect(&state, prev, read)?;
                (self.to_metres(&fixed, cone)?, Some(fixed))
            }
            _ => b.reconstruct_with(&state, |fixed| {
                let hf = self.to_metres(fixed, cone)?;
                Ok::<_, SynthError>((hf, keep.then(|| fixed.to_vec())))
            })??,
        };
        if let (Some(f), Some(fixed)) = (frames.as_mut(), fixed) {
            f.heights = fixed;
        }
        if let (Some(p), true) = (parent, parent_whole) {
            keep_state(&mut frames, 1, p);
        }
        keep_state(&mut frames, 0, state);
        timings.reconstruct = t.elapsed();
        timings.total = t0.elapsed();
        if let Some(times) = b.device_times()? {
            timings.device_clock = true;
            for l in &mut timings.levels {
                *l = LevelTiming::default();
            }
            timings.reconstruct = Duration::ZERO;
            for st in times {
                match st.stage {
                    Stage::UpsampleJitter => timings.levels[st.level].upsample += st.time,
                    Stage::Correct => timings.levels[st.level].correct += st.time,
                    Stage::Reconstruct => timings.reconstruct += st.time,
                }
            }
        }
        Ok((
            Synthesis {
                heightfield,
                levels: kept,
                timings,
            },
            frames,
        ))
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
        let start = Start::choose(
            self.jitter > 0,
            m,
            l,
            &self.atlas[l],
            self.params.start_exemplar,
        );
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
        Cone::plan(world, window, (top, l, self.params.passes), needs)
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
    fn initial(&self, cone: &Cone, start: Start, seed: u32) -> State {
        let (width, height) = cone.world();
        let (m, l) = (top_level(width, height), self.coarsest());
        let region = cone.region(cone.top());
        match start {
            Start::Blocks { bits } => {
                let from = self.params.start_exemplar;
                let world = level_size(width, height, l);
                let at = (region, world);
                let atlas = &self.atlas[l];
                let profile = self
                    .profile
                    .get_or_init(|| coarse::Profile::new(self.db, atlas, from));
                let src = coarse::Source {
                    atlas,
                    from,
                    profile,
                };
                coarse::blocks(src, at, (l, bits), seed, self.jitter)
            }
            Start::Centre => {
                let top = start.top(m, l);
                let a = &self.atlas[top.min(l)];
                coarse::centre(a, self.start(), (width, height), region, top, l)
            }
        }
    }

    /// Level-0 fixed-point heights (over the cone's level-0 region) →
    /// metres, cropped to the cone's window (levels are at least 2×2).
    fn to_metres(&self, fixed: &[i32], cone: &Cone) -> Result<Heightfield, SynthError> {
        let q = self.db.quantization();
        let cell = self.cell_size_m();
        let scale = q.scale_m / (1 << HEIGHT_FRAC_BITS) as f64;
        let (r, win) = (cone.region(0), cone.window());
        let (dx, dy, stride) = (win.x0 - r.x0, win.y0 - r.y0, r.width());
        Ok(Heightfield::from_rows(
            win.width(),
            win.height(),
            cell,
            |y, row| {
                let from = &fixed[(y + dy) * stride + dx..][..row.len()];
                for (h, &v) in row.iter_mut().zip(from) {
                    *h = (q.offset_m + scale * v as f64) as f32;
                }
            },
        )?)
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
