//! Junctions: where curves cross each other or themselves (paper §3: "at
//! curve intersections (including self-intersections) we automatically place
//! junction-located widgets", which control height only).

use super::segments::Segments;
use glam::DVec2;

/// Two junctions closer than this (output pixels) are one.
pub const MERGE_DIST: f64 = 1.0;

/// One crossing: where, and the arc length on each curve it lies on.
#[derive(Debug, Clone, PartialEq)]
pub struct Crossing {
    pub at: DVec2,
    /// `(curve index, arc length on it)`; a self-crossing lists its curve
    /// twice.
    pub members: Vec<(usize, f64)>,
}

/// Proper intersection of segments `p0p1` and `q0q1`: parameters (u, v),
/// each in `[0, 1)` so a crossing exactly at a shared vertex is counted on
/// one segment pair only (the last segment of a curve also accepts 1).
fn intersect(
    p0: DVec2,
    p1: DVec2,
    q0: DVec2,
    q1: DVec2,
    p_last: bool,
    q_last: bool,
) -> Option<(f64, f64)> {
    let r = p1 - p0;
    let s = q1 - q0;
    let den = r.perp_dot(s);
    if den == 0.0 {
        return None; // parallel or collinear: no single crossing point
    }
    let w = q0 - p0;
    let u = w.perp_dot(s) / den;
    let v = w.perp_dot(r) / den;
    let ok = |t: f64, last: bool| t >= 0.0 && (t < 1.0 || (last && t <= 1.0));
    (ok(u, p_last) && ok(v, q_last)).then_some((u, v))
}

/// All crossings among `curves` (resampled points, with arc lengths at each
/// vertex), including self-crossings; nearby crossings of the same curves
/// merged. Deterministic order: by first curve, then arc length.
pub fn find(curves: &[(&[DVec2], &[f64])]) -> Vec<Crossing> {
    let grids: Vec<Segments> = curves
        .iter()
        .map(|(p, _)| Segments::polyline(p, false))
        .collect();
    let mut found: Vec<Crossing> = Vec::new();
    let mut near = Vec::new();
    for (a, (pa, sa)) in curves.iter().enumerate() {
        let na = pa.len() - 1;
        for (b, grid) in grids.iter().enumerate().skip(a) {
            let (pb, sb) = curves[b];
            let nb = pb.len() - 1;
            for i in 0..na {
                let (p0, p1) = (pa[i], pa[i + 1]);
                grid.near_box(p0.min(p1), p0.max(p1), &mut near);
                for &j in &near {
                    let j = j as usize;
                    // A curve's neighbouring segments share a vertex, not a crossing;
                    // count each self pair once.
                    if a == b && j <= i + 1 {
                        continue;
                    }
                    let Some((u, v)) =
                        intersect(p0, p1, pb[j], pb[j + 1], i + 1 == na, j + 1 == nb)
                    else {
                        continue;
                    };
                    let at = p0.lerp(p1, u);
                    let la = sa[i] + u * (sa[i + 1] - sa[i]);
                    let lb = sb[j] + v * (sb[j + 1] - sb[j]);
                    let dup = found.iter().any(|c| {
                        c.at.distance(at) < MERGE_DIST
                            && c.members.iter().any(|m| m.0 == a)
                            && c.members.iter().any(|m| m.0 == b)
                    });
                    if !dup {
                        found.push(Crossing {
                            at,
                            members: vec![(a, la), (b, lb)],
                        });
                    }
                }
            }
        }
    }
    // Three curves through one point give three pairwise crossings: one junction.
    let mut merged: Vec<Crossing> = Vec::new();
    for c in found {
        if let Some(m) = merged.iter_mut().find(|m| m.at.distance(c.at) < MERGE_DIST) {
            for mem in c.members {
                if !m
                    .members
                    .iter()
                    .any(|x| x.0 == mem.0 && (x.1 - mem.1).abs() < MERGE_DIST)
                {
                    m.members.push(mem);
                }
            }
        } else {
            merged.push(c);
        }
    }
    merged
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::control::curve::smooth::{arc_lengths, resample};

    fn line(a: (f64, f64), b: (f64, f64)) -> Vec<DVec2> {
        resample(&[DVec2::new(a.0, a.1), DVec2::new(b.0, b.1)]).unwrap()
    }

    #[test]
    fn finds_a_crossing_of_two_curves() {
        let a = line((0.0, 10.0), (30.0, 10.0));
        let b = line((12.5, 0.0), (12.5, 25.0));
        let (sa, sb) = (arc_lengths(&a), arc_lengths(&b));
        let c = find(&[(&a, &sa), (&b, &sb)]);
        assert_eq!(c.len(), 1, "{c:?}");
        assert!(c[0].at.distance(DVec2::new(12.5, 10.0)) < 1e-9);
        assert_eq!(c[0].members.len(), 2);
        assert!((c[0].members[0].1 - 12.5).abs() < 1e-9);
        assert!((c[0].members[1].1 - 10.0).abs() < 1e-9);
        // Parallel curves never cross.
        let p = line((0.0, 12.0), (30.0, 12.0));
        let sp = arc_lengths(&p);
        assert!(find(&[(&a, &sa), (&p, &sp)]).is_empty());
    }

    #[test]
    fn finds_a_self_crossing_loop() {
        let raw = super::super::tests::loop_de_loop();
        let p = resample(&raw).unwrap();
        let s = arc_lengths(&p);
        let c = find(&[(&p, &s)]);
        assert_eq!(c.len(), 1, "{c:?}");
        let m = &c[0].members;
        assert_eq!((m[0].0, m[1].0), (0, 0));
        assert!(
            (m[0].1 - m[1].1).abs() > 30.0,
            "two distinct arc lengths: {m:?}"
        );
        // A simple arc does not cross itself.
        let arc = &p[..p.len() / 2];
        let sarc = arc_lengths(arc);
        assert!(find(&[(arc, &sarc)]).is_empty());
    }

    #[test]
    fn three_curves_through_one_point_make_one_junction() {
        let a = line((0.0, 20.0), (40.0, 20.0));
        let b = line((20.0, 0.0), (20.0, 40.0));
        let c = line((0.0, 0.0), (40.0, 40.0));
        let (sa, sb, sc) = (arc_lengths(&a), arc_lengths(&b), arc_lengths(&c));
        let j = find(&[(&a, &sa), (&b, &sb), (&c, &sc)]);
        assert_eq!(j.len(), 1, "{j:?}");
        let mut members: Vec<usize> = j[0].members.iter().map(|m| m.0).collect();
        members.sort();
        assert_eq!(members, vec![0, 1, 2]);
    }
}
