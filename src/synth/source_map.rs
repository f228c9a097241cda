//! Level-0 synthesis coordinates → a [`CoordsMap`]: which exemplar texel
//! every output pixel was drawn from (`synth --coords`; `eval` reads it back
//! for type usage).

use crate::database::Database;
use crate::io::maps::coords_map::{CoordsMap, NO_EXEMPLAR, Source};
use crate::level::fixed::{Coord, round};

/// The sources of the `width × height` output from level-0 coordinates
/// (`stride` pixels per row, as [`super::LevelMaps`] and
/// [`super::PassResult`] keep them). A coordinate is fixed point; its
/// source is the **nearest** texel (half up, [`round`]): reconstruction
/// interpolates between it and its neighbours, but the nearest texel is the
/// one that dominates. A coordinate outside every exemplar (never made by
/// synthesis; coordinates stay in exemplar interiors) maps to
/// [`NO_EXEMPLAR`].
pub fn source_map(
    coords: &[Coord],
    stride: usize,
    width: usize,
    height: usize,
    db: &Database,
) -> CoordsMap {
    let level = db.level(0);
    let mut sources = Vec::with_capacity(width * height);
    for y in 0..height {
        for c in &coords[y * stride..y * stride + width] {
            let (tx, ty) = (round(c.x), round(c.y));
            let src = (tx >= 0 && ty >= 0)
                .then(|| {
                    level
                        .layout
                        .exemplar_at(level.columns, tx as u32, ty as u32)
                })
                .flatten()
                .map_or(
                    Source {
                        x: 0,
                        y: 0,
                        exemplar: NO_EXEMPLAR,
                    },
                    |e| Source {
                        x: (tx as u32 - level.layout.rects[e].x0) as u16,
                        y: ty as u16,
                        exemplar: e as u16,
                    },
                );
            sources.push(src);
        }
    }
    CoordsMap::new(width, height, sources).expect("sizes come from a synthesis")
}
