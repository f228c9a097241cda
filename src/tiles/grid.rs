//! The tile grid of a world: which pixels each tile file holds and under
//! which name.

use crate::io::engine::Engine;
use crate::synth::cone::Rect;

/// A world cut into `tile × tile` cores (the last row and column shorter),
/// each written with `overlap` more pixels on every side where the world
/// has them — so a consumer that blends tile borders has the pixels to
/// blend, while the cores alone rebuild the world exactly.
///
/// For an `engine`, `tile` counts quads: tile `i` starts at sample
/// `i·tile` and its file holds `tile + 1` samples, the last one shared
/// with the next tile ([`super::engine`]); the world is `k·tile + 1`
/// samples across, and the last tile's core takes the world's last sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Grid {
    pub world: (usize, usize),
    pub tile: usize,
    pub overlap: usize,
    pub engine: Option<Engine>,
}

/// One tile of a [`Grid`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Tile {
    pub col: usize,
    pub row: usize,
    /// The pixels this tile stands for in the mosaic.
    pub core: Rect,
    /// The pixels its file holds: the core and the overlap around it.
    pub extent: Rect,
}

impl Grid {
    /// Columns and rows.
    pub fn size(&self) -> (usize, usize) {
        let shared = usize::from(self.engine.is_some());
        (
            (self.world.0 - shared).div_ceil(self.tile).max(1),
            (self.world.1 - shared).div_ceil(self.tile).max(1),
        )
    }

    /// Every tile, row by row.
    pub fn tiles(&self) -> impl Iterator<Item = Tile> + '_ {
        let (cols, rows) = self.size();
        (0..rows).flat_map(move |row| (0..cols).map(move |col| self.tile(col, row)))
    }

    fn tile(&self, col: usize, row: usize) -> Tile {
        let (w, h) = self.world;
        let (cols, rows) = self.size();
        let (x0, y0) = (col * self.tile, row * self.tile);
        // The end of a core: the next tile's start, the world's end for the
        // last (which, for an engine, is its shared sample).
        let end = |start: usize, last: bool, n: usize| match last && self.engine.is_some() {
            true => n,
            false => (start + self.tile).min(n),
        };
        let core = Rect {
            x0,
            y0,
            x1: end(x0, col + 1 == cols, w),
            y1: end(y0, row + 1 == rows, h),
        };
        let extent = match self.engine {
            Some(_) => Rect {
                x1: (x0 + self.tile + 1).min(w),
                y1: (y0 + self.tile + 1).min(h),
                ..core
            },
            None => core.widen(self.overlap, (w, h)),
        };
        Tile {
            col,
            row,
            core,
            extent,
        }
    }

    /// The file name of a tile: `tile_<col>_<row>.<ext>`, both numbers
    /// zero-padded to the grid's widest, so names sort in grid order; an
    /// engine's own names for its tiles ([`super::engine::file_name`]).
    pub fn file_name(&self, t: &Tile, ext: &str) -> String {
        if let Some(e) = self.engine {
            return super::engine::file_name(e, self, t);
        }
        let (cols, rows) = self.size();
        let digits = (cols.max(rows) - 1).max(1).ilog10() as usize + 1;
        format!("tile_{:0digits$}_{:0digits$}.{ext}", t.col, t.row)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cores_partition_the_world_and_extents_add_the_overlap() {
        let g = Grid {
            world: (250, 100),
            tile: 100,
            overlap: 8,
            engine: None,
        };
        assert_eq!(g.size(), (3, 1));
        let t: Vec<Tile> = g.tiles().collect();
        assert_eq!(t[0].core, Rect::new(0, 0, 100, 100));
        assert_eq!(t[0].extent, Rect::new(0, 0, 108, 100));
        assert_eq!(t[2].core, Rect::new(200, 0, 50, 100));
        assert_eq!(t[2].extent, Rect::new(192, 0, 58, 100));
        let area: usize = t.iter().map(|t| t.core.pixels()).sum();
        assert_eq!(area, 250 * 100);
        assert_eq!(g.file_name(&t[2], "tif"), "tile_2_0.tif");
        let big = Grid {
            world: (65536, 1024),
            tile: 1024,
            overlap: 0,
            engine: None,
        };
        let last = big.tiles().last().unwrap();
        assert_eq!(big.file_name(&last, "png"), "tile_63_00.png");
    }

    #[test]
    fn engine_tiles_share_their_edge_samples() {
        let g = Grid {
            world: (2 * 1008 + 1, 1009),
            tile: 1008,
            overlap: 0,
            engine: Some(Engine::Unreal),
        };
        assert_eq!(g.size(), (2, 1));
        let t: Vec<Tile> = g.tiles().collect();
        assert_eq!(t[0].core, Rect::new(0, 0, 1008, 1009));
        assert_eq!(t[0].extent, Rect::new(0, 0, 1009, 1009));
        assert_eq!(t[1].core, Rect::new(1008, 0, 1009, 1009));
        assert_eq!(t[1].extent, Rect::new(1008, 0, 1009, 1009));
        assert_eq!(g.file_name(&t[1], "png"), "tile_x1_y0.png");
        let unity = Grid {
            world: (257, 3 * 256 + 1),
            tile: 256,
            engine: Some(Engine::Unity),
            ..g
        };
        let t: Vec<Tile> = unity.tiles().collect();
        assert_eq!(t.len(), 3);
        assert_eq!(t[2].extent, Rect::new(0, 512, 257, 257));
        // Z counts northwards: the first row of tiles is the northernmost.
        let names: Vec<String> = t.iter().map(|x| unity.file_name(x, "raw")).collect();
        assert_eq!(names, ["tile_0_2.raw", "tile_0_1.raw", "tile_0_0.raw"]);
        let area: usize = t.iter().map(|t| t.core.pixels()).sum();
        assert_eq!(area, 257 * 769);
    }
}
