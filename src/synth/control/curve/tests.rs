use super::*;

fn widget(at: f64, height_m: f64, slope: [f64; 2], reach: [f64; 2]) -> Widget {
    Widget {
        at,
        height_m,
        slope_deg: slope,
        reach_px: reach,
    }
}

fn one(spec: CurveSpec) -> Curve {
    let (mut c, _) = build(&[spec], &[], 2.0, &FieldCache::new()).unwrap();
    c.remove(0)
}

fn straight(widgets: Vec<Widget>) -> CurveSpec {
    CurveSpec {
        points: vec![DVec2::new(10.0, 30.0), DVec2::new(90.0, 30.0)],
        widgets,
        smoothing: 0,
    }
}

#[test]
fn hermite_heights_are_exact_at_widgets() {
    let ws = vec![
        widget(0.0, 100.0, [0.0; 2], [8.0; 2]),
        widget(0.25, 180.0, [0.0; 2], [8.0; 2]),
        widget(0.5, 120.0, [0.0; 2], [8.0; 2]),
        widget(1.0, 150.0, [0.0; 2], [8.0; 2]),
    ];
    let c = one(straight(ws.clone()));
    assert_eq!(c.length(), 80.0);
    for w in &ws {
        // On the curve (d = 0) the target is the interpolated height itself.
        let p = c.point_at(w.at * 80.0);
        let s = c.sample(p.x, p.y).unwrap();
        assert!((s.target_m - w.height_m).abs() < 1e-9, "{w:?}: {s:?}");
        assert_eq!(s.distance, 0.0);
    }
    // Between widgets the height stays within its neighbours (no overshoot).
    let mid = c.sample(40.0, 30.0).unwrap().target_m;
    assert!(mid > 120.0 && mid < 180.0, "{mid}");
}

#[test]
fn left_and_right_sides_get_their_own_properties() {
    // Heading east: left is north (smaller y).
    let c = one(straight(vec![widget(
        0.5,
        50.0,
        [10.0, -30.0],
        [10.0, 20.0],
    )]));
    let cell = 2.0;
    let north = c.sample(50.0, 25.0).unwrap();
    assert_eq!(north.distance, 5.0);
    let want = 50.0 + 10f64.to_radians().tan() * 5.0 * cell;
    assert!((north.target_m - want).abs() < 1e-9, "{north:?}");
    let south = c.sample(50.0, 45.0).unwrap();
    let want = 50.0 + (-30f64).to_radians().tan() * 15.0 * cell;
    assert!((south.target_m - want).abs() < 1e-9, "{south:?}");
    assert!((south.reach - 20.0).abs() < 1.0, "{south:?}");
    // 15 px north is beyond the left reach (10), 15 px south within the right (20).
    assert!(c.sample(50.0, 15.0).is_none());
    assert!(c.sample(50.0, 48.0).is_some());
    assert!(c.sample(50.0, 52.0).is_none());
}

#[test]
fn end_caps_blend_left_and_right_by_angle() {
    let c = one(straight(vec![widget(0.5, 0.0, [0.0; 2], [10.0, 30.0])]));
    let f = c.field();
    let props = |x: f64, y: f64| {
        let p = DVec2::new(x, y);
        c.props(f.closest(p).unwrap(), p)
    };
    // Beyond the east end: straight ahead is halfway, the normals are the sides.
    let ahead = props(100.0, 30.0);
    assert!((ahead.right - 0.5).abs() < 1e-9 && (ahead.reach_px - 20.0).abs() < 1e-9);
    assert!(props(90.0, 20.0).right < 1e-9);
    assert!((props(90.0, 40.0).right - 1.0).abs() < 1e-9);
    // Monotone around the cap, from left to right.
    let mut last = -1.0;
    for k in 0..=20 {
        let a = -std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * k as f64 / 20.0;
        let r = props(90.0 + 8.0 * a.cos(), 30.0 + 8.0 * a.sin()).right;
        assert!(r >= last - 1e-12, "{k}: {r} < {last}");
        last = r;
    }
}

/// A half circle around (50, 50), concave side on the right, whose right
/// reach grows from 10 px at the start to 35 px at the end: the raw
/// envelope is cut along the medial axis x = 50 below the centre, where the
/// closest point jumps from one end to the other (paper Fig. 5a).
fn arc() -> Curve {
    let pts: Vec<DVec2> = (0..=64)
        .map(|k| {
            let t = std::f64::consts::PI * (1.0 + k as f64 / 64.0);
            DVec2::new(50.0 + 20.0 * t.cos(), 50.0 + 20.0 * t.sin())
        })
        .collect();
    one(CurveSpec {
        points: pts,
        widgets: vec![
            widget(0.0, 0.0, [0.0; 2], [5.0, 10.0]),
            widget(1.0, 0.0, [0.0; 2], [5.0, 35.0]),
        ],
        smoothing: 0,
    })
}

#[test]
fn isocurve_smoothing_removes_the_medial_axis_discontinuity() {
    let c = arc();
    let f = c.field();
    let (w, h) = (f.width, f.height);
    // Largest reach change between 4-neighbours inside the region, raw vs smoothed.
    let (mut raw_jump, mut smooth_jump) = (0f64, 0f64);
    for j in 0..h - 1 {
        for i in 0..w - 1 {
            for (a, b) in [((i, j), (i + 1, j)), ((i, j), (i, j + 1))] {
                let (Some(ra), Some(rb)) =
                    (c.raw_reach_at_node(a.0, a.1), c.raw_reach_at_node(b.0, b.1))
                else {
                    continue;
                };
                raw_jump = raw_jump.max((ra - rb).abs());
                let (ea, eb) = (c.reach_at_node(a.0, a.1), c.reach_at_node(b.0, b.1));
                if ea >= 0.0 && eb >= 0.0 {
                    smooth_jump = smooth_jump.max((ea - eb).abs() as f64);
                }
            }
        }
    }
    assert!(
        raw_jump > 15.0,
        "the test case must have a discontinuity: {raw_jump}"
    );
    assert!(
        smooth_jump <= 2.0 + 1e-3,
        "effective reach jumps by {smooth_jump} px"
    );
    // The boundary itself, around the medial-axis cut (x = 50 below the
    // centre, down to y = 50 + √(35² − 20²) ≈ 78.7 where the raw boundary
    // leaves the cut for the end cap's circle): the sharpest turn over 4 px,
    // raw vs smoothed.
    let sharpest = |loops: &[Vec<DVec2>]| -> f64 {
        let (mut worst, mut near) = (0f64, 0);
        for l in loops {
            let mut closed = l.clone();
            closed.push(l[0]);
            let r = smooth::resample(&closed).unwrap();
            let n = r.len() - 1;
            for k in 0..n {
                let (a, b, cc) = (r[(k + n - 2) % n], r[k], r[(k + 2) % n]);
                if (b.x - 50.0).abs() > 10.0 || b.y < 52.0 {
                    continue;
                }
                near += 1;
                let turn = (b - a).angle_to(cc - b).abs();
                worst = worst.max(turn.to_degrees());
            }
        }
        assert!(near > 10, "the boundary passes the cut");
        worst
    };
    let (raw, smoothed) = (sharpest(c.raw_envelope()), sharpest(c.envelope()));
    eprintln!("sharpest turn over 4 px near the cut: raw {raw:.1} deg, smoothed {smoothed:.1} deg");
    assert!(raw > 55.0, "raw envelope has a corner: {raw}");
    // ≤ 25° over 4 px: a radius of curvature of at least ~9 px everywhere there.
    assert!(
        smoothed < 25.0,
        "smoothed envelope turns by {smoothed} degrees over 4 px"
    );
    // Smoothing keeps the extent where reach varies smoothly: at the arc's
    // middle (reach ≈ 22.5 on the right) the effective reach is within 2 px.
    let top = c.sample(50.0, 30.0 + 20.0).unwrap();
    assert!((top.reach - 22.5).abs() < 2.5, "{top:?}");
}

#[test]
fn junctions_at_crossings_take_the_mean_height_or_the_set_one() {
    let a = CurveSpec {
        points: vec![DVec2::new(0.0, 40.0), DVec2::new(80.0, 40.0)],
        widgets: vec![widget(0.25, 100.0, [0.0; 2], [6.0; 2])],
        smoothing: 0,
    };
    let b = CurveSpec {
        points: vec![DVec2::new(40.0, 0.0), DVec2::new(40.0, 80.0)],
        widgets: vec![
            widget(0.0, 0.0, [0.0; 2], [6.0; 2]),
            widget(1.0, 100.0, [0.0; 2], [6.0; 2]),
        ],
        smoothing: 0,
    };
    let cache = FieldCache::new();
    let (curves, junctions) = build(&[a.clone(), b.clone()], &[], 2.0, &cache).unwrap();
    assert_eq!(junctions.len(), 1);
    let j = &junctions[0];
    assert!(j.at.distance(DVec2::new(40.0, 40.0)) < 1e-9);
    assert!(
        (j.height_m - 75.0).abs() < 1e-9,
        "mean of 100 and 50: {}",
        j.height_m
    );
    // Both curves pass through the junction height.
    for c in &curves {
        assert!((c.sample(40.0, 40.0).unwrap().target_m - 75.0).abs() < 1e-9);
    }
    let set = [JunctionHeight {
        at: DVec2::new(41.0, 39.0),
        height_m: 10.0,
    }];
    let (curves, _) = build(&[a.clone(), b.clone()], &set, 2.0, &cache).unwrap();
    assert!((curves[1].sample(40.0, 40.0).unwrap().target_m - 10.0).abs() < 1e-9);
    // Changing heights reused both distance fields.
    assert_eq!(cache.computed(), 2);
    let far = [JunctionHeight {
        at: DVec2::new(10.0, 10.0),
        height_m: 10.0,
    }];
    assert!(matches!(
        build(&[a, b], &far, 2.0, &cache),
        Err(CurveError::NoJunction { .. })
    ));
}

/// A loop-de-loop: a circle drawn past its start, so that it crosses
/// itself once (also the junction finder's test case).
pub(super) fn loop_de_loop() -> Vec<DVec2> {
    (0..=80)
        .map(|k| {
            let t = k as f64 / 80.0 * 2.4 * std::f64::consts::PI;
            DVec2::new(30.0 + 15.0 * t.sin() + 4.0 * t, 30.0 - 15.0 * t.cos())
        })
        .collect()
}

#[test]
fn self_crossing_curves_get_one_junction_height_at_both_passes() {
    let pts = loop_de_loop();
    let spec = CurveSpec {
        points: pts,
        widgets: vec![
            widget(0.0, 0.0, [0.0; 2], [4.0; 2]),
            widget(1.0, 300.0, [0.0; 2], [4.0; 2]),
        ],
        smoothing: 1,
    };
    let (curves, junctions) = build(&[spec], &[], 2.0, &FieldCache::new()).unwrap();
    assert_eq!(junctions.len(), 1);
    let j = &junctions[0];
    let c = &curves[0];
    for &(_, s) in &j.members {
        assert!((c.height_at(s) - j.height_m).abs() < 1e-9);
    }
}

#[test]
fn bad_curves_are_errors() {
    let cache = FieldCache::new();
    let w = widget(0.5, 0.0, [0.0; 2], [5.0; 2]);
    let mut s = straight(vec![w]);
    s.points.truncate(1);
    assert!(matches!(
        build(&[s], &[], 1.0, &cache),
        Err(CurveError::TooFewPoints { curve: 0, count: 1 })
    ));
    let s = CurveSpec {
        points: vec![DVec2::ONE; 3],
        widgets: vec![w],
        smoothing: 2,
    };
    assert_eq!(
        build(&[s], &[], 1.0, &cache).unwrap_err(),
        CurveError::ZeroLength { curve: 0 }
    );
    assert!(matches!(
        build(&[straight(vec![])], &[], 1.0, &cache),
        Err(CurveError::NoWidget { .. })
    ));
    // A zig-zag 2^22 px long would resample to 4 M points: refused up front.
    let zig = CurveSpec {
        points: (0..70_000)
            .map(|k| DVec2::new((k % 2) as f64 * 60.0, 0.0))
            .collect(),
        widgets: vec![w],
        smoothing: 0,
    };
    assert!(matches!(
        build(&[zig], &[], 1.0, &cache),
        Err(CurveError::TooLong { curve: 0, .. })
    ));
    let bad = widget(0.5, 0.0, [0.0; 2], [0.0, 5.0]);
    let e = build(&[straight(vec![bad])], &[], 1.0, &cache).unwrap_err();
    assert!(e.to_string().contains("reach"), "{e}");
}

#[test]
fn builds_are_identical_on_any_thread_count() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let c = arc();
            let mut bits = Vec::new();
            for j in 0..100 {
                for i in 0..100 {
                    if let Some(s) = c.sample(i as f64, j as f64) {
                        bits.extend([
                            s.target_m.to_bits(),
                            s.distance.to_bits(),
                            s.reach.to_bits(),
                        ]);
                    }
                }
            }
            let env: Vec<u64> = c
                .envelope()
                .iter()
                .flatten()
                .flat_map(|p| [p.x.to_bits(), p.y.to_bits()])
                .collect();
            (bits, env)
        })
    };
    let one = run(1);
    assert!(one.0.len() > 3000);
    assert_eq!(one, run(2));
    assert_eq!(one, run(3));
}

mod prop {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        /// Any sketch builds, and every sample is inside the bounds, within
        /// its reach, finite, and exact in distance to the smoothed curve.
        #[test]
        fn random_curves_build_and_sample_consistently(
            pts in proptest::collection::vec((0.0f64..64.0, 0.0f64..64.0), 2..8),
            reach in (1.0f64..20.0, 1.0f64..20.0),
            slope in (-60.0f64..60.0, -60.0f64..60.0),
            smoothing in 0u32..4,
        ) {
            let points: Vec<DVec2> = pts.iter().map(|&(x, y)| DVec2::new(x, y)).collect();
            prop_assume!(points.windows(2).any(|w| w[0].distance(w[1]) > 0.5));
            let spec = CurveSpec {
                points,
                widgets: vec![
                    widget(0.0, 100.0, [slope.0, slope.1], [reach.0, reach.1]),
                    widget(1.0, 300.0, [slope.1, slope.0], [reach.1, reach.0]),
                ],
                smoothing,
            };
            let (curves, _) = build(&[spec], &[], 10.0, &FieldCache::new()).unwrap();
            let c = &curves[0];
            let [x0, y0, x1, y1] = c.bounds();
            let pts = c.points();
            for j in -30..100 {
                for i in -30..100 {
                    let (x, y) = (i as f64, j as f64);
                    let Some(s) = c.sample(x, y) else { continue };
                    prop_assert!(x >= x0 && x < x1 && y >= y0 && y < y1);
                    prop_assert!(s.distance <= s.reach && s.target_m.is_finite());
                    let brute = pts
                        .windows(2)
                        .map(|w| {
                            let d = w[1] - w[0];
                            let u = ((DVec2::new(x, y) - w[0]).dot(d) / d.length_squared().max(1e-300)).clamp(0.0, 1.0);
                            DVec2::new(x, y).distance(w[0] + d * u)
                        })
                        .fold(f64::INFINITY, f64::min);
                    prop_assert!((s.distance - brute).abs() < 1e-9, "{} vs {brute}", s.distance);
                }
            }
        }
    }
}

/// A sample's bits (`==` on floats would let −0 pass for 0).
fn bits(s: Option<Sample>) -> Option<[u64; 3]> {
    s.map(|s| [s.target_m, s.distance, s.reach].map(f64::to_bits))
}

/// Whether two curves are the same constraint, bit for bit: shape, field,
/// envelope, and every sample at the pixel centres and lattice nodes
/// around them (also as [`Curve::centres`] keeps them).
fn assert_same_curve(a: &Curve, b: &Curve, what: &str) {
    assert_eq!((&a.points, &a.cum), (&b.points, &b.cum), "{what}: shape");
    let (fa, fb) = (&a.field, &b.field);
    assert_eq!(
        (fa.x0, fa.y0, fa.width, fa.height, fa.margin.to_bits()),
        (fb.x0, fb.y0, fb.width, fb.height, fb.margin.to_bits()),
        "{what}: lattice"
    );
    assert!(fa.seg == fb.seg, "{what}: closest segments");
    let reach = |c: &Curve| {
        c.env
            .reach_eff
            .iter()
            .map(|r| r.to_bits())
            .collect::<Vec<_>>()
    };
    assert!(reach(a) == reach(b), "{what}: effective reach");
    assert_eq!(a.envelope(), b.envelope(), "{what}: envelope");
    assert_eq!(a.raw_envelope(), b.raw_envelope(), "{what}: raw envelope");
    let (ka, kb) = (a.centres().unwrap(), b.centres().unwrap());
    let [x0, y0, x1, y1] = a.bounds();
    for y in (y0 as i64 - 2).max(0)..y1 as i64 + 2 {
        for x in (x0 as i64 - 2).max(0)..x1 as i64 + 2 {
            let (fx, fy) = (x as f64, y as f64);
            let here = bits(a.sample(fx + 0.5, fy + 0.5));
            assert_eq!(
                here,
                bits(b.sample(fx + 0.5, fy + 0.5)),
                "{what}: ({x}, {y})"
            );
            let (xu, yu) = (x as usize, y as usize);
            assert_eq!(bits(ka.get(a, xu, yu)), here, "{what}: kept ({x}, {y})");
            assert_eq!(bits(kb.get(b, xu, yu)), here, "{what}: kept ({x}, {y})");
            assert_eq!(
                bits(a.sample(fx, fy)),
                bits(b.sample(fx, fy)),
                "{what}: node ({x}, {y})"
            );
        }
    }
}

#[test]
fn builds_reusing_fields_and_envelopes_equal_builds_from_scratch() {
    let w = |at, h, r: f64| widget(at, h, [15.0, -20.0], [r, 0.7 * r]);
    let a = CurveSpec {
        points: (0..=8)
            .map(|k| {
                let t = k as f64 / 8.0;
                DVec2::new(10.0 + 100.0 * t, 40.0 + 12.0 * (t * 6.0).sin())
            })
            .collect(),
        widgets: vec![w(0.0, 100.0, 10.0), w(0.6, 160.0, 14.0), w(1.0, 90.0, 10.0)],
        smoothing: 2,
    };
    let b = CurveSpec {
        points: vec![
            DVec2::new(60.0, 5.0),
            DVec2::new(55.0, 45.0),
            DVec2::new(70.0, 90.0),
        ],
        widgets: vec![w(0.5, 40.0, 8.0)],
        smoothing: 1,
    };
    let c = CurveSpec {
        points: vec![DVec2::new(5.0, 70.0), DVec2::new(115.0, 20.0)],
        widgets: vec![w(0.3, 70.0, 6.0)],
        smoothing: 0,
    };
    let mut higher = a.clone();
    higher.widgets[1].height_m = 260.0;
    let mut steeper = higher.clone();
    steeper.widgets[0].slope_deg = [35.0, -5.0];
    let mut moved = steeper.clone();
    moved.points[3].y += 6.0;
    let scenes = [
        ("first", vec![a.clone(), b.clone()], false),
        ("a widget's height", vec![higher.clone(), b.clone()], false),
        ("a widget's slope", vec![steeper, b.clone()], false),
        ("re-sketch", vec![moved.clone(), b.clone()], false),
        (
            "a crossing curve added",
            vec![moved.clone(), b.clone(), c.clone()],
            false,
        ),
        ("a curve deleted", vec![moved.clone(), c.clone()], false),
        ("a junction's height", vec![moved, c], true),
        ("back to the first", vec![a, b], false),
    ];
    let cache = FieldCache::new();
    let mut before: Vec<Curve> = Vec::new();
    for (what, specs, set) in scenes {
        let fresh = build(&specs, &[], 2.0, &FieldCache::new()).unwrap();
        let heights: Vec<JunctionHeight> = match set {
            true => vec![JunctionHeight {
                at: fresh.1[0].at,
                height_m: 333.0,
            }],
            false => Vec::new(),
        };
        let (scratch, scratch_j) = build(&specs, &heights, 2.0, &FieldCache::new()).unwrap();
        let (reused, reused_j) = build(&specs, &heights, 2.0, &cache).unwrap();
        assert_eq!(scratch_j, reused_j, "{what}: junctions");
        assert!(!reused_j.is_empty(), "{what}: the curves cross");
        for (x, y) in scratch.iter().zip(&reused) {
            assert_same_curve(x, y, what);
        }
        // The edits that keep a shape and its reach reused its envelope.
        if what == "a widget's height" || what == "a widget's slope" {
            assert!(Arc::ptr_eq(&before[0].env, &reused[0].env), "{what}");
            assert!(Arc::ptr_eq(&before[1].env, &reused[1].env), "{what}");
        }
        before = reused;
    }
    // Fields: a, b, moved a, c (every later shape was seen before).
    assert_eq!(cache.computed(), 4);
}
