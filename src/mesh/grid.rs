//! The regular mesh: every sample a vertex (every `stride`-th for a
//! coarser level of detail, each tile's last row and column always kept),
//! two triangles a cell, all cut along the same diagonal (south-west to
//! north-east). Tiles of `tile` cells share their border samples, and the
//! samples along a shared border are the same from both sides (they
//! depend on the border's own range only), so neighbours meet exactly.

use super::Triangulation;

/// `from`, `from + stride`, … below `to`, then `to`.
fn samples(from: usize, to: usize, stride: usize) -> Vec<u32> {
    let mut v: Vec<u32> = (from..to).step_by(stride).map(|s| s as u32).collect();
    v.push(to as u32);
    v
}

/// The tiles of a `width × height` grid (at least 2×2), row-major.
pub fn triangulate(width: usize, height: usize, tile: usize, stride: usize) -> Vec<Triangulation> {
    let tiles = ((width - 1).div_ceil(tile), (height - 1).div_ceil(tile));
    let mut out = Vec::with_capacity(tiles.0 * tiles.1);
    for ty in 0..tiles.1 {
        let ys = samples(ty * tile, ((ty + 1) * tile).min(height - 1), stride);
        for tx in 0..tiles.0 {
            let xs = samples(tx * tile, ((tx + 1) * tile).min(width - 1), stride);
            let n = xs.len() as u32;
            let mut t = Triangulation {
                vertices: Vec::with_capacity(xs.len() * ys.len()),
                triangles: Vec::with_capacity(2 * (xs.len() - 1) * (ys.len() - 1)),
            };
            for &y in &ys {
                t.vertices.extend(xs.iter().map(|&x| [x, y]));
            }
            for j in 0..ys.len() as u32 - 1 {
                for i in 0..n - 1 {
                    // a b on this row, c d below: counter-clockwise from above.
                    let (a, b) = (j * n + i, j * n + i + 1);
                    let (c, d) = (a + n, b + n);
                    t.triangles.push([a, c, b]);
                    t.triangles.push([b, c, d]);
                }
            }
            out.push(t);
        }
    }
    out
}
