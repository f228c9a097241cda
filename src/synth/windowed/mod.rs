//! Windowed synthesis (issue 17): any window of a world of any size,
//! computed over the window's [`Cone`] only — memory and time in
//! proportion to the window, never the world — and byte for byte the same
//! as the same crop of the whole world's synthesis, because every level's
//! stages see, inside the cone, exactly the inputs they see in the whole
//! world and hash absolute coordinates (DESIGN §6).
//!
//! Under user control ([`controls`]) a window is what a scene's session
//! makes, with pastes computed over their bounded sources ([`paste`]) and
//! the control pyramids over aligned footprints ([`pyramid`]).
//!
//! (Not to be confused with [`super::window`], the region a coherent
//! re-synthesis restricts itself to.)

mod controls;
mod paste;
mod pyramid;

pub use controls::{Paint, WindowControls};

use super::cone::{Cone, Rect};
use super::{SynthError, Synthesis, Synthesizer};
use crate::georef::Georef;
use crate::heightfield::Heightfield;
use crate::size::{GridWindow, MAX_SIDE};

/// Why a world size or window cannot be synthesized.
#[non_exhaustive]
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum WindowError {
    #[error("world size {width}x{height} is invalid: expected 1..={MAX_SIDE} pixels per side")]
    World { width: usize, height: usize },
    #[error(
        "window {}x{} at ({}, {}) is invalid: expected at least 1x1 pixels inside the {}x{} world",
        .0.w, .0.h, .0.x, .0.y, .0.width, .0.height
    )]
    Window(GridWindow),
    #[error("{what} gave {got} values for a rectangle of {expected} pixels")]
    Paint {
        what: &'static str,
        got: usize,
        expected: usize,
    },
    #[error(
        "type paint at pixel ({x}, {y}) has type {id}: expected 0..={max} or 255 (unconstrained)"
    )]
    TypeId {
        x: usize,
        y: usize,
        id: u8,
        max: usize,
    },
}

impl Synthesizer<'_> {
    /// The heights of `window` (output pixels) of the `world` (width,
    /// height) that `seed` makes: the same samples as the window's crop of
    /// `synthesize(world.0, world.1, seed)`, computed over the window's
    /// cone only, so that worlds far too large for memory can be made tile
    /// by tile, anywhere, in any order. The heightfield is placed in the
    /// world's local grid (`Georef::local` of the world, shifted to the
    /// window), so GIS tools put the tiles of one world side by side.
    pub fn synthesize_window(
        &self,
        world: (usize, usize),
        window: Rect,
        seed: u32,
    ) -> Result<Heightfield, SynthError> {
        Ok(self.run_window(world, window, seed)?.heightfield)
    }

    /// [`Synthesizer::synthesize_window`] with timings (and the cone's
    /// levels, with [`super::Params::keep_levels`]).
    pub fn run_window(
        &self,
        world: (usize, usize),
        window: Rect,
        seed: u32,
    ) -> Result<Synthesis, SynthError> {
        let cone = self.window_cone(world, window)?;
        let mut out = self.dispatch(&cone, seed, None)?.0;
        self.place(&mut out.heightfield, &cone);
        Ok(out)
    }

    /// The cone a window of a world computes (see [`Cone`]), after checking
    /// both; [`Cone::bytes`] is the memory it needs.
    pub fn window_cone(&self, world: (usize, usize), window: Rect) -> Result<Cone, SynthError> {
        check_window(world, window)?;
        let cone = self.cone(world, window, &[]);
        let r = cone.region(0);
        crate::size::check_dims(r.width(), r.height())?;
        Ok(cone)
    }

    /// Places a window's heights in its world's local grid.
    pub(crate) fn place(&self, hf: &mut Heightfield, cone: &Cone) {
        let w = cone.window();
        let grid = Georef::local(cone.world().1, self.cell_size_m());
        hf.set_georef(Some(grid.shifted(w.x0, w.y0)));
    }
}

/// Checks a world size (each side 1..=[`MAX_SIDE`]; its pixel count is
/// unbounded, as only windows are ever allocated) and a window inside it.
pub fn check_window((width, height): (usize, usize), window: Rect) -> Result<(), WindowError> {
    if !(1..=MAX_SIDE).contains(&width) || !(1..=MAX_SIDE).contains(&height) {
        return Err(WindowError::World { width, height });
    }
    if window.x1 <= window.x0 || window.y1 <= window.y0 || window.x1 > width || window.y1 > height {
        return Err(WindowError::Window(GridWindow {
            x: window.x0,
            y: window.y0,
            w: window.x1.saturating_sub(window.x0),
            h: window.y1.saturating_sub(window.y0),
            width,
            height,
        }));
    }
    Ok(())
}
