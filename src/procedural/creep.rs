//! Soil creep: linear hillslope diffusion, `∂h/∂t = D ∇²h` (Culling 1960).
//!
//! Where thermal erosion only acts above a threshold slope and leaves
//! straight talus planes, creep moves material downhill in proportion to the
//! slope everywhere, rounding crests into convex hilltops and softening the
//! facets that grid-based erosion leaves: the look of soil-mantled, rolling
//! landscapes.
//!
//! One explicit Jacobi step: `h' = h + r · Σ w_q (h_q − h) / 20` over the
//! 8 neighbours with isotropic weights (4 along edges, 1 diagonally, the
//! 9-point Laplacian of Patra & Karttunen 2006). `r ∈ (0, 0.5]` is the
//! fraction of the way to the weighted neighbour mean moved per step; the
//! diffusivity per step is `D = r · (3/10) · cell²`. The grid edge is closed
//! (missing neighbours are skipped), so mass is conserved.

use super::error::{ProceduralError, check_range};
use super::grid::{MOORE, neighbour, store, sweep, to_f64};
use crate::heightfield::Heightfield;
use crate::progress::Progress;

/// Weight of each neighbour in `MOORE` order: 4 along an edge, 1 diagonally.
const WEIGHTS: [f64; 8] = [1.0, 4.0, 1.0, 4.0, 4.0, 1.0, 4.0, 1.0];
/// The sum of [`WEIGHTS`]. Edge cells use the same normaliser (their missing
/// neighbours simply contribute nothing), so every exchange is symmetric and
/// mass is conserved.
const WEIGHT_SUM: f64 = 20.0;

/// Runs `iterations` creep steps with rate `r ∈ (0, 0.5]`. Refuses nodata.
pub fn creep(
    hf: &mut Heightfield,
    rate: f64,
    iterations: u32,
    progress: &dyn Progress,
) -> Result<(), ProceduralError> {
    check_range("creep rate", rate, 1e-6, 0.5, "a fraction in (0, 0.5]")?;
    let (w, h) = (hf.width(), hf.height());
    let mut cur = to_f64(hf)?;
    let mut next = vec![0.0; cur.len()];
    progress.start("soil creep", iterations as u64);
    for _ in 0..iterations {
        sweep(&mut next, w, |x, y| {
            let hp = cur[y * w + x];
            let mut flux = 0.0;
            for (&(dx, dy, _), &wt) in MOORE.iter().zip(&WEIGHTS) {
                if let Some(q) = neighbour(x, y, dx, dy, w, h) {
                    flux += wt * (cur[q] - hp);
                }
            }
            hp + rate * (flux / WEIGHT_SUM)
        });
        std::mem::swap(&mut cur, &mut next);
        progress.advance(1);
    }
    progress.finish();
    store(hf, &cur);
    Ok(())
}
