//! Normalised cross-correlation of small square templates with every
//! position of a target grid in its 8 orientations, by FFT.
//!
//! The NCC of template t (n × n) at position q of target e is
//! `Σ (t − t̄)(e_q − ē_q) / √(Σ(t − t̄)² · Σ(e_q − ē_q)²)` — the definition of
//! scikit-image's `match_template`, which the reference script
//! (`../shared/tools/novelty.py`) uses: 0 where the denominator is at most
//! f32's epsilon. With a zero-mean template the numerator is `Σ t₀·e_q`, a
//! correlation: one FFT of the target (per orientation, once) and, per
//! template, one forward and one inverse transform per orientation; the
//! target's window statistics come from prefix sums.
//!
//! Two real templates share each transform (one in the real part, one in
//! the imaginary part): the correlation of `z = t₁ + i·t₂` with a real
//! target is `c₁ + i·c₂`, and its spectrum is `E(k)·Z(−k)`.
//!
//! Orientations rotate the target, not the template: matching an oriented
//! template against e is matching t against the inverse orientation of e,
//! and the eight orientations are a group, so the best over them is the
//! same — with 8 target spectra made once instead of 8 per template.

use crate::eval::fft::{Complex64, Fft2};
use rayon::prelude::*;

/// A grid of heights, row-major.
#[derive(Debug, Clone)]
pub(crate) struct Grid {
    pub w: usize,
    pub h: usize,
    pub v: Vec<f64>,
}

impl Grid {
    /// The mean of every `ds × ds` block of `data` (`w × h`, row-major; the
    /// last partial row and column of blocks are dropped).
    pub fn down(data: &[f32], w: usize, h: usize, ds: usize) -> Grid {
        let (gw, gh) = (w / ds, h / ds);
        let mut v = vec![0.0; gw * gh];
        let area = (ds * ds) as f64;
        v.par_chunks_mut(gw.max(1))
            .enumerate()
            .for_each(|(y, row)| {
                for (x, o) in row.iter_mut().enumerate() {
                    let mut s = 0.0;
                    for yy in y * ds..(y + 1) * ds {
                        s += data[yy * w + x * ds..][..ds]
                            .iter()
                            .map(|&a| f64::from(a))
                            .sum::<f64>();
                    }
                    *o = s / area;
                }
            });
        Grid { w: gw, h: gh, v }
    }

    /// The `n × n` window with corner (x, y), row-major.
    pub fn window(&self, x: usize, y: usize, n: usize) -> Vec<f64> {
        (y..y + n)
            .flat_map(|r| self.v[r * self.w + x..][..n].iter().copied())
            .collect()
    }

    /// Population standard deviation of the `n × n` window at (x, y).
    pub fn window_std(&self, x: usize, y: usize, n: usize) -> f64 {
        std_dev(&self.window(x, y, n))
    }

    /// This grid in orientation `o` ([`Orientation`]).
    pub fn oriented(&self, o: Orientation) -> Grid {
        let (w, h) = o.size(self.w, self.h);
        let mut v = vec![0.0; w * h];
        v.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
            for (x, out) in row.iter_mut().enumerate() {
                let (sx, sy) = o.source(x, y, w, h);
                *out = self.v[sy * self.w + sx];
            }
        });
        Grid { w, h, v }
    }
}

/// Population standard deviation (numpy's `std`).
pub(crate) fn std_dev(v: &[f64]) -> f64 {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    (v.iter().map(|a| (a - mean).powi(2)).sum::<f64>() / n).sqrt()
}

/// One of the 8 orientations of a grid (rotations by 90° and mirrors):
/// bit 0 mirrors x, bit 1 mirrors y, bit 2 transposes (applied last to the
/// source coordinate: see [`Orientation::source`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Orientation(pub u8);

impl Orientation {
    pub const ALL: [Orientation; 8] = [
        Orientation(0),
        Orientation(1),
        Orientation(2),
        Orientation(3),
        Orientation(4),
        Orientation(5),
        Orientation(6),
        Orientation(7),
    ];

    fn transposed(self) -> bool {
        self.0 & 4 != 0
    }

    /// The oriented size of a `w × h` grid.
    pub fn size(self, w: usize, h: usize) -> (usize, usize) {
        if self.transposed() { (h, w) } else { (w, h) }
    }

    /// The source cell of cell (x, y) of the oriented `w × h` grid.
    pub fn source(self, x: usize, y: usize, w: usize, h: usize) -> (usize, usize) {
        let u = if self.0 & 1 != 0 { w - 1 - x } else { x };
        let v = if self.0 & 2 != 0 { h - 1 - y } else { y };
        if self.transposed() { (v, u) } else { (u, v) }
    }

    /// The cell of the oriented `w × h` grid that source cell (x, y) becomes
    /// (the inverse of [`Orientation::source`]).
    pub fn target(self, x: usize, y: usize, w: usize, h: usize) -> (usize, usize) {
        let (u, v) = if self.transposed() { (y, x) } else { (x, y) };
        let x = if self.0 & 1 != 0 { w - 1 - u } else { u };
        let y = if self.0 & 2 != 0 { h - 1 - v } else { v };
        (x, y)
    }

    /// The oriented positions `[x0, y0, x1, y1)` (in an oriented `w × h`
    /// grid) of the `n × n` windows whose source corners lie in
    /// `[sx0, sx1] × [sy0, sy1]` (inclusive): an axis-aligned box maps to
    /// one.
    pub fn target_box(
        self,
        (sx0, sy0, sx1, sy1): (usize, usize, usize, usize),
        n: usize,
        w: usize,
        h: usize,
    ) -> [usize; 4] {
        let corner = |sx: usize, sy: usize| {
            let (ax, ay) = self.target(sx, sy, w, h);
            let (bx, by) = self.target(sx + n - 1, sy + n - 1, w, h);
            (ax.min(bx), ay.min(by))
        };
        let (a, b) = (corner(sx0, sy0), corner(sx1, sy1));
        [
            a.0.min(b.0),
            a.1.min(b.1),
            a.0.max(b.0) + 1,
            a.1.max(b.1) + 1,
        ]
    }

    /// The corner, in the source grid, of the `n × n` window with corner
    /// (x, y) in the oriented `w × h` grid (a square maps to a square).
    pub fn source_window(self, x: usize, y: usize, n: usize, w: usize, h: usize) -> (usize, usize) {
        let (ax, ay) = self.source(x, y, w, h);
        let (bx, by) = self.source(x + n - 1, y + n - 1, w, h);
        (ax.min(bx), ay.min(by))
    }
}

/// One orientation of a target: its spectrum (transposed, see
/// [`Fft2::forward_transposed`]) and, per valid position, the window's sum
/// of squared deviations `Σ(e_q − ē_q)²` and the inverse of its root.
struct Oriented {
    o: Orientation,
    w: usize,
    h: usize,
    spectrum: Vec<Complex64>,
    ssd: Vec<f64>,
    inv_sd: Vec<f64>,
}

/// A target prepared for matching `n × n` templates against it.
pub(crate) struct Target {
    n: usize,
    /// FFT side: a power of two at least as large as every orientation.
    side: usize,
    plan: Fft2,
    orients: Vec<Oriented>,
}

/// Where a template matches a target best.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Best {
    pub ncc: f64,
    pub o: Orientation,
    /// Corner of the matching window in the oriented target.
    pub x: usize,
    pub y: usize,
}

/// Positions `[x0, y0, x1, y1)` of an oriented target that template `k`
/// must not match (its own neighbourhood, for self-repetition), if any.
pub(crate) type Exclude<'a> = dyn Fn(usize, Orientation) -> Option<[usize; 4]> + Sync + 'a;

impl Target {
    /// Prepares `g` (at least `n × n`) for `n × n` templates.
    pub fn new(g: &Grid, n: usize) -> Target {
        assert!(g.w >= n && g.h >= n, "target {}x{} under {n}", g.w, g.h);
        let side = g.w.max(g.h).next_power_of_two();
        let plan = Fft2::new(side, side);
        // The target's mean is removed first: it changes no correlation with
        // a zero-mean template, and keeps the transforms' rounding relative
        // to the relief rather than to the altitude.
        let mean = g.v.iter().sum::<f64>() / g.v.len() as f64;
        let orients = Orientation::ALL
            .iter()
            .map(|&o| {
                let og = g.oriented(o);
                let mut grid = vec![Complex64::default(); side * side];
                for y in 0..og.h {
                    for x in 0..og.w {
                        grid[y * side + x].re = og.v[y * og.w + x] - mean;
                    }
                }
                let mut spectrum = vec![Complex64::default(); side * side];
                plan.forward_transposed(&mut grid, og.h, &mut spectrum);
                let mut ssd = window_ssd(&og, n, mean);
                // A window whose spread is below FLAT_SSD of the mean
                // window's is flat: its prefix-sum SSD is rounding residue,
                // and the correlation's rounding divided by it gave best
                // NCCs above 1 (a 3×-side coast: median 1.12).
                let floor = FLAT_SSD * ssd.iter().sum::<f64>() / ssd.len() as f64;
                for v in &mut ssd {
                    if *v <= floor {
                        *v = 0.0;
                    }
                }
                let inv_sd = ssd
                    .iter()
                    .map(|&v| if v > 0.0 { 1.0 / v.sqrt() } else { 0.0 })
                    .collect();
                Oriented {
                    o,
                    w: og.w,
                    h: og.h,
                    spectrum,
                    ssd,
                    inv_sd,
                }
            })
            .collect();
        Target {
            n,
            side,
            plan,
            orients,
        }
    }

    /// The best match of each template (`n × n`, row-major) over every
    /// position and orientation but those `exclude` names; `None` where
    /// every position is excluded.
    pub fn best(&self, templates: &[Vec<f64>], exclude: &Exclude<'_>) -> Vec<Option<Best>> {
        let pairs: Vec<(usize, &[Vec<f64>])> = templates.chunks(2).enumerate().collect();
        pairs
            .par_iter()
            .flat_map_iter(|&(k, pair)| self.best_pair(2 * k, pair, exclude))
            .collect()
    }

    /// [`Target::best`] of one or two templates, the first numbered `first`
    /// (`exclude`'s first argument).
    fn best_pair(
        &self,
        first: usize,
        pair: &[Vec<f64>],
        exclude: &Exclude<'_>,
    ) -> Vec<Option<Best>> {
        let (n, side) = (self.n, self.side);
        let mut z = vec![Complex64::default(); side * side];
        let mut tss = [0.0; 2];
        for (j, t) in pair.iter().enumerate() {
            let mean = t.iter().sum::<f64>() / t.len() as f64;
            for y in 0..n {
                for x in 0..n {
                    let d = t[y * n + x] - mean;
                    tss[j] += d * d;
                    let c = &mut z[y * side + x];
                    if j == 0 { c.re = d } else { c.im = d }
                }
            }
        }
        let mut zt = vec![Complex64::default(); side * side];
        self.plan.forward_transposed(&mut z, n, &mut zt);
        // Z(−k), transposed like the target spectra: Q(k) = E(k)·Z(−k) is
        // then one elementwise product per orientation.
        let reversed = |i: usize| (side - i) % side;
        z.par_chunks_mut(side).enumerate().for_each(|(u, row)| {
            let from = &zt[reversed(u) * side..][..side];
            for (v, c) in row.iter_mut().enumerate() {
                *c = from[reversed(v)];
            }
        });
        let eps2 = f64::from(f32::EPSILON).powi(2);
        let mut best: Vec<Option<Best>> = vec![None; pair.len()];
        let mut out = vec![Complex64::default(); side * side];
        for or in &self.orients {
            zt.par_chunks_mut(side)
                .zip(or.spectrum.par_chunks(side).zip(z.par_chunks(side)))
                .for_each(|(q, (e, zr))| {
                    for ((q, e), zr) in q.iter_mut().zip(e).zip(zr) {
                        *q = e * zr;
                    }
                });
            let (vw, vh) = (or.w - n + 1, or.h - n + 1);
            self.plan.inverse_transposed(&mut zt, vh, &mut out);
            for (j, b) in best.iter_mut().enumerate() {
                if tss[j] <= 0.0 {
                    continue;
                }
                // ncc = c / √(ssd·tss) where ssd·tss > ε² (f32's ε, as
                // scikit-image), else 0.
                let (min_ssd, inv_t) = (eps2 / tss[j], 1.0 / tss[j].sqrt());
                let skip = exclude(first + j, or.o);
                for y in 0..vh {
                    let (row, ssd, isd) = (
                        &out[y * side..][..vw],
                        &or.ssd[y * vw..][..vw],
                        &or.inv_sd[y * vw..][..vw],
                    );
                    let cut = skip.filter(|r| (r[1]..r[3]).contains(&y));
                    for x in 0..vw {
                        let c = if j == 0 { row[x].re } else { row[x].im };
                        let ncc = if ssd[x] > min_ssd {
                            c * isd[x] * inv_t
                        } else {
                            0.0
                        };
                        if b.is_some_and(|b| ncc <= b.ncc) {
                            continue;
                        }
                        if cut.is_some_and(|r| (r[0]..r[2]).contains(&x)) {
                            continue;
                        }
                        *b = Some(Best { ncc, o: or.o, x, y });
                    }
                }
            }
        }
        best
    }

    /// The size of the target in orientation `o`.
    pub fn size(&self, o: Orientation) -> (usize, usize) {
        let or = &self.orients[o.0 as usize];
        (or.w, or.h)
    }
}

/// Share of the target's mean window SSD under which a window counts as
/// flat (NCC 0): far above the prefix sums' rounding (about 1e-16 of the
/// image's Σe²), far below any relief (a window of 1 024 cells at 3 mm
/// std against one of 100 m).
const FLAT_SSD: f64 = 1e-9;

/// `Σ(e − ē)²` of every `n × n` window of `g` (values less `shift`), per
/// valid position, row-major: `Σe² − (Σe)²/n²` from prefix sums.
fn window_ssd(g: &Grid, n: usize, shift: f64) -> Vec<f64> {
    let (w, h) = (g.w, g.h);
    let (pw, ph) = (w + 1, h + 1);
    let mut s1 = vec![0.0f64; pw * ph];
    let mut s2 = vec![0.0f64; pw * ph];
    for y in 0..h {
        let (mut r1, mut r2) = (0.0, 0.0);
        for x in 0..w {
            let v = g.v[y * w + x] - shift;
            r1 += v;
            r2 += v * v;
            s1[(y + 1) * pw + x + 1] = s1[y * pw + x + 1] + r1;
            s2[(y + 1) * pw + x + 1] = s2[y * pw + x + 1] + r2;
        }
    }
    let (vw, vh) = (w - n + 1, h - n + 1);
    let m = (n * n) as f64;
    let rect = |s: &[f64], x: usize, y: usize| {
        s[(y + n) * pw + x + n] - s[y * pw + x + n] - s[(y + n) * pw + x] + s[y * pw + x]
    };
    let mut out = vec![0.0; vw * vh];
    for y in 0..vh {
        for x in 0..vw {
            let a = rect(&s1, x, y);
            out[y * vw + x] = rect(&s2, x, y) - a * a / m;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(w: usize, h: usize, seed: u32) -> Grid {
        let v = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f64, (i / w) as f64);
                let r = crate::hash::hash4(seed, 1, i as u32, 0) as f64 / u32::MAX as f64;
                (x * 0.3).sin() * 40.0 + (y * 0.17 + x * 0.05).cos() * 25.0 + r * 10.0
            })
            .collect();
        Grid { w, h, v }
    }

    /// The direct definition, for comparison.
    fn ncc_direct(t: &[f64], g: &Grid, x: usize, y: usize, n: usize) -> f64 {
        let e = g.window(x, y, n);
        let (mt, me) = (
            t.iter().sum::<f64>() / t.len() as f64,
            e.iter().sum::<f64>() / e.len() as f64,
        );
        let num: f64 = t.iter().zip(&e).map(|(a, b)| (a - mt) * (b - me)).sum();
        let da: f64 = t.iter().map(|a| (a - mt).powi(2)).sum();
        let db: f64 = e.iter().map(|b| (b - me).powi(2)).sum();
        num / (da * db).sqrt()
    }

    #[test]
    fn orientations_are_the_eight_symmetries_and_windows_map_back() {
        let g = grid(5, 3, 1);
        let mut seen = Vec::new();
        for o in Orientation::ALL {
            let og = g.oriented(o);
            assert_eq!((og.w, og.h), o.size(5, 3));
            seen.push(og.v.clone());
            // A window of the oriented grid holds the values of its source
            // window, as a set.
            let n = 2;
            for y in 0..=og.h - n {
                for x in 0..=og.w - n {
                    let (sx, sy) = o.source_window(x, y, n, og.w, og.h);
                    let mut a = og.window(x, y, n);
                    let mut b = g.window(sx, sy, n);
                    a.sort_by(f64::total_cmp);
                    b.sort_by(f64::total_cmp);
                    assert_eq!(a, b, "orientation {o:?}, window ({x}, {y})");
                }
            }
        }
        seen.sort_by(|a, b| a.partial_cmp(b).unwrap());
        seen.dedup();
        assert_eq!(seen.len(), 8, "eight distinct orientations");
    }

    #[test]
    fn flat_parts_of_a_large_target_match_nothing() {
        // A large target, half of it flat far from the mean (a sea beside
        // land, with quantisation noise): its flat windows must score 0,
        // not rounding over rounding.
        let (w, h, n) = (700, 700, 32);
        let rough = grid(w, h, 5);
        let v = (0..w * h)
            .map(|i| {
                if i % w < w / 2 {
                    // Quantisation-sized noise (a millimetre).
                    -500.0 + rough.v[i] * 1e-5
                } else {
                    rough.v[i] * 30.0 + 900.0
                }
            })
            .collect();
        let g = Grid { w, h, v };
        let target = Target::new(&g, n);
        let templates: Vec<Vec<f64>> = (0..6)
            .map(|k| g.window(w / 2 + 40 * k, 20 + 90 * k, n))
            .collect();
        for b in target.best(&templates, &|_, _| None).into_iter().flatten() {
            assert!(b.ncc <= 1.0 + 1e-9, "NCC {} at ({}, {})", b.ncc, b.x, b.y);
        }
    }

    #[test]
    fn fft_correlation_equals_the_definition_everywhere() {
        let (g, n) = (grid(23, 17, 2), 6);
        let target = Target::new(&g, n);
        let other = grid(9, 9, 3);
        let templates = vec![g.window(4, 7, n), other.window(1, 2, n), g.window(0, 0, n)];
        // Every template against every position directly; excluded: a box
        // in each orientation that differs per template.
        let boxes = |k: usize, o: Orientation| -> Option<[usize; 4]> {
            (k != 1).then_some([k + o.0 as usize % 3, 1, 9 + k, 6 + o.0 as usize % 4])
        };
        for exclude in [false, true] {
            let none = |_: usize, _: Orientation| None;
            let got = if exclude {
                target.best(&templates, &boxes)
            } else {
                target.best(&templates, &none)
            };
            for (k, t) in templates.iter().enumerate() {
                let mut want = f64::MIN;
                for o in Orientation::ALL {
                    let og = g.oriented(o);
                    for y in 0..=og.h - n {
                        for x in 0..=og.w - n {
                            let out = exclude
                                && boxes(k, o).is_some_and(|r| {
                                    (r[0]..r[2]).contains(&x) && (r[1]..r[3]).contains(&y)
                                });
                            if !out {
                                want = want.max(ncc_direct(t, &og, x, y, n));
                            }
                        }
                    }
                }
                let b = got[k].expect("positions remain");
                assert!(
                    (b.ncc - want).abs() < 1e-9,
                    "{k} (exclude {exclude}): {} vs {want}",
                    b.ncc
                );
                let og = g.oriented(b.o);
                assert!(
                    (ncc_direct(t, &og, b.x, b.y, n) - b.ncc).abs() < 1e-9,
                    "its position"
                );
            }
        }
        // A window of the target finds itself (NCC 1), also mirrored and
        // rotated.
        let none = |_: usize, _: Orientation| None;
        let t = g.window(4, 7, n);
        for o in Orientation::ALL {
            let rotated = Grid {
                w: n,
                h: n,
                v: t.clone(),
            }
            .oriented(o)
            .v;
            let b = target.best(&[rotated], &none)[0].unwrap();
            assert!((b.ncc - 1.0).abs() < 1e-9, "{o:?}: {}", b.ncc);
        }
    }

    #[test]
    fn target_boxes_hold_exactly_the_windows_from_the_source_box() {
        let (w, h, n) = (11, 7, 3);
        let src = (2, 1, 5, 3);
        for o in Orientation::ALL {
            let (ow, oh) = o.size(w, h);
            let r = o.target_box(src, n, ow, oh);
            for y in 0..=oh - n {
                for x in 0..=ow - n {
                    let (sx, sy) = o.source_window(x, y, n, ow, oh);
                    let inside = (src.0..=src.2).contains(&sx) && (src.1..=src.3).contains(&sy);
                    let boxed = (r[0]..r[2]).contains(&x) && (r[1]..r[3]).contains(&y);
                    assert_eq!(inside, boxed, "{o:?} ({x}, {y})");
                }
            }
        }
    }
}
