//! The sculpt edit of a session: swaps the sculpt layer in the blend only
//! where the old and new layers can differ, and frees (W⁰ = unweighted)
//! only the pixels whose target changed, so a stroke re-synthesizes what
//! it painted and leaves every earlier stroke's ground as it was.

use super::Session;
use crate::stages::correct::W_FREE;
use crate::synth::control::SculptLayer;
use crate::synth::control::sculpt::Within;
use std::sync::Arc;

impl Session<'_> {
    pub(super) fn sculpt(&mut self, layer: Option<Arc<SculptLayer>>, weights0: &mut [u8]) {
        let old = self.controls.sculpt.take();
        let Some(rect) = SculptLayer::changed(old.as_deref(), layer.as_deref()) else {
            self.controls.sculpt = layer;
            return;
        };
        if let Some(o) = &old {
            self.blend.subtract(&Within { layer: o, rect });
        }
        if let Some(n) = &layer {
            self.blend.add(&Within { layer: n, rect });
        }
        let (w, h) = crate::level::state::level_size(self.width, self.height, 0);
        let clip = |v: f64, n: usize| (v.floor().max(0.0) as usize).min(n);
        let target = |l: &Option<Arc<SculptLayer>>, x: f64, y: f64| {
            l.as_ref().and_then(|l| l.target(x, y)).map(f64::to_bits)
        };
        for y in clip(rect[1], h)..clip(rect[3] + 1.0, h) {
            for x in clip(rect[0], w)..clip(rect[2] + 1.0, w) {
                let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
                if target(&old, px, py) != target(&layer, px, py) {
                    weights0[y * w + x] = W_FREE;
                }
            }
        }
        self.controls.sculpt = layer;
    }
}
