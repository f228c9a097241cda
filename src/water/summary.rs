//! `terrasynth water --json`: lake count, area and volume, the sea, river
//! length by Strahler order.

use super::Water;
use super::lakes::{LAND, Lake, SEA};
use super::rivers::End;
use serde::Serialize;
use std::collections::BTreeMap;

/// How many of the largest lakes the summary lists.
const LARGEST: usize = 10;

/// What [`Water::summary`] reports.
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    pub width: usize,
    pub height: usize,
    pub cell_size_m: f64,
    pub sea_level_m: Option<f32>,
    /// `None` without a sea level.
    pub sea: Option<Sea>,
    pub lakes: Lakes,
    /// Cells the fill raised outside the sea (lakes included).
    pub filled_cells: usize,
    pub rivers: Rivers,
}

#[derive(Debug, Clone, Serialize)]
pub struct Sea {
    pub cells: usize,
    pub area_km2: f64,
    pub volume_m3: f64,
}

#[derive(Debug, Clone, Serialize)]
pub struct Lakes {
    pub count: usize,
    pub area_km2: f64,
    pub volume_m3: f64,
    pub min_depth_m: f64,
    pub min_area_km2: f64,
    /// Filled depressions below the thresholds (not lakes).
    pub below_thresholds: usize,
    /// The largest lakes by area, at most ten.
    pub largest: Vec<Lake>,
}

#[derive(Debug, Clone, Serialize)]
pub struct Rivers {
    pub min_area_km2: f64,
    pub threshold_cells: u32,
    pub cells: usize,
    pub segments: usize,
    pub max_order: u8,
    /// Strahler order → kilometres of river.
    pub length_km_by_order: BTreeMap<u8, f64>,
    /// How segments end: confluence, lake, sea, border → count.
    pub segment_ends: BTreeMap<End, usize>,
}

impl Water {
    /// The summary `--json` prints.
    pub fn summary(&self) -> Summary {
        let cell_area = self.cell_size * self.cell_size;
        let class = &self.bodies.class;
        let sea = self.params.sea_level.map(|_| {
            let cells: Vec<usize> = (0..class.len()).filter(|&i| class[i] == SEA).collect();
            Sea {
                cells: cells.len(),
                area_km2: cells.len() as f64 * cell_area / 1e6,
                volume_m3: cells
                    .iter()
                    .fold(0.0, |v, &i| v + self.bodies.depth[i] as f64 * cell_area),
            }
        });
        let lakes = &self.bodies.lakes;
        let mut largest = lakes.clone();
        largest.sort_by(|a, b| b.cells.cmp(&a.cells).then((a.y, a.x).cmp(&(b.y, b.x))));
        largest.truncate(LARGEST);
        let mut length_km_by_order = BTreeMap::new();
        let mut segment_ends = BTreeMap::new();
        for s in &self.rivers.segments {
            *length_km_by_order.entry(s.order).or_insert(0.0) +=
                s.length_cells(self.width) * self.cell_size / 1e3;
            *segment_ends.entry(s.end).or_insert(0) += 1;
        }
        Summary {
            width: self.width,
            height: self.height,
            cell_size_m: self.cell_size,
            sea_level_m: self.params.sea_level,
            sea,
            lakes: Lakes {
                count: lakes.len(),
                // Folds from +0.0: an empty f64 sum is −0.0.
                area_km2: lakes.iter().fold(0.0, |a, l| a + l.area_km2),
                volume_m3: lakes.iter().fold(0.0, |v, l| v + l.volume_m3),
                min_depth_m: self.params.lakes.min_depth_m,
                min_area_km2: self.params.lakes.min_area_km2,
                below_thresholds: self.bodies.below_thresholds,
                largest,
            },
            filled_cells: self.filled_cells,
            rivers: Rivers {
                min_area_km2: self.params.river_area_km2,
                threshold_cells: self.river_threshold_cells(),
                cells: self
                    .rivers
                    .order
                    .iter()
                    .zip(class)
                    .filter(|(o, c)| **o > 0 && **c == LAND)
                    .count(),
                segments: self.rivers.segments.len(),
                max_order: self
                    .rivers
                    .segments
                    .iter()
                    .map(|s| s.order)
                    .max()
                    .unwrap_or(0),
                length_km_by_order,
                segment_ends,
            },
        }
    }
}
