//! `water --routing mfd`: flow shared among lower neighbours by slope
//! (drop over distance), flats crossed down the flat gradient, and every
//! cell's area arriving at an outlet. pysheds' `routing='mfd'` is the
//! reference on real DEMs (tests/python/test_water.py).

use terrasynth::Heightfield;
use terrasynth::water::d8::{OUTLET, Surface};
use terrasynth::water::{self, Params, Routing, mfd};

/// A 3×3 surface whose cells outside `live` are sinks (they pass nothing
/// on), so each live cell's inflow is known by hand.
fn accumulate(z: &[f32], gradient: Option<&[u32]>, live: &[usize]) -> Vec<f32> {
    let sinks: Vec<bool> = (0..9).map(|i| !live.contains(&i)).collect();
    mfd::accumulate(&Surface {
        heights: z,
        width: 3,
        height: 3,
        gradient,
        sinks: Some(&sinks),
    })
}

#[test]
fn flow_splits_by_drop_over_distance() {
    // The centre (5 m) drops 1 m south (distance 1) and 1 m south-east
    // (distance √2): shares 1 : 1/√2 of its one cell.
    #[rustfmt::skip]
    let z = [
        10.0, 10.0, 10.0,
        10.0, 5.0, 10.0,
        10.0, 4.0, 4.0f32,
    ];
    let acc = accumulate(&z, None, &[4, 7, 8]);
    let south = 1.0 / (1.0 + std::f64::consts::FRAC_1_SQRT_2);
    assert!(
        (acc[7] as f64 - (1.0 + south)).abs() < 1e-6,
        "south {}",
        acc[7]
    );
    assert!(
        (acc[8] as f64 - (2.0 - south)).abs() < 1e-6,
        "south-east {}",
        acc[8]
    );
    assert_eq!(acc[4], 1.0);
}

#[test]
fn a_flat_drains_down_its_gradient_in_proportion() {
    // A level plate: the centre (gradient 5) sends to the west (2) and the
    // east (1) in proportion 3 : 4; the higher-gradient rows take nothing.
    let z = [0.0f32; 9];
    let g = [9, 9, 9, 2, 5, 1, 9, 9, 9];
    let acc = accumulate(&z, Some(&g), &[3, 4, 5]);
    assert!((acc[3] - (1.0 + 3.0 / 7.0)).abs() < 1e-6, "west {}", acc[3]);
    assert!((acc[5] - (1.0 + 4.0 / 7.0)).abs() < 1e-6, "east {}", acc[5]);
    // Without the gradient the plate holds its water: nothing moves.
    assert_eq!(accumulate(&z, None, &[3, 4, 5])[5], 1.0);
}

#[test]
fn every_cell_reaches_an_outlet_and_rivers_stay_d8() {
    // Ridges, bowls that fill and a sea: MFD's outlets are D8's (no lower
    // neighbour, no way down a flat), and together they collect every cell.
    let (w, h) = (211, 157);
    let z: Vec<f32> = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            let z = 40.0 * (x / 13.0).sin() * (y / 17.0).cos() + 0.3 * x - 10.0;
            (z * 4.0).round() / 4.0
        })
        .collect();
    let hf = Heightfield::from_vec(w, h, 30.0, z).unwrap();
    let params = Params {
        sea_level: Some(-20.0),
        ..Params::default()
    };
    let d8 = water::compute(&hf, &params).unwrap();
    let m = water::compute_with(&hf, &params, Routing::Mfd).unwrap();
    let flow = m.mfd_accumulation.as_ref().expect("MFD asked for");
    assert!(d8.filled_cells > w * h / 20, "a test with lakes");
    let at_outlets: f64 = (0..w * h)
        .filter(|&i| m.receivers[i] == OUTLET)
        .map(|i| flow[i] as f64)
        .sum();
    let n = (w * h) as f64;
    assert!(
        (at_outlets - n).abs() < n * 1e-5,
        "{at_outlets} of {n} cells arrive"
    );
    // Spread out, not D8 again: most cells with inflow get a share, not a whole.
    let fractional = flow.iter().filter(|v| v.fract() != 0.0).count();
    assert!(
        fractional > w * h / 4,
        "{fractional} cells with a fractional area"
    );
    assert_eq!(m.rivers.order, d8.rivers.order, "rivers follow D8");
    assert_eq!(m.accumulation, d8.accumulation);
    assert!(d8.mfd_accumulation.is_none());
    assert_eq!(m.flow(), *flow);
}
