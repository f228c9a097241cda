//! Merging a chosen patch into the output (seed 004 §4.3; seed 001 §5):
//! 1. a graph-cut seam over the window ([`crate::patch::merge::graphcut`]), on the patch
//!    shifted by its mean difference to the overlap (the gradient-domain
//!    merge removes that offset anyway, so it must not drive the seam);
//! 2. Shepard interpolation of the gradient mismatch along the seam into
//!    the new side (Tasse et al., after Milliron et al. 2002): the new
//!    patch's gradients are bent to equal the old ones at the seam and the
//!    correction fades out over `R` = patch/4;
//! 3. a Poisson solve for heights with those gradients, the old pixels as
//!    Dirichlet values (the crate's multigrid-preconditioned solver for
//!    small grids, [`crate::poisson::Method::Multigrid`], started from the patch).

pub(crate) mod broad_shape;
pub mod graphcut;
pub mod join_pits;

use crate::blend::gradient_domain::guided_rhs;
use crate::patch::merge::graphcut::{Label, Seam, kwatra, min_cut};
use crate::poisson::{Method, SolveOptions, SolveReport, solve};

/// The output being synthesized.
#[derive(Debug, Clone, PartialEq)]
pub struct Canvas {
    pub width: usize,
    pub height: usize,
    pub heights: Vec<f32>,
    pub filled: Vec<bool>,
    /// Which source each filled pixel came from (index into the library's
    /// sources; [`Canvas::NO_SOURCE`] where nothing is placed): the
    /// coherence cost of round two reads it ([`crate::patch::Weights::coherence`]).
    pub source: Vec<u32>,
    /// Which placement each filled pixel came from (its index among the
    /// merges, in order; [`Canvas::NO_SOURCE`] where nothing is placed):
    /// where a pixel's 3×3 neighbours came from two placements, the
    /// neighbourhood exists in no source ([`join_pits`]).
    pub placement: Vec<u32>,
    /// How many patches were merged so far.
    pub placed: u32,
}

impl Canvas {
    /// [`Canvas::source`] of a pixel nothing has been placed on.
    pub const NO_SOURCE: u32 = u32::MAX;

    pub fn new(width: usize, height: usize) -> Canvas {
        Canvas {
            width,
            height,
            heights: vec![0.0; width * height],
            filled: vec![false; width * height],
            source: vec![Canvas::NO_SOURCE; width * height],
            placement: vec![Canvas::NO_SOURCE; width * height],
            placed: 0,
        }
    }
}

/// A square window of the canvas (always inside it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Window {
    pub x0: usize,
    pub y0: usize,
    pub n: usize,
}

impl Window {
    /// The `n × n` window centred near `(cx, cy)`, shifted to fit.
    pub fn around(cx: f32, cy: f32, n: usize, w: usize, h: usize) -> Window {
        let fit = |c: f32, size: usize| {
            let lo = (c - n as f32 / 2.0).round().max(0.0) as usize;
            lo.min(size.saturating_sub(n))
        };
        Window {
            x0: fit(cx, w),
            y0: fit(cy, h),
            n,
        }
    }
}

/// Mean of `a − b` over the overlap (0 when there is none).
pub fn offset(c: &Canvas, win: Window, patch: &[f32]) -> f32 {
    let (mut s, mut k) = (0.0f64, 0usize);
    for y in 0..win.n {
        for x in 0..win.n {
            let i = (win.y0 + y) * c.width + win.x0 + x;
            if c.filled[i] {
                s += (c.heights[i] - patch[y * win.n + x]) as f64;
                k += 1;
            }
        }
    }
    if k == 0 { 0.0 } else { (s / k as f64) as f32 }
}

/// The seam between the canvas and `patch` (already offset) in `win`;
/// `core` marks pixels that must come from the patch.
pub fn seam(c: &Canvas, win: Window, patch: &[f32], core: Option<&[bool]>) -> Seam {
    cut(c, win, patch, core, None)
}

/// [`seam`] restricted to a band around the seam `coarse` found at half
/// resolution ([`seam_coarse`]): a free pixel more than one coarse block
/// (two pixels) from where the coarse labels change takes its block's
/// label; only the band is cut (banded graph cut, Lombaert et al. 2005).
/// The free region shrinks from the whole overlap to a strip a few pixels
/// wide along the seam, which makes the full-resolution cut several times
/// cheaper; the seam can still move by up to two pixels, where the fine
/// detail decides it. `win.n` must be even.
pub fn seam_banded(
    c: &Canvas,
    win: Window,
    patch: &[f32],
    core: Option<&[bool]>,
    coarse: &Seam,
) -> Seam {
    cut(c, win, patch, core, Some(&coarse.take_new))
}

fn cut(
    c: &Canvas,
    win: Window,
    patch: &[f32],
    core: Option<&[bool]>,
    coarse: Option<&[bool]>,
) -> Seam {
    let n = win.n;
    let idx = |x: usize, y: usize| (win.y0 + y) * c.width + win.x0 + x;
    // Coarse blocks whose 3×3 neighbourhood holds both labels.
    let m = n / 2;
    let near_seam: Option<Vec<bool>> = coarse.map(|t| {
        (0..m * m)
            .map(|k| {
                let (bx, by) = (k % m, k / m);
                let (x0, y0) = (bx.saturating_sub(1), by.saturating_sub(1));
                let (x1, y1) = ((bx + 1).min(m - 1), (by + 1).min(m - 1));
                (y0..=y1).any(|y| (x0..=x1).any(|x| t[y * m + x] != t[k]))
            })
            .collect()
    });
    let mut labels = vec![Label::Free; n * n];
    let mut any_overlap = false;
    for y in 0..n {
        for x in 0..n {
            let i = idx(x, y);
            let k = y * n + x;
            labels[k] = if !c.filled[i] || core.is_some_and(|m| m[k]) {
                Label::New
            } else if x == 0 || y == 0 || x + 1 == n || y + 1 == n {
                any_overlap = true;
                Label::Old
            } else {
                any_overlap = true;
                let b = (y / 2) * m + x / 2;
                match (coarse, &near_seam) {
                    (Some(t), Some(near)) if !near[b] => {
                        if t[b] {
                            Label::New
                        } else {
                            Label::Old
                        }
                    }
                    _ => Label::Free,
                }
            };
        }
    }
    if !any_overlap {
        return Seam {
            cost: 0,
            take_new: vec![true; n * n],
        };
    }
    // Heights in integer decimetres, rounded once per pixel.
    let dm = |v: f32| (v * 10.0).round() as i64;
    let mut a = vec![0i64; n * n];
    let mut f = vec![false; n * n];
    for y in 0..n {
        for x in 0..n {
            let i = idx(x, y);
            a[y * n + x] = dm(c.heights[i]);
            f[y * n + x] = c.filled[i];
        }
    }
    let b: Vec<i64> = patch.iter().map(|&v| dm(v)).collect();
    let edge = |s: usize, t: usize| -> i64 {
        let gb = 2 * (b[t] - b[s]).abs();
        match (f[s], f[t]) {
            (true, true) => {
                let ga = 2 * (a[t] - a[s]).abs();
                kwatra(a[s] - b[s], a[t] - b[t], ga + gb)
            }
            (true, false) => kwatra(2 * (a[s] - b[s]), 0, gb),
            (false, true) => kwatra(2 * (a[t] - b[t]), 0, gb),
            (false, false) => 0,
        }
    };
    let mut ch = vec![0i64; n * n];
    let mut cv = vec![0i64; n * n];
    // Edges between two pixels of the same fixed label are never cut: their
    // cost is not needed (and this skips most of a banded window).
    let fixed_same = |k: usize, l: usize| labels[k] != Label::Free && labels[k] == labels[l];
    for y in 0..n {
        for x in 0..n {
            let k = y * n + x;
            if x + 1 < n && !fixed_same(k, k + 1) {
                ch[k] = edge(k, k + 1);
            }
            if y + 1 < n && !fixed_same(k, k + n) {
                cv[k] = edge(k, k + n);
            }
        }
    }
    min_cut(n, n, &labels, &ch, &cv)
}

/// The seam at half resolution, for ranking finalists and as the guide of
/// [`seam_banded`]: the window and the patch are averaged over 2×2 blocks
/// (a block counts as filled only if all four pixels are, and as core if
/// any is) and cut there; the cost is doubled so that it estimates the
/// full-resolution cut (a seam crosses half as many edges at half the
/// resolution). While the half-resolution window is at least 16 pixels,
/// that cut is itself banded around the seam one level coarser (a
/// coarse-to-fine banded graph cut down to an 8-pixel grid), so every level
/// cuts only a strip along the seam.
pub fn seam_coarse(c: &Canvas, win: Window, patch: &[f32], core: Option<&[bool]>) -> Seam {
    let n = win.n;
    let m = n / 2;
    let mut small = Canvas::new(m, m);
    let mut sp = vec![0.0f32; m * m];
    let mut sc = vec![false; m * m];
    for y in 0..m {
        for x in 0..m {
            let (mut h, mut p, mut all, mut any_core) = (0.0f32, 0.0f32, true, false);
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let (px, py) = (2 * x + dx, 2 * y + dy);
                let i = (win.y0 + py) * c.width + win.x0 + px;
                all &= c.filled[i];
                h += c.heights[i];
                p += patch[py * n + px];
                any_core |= core.is_some_and(|m| m[py * n + px]);
            }
            let k = y * m + x;
            small.filled[k] = all;
            small.heights[k] = h * 0.25;
            sp[k] = p * 0.25;
            sc[k] = any_core;
        }
    }
    let win = Window { x0: 0, y0: 0, n: m };
    let sc = core.map(|_| &sc[..]);
    let mut s = if m >= 16 && m % 2 == 0 {
        let guide = seam_coarse(&small, win, &sp, sc);
        seam_banded(&small, win, &sp, sc, &guide)
    } else {
        seam(&small, win, &sp, sc)
    };
    s.cost *= 2;
    s
}

/// Merges `patch` (already offset), cut from source `source`, into the
/// canvas at `win`, taking the pixels `take_new`. Returns the Poisson
/// solve's report (None when nothing old bordered the patch and it was
/// copied as is).
pub fn apply(
    c: &mut Canvas,
    win: Window,
    (patch, source): (&[f32], u32),
    take_new: &[bool],
    opts: &SolveOptions,
) -> Option<SolveReport> {
    let n = win.n;
    let (w, h) = (c.width, c.height);
    // Solve grid: the window grown by one pixel, clipped.
    let gx0 = win.x0.saturating_sub(1);
    let gy0 = win.y0.saturating_sub(1);
    let gx1 = (win.x0 + n + 1).min(w);
    let gy1 = (win.y0 + n + 1).min(h);
    let (gw, gh) = (gx1 - gx0, gy1 - gy0);
    let in_win = |gx: usize, gy: usize| {
        let (x, y) = (gx + gx0, gy + gy0);
        x >= win.x0 && y >= win.y0 && x < win.x0 + n && y < win.y0 + n
    };
    let pk = |gx: usize, gy: usize| (gy + gy0 - win.y0) * n + (gx + gx0 - win.x0);
    let ci = |gx: usize, gy: usize| (gy + gy0) * w + gx + gx0;
    // Pixel classes: 0 = new (free), 1 = fixed old, 2 = free filler outside.
    let mut class = vec![0u8; gw * gh];
    let mut u = vec![0.0f32; gw * gh];
    let mut any_fixed = false;
    for gy in 0..gh {
        for gx in 0..gw {
            let g = gy * gw + gx;
            if in_win(gx, gy) {
                let k = pk(gx, gy);
                if take_new[k] {
                    class[g] = 0;
                    u[g] = patch[k];
                } else {
                    class[g] = 1;
                    u[g] = c.heights[ci(gx, gy)];
                    any_fixed = true;
                }
            } else if c.filled[ci(gx, gy)] {
                class[g] = 1;
                u[g] = c.heights[ci(gx, gy)];
                any_fixed = true;
            } else {
                class[g] = 2;
            }
        }
    }
    if !any_fixed {
        for y in 0..n {
            for x in 0..n {
                let i = (win.y0 + y) * w + win.x0 + x;
                c.heights[i] = patch[y * n + x];
                c.filled[i] = true;
                c.source[i] = source;
                c.placement[i] = c.placed;
            }
        }
        c.placed += 1;
        return None;
    }
    let has_a = |gx: usize, gy: usize| c.filled[ci(gx, gy)];
    let av = |gx: usize, gy: usize| c.heights[ci(gx, gy)];
    let bv = |gx: usize, gy: usize| patch[pk(gx, gy)];
    // Seam points: new pixels in the window next to old ones in the window,
    // with the gradient mismatch ∇a − ∇b there (forward differences where
    // both sides are known).
    let mut seam_pts: Vec<(f32, f32, f32, f32)> = Vec::new();
    for gy in 0..gh {
        for gx in 0..gw {
            if class[gy * gw + gx] != 0 {
                continue;
            }
            let touches_old =
                [(0isize, -1isize), (0, 1), (-1, 0), (1, 0)]
                    .iter()
                    .any(|&(dx, dy)| {
                        let (nx, ny) = (gx as isize + dx, gy as isize + dy);
                        nx >= 0
                            && ny >= 0
                            && (nx as usize) < gw
                            && (ny as usize) < gh
                            && class[ny as usize * gw + nx as usize] == 1
                    });
            if !touches_old || !has_a(gx, gy) {
                continue;
            }
            let diff = |dx: usize, dy: usize| {
                let (nx, ny) = (gx + dx, gy + dy);
                if nx < gw && ny < gh && in_win(nx, ny) && has_a(nx, ny) {
                    (av(nx, ny) - av(gx, gy)) - (bv(nx, ny) - bv(gx, gy))
                } else {
                    0.0
                }
            };
            seam_pts.push((gx as f32, gy as f32, diff(1, 0), diff(0, 1)));
        }
    }
    // Keep at most 96 seam points (evenly), to bound the Shepard cost.
    let stride = seam_pts.len().div_ceil(96).max(1);
    let seam_pts: Vec<_> = seam_pts.into_iter().step_by(stride).collect();
    let radius = (n as f32 / 4.0).max(2.0);
    // Points at `d ≥ radius` have weight exactly 0 and, when all are that
    // far, the fade is 0 too: skipping them before the square root gives the
    // same bits at a fraction of the cost (this loop runs for every new
    // pixel against every kept seam point).
    let r2 = radius * radius;
    let corr = |gx: usize, gy: usize| -> (f32, f32) {
        if seam_pts.is_empty() {
            return (0.0, 0.0);
        }
        let (mut sx, mut sy, mut sw, mut dmin) = (0.0f32, 0.0f32, 0.0f32, f32::INFINITY);
        for &(px, py, cx, cy) in &seam_pts {
            let d2 = (px - gx as f32).powi(2) + (py - gy as f32).powi(2);
            if d2 >= r2 {
                continue;
            }
            let d = d2.sqrt();
            dmin = dmin.min(d);
            if d < 1e-3 {
                return (cx, cy);
            }
            let wgt = ((radius - d).max(0.0) / (radius * d)).powi(2);
            sx += wgt * cx;
            sy += wgt * cy;
            sw += wgt;
        }
        if sw <= 0.0 {
            return (0.0, 0.0);
        }
        let fade = (1.0 - dmin / radius).max(0.0).powi(2);
        (fade * sx / sw, fade * sy / sw)
    };
    let corrs: Vec<(f32, f32)> = (0..gw * gh)
        .map(|g| {
            if class[g] == 0 {
                corr(g % gw, g / gw)
            } else {
                (0.0, 0.0)
            }
        })
        .collect();
    // Guidance per edge.
    let mut gxv = vec![0.0f32; gw * gh];
    let mut gyv = vec![0.0f32; gw * gh];
    for gy in 0..gh {
        for gx in 0..gw {
            let g = gy * gw + gx;
            for (dir, (nx, ny)) in [(0, (gx + 1, gy)), (1, (gx, gy + 1))] {
                if nx >= gw || ny >= gh {
                    continue;
                }
                let gn = ny * gw + nx;
                let (c1, c2) = (class[g], class[gn]);
                let val = match (c1, c2) {
                    (0, 0) => {
                        let (a1, a2) = (corrs[g], corrs[gn]);
                        let cc = if dir == 0 { a1.0 + a2.0 } else { a1.1 + a2.1 } * 0.5;
                        bv(nx, ny) - bv(gx, gy) + cc
                    }
                    (0, 1) | (1, 0) => {
                        let both_in = in_win(gx, gy) && in_win(nx, ny);
                        if has_a(gx, gy) && has_a(nx, ny) {
                            av(nx, ny) - av(gx, gy)
                        } else if both_in {
                            bv(nx, ny) - bv(gx, gy)
                        } else {
                            // New pixel on the window edge against old ground
                            // outside: continue the patch's own slope.
                            let (px, py) = if c1 == 0 { (gx, gy) } else { (nx, ny) };
                            let back = if dir == 0 {
                                if c1 == 0 {
                                    px.checked_sub(1).map(|q| (q, py))
                                } else {
                                    Some((px + 1, py))
                                }
                            } else if c1 == 0 {
                                py.checked_sub(1).map(|q| (px, q))
                            } else {
                                Some((px, py + 1))
                            };
                            match back {
                                Some((qx, qy)) if qx < gw && qy < gh && in_win(qx, qy) => {
                                    if c1 == 0 {
                                        bv(px, py) - bv(qx, qy)
                                    } else {
                                        bv(qx, qy) - bv(px, py)
                                    }
                                }
                                _ => 0.0,
                            }
                        }
                    }
                    _ => 0.0,
                };
                if dir == 0 {
                    gxv[g] = val;
                } else {
                    gyv[g] = val;
                }
            }
        }
    }
    // Initial guess: the patch itself, continued into the free ring outside
    // the window by its nearest pixel ([`Method::Multigrid`] starts from `u`).
    for g in 0..gw * gh {
        if class[g] == 2 {
            let x = (g % gw + gx0).clamp(win.x0, win.x0 + n - 1) - win.x0;
            let y = (g / gw + gy0).clamp(win.y0, win.y0 + n - 1) - win.y0;
            u[g] = patch[y * n + x];
        }
    }
    let fixed: Vec<bool> = class.iter().map(|&k| k == 1).collect();
    let rhs = guided_rhs(gw, gh, &gxv, &gyv);
    let report = solve(Method::Multigrid, gw, gh, &mut u, &fixed, Some(&rhs), opts).ok();
    for gy in 0..gh {
        for gx in 0..gw {
            if in_win(gx, gy) && class[gy * gw + gx] == 0 {
                let i = ci(gx, gy);
                c.heights[i] = u[gy * gw + gx];
                c.filled[i] = true;
                c.source[i] = source;
                c.placement[i] = c.placed;
            }
        }
    }
    c.placed += 1;
    report
}
