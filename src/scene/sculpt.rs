//! A scene's sculpt strokes as the session's sculpt layer, and baking the
//! strokes an editor has just painted (their targets from the terrain
//! shown) into the document it stores.

use super::bake::bake;
use super::*;
use crate::heightfield::Heightfield;
use crate::synth::control::SculptLayer;
use crate::synth::control::sculpt::{Brush, SculptStroke};
use serde_json::{Value, json};
use std::sync::Arc;

impl Scene {
    /// The layer of the scene's sculpt strokes (None without any); a
    /// stroke without targets is an error naming it.
    pub fn sculpt_layer(&self) -> Result<Option<Arc<SculptLayer>>, SceneError> {
        if self.sculpt.is_empty() {
            return Ok(None);
        }
        let mut strokes = Vec::with_capacity(self.sculpt.len());
        for (i, s) in self.sculpt.iter().enumerate() {
            let Some(targets) = s.targets.clone() else {
                return Err(self.err(
                    format!("sculpt[{i}].targets"),
                    SceneErrorKind::Missing(
                        "the stroke's baked target heights (the editor writes them when the stroke is painted)",
                    ),
                ));
            };
            strokes.push(Arc::new(SculptStroke {
                points: s.stroke.points.clone(),
                radius_px: s.stroke.radius_px,
                targets,
                hard: s.stroke.brush == Brush::Erode,
            }));
        }
        Ok(Some(Arc::new(SculptLayer::new(strokes))))
    }

    /// Bakes every stroke without targets against `terrain` (the heights
    /// it was painted on), in order, each over the strokes before it;
    /// returns their indices.
    pub fn bake_sculpt(&mut self, terrain: &Heightfield) -> Vec<usize> {
        let mut baked = Vec::new();
        for i in 0..self.sculpt.len() {
            if self.sculpt[i].targets.is_some() {
                continue;
            }
            let below: Vec<Arc<SculptStroke>> = self.sculpt[..i]
                .iter()
                .filter_map(|s| {
                    Some(Arc::new(SculptStroke {
                        points: s.stroke.points.clone(),
                        radius_px: s.stroke.radius_px,
                        targets: s.targets.clone()?,
                        hard: s.stroke.brush == Brush::Erode,
                    }))
                })
                .collect();
            let below = (!below.is_empty()).then(|| SculptLayer::new(below));
            self.sculpt[i].targets = Some(bake(&self.sculpt[i].stroke, terrain, below.as_ref()));
            baked.push(i);
        }
        baked
    }
}

impl Scene {
    /// [`Scene::bake_sculpt`] for the next scene of a session (`terrasynth
    /// edit`): a stroke `prev` has at the same index, as painted, keeps the
    /// targets it was baked into there; the others are baked against
    /// `terrain`, the frame `prev` made.
    pub fn bake_sculpt_over(&mut self, prev: &Scene, terrain: &Heightfield) -> Vec<usize> {
        for (s, p) in self.sculpt.iter_mut().zip(&prev.sculpt) {
            if s.targets.is_none() && s.stroke == p.stroke {
                s.targets = p.targets.clone();
            }
        }
        self.bake_sculpt(terrain)
    }
}

/// A baked stroke's `"targets"` as the scene format writes it.
pub fn targets_json(s: &SculptSpec) -> Value {
    match &s.targets {
        None => Value::Null,
        Some(g) => json!({
            "at": [g.x0, g.y0],
            "step_px": g.step,
            "size": [g.width, g.height],
            "heights_m": g.heights_m,
        }),
    }
}
