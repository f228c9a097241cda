use super::*;
use crate::synth::control::PointConstraint;
use proptest::prelude::*;

fn q() -> Quantization {
    Quantization {
        offset_m: -100.0,
        scale_m: 0.05,
    }
}

/// A flat point (the level cap applies).
fn point(x: f64, y: f64, h: f64, r: f64) -> PointConstraint {
    PointConstraint::new((x, y), h, 0.3, 0.0, r, 30.0).unwrap()
}

#[test]
fn a_lone_point_targets_its_plane_within_its_reach() {
    for slope in [0.0, 0.2] {
        lone_point(PointConstraint::new((100.0, 60.0), 400.0, 0.3, slope, 40.0, 30.0).unwrap());
    }
}

/// A flat point reaches min(40, 4·2^i) px at level i, a sloped one its
/// whole 40 px at every level.
fn lone_point(p: PointConstraint) {
    let mut b = Blend::new(256, 256, 6, q());
    assert!(b.targets(2, 30.0).is_none());
    b.add(&p);
    for level in 0..=6 {
        let t = b.targets(level, 30.0).unwrap();
        let s = (1 << level) as f64;
        let reach = if p.slope_angle == 0.0 {
            40f64.min(4.0 * s)
        } else {
            40.0
        };
        for y in 0..t.height {
            for x in 0..t.width {
                let (ox, oy) = ((x as f64 + 0.5) * s, (y as f64 + 0.5) * s);
                let c = t.cells[y * t.width + x];
                match p.sample(ox, oy).filter(|s| s.distance <= reach) {
                    None => assert_eq!(c, Target::NONE),
                    Some(smp) => {
                        let want = q().units(smp.target_m);
                        assert!(
                            (c.height as f64 - want).abs() <= 0.5 + 1.0 / 16.0,
                            "{c:?} {want}"
                        );
                        // A 1:4 cone in metres from the pixel's footprint.
                        let d = (smp.distance - s / 2.0).max(0.0);
                        let tol = S * d * 30.0 / q().scale_m;
                        assert!((c.tol as f64 - tol.min(MAX_TOL as f64)).abs() <= 1.0);
                    }
                }
            }
        }
    }
    b.subtract(&p);
    assert!(b.is_empty());
    assert_eq!(
        b,
        Blend::new(256, 256, 6, q()),
        "zeroed sums equal fresh ones"
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Targets carried from edit to edit and re-derived only where
    /// [`Blend::take_touched`] says sums changed equal the targets
    /// derived whole, and the touched bounds hold every change; the
    /// reach count agrees with the sums.
    #[test]
    fn retargeted_cells_equal_whole_targets(
        steps in prop::collection::vec(
            (0usize..4, 0.0f64..120.0, 0.0f64..90.0, -50.0f64..900.0, 3.0f64..40.0),
            1..10,
        )
    ) {
        let mut b = Blend::new(120, 90, 4, q());
        let mut placed: [Option<PointConstraint>; 4] = Default::default();
        let mut kept: Vec<Option<Vec<Target>>> = vec![None; 5];
        for (slot, x, y, h, r) in steps {
            // Move the slot's point, or remove it when it was placed
            // at the same spot (r < 6).
            match placed[slot].take() {
                Some(old) if r < 6.0 => b.subtract(&old),
                old => {
                    if let Some(old) = old {
                        b.subtract(&old);
                    }
                    let p = point(x, y, h, r);
                    b.add(&p);
                    placed[slot] = Some(p);
                }
            }
            let touched = b.take_touched();
            for level in 0..=4 {
                let whole = b.targets(level, 30.0).map(|t| t.cells);
                prop_assert_eq!(b.reaches(level), whole.is_some());
                let carried = match (kept[level].take(), b.reaches(level)) {
                    (Some(mut t), true) => {
                        let before = t.clone();
                        let changed = b.retarget(level, 30.0, &mut t, touched[level]);
                        let w = b.levels[level].width;
                        for (k, (a, c)) in before.iter().zip(&t).enumerate() {
                            let (px, py) = (k % w, k / w);
                            let inside = changed.is_some_and(|[x0, y0, x1, y1]| {
                                (x0..x1).contains(&px) && (y0..y1).contains(&py)
                            });
                            prop_assert!(a == c || inside, "level {} ({}, {}) changed outside", level, px, py);
                        }
                        Some(t)
                    }
                    _ => whole.clone(),
                };
                prop_assert_eq!(&carried, &whole, "level {}", level);
                kept[level] = carried;
            }
        }
        prop_assert_eq!(b.is_empty(), placed.iter().all(Option::is_none));
    }
}

/// A meandering curve over a 300 × 240 output, its reach varying.
fn meander() -> crate::synth::control::curve::Curve {
    use crate::synth::control::curve::{CurveSpec, FieldCache, Widget, build};
    use glam::DVec2;
    let points = (0..=12)
        .map(|k| {
            let t = k as f64 / 12.0;
            DVec2::new(20.0 + 260.0 * t, 120.0 + 70.0 * (t * 7.0).sin())
        })
        .collect();
    let widget = |at, reach: f64| Widget {
        at,
        height_m: 300.0,
        slope_deg: [20.0, -10.0],
        reach_px: [reach, 0.6 * reach],
    };
    let spec = CurveSpec {
        points,
        widgets: vec![widget(0.0, 50.0), widget(1.0, 6.0)],
        smoothing: 2,
    };
    let (mut curves, _) = build(&[spec], &[], 30.0, &FieldCache::new()).unwrap();
    curves.remove(0)
}

#[test]
fn kept_samples_give_the_same_sums() {
    let c = meander();
    let kept = c.centres().expect("a curve keeps its samples");
    let (mut a, mut b) = (Blend::new(300, 240, 6, q()), Blend::new(300, 240, 6, q()));
    a.add(&c);
    b.add_kept(&c, kept);
    assert_eq!(a, b);
    assert_eq!(a.take_touched(), b.take_touched());
    a.subtract(&c);
    b.subtract_kept(&c, kept);
    assert_eq!(a, b);
    assert!(b.is_empty());
}

#[test]
fn skipped_tiles_hold_no_curve_sample_within_its_reach() {
    let curves = [meander()];
    let mut b = Blend::new(300, 240, 6, q());
    b.add(&curves[0]);
    for level in 0..=6 {
        let t = b.targets(level, 30.0).unwrap();
        let s = (1 << level) as f64;
        let mut reached = 0;
        for y in 0..t.height {
            for x in 0..t.width {
                let smp = curves[0].sample((x as f64 + 0.5) * s, (y as f64 + 0.5) * s);
                let inside = smp.is_some_and(|m| m.distance <= m.reach);
                let c = t.cells[y * t.width + x];
                assert_eq!(c != Target::NONE, inside, "level {level} ({x}, {y})");
                reached += inside as usize;
            }
        }
        assert!(reached > 0, "level {level}");
    }
}

#[test]
fn overlaps_blend_by_inverse_distance() {
    let mut b = Blend::new(64, 64, 3, q());
    let (p1, p2) = (point(12.0, 12.0, 0.0, 60.0), point(32.0, 12.0, 100.0, 60.0));
    b.add(&p1);
    b.add(&p2);
    // Level-3 pixel (1, 1) is centred at (12, 12): p1's site, d₁ = 0;
    // p2 is 20 px away, inside level 3's cap of 32 px.
    let t = b.targets(3, 30.0).unwrap();
    let c = t.cells[t.width + 1];
    let (w1, w2) = (1.0, 1.0 / 21.0);
    let (h1, h2) = (
        q().units(p1.sample(12.0, 12.0).unwrap().target_m),
        q().units(p2.sample(12.0, 12.0).unwrap().target_m),
    );
    let want = (w1 * h1 + w2 * h2) / (w1 + w2);
    assert!((c.height as f64 - want).abs() <= 1.0, "{c:?} {want}");
    // Tolerance distances from the footprint's inscribed disc (radius 4).
    let want_t = S * (w2 * 16.0) / (w1 + w2) * 30.0 / q().scale_m;
    assert!((c.tol as f64 - want_t).abs() <= 1.0, "{c:?} {want_t}");
    // At level 2 (cap 16 px) p2 does not reach: p1 alone.
    let t = b.targets(2, 30.0).unwrap();
    let c = t.cells[2 * t.width + 2];
    let h = q().units(p1.sample(10.0, 10.0).unwrap().target_m);
    assert!((c.height as f64 - h).abs() <= 1.0, "{c:?} {h}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// subtract → modify → add equals evaluation from scratch, exactly.
    #[test]
    fn running_sums_equal_evaluation_from_scratch(
        pts in proptest::collection::vec(
            (0.0..200.0f64, 0.0..150.0f64, -50.0..3000.0f64, 1.0..90.0f64), 1..6),
        edit in 0usize..6,
        moved in (0.0..200.0f64, 0.0..150.0f64, -50.0..3000.0f64, 1.0..90.0f64),
    ) {
        let make = |&(x, y, h, r): &(f64, f64, f64, f64)| point(x, y, h, r);
        let mut cs: Vec<PointConstraint> = pts.iter().map(make).collect();
        let mut running = Blend::new(200, 150, 6, q());
        for c in &cs {
            running.add(c);
        }
        let k = edit % cs.len();
        running.subtract(&cs[k]);
        cs[k] = make(&moved);
        running.add(&cs[k]);
        let mut scratch = Blend::new(200, 150, 6, q());
        for c in &cs {
            scratch.add(c);
        }
        prop_assert!(running == scratch);
        for level in 0..=6 {
            prop_assert_eq!(running.targets(level, 30.0), scratch.targets(level, 30.0));
        }
    }
}
