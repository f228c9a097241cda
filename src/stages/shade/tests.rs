//! The integer helpers against their definitions.

use super::arith::apply_shade;
use super::lines::on_grid;
use super::*;

#[test]
fn isqrt_is_floor_sqrt() {
    // Where floor(√n) changes (every k² and its neighbours), the small
    // values, the top of the range and a stride through the rest.
    let squares = (0..=65_535u32).flat_map(|k| {
        let s = k * k;
        [s, s.saturating_sub(1), s + 1, s + 2 * k]
    });
    let rest = (0..70_000u32).chain((0..u32::MAX - 9_999).step_by(9_973));
    for n in squares.chain(rest).chain([u32::MAX, u32::MAX - 1]) {
        let r = isqrt(n) as u64;
        assert!(r * r <= n as u64 && (r + 1) * (r + 1) > n as u64, "{n}");
    }
}

#[test]
fn rounding_helpers() {
    assert_eq!((shr_sym(-5, 1), shr_sym(5, 1)), (-2, 2));
    assert_eq!(
        (shr_round(-6, 2), shr_round(6, 2), shr_round(5, 2)),
        (-2, 2, 1)
    );
    assert!(on_grid(4, 4 * 256) && !on_grid(3, 4 * 256) && !on_grid(0, 256));
    assert!(on_grid(1, 256) && on_grid(2, 256));
}

#[test]
fn blend_ends_are_exact() {
    let (a, b) = (0x0012_3456, 0x00ab_cdef);
    assert_eq!(blend(a, b, 0), a);
    assert_eq!(blend(a, b, FULL), b);
    assert_eq!(apply_shade(a, FULL), a);
    assert_eq!(apply_shade(a, 2 * FULL), 0x00ff_ffff);
}

#[test]
fn an_out_of_range_height_is_named_by_its_first_pixel() {
    // Many offenders far apart (the scan is parallel): the first is named.
    let n = 300_000usize;
    let mut heights = vec![0i32; n];
    for i in (123_457..n).step_by(40_000) {
        heights[i] = MAX_ABS_HEIGHT + 1;
    }
    heights[123_456] = NODATA;
    let p = ShadeParams {
        width: 600,
        height: 500,
        ..bytemuck::Zeroable::zeroed()
    };
    let b = ShadeBuffers {
        heights: &heights,
        types: &[],
        tint: &[0],
        type_colours: &[],
    };
    let err = p.validate(&b).unwrap_err();
    assert!(err.0.contains("at pixel 123457 "), "{err}");
}
