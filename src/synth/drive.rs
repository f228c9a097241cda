//! The synthesis loop ([`Synthesizer::drive`]): every level, top to
//! bottom, on one backend — upsampling, the correction passes (plain, under
//! control, or restricted to an edit's window), and level 0's
//! reconstruction into metres.

use super::cone::Cone;
use super::restricted::LevelBuffers;
use super::window::{REACH_PER_SUBPASS, widen};
use super::{Control, Frames, LevelMaps, LevelTiming, SynthError, Synthesis, Synthesizer, Timings};
use crate::backend::Backend;
use crate::heightfield::Heightfield;
use crate::level::state::top_level;
use crate::stages::common::HEIGHT_FRAC_BITS;
use crate::stages::correct::SUBPASSES;
use crate::stages::{Stage, reconstruct};
use std::time::{Duration, Instant};

impl Synthesizer<'_> {
    /// The synthesis loop, one for every backend, for plain and controlled
    /// synthesis and for whole worlds and windows: the same stage calls in
    /// the same order, so every backend yields the same bytes, and a
    /// window's pixels are those of the whole world (each level computes
    /// its [`Cone`] region; stages hash absolute coordinates). Stage
    /// timings are wall clock up to [`Backend::finish`], i.e. including the
    /// device's work, unless the backend has a device clock.
    pub(super) fn drive<B: Backend>(
        &self,
        b: &B,
        cone: &Cone,
        seed: u32,
        control: Option<&Control<'_>>,
    ) -> Result<(Synthesis, Option<Frames>), SynthError> {
        let t0 = Instant::now();
        let (width, height) = cone.world();
        let (start, top, l) = self.levels(width, height);
        let passes = self.level_passes(width, height);
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
        let mut state = b.upload(self.initial(cone, start, seed, control))?;
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
                Some(c) if level <= l => {
                    self.window(c, (level, passes[level]), (w, h), changed_parent)
                }
                _ => None,
            };
            if level < top {
                let t = Instant::now();
                // `whole`: the parent is its level's whole state, not a crop.
                let (above, whole) = match cone.parent_crop(level) {
                    Some(c) => {
                        parent_size = (c.width(), c.height());
                        let crop = b.crop(&state, [c.x0, c.y0, c.x1, c.y1])?;
                        keep_state(&mut frames, level + 1, state);
                        (crop, false)
                    }
                    None => {
                        let r = cone.region(level + 1);
                        parent_size = (r.width(), r.height());
                        (state, true)
                    }
                };
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
                        for _pass in 0..passes[level] {
                            for &sub in &SUBPASSES {
                                let p = self.correct_params(level, sub);
                                b.correct(&state, parent.as_ref(), level, &p);
                            }
                        }
                    }
                    Some(c) => {
                        let can_crop = self.can_crop(c, level, passes[level]);
                        changed_parent = match window.filter(|_| can_crop) {
                            Some(win) => {
                                let buf = LevelBuffers {
                                    state: &state,
                                    parent: parent.as_ref().map(|p| (p, parent_size)),
                                    level,
                                    passes: passes[level],
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
                                (level, passes[level], region),
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
                    Stage::Reconstruct | Stage::RepairExtrema => timings.reconstruct += st.time,
                    // Untimed (the control pyramids' reductions run once
                    // per pass, outside any level's time) or not synthesis
                    // stages.
                    Stage::ReduceTypes | Stage::ReduceWeights | Stage::Shade | Stage::FillSsd => {}
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
}
