//! What a sculpt stroke is, as painted: its [`Brush`] (raise, lower,
//! smooth, flatten, erode) and the [`BrushStroke`] it was drawn with.
//! Baking a stroke into target heights from the terrain it was painted on
//! is the scene's (`scene::bake`): it runs the erosion filter, which sits
//! above the synthesis.

use glam::DVec2;

/// Most nodes a baked grid has (~2.5 MB of scene JSON), so that a long,
/// wide stroke on a large terrain stays a document an editor can send.
pub const MAX_BAKED_NODES: f64 = 250_000.0;
/// What a stroke does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Brush {
    Raise,
    Lower,
    Smooth,
    Flatten,
    Erode,
}

impl Brush {
    pub const ALL: [Brush; 5] = [
        Brush::Raise,
        Brush::Lower,
        Brush::Smooth,
        Brush::Flatten,
        Brush::Erode,
    ];

    /// The name in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Brush::Raise => "raise",
            Brush::Lower => "lower",
            Brush::Smooth => "smooth",
            Brush::Flatten => "flatten",
            Brush::Erode => "erode",
        }
    }

    pub fn from_name(name: &str) -> Option<Brush> {
        Brush::ALL.into_iter().find(|b| b.name() == name)
    }

    /// Whether its strength is metres (raise, lower), else a share 0–1.
    pub fn strength_in_metres(self) -> bool {
        matches!(self, Brush::Raise | Brush::Lower)
    }

    /// Spacing of its target grid, output pixels: a quarter of the radius
    /// (2–16 px); for erosion, whose valleys are narrow, a sixteenth (2–16
    /// px). `scene::bake` widens it for a stroke so large that the grid would
    /// pass [`MAX_BAKED_NODES`].
    pub fn step(self, radius_px: f64) -> f64 {
        let share = match self {
            Brush::Erode => 16.0,
            _ => 4.0,
        };
        (radius_px / share).round().clamp(2.0, 16.0)
    }
}

/// A stroke as painted, before baking.
#[derive(Debug, Clone, PartialEq)]
pub struct BrushStroke {
    pub brush: Brush,
    /// The polyline (one point for a dab), output pixels.
    pub points: Vec<DVec2>,
    pub radius_px: f64,
    /// Metres for raise and lower, a share 0–1 for the others.
    pub strength: f64,
    /// The outer share of the radius over which the effect fades (0–1).
    pub falloff: f64,
}

impl BrushStroke {
    /// The weight at distance `d` from the polyline.
    pub fn weight(&self, d: f64) -> f64 {
        let r = self.radius_px;
        let inner = r * (1.0 - self.falloff);
        if d >= r {
            0.0
        } else if d <= inner {
            1.0
        } else {
            let t = (r - d) / (r - inner);
            t * t * (3.0 - 2.0 * t)
        }
    }
}
