//! Grid-size validation: [`SizeError`] and the limits every reader and
//! constructor checks a declared size against ([`check_dims`]) before it
//! allocates. Kept apart from [`crate::error`] and [`crate::heightfield`] so
//! that the per-area error types (`io`, `database`, `render`, …) can wrap
//! `SizeError` without depending on the crate-wide [`crate::error::Error`],
//! which in turn wraps them.

use thiserror::Error;

/// A grid size, window or cell size that cannot be used.
#[non_exhaustive]
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SizeError {
    #[error("size {width}x{height} is empty: width and height must be at least 1")]
    Empty { width: usize, height: usize },
    #[error(
        "size {width}x{height} is too large: at most {max_side} per side and {max_pixels} samples"
    )]
    TooLarge {
        width: usize,
        height: usize,
        max_side: usize,
        max_pixels: usize,
    },
    #[error("sample count {found} does not match the size ({expected} expected)")]
    Length { expected: usize, found: usize },
    #[error("sample at pixel ({x}, {y}) is infinite: heights must be finite, or NaN for nodata")]
    Infinite { x: usize, y: usize },
    #[error("cell size {0} m is invalid: expected a finite value > 0")]
    CellSize(f64),
    #[error(
        "window {}x{} at ({}, {}) does not fit a {}x{} grid",
        .0.w, .0.h, .0.x, .0.y, .0.width, .0.height
    )]
    Window(GridWindow),
}

/// A `w × h` window at `(x, y)` asked of a `width × height` grid: what a
/// window error reports, for heightfields and masks ([`SizeError::Window`])
/// as for windows of a synthesized world.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GridWindow {
    pub x: usize,
    pub y: usize,
    pub w: usize,
    pub h: usize,
    pub width: usize,
    pub height: usize,
}

/// Largest accepted side, in samples. Larger grids are refused before any
/// allocation (a corrupt header must not make us allocate gigabytes).
pub const MAX_SIDE: usize = 1 << 20;
/// Largest accepted sample count (4 GiB of `f32`).
pub const MAX_PIXELS: usize = 1 << 30;

/// Checks a declared grid size before anything is allocated for it.
pub fn check_dims(width: usize, height: usize) -> Result<(), SizeError> {
    if width == 0 || height == 0 {
        return Err(SizeError::Empty { width, height });
    }
    if width > MAX_SIDE || height > MAX_SIDE || width.saturating_mul(height) > MAX_PIXELS {
        return Err(SizeError::TooLarge {
            width,
            height,
            max_side: MAX_SIDE,
            max_pixels: MAX_PIXELS,
        });
    }
    Ok(())
}

/// Checks that a `w × h` window at `(x, y)` is not empty and lies inside a
/// `width × height` grid.
pub fn check_window(
    x: usize,
    y: usize,
    w: usize,
    h: usize,
    width: usize,
    height: usize,
) -> Result<(), SizeError> {
    if w == 0 || h == 0 || x + w > width || y + h > height {
        return Err(SizeError::Window(GridWindow {
            x,
            y,
            w,
            h,
            width,
            height,
        }));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_must_be_inside_and_not_empty() {
        assert_eq!(check_window(2, 3, 5, 5, 7, 8), Ok(()));
        let e = check_window(3, 4, 5, 6, 7, 8).unwrap_err();
        assert_eq!(
            e.to_string(),
            "window 5x6 at (3, 4) does not fit a 7x8 grid"
        );
        assert!(check_window(0, 0, 0, 1, 7, 8).is_err());
    }
}
