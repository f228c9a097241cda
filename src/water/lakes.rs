//! Lakes as water depth: where the fill raised the ground, the difference
//! is standing water. A lake is one 8-connected body of raised cells at one
//! level; bodies shallower than a minimum depth (their deepest cell) or
//! smaller than a minimum area are not lakes. Those are the noise of a DEM
//! (SRTM's heights are integer metres with metres of noise, and every
//! 1–2 m dimple of a few cells fills), still filled for flow, never shown
//! as water.

use serde::Serialize;

/// [`Bodies::class`] of a cell: dry ground (or a fill too small to be a lake).
pub const LAND: u8 = 0;
/// [`Bodies::class`] of a cell: part of a lake.
pub const LAKE: u8 = 1;
/// [`Bodies::class`] of a cell: the sea.
pub const SEA: u8 = 2;

/// One lake.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Lake {
    /// Its deepest cell (column, row).
    pub x: usize,
    pub y: usize,
    /// Water surface, metres (the spill level).
    pub level_m: f32,
    pub cells: usize,
    pub area_km2: f64,
    pub volume_m3: f64,
    pub max_depth_m: f32,
}

/// The water bodies of a filled surface.
#[derive(Debug, Clone)]
pub struct Bodies {
    /// [`LAND`], [`LAKE`] or [`SEA`] per cell.
    pub class: Vec<u8>,
    /// Water depth in metres: lakes and sea, 0 elsewhere.
    pub depth: Vec<f32>,
    /// Every lake, in row-major order of its first cell.
    pub lakes: Vec<Lake>,
    /// Bodies the fill raised but too shallow or small to be lakes.
    pub below_thresholds: usize,
}

/// What makes a filled depression a lake.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Thresholds {
    /// Metres at its deepest cell.
    pub min_depth_m: f64,
    /// Square kilometres.
    pub min_area_km2: f64,
}

/// Finds the lakes (and marks the sea) of `filled`, the fill of `original`.
pub fn find(
    original: &[f32],
    filled: &[f32],
    (w, h, cell_size): (usize, usize, f64),
    sea: Option<&[bool]>,
    t: Thresholds,
) -> Bodies {
    let n = w * h;
    let cell_area = cell_size * cell_size;
    let mut class = vec![LAND; n];
    let mut depth = vec![0.0f32; n];
    if let Some(m) = sea {
        for i in (0..n).filter(|&i| m[i]) {
            class[i] = SEA;
            depth[i] = filled[i] - original[i];
        }
    }
    let raised = |i: usize| filled[i] > original[i] && !sea.is_some_and(|m| m[i]);
    let mut seen = vec![false; n];
    let offsets: [isize; 8] = super::d8::CLOCKWISE.map(|(dx, dy, _)| dy * w as isize + dx);
    let (mut lakes, mut below_thresholds) = (Vec::new(), 0);
    let mut body = Vec::new();
    let mut stack = Vec::new();
    for start in 0..n {
        if seen[start] || !raised(start) {
            continue;
        }
        let level = filled[start];
        seen[start] = true;
        stack.push(start);
        body.clear();
        while let Some(c) = stack.pop() {
            body.push(c);
            // Raised cells are interior (the border is never raised).
            for o in offsets {
                let k = c.wrapping_add_signed(o);
                if !seen[k] && filled[k] == level && raised(k) {
                    seen[k] = true;
                    stack.push(k);
                }
            }
        }
        let deepest = *body
            .iter()
            .max_by(|&&a, &&b| (level - original[a]).total_cmp(&(level - original[b])))
            .expect("a body holds its first cell");
        let max_depth = level - original[deepest];
        let area_km2 = body.len() as f64 * cell_area / 1e6;
        if (max_depth as f64) < t.min_depth_m || area_km2 < t.min_area_km2 {
            below_thresholds += 1;
            continue;
        }
        let mut volume = 0.0f64;
        for &c in &body {
            class[c] = LAKE;
            depth[c] = level - original[c];
            volume += depth[c] as f64 * cell_area;
        }
        lakes.push(Lake {
            x: deepest % w,
            y: deepest / w,
            level_m: level,
            cells: body.len(),
            area_km2,
            volume_m3: volume,
            max_depth_m: max_depth,
        });
    }
    Bodies {
        class,
        depth,
        lakes,
        below_thresholds,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn deep_wide_fills_are_lakes_and_dimples_are_not() {
        // 8×4 at 10 m, cells of 100 m (0.01 km²): a 3-cell basin 4 m deep
        // and a 1-cell dimple 1 m deep, both filled to 10 m.
        let (w, h) = (8, 4);
        let mut z = vec![10.0f32; w * h];
        z[w + 1] = 6.0;
        z[w + 2] = 7.0;
        z[2 * w + 1] = 8.0;
        z[w + 5] = 9.0;
        let filled = vec![10.0f32; w * h];
        let t = Thresholds {
            min_depth_m: 2.0,
            min_area_km2: 0.02,
        };
        let b = find(&z, &filled, (w, h, 100.0), None, t);
        assert_eq!(b.lakes.len(), 1);
        assert_eq!(b.below_thresholds, 1);
        let l = &b.lakes[0];
        assert_eq!((l.x, l.y, l.cells, l.max_depth_m), (1, 1, 3, 4.0));
        assert!((l.volume_m3 - (4.0 + 3.0 + 2.0) * 1e4).abs() < 1e-6);
        assert_eq!(b.depth[w + 5], 0.0, "the dimple is not water");
        assert_eq!(b.class[w + 2], LAKE);
    }
}
