//! Which level-0 pixels a constraint edit leaves unweighted (W⁰ = 4, see
//! [`super`]): where the constraint's samples changed and it reaches.
//!
//! A constraint added or removed changes every sample within its reach. A
//! replaced one changes only where its old and new samples differ: a moved
//! point everywhere, but a curve whose widget's height or slope changed
//! only along the arc its Hermite interpolation moved (before, the whole
//! curve's reach was freed, and so re-synthesized).

use crate::stages::correct::W_FREE;
use crate::synth::control::{Constraint, Sample};
use rayon::prelude::*;

/// Side of the tiles skipped at once where no sample can reach.
const TILE: usize = 8;

/// Marks `W_FREE` in the `w × h` level-0 `weights` where `new`'s samples
/// differ from `old`'s and either reaches (`old` None, or a different
/// [`Hold`] — a point's level cap goes with its slope — wherever either
/// reaches). Reads the samples constraints keep ([`Constraint::centres`]);
/// tile rows in parallel, skipping tiles no sample can reach
/// ([`Hold::max_reach`], [`Constraint::distance_bound`]) as the blend does.
/// Sampling old and new serially, tile by tile, this took ~28 ms of an edit
/// of the editor bench's 820-px curve at 1024².
///
/// [`Hold`]: crate::synth::control::Hold
/// [`Hold::max_reach`]: crate::synth::control::Hold::max_reach
pub(super) fn free_changed(
    new: &dyn Constraint,
    old: Option<&dyn Constraint>,
    weights: &mut [u8],
    w: usize,
    h: usize,
) {
    let sides: Vec<&dyn Constraint> = std::iter::once(new).chain(old).collect();
    let same_hold = old.is_some_and(|o| o.hold() == new.hold());
    let kept: Vec<_> = sides.iter().map(|c| c.centres()).collect();
    let clip = |v: f64, n: usize| (v.floor().max(0.0) as usize).min(n);
    let [x0, y0, x1, y1] = sides
        .iter()
        .map(|c| c.bounds())
        .reduce(|a, b| {
            [
                a[0].min(b[0]),
                a[1].min(b[1]),
                a[2].max(b[2]),
                a[3].max(b[3]),
            ]
        })
        .expect("at least the new constraint");
    let (xs, ys) = (
        clip(x0, w)..clip(x1 + 1.0, w),
        clip(y0, h)..clip(y1 + 1.0, h),
    );
    let sample = |k: usize, x: usize, y: usize| -> Option<Sample> {
        match kept[k] {
            Some(c) => c.get(sides[k], x, y),
            None => sides[k].sample(x as f64 + 0.5, y as f64 + 0.5),
        }
    };
    let within = |s: Option<Sample>| s.is_some_and(|s| s.distance <= s.reach);
    let bits = |s: Option<Sample>| s.map(|s| [s.target_m, s.distance, s.reach].map(f64::to_bits));
    weights[ys.start * w..ys.end * w]
        .par_chunks_mut(TILE * w)
        .enumerate()
        .for_each(|(k, rows)| {
            let (ty, n) = (ys.start + k * TILE, rows.len() / w);
            for tx in xs.clone().step_by(TILE) {
                let tx1 = (tx + TILE).min(xs.end);
                let spread = ((tx1 - 1 - tx) as f64).hypot((n - 1) as f64);
                let centre = ((tx + tx1) as f64 / 2.0, (2 * ty + n) as f64 / 2.0);
                let beyond = |c: &&dyn Constraint| {
                    c.distance_bound(centre.0, centre.1) - spread / 2.0 > c.hold().max_reach
                };
                if sides.iter().all(beyond) {
                    continue;
                }
                for (j, row) in rows.chunks_mut(w).enumerate() {
                    for (x, wt) in row.iter_mut().enumerate().take(tx1).skip(tx) {
                        let a = sample(0, x, ty + j);
                        let free = match sides.len() {
                            1 => within(a),
                            _ => {
                                let b = sample(1, x, ty + j);
                                (within(a) || within(b)) && (!same_hold || bits(a) != bits(b))
                            }
                        };
                        if free {
                            *wt = W_FREE;
                        }
                    }
                }
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stages::correct::W_COHERENT;
    use crate::synth::control::PointConstraint;
    use crate::synth::control::curve::{Curve, CurveSpec, FieldCache, Widget, build};
    use glam::DVec2;

    const W: usize = 130;
    const H: usize = 110;

    /// A curve partly off the output's west edge, widgets along it with
    /// these heights.
    fn curve(heights: &[f64]) -> Curve {
        let n = (heights.len() - 1).max(1);
        let spec = CurveSpec {
            points: vec![
                DVec2::new(-20.0, 30.0),
                DVec2::new(60.0, 90.0),
                DVec2::new(150.0, 40.0),
            ],
            widgets: heights
                .iter()
                .enumerate()
                .map(|(k, &h)| Widget {
                    at: k as f64 / n as f64,
                    height_m: h,
                    slope_deg: [10.0, -20.0],
                    reach_px: [25.0, 9.0],
                })
                .collect(),
            smoothing: 2,
        };
        let (mut curves, _) = build(&[spec], &[], 30.0, &FieldCache::new()).unwrap();
        curves.remove(0)
    }

    /// The marking by brute force: every pixel sampled.
    fn brute(new: &dyn Constraint, old: Option<&dyn Constraint>) -> Vec<u8> {
        let within = |s: Option<Sample>| s.is_some_and(|s| s.distance <= s.reach);
        let mut want = vec![W_COHERENT; W * H];
        for y in 0..H {
            for x in 0..W {
                let (fx, fy) = (x as f64 + 0.5, y as f64 + 0.5);
                let a = new.sample(fx, fy);
                let free = match old {
                    None => within(a),
                    Some(o) => {
                        let b = o.sample(fx, fy);
                        (within(a) || within(b))
                            && (o.hold() != new.hold() || format!("{a:?}") != format!("{b:?}"))
                    }
                };
                if free {
                    want[y * W + x] = W_FREE;
                }
            }
        }
        want
    }

    fn marked(new: &dyn Constraint, old: Option<&dyn Constraint>) -> Vec<u8> {
        let mut got = vec![W_COHERENT; W * H];
        free_changed(new, old, &mut got, W, H);
        got
    }

    #[test]
    fn an_added_constraint_frees_every_pixel_within_its_reach() {
        let c = curve(&[100.0]);
        let p = PointConstraint::new((100.0, 20.0), 50.0, 0.3, 0.2, 18.0, 30.0).unwrap();
        for c in [&c as &dyn Constraint, &p] {
            let want = brute(c, None);
            assert!(want.contains(&W_FREE) && want.contains(&W_COHERENT));
            assert!(marked(c, None) == want, "{c:?}");
        }
    }

    #[test]
    fn a_widget_height_change_frees_only_the_arc_it_moved() {
        let heights = [100.0, 120.0, 140.0, 160.0, 180.0, 200.0, 220.0];
        let old = curve(&heights);
        let mut raised = heights;
        raised[6] = 300.0;
        let new = curve(&raised);
        let got = marked(&new, Some(&old));
        assert!(got == brute(&new, Some(&old)));
        let free = |m: &[u8]| m.iter().filter(|&&v| v == W_FREE).count();
        let reach = free(&brute(&new, None));
        assert!(
            free(&got) > 0 && free(&got) < reach * 2 / 3,
            "{} of {reach}",
            free(&got)
        );
        // A moved point changes every sample within its old and new reach.
        let p = |x| PointConstraint::new((x, 50.0), 50.0, 0.3, 0.2, 18.0, 30.0).unwrap();
        let (a, b) = (p(60.0), p(70.0));
        let want = brute(&b, Some(&a));
        assert!(marked(&b, Some(&a)) == want);
        let mut both = brute(&a, None);
        for (w, v) in both.iter_mut().zip(brute(&b, None)) {
            *w = (*w).max(v);
        }
        assert!(want == both);
    }

    #[test]
    fn a_changed_hold_frees_the_whole_reach() {
        // A level point (level cap 4) made sloped (no cap): along the line
        // through the site across the slope the samples are the same, but
        // how the constraint holds them is not.
        let p = |slope| PointConstraint::new((60.5, 50.5), 50.0, 0.0, slope, 18.0, 30.0).unwrap();
        let (level, sloped) = (p(0.0), p(0.2));
        assert_ne!(level.hold(), sloped.hold());
        let want = brute(&sloped, Some(&level));
        assert!(marked(&sloped, Some(&level)) == want);
        assert!(want == brute(&sloped, None), "the whole reach");
    }
}
