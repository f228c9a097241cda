// Shared by every kernel: the source of each stage is this file followed by
// the stage's own (see src/backend/kernels.rs; WGSL has no includes).
//
// Mirrors src/hash.rs (stateless PCG hash), src/level/fixed.rs (fixed-point
// coordinates, rounding rules) and src/stages/common.rs (what several stages
// share) bit for bit (DESIGN §6). Integer arithmetic
// only: u32 multiplies and adds wrap as Rust's `wrapping_*` do, `>>` on i32
// is arithmetic like Rust's, and no shift amount ever reaches 32.

// Fractional bits of a synthesis coordinate (fixed::FRAC_BITS).
const FRAC_BITS: u32 = 8u;
// One texel in fixed point (fixed::ONE).
const ONE: i32 = 256;
// Texels kept between synthesis coordinates and exemplar edges (layout::MARGIN).
const MARGIN: i32 = 2;
// The target set of an unconstrained pixel (stages::common::ALL_TYPES).
const ALL_TYPES: u32 = 4294967295u;
// What a texel's packed mode-1 appearance is offset by (appearance::MODE1_BIAS).
const MODE1_BIAS: i32 = -32768;

// Per-column addressing of one atlas level (level::atlas::Column).
struct Column {
    base: i32,
    stride: u32,
    min_x: i32,
    max_x: i32,
    max_y: i32,
}

// hash::pcg: one PCG-RXS-M-XS round.
fn pcg(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// hash::hash4.
fn hash4(a: u32, b: u32, c: u32, d: u32) -> u32 {
    return pcg(a ^ pcg(b ^ pcg(c ^ pcg(d))));
}

// fixed::round: nearest texel, half up, by an arithmetic shift.
fn round_fixed(c: i32) -> i32 {
    return (c + (ONE >> 1u)) >> FRAC_BITS;
}

// fixed::div_floor (Rust's div_euclid for b > 0): WGSL's `/` truncates, so
// a negative quotient with a remainder is one too large.
fn div_floor(a: i32, b: i32) -> i32 {
    let q = a / b;
    if (a % b != 0 && a < 0) {
        return q - 1;
    }
    return q;
}

// Rust's rem_euclid for b > 0: WGSL's `%` takes the sign of the dividend.
fn rem_floor(a: i32, b: i32) -> i32 {
    let r = a % b;
    if (r < 0) {
        return r + b;
    }
    return r;
}
