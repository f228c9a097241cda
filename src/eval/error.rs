use thiserror::Error;

/// Why a terrain could not be evaluated.
#[non_exhaustive]
#[derive(Debug, Error, Clone, PartialEq)]
pub enum EvalError {
    #[error(
        "terrain {width}x{height} is too small to describe: expected at least {min}x{min} cells"
    )]
    TooSmall {
        width: usize,
        height: usize,
        min: usize,
    },
    #[error(
        "{count} nodata samples (the first at pixel ({x}, {y})): descriptors need every height; fill them first (terrasynth convert --fill-nodata)"
    )]
    Nodata { count: usize, x: usize, y: usize },
    #[error(
        "novelty settings {0:?} are invalid: expected window / downsample >= 4, max_windows >= 2, \
         0 < threshold <= 1 and flat >= 0"
    )]
    NoveltyParams(super::novelty::Params),
    #[error(
        "coordinates map pixel ({x}, {y}) names exemplar {exemplar}, but the database has {count} (0..={max})",
        max = count.saturating_sub(1)
    )]
    NoSuchExemplar {
        x: usize,
        y: usize,
        exemplar: u16,
        count: usize,
    },
    #[error(
        "coordinates map pixel ({x}, {y}) points at ({sx}, {sy}), outside exemplar {exemplar} ({width}x{height}): was the map made with another database?"
    )]
    OutsideExemplar {
        x: usize,
        y: usize,
        sx: u16,
        sy: u16,
        exemplar: u16,
        width: u32,
        height: u32,
    },
}
