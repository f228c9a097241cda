//! The tile grid of a world: which pixels each tile file holds and under
//! which name.

use crate::synth::cone::Rect;

/// A world cut into `tile × tile` cores (the last row and column shorter),
/// each written with `overlap` more pixels on every side where the world
/// has them — so a consumer that blends tile borders has the pixels to
/// blend, while the cores alone rebuild the world exactly.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Grid {
    pub world: (usize, usize),
    pub tile: usize,
    pub overlap: usize,
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
        (
            self.world.0.div_ceil(self.tile),
            self.world.1.div_ceil(self.tile),
        )
    }

    /// Every tile, row by row.
    pub fn tiles(&self) -> impl Iterator<Item = Tile> + '_ {
        let (cols, rows) = self.size();
        (0..rows).flat_map(move |row| (0..cols).map(move |col| self.tile(col, row)))
    }

    fn tile(&self, col: usize, row: usize) -> Tile {
        let (w, h) = self.world;
        let (x0, y0) = (col * self.tile, row * self.tile);
        let core = Rect {
            x0,
            y0,
            x1: (x0 + self.tile).min(w),
            y1: (y0 + self.tile).min(h),
        };
        Tile {
            col,
            row,
            core,
            extent: core.widen(self.overlap, (w, h)),
        }
    }

    /// The file name of a tile: `tile_<col>_<row>.<ext>`, both numbers
    /// zero-padded to the grid's widest, so names sort in grid order.
    pub fn file_name(&self, t: &Tile, ext: &str) -> String {
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
        };
        let last = big.tiles().last().unwrap();
        assert_eq!(big.file_name(&last, "png"), "tile_63_00.png");
    }
}
