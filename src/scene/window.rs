//! Scenes for windowed synthesis (issue 17): a scene prepared once — its
//! constraints built, its pastes placed, image paint read — whose windows
//! are then synthesized anywhere, in any order, each byte for byte the
//! same crop as `synth --scene` of the whole scene
//! (`Synthesizer::synthesize_window_with`).
//!
//! Stroke paint (types, freezing) is painted over each window's footprint
//! only; image paint is the scene's size by definition, so it is read once,
//! whole, and cropped.

use super::raster::paint_strokes;
use super::{Freeze, Scene, SceneEdits, SceneError, Stroke, TypePaint};
use crate::database::Database;
use crate::heightfield::Heightfield;
use crate::io::maps::type_mask::NO_TYPE;
use crate::synth::cone::Rect;
use crate::synth::control::{Constraint, Paste};
use crate::synth::session::Edit;
use crate::synth::{Params, SynthError, Synthesizer, WindowControls};
use std::sync::Arc;

/// Paint of one kind: strokes painted on demand, or a scene-sized raster.
enum Painted<T> {
    Strokes(Vec<(Stroke, T)>),
    Raster(Vec<T>),
}

impl<T: Copy + Send + Sync> Painted<T> {
    /// The pixels of `rect` (inside a `width`-wide scene).
    fn over(&self, width: usize, rect: Rect, blank: T) -> Vec<T> {
        match self {
            Painted::Strokes(s) => paint_strokes(rect, s, blank),
            Painted::Raster(r) => (rect.y0..rect.y1)
                .flat_map(|y| r[y * width + rect.x0..y * width + rect.x1].iter().copied())
                .collect(),
        }
    }
}

/// A scene ready for windowed synthesis.
pub struct WindowedScene {
    pub width: usize,
    pub height: usize,
    pub seed: u32,
    params: Params,
    constraints: Vec<Arc<dyn Constraint>>,
    pastes: Vec<Paste>,
    types: Option<Painted<u8>>,
    freeze: Option<Painted<bool>>,
}

impl WindowedScene {
    /// Builds the scene's controls against `db` (the same checks and the
    /// same constraints as `SceneEdits::edits`).
    pub fn new(scene: &Scene, db: &Database) -> Result<WindowedScene, SceneError> {
        // The edits of the scene without paint: constraints and pastes,
        // with no scene-sized raster made.
        let bare = Scene {
            types: None,
            freeze: None,
            ..scene.clone()
        };
        let mut constraints = Vec::new();
        let mut pastes = Vec::new();
        for e in SceneEdits::new().edits(&bare, db)? {
            match e {
                Edit::SetConstraint(_, c) => constraints.push(c),
                Edit::Paste(p) => pastes.push(p),
                Edit::Sculpt(Some(layer)) => constraints.push(layer as Arc<dyn Constraint>),
                _ => {}
            }
        }
        let types = match &scene.types {
            None => None,
            Some(TypePaint::Strokes(_)) => {
                scene.type_strokes(db.type_names())?.map(Painted::Strokes)
            }
            Some(TypePaint::Image(_)) => scene.type_raster(db.type_names())?.map(Painted::Raster),
        };
        let freeze = match &scene.freeze {
            None => None,
            Some(Freeze::Strokes(s)) => Some(Painted::Strokes(
                s.iter().map(|(v, s)| (s.clone(), *v)).collect(),
            )),
            Some(Freeze::Mask(_)) => scene.freeze_raster()?.map(Painted::Raster),
        };
        Ok(WindowedScene {
            width: scene.width,
            height: scene.height,
            seed: scene.seed,
            params: SceneEdits::params(scene),
            constraints,
            pastes,
            types,
            freeze,
        })
    }

    /// The synthesis parameters the scene asks for.
    pub fn params(&self) -> Params {
        self.params.clone()
    }

    /// The heights of `window` of the scene's terrain, synthesized by
    /// `synth` (made with [`WindowedScene::params`] on the scene's
    /// database).
    pub fn synthesize_window(
        &self,
        synth: &Synthesizer<'_>,
        window: Rect,
    ) -> Result<Heightfield, SynthError> {
        let w = self.width;
        let types = |r: Rect| {
            self.types
                .as_ref()
                .map_or(vec![], |p| p.over(w, r, NO_TYPE))
        };
        let freeze = |r: Rect| self.freeze.as_ref().map_or(vec![], |p| p.over(w, r, false));
        let controls = WindowControls {
            constraints: &self.constraints,
            types: self.types.is_some().then_some(&types as _),
            freeze: self.freeze.is_some().then_some(&freeze as _),
            pastes: &self.pastes,
        };
        synth.synthesize_window_with((self.width, self.height), window, self.seed, &controls)
    }
}
