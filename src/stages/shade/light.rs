//! Step 3 of the pipeline: the multi-directional Lambert hillshade
//! ([`hillshade`]), with fixed or USGS aspect weights. Public so the CPU
//! side can ask for the value of flat ground with the kernel's arithmetic.

use super::arith::{isqrt, shr_sym};
use super::{SLOPE_ONE, ShadeParams, flags};

/// Combined hillshade, 0..=4096, of the surface with slopes `(sx, sy)`
/// ([`SLOPE_ONE`] fixed point, y southward). Public so the CPU side can ask
/// for the value of flat ground with exactly the kernel's arithmetic.
pub fn hillshade(p: &ShadeParams, sx: i32, sy: i32) -> u32 {
    // Surface normal (−sx, −sy, 1), rescaled so its largest component lies in
    // [2^14, 2^15): the squared length then fits in u32 (< 3·2^30) and the
    // dot products in i32 (< 3·2^27).
    let (mut nx, mut ny, mut nz) = (-sx, -sy, SLOPE_ONE);
    let m = nx.unsigned_abs().max(ny.unsigned_abs()).max(nz as u32);
    let bits = 32 - m.leading_zeros(); // m >= 2^12, so bits >= 13
    if bits > 15 {
        let k = bits - 15;
        nx = shr_sym(nx, k);
        ny = shr_sym(ny, k);
        nz = shr_sym(nz, k);
    } else {
        let k = 15 - bits;
        nx <<= k;
        ny <<= k;
        nz <<= k;
    }
    // len in [2^14, 2^15.8); its reciprocal 2^30 / len in (2^14.2, 2^16].
    let len = isqrt((nx * nx) as u32 + (ny * ny) as u32 + (nz * nz) as u32);
    let recip = (1u32 << 30) / len;

    // Aspect direction (downslope, the normal's horizontal part) scaled to a
    // largest component in [2^7, 2^8), for the USGS weights.
    let aspect = p.flags & flags::ASPECT_WEIGHTS != 0 && (nx != 0 || ny != 0);
    let (mut dx, mut dy) = (nx, ny);
    if aspect {
        let m = dx.unsigned_abs().max(dy.unsigned_abs());
        let bits = 32 - m.leading_zeros();
        if bits > 8 {
            dx = shr_sym(dx, bits - 8);
            dy = shr_sym(dy, bits - 8);
        } else {
            dx <<= 8 - bits;
            dy <<= 8 - bits;
        }
    }

    // Lambert term dot / len, 0..=4096: dot < (len + 1) · 4096 < 2^27.8, so
    // (dot >> 12) · recip < 2^15.8 · 2^16 fits u32.
    let lambert = |l: &[i32; 4]| -> u32 {
        let dot = nx * l[0] + ny * l[1] + nz * l[2];
        ((dot.max(0) as u32 >> 12) * recip) >> 18
    };
    let mut sum = 0u32; // < 4 · 2^15 · 2^12 = 2^29
    let mut wsum = 0u32;
    for l in &p.lights[..p.light_count as usize] {
        let lambert = lambert(l);
        let w = if aspect {
            // sin²(aspect − azimuth) = cross(d, a)² / (|d|²|a|²), with the
            // light's horizontal direction a at ≤ 2^7: |cross| < 2^15.5.
            let cross = dx * shr_sym(l[1], 5) - dy * shr_sym(l[0], 5);
            ((((cross * cross) as u32) >> 16) * l[3] as u32) >> 8 // < 2^15
        } else {
            l[3] as u32
        };
        sum += w * lambert;
        wsum += w;
    }
    if wsum == 0 {
        // Aspect weights all vanished (a light from straight above, or the
        // slope exactly along every light): fall back to the fixed weights.
        sum = 0;
        for l in &p.lights[..p.light_count as usize] {
            sum += l[3] as u32 * lambert(l);
            wsum += l[3] as u32;
        }
    }
    sum / wsum
}
