//! A session's whole state between frames, kept so that an editor can step
//! back to it instead of re-synthesizing.
//!
//! Why: a paste is permanent in a session (its values are written into the
//! previous frame's results and frozen, paper §5.3), so no edit can take
//! it out again; before snapshots, undoing or deleting a paste started a
//! new session and synthesized the whole terrain (1.5–2.2 s at 1024² on 2
//! cores, issue 43). Swapping a snapshot in takes no synthesis at all,
//! and gives back the very bytes the session had: the frame shown is the
//! one shown before, and later edits start from the same state as they
//! would have then.
//!
//! A snapshot is a copy of every per-pixel buffer the session keeps (~42 B
//! per output pixel without constraints, ~84 B with them: 44–88 MB at
//! 1024², measured); [`Snapshot::bytes`] says how much, so a keeper can
//! bound it. It counts the constraints' own buffers too (a curve's kept
//! samples, distance field and envelope, [`Constraint::bytes`]: 2.3 MB for
//! a 256-px curve, ~7 MB for an 820-px one at 1024²): a snapshot shares
//! them with the session, but one kept across an edit of a curve is what
//! keeps the old curve alive.
//!
//! [`Constraint::bytes`]: crate::synth::control::Constraint::bytes

use super::Session;
use crate::heightfield::Heightfield;
use crate::synth::control::{Blend, Controls};
use crate::synth::{Frames, Guides};

/// What a [`Session`] holds between frames (its synthesizer aside, which
/// no frame changes).
#[derive(Debug, Clone)]
pub struct Snapshot {
    /// The session's size and seed: a snapshot fits only a session made
    /// with the same ones.
    shape: (usize, usize, u32),
    controls: Controls,
    blend: Blend,
    frames: Option<Frames>,
    guides: Option<Guides>,
    pasted: Vec<Vec<bool>>,
    last: Option<Heightfield>,
}

/// What the buffers of `$s`, a [`Session`] or a [`Snapshot`] (they hold
/// the same ones, under the same names), hold in bytes: `bytes_of` them.
macro_rules! state_bytes {
    ($s:expr) => {
        bytes_of(
            &$s.controls,
            &$s.blend,
            &$s.frames,
            &$s.guides,
            &$s.pasted,
            &$s.last,
        )
    };
}

impl Snapshot {
    /// The last frame's heights it holds.
    pub fn heightfield(&self) -> Option<&Heightfield> {
        self.last.as_ref()
    }

    /// What its buffers hold, in bytes (estimated from their lengths).
    pub fn bytes(&self) -> usize {
        state_bytes!(self)
    }
}

/// What a state's buffers hold, in bytes (estimated from their lengths).
fn bytes_of(
    controls: &Controls,
    blend: &Blend,
    frames: &Option<Frames>,
    guides: &Option<Guides>,
    pasted: &[Vec<bool>],
    last: &Option<Heightfield>,
) -> usize {
    let frames = frames.as_ref().map_or(0, |f| {
        let passes: usize = (f.levels.iter().flatten())
            .map(|r| r.coords.len() * 8 + r.offsets.len() * 4)
            .sum();
        passes + f.heights.len() * 4
    });
    let raster = |m: Option<usize>| m.unwrap_or(0);
    frames
        + controls
            .constraints
            .values()
            .map(|c| c.bytes())
            .sum::<usize>()
        + guides.as_ref().map_or(0, guide_bytes)
        + pasted.iter().map(Vec::len).sum::<usize>()
        + raster(controls.types.as_ref().map(Vec::len))
        + raster(controls.freeze.as_ref().map(Vec::len))
        + blend.bytes()
        + last.as_ref().map_or(0, |h| h.len() * 4)
}

fn guide_bytes(g: &Guides) -> usize {
    (g.levels.iter())
        .map(|l| {
            l.targets.as_ref().map_or(0, |t| t.len() * 8)
                + l.allowed.as_ref().map_or(0, |a| a.len() * 4)
                + l.weights.as_ref().map_or(0, Vec::len)
        })
        .sum()
}

impl Session<'_> {
    /// What a [`Session::snapshot`] would hold, in bytes, without taking it.
    pub fn snapshot_bytes(&self) -> usize {
        state_bytes!(self)
    }

    /// A copy of the session's state (the kept final states aside: they
    /// repeat the last pass's results and are rebuilt from them, with the
    /// same bytes).
    pub fn snapshot(&self) -> Snapshot {
        Snapshot {
            shape: (self.width, self.height, self.seed),
            controls: self.controls.clone(),
            blend: self.blend.clone(),
            frames: self.frames.clone(),
            guides: self.guides.clone(),
            pasted: self.pasted.clone(),
            last: self.last.clone(),
        }
    }

    /// [`Session::snapshot`] into `s`'s buffers (a state its keeper would
    /// drop): where they are large enough nothing is allocated, so the copy
    /// faults in no new pages and frees none (at 1024² that was about half
    /// of a paste's ~30 ms keep). `s` may come from any session.
    pub fn snapshot_into(&self, s: &mut Snapshot) {
        s.shape = (self.width, self.height, self.seed);
        s.controls.clone_from(&self.controls);
        s.blend.clone_from(&self.blend);
        s.frames.clone_from(&self.frames);
        s.guides.clone_from(&self.guides);
        s.pasted.clone_from(&self.pasted);
        s.last.clone_from(&self.last);
    }

    /// Exchanges the session's state with `s`'s: the session is then as it
    /// was when `s` was taken, and `s` holds what it was (swapping again
    /// goes back). Nothing is copied. False, and nothing changes, when `s`
    /// was taken of a session of another size or seed.
    pub fn swap(&mut self, s: &mut Snapshot) -> bool {
        if s.shape != (self.width, self.height, self.seed) || s.pasted.len() != self.pasted.len() {
            return false;
        }
        std::mem::swap(&mut self.controls, &mut s.controls);
        std::mem::swap(&mut self.blend, &mut s.blend);
        std::mem::swap(&mut self.frames, &mut s.frames);
        std::mem::swap(&mut self.guides, &mut s.guides);
        std::mem::swap(&mut self.pasted, &mut s.pasted);
        std::mem::swap(&mut self.last, &mut s.last);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::bytes_of;
    use crate::database::Quantization;
    use crate::synth::control::curve::{CurveSpec, FieldCache, Widget, build};
    use crate::synth::control::{Blend, Constraint, ConstraintId, Controls};
    use glam::DVec2;
    use std::sync::Arc;

    #[test]
    fn a_states_bytes_count_its_constraints_samples_field_and_envelope() {
        let spec = CurveSpec {
            points: vec![
                DVec2::new(20.0, 60.0),
                DVec2::new(140.0, 130.0),
                DVec2::new(240.0, 190.0),
            ],
            widgets: vec![Widget {
                at: 0.5,
                height_m: 900.0,
                slope_deg: [10.0, 10.0],
                reach_px: [24.0, 24.0],
            }],
            smoothing: 2,
        };
        let (mut curves, _) = build(&[spec], &[], 30.0, &FieldCache::new()).unwrap();
        let curve = curves.remove(0);
        let without = curve.bytes();
        let samples = curve.centres().expect("kept").bytes();
        assert_eq!(curve.bytes(), without + samples, "the samples, once taken");
        assert!(samples > 256 * 100 * 32, "{samples}");
        let blend = Blend::new(
            256,
            256,
            3,
            Quantization {
                offset_m: 0.0,
                scale_m: 0.05,
            },
        );
        let mut controls = Controls::default();
        let empty = bytes_of(&controls, &blend, &None, &None, &[], &None);
        let curve: Arc<dyn Constraint> = Arc::new(curve);
        controls.constraints.insert(ConstraintId(1), curve.clone());
        let held = bytes_of(&controls, &blend, &None, &None, &[], &None);
        assert_eq!(held - empty, curve.bytes());
    }
}
