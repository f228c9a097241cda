// Stage `upsample_jitter` (paper eq. 1–2): the mirror of
// src/stages/upsample_jitter.rs, one invocation per child pixel.

// Step kinds (upsample_jitter::Step).
const STEP_PYRAMID: u32 = 0u;
const STEP_VIRTUAL: u32 = 1u;
const STEP_WRAP: u32 = 2u;

struct UpsampleParams {
    child_width: u32,
    child_height: u32,
    parent_width: u32,
    seed: u32,
    level: u32,
    jitter: i32,
    step: u32,
    shift: u32,
    min_x: i32,
    max_x: i32,
    min_y: i32,
    max_y: i32,
    // Absolute position of the child buffer's pixel (0, 0) (even; the
    // jitter hashes absolute coordinates).
    origin_x: u32,
    origin_y: u32,
    pad0: u32,
    pad1: u32,
}

@group(0) @binding(0) var<uniform> p: UpsampleParams;
@group(0) @binding(1) var<storage, read> parent_s: array<vec2<i32>>;
@group(0) @binding(2) var<storage, read> parent_v: array<i32>;
@group(0) @binding(3) var<storage, read_write> child_s: array<vec2<i32>>;
@group(0) @binding(4) var<storage, read_write> child_v: array<i32>;
// The child level's columns (read by the pyramid step only).
@group(0) @binding(5) var<storage, read> columns: array<Column>;

// upsample_jitter::jitter: two values in [−r, r) (fixed point).
fn jitter(seed: u32, level: u32, x: u32, y: u32, r: i32) -> vec2<i32> {
    let h = hash4(seed, level, x, y);
    let jx = i32(h & 0xFFFFu) - 32768;
    let jy = i32(h >> 16u) - 32768;
    return vec2<i32>((jx * r) >> 15u, (jy * r) >> 15u);
}

// upsample_jitter::wrap: toroidal wrap of a fixed-point value into texels
// [lo, hi].
fn wrap(v: i32, lo: i32, hi: i32) -> i32 {
    let period = (hi - lo + 1) << FRAC_BITS;
    return (lo << FRAC_BITS) + rem_floor(v - (lo << FRAC_BITS), period);
}

// upsample_jitter::clamp: into the interior of the exemplar that holds
// home_x (the child's x before jitter).
fn clamp_exemplar(c: vec2<i32>, home_x: i32) -> vec2<i32> {
    let col = columns[round_fixed(home_x)];
    return vec2<i32>(
        clamp(c.x, col.min_x << FRAC_BITS, col.max_x << FRAC_BITS),
        clamp(c.y, MARGIN << FRAC_BITS, col.max_y << FRAC_BITS),
    );
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let x = gid.x;
    let y = gid.y;
    if (x >= p.child_width || y >= p.child_height) {
        return;
    }
    let pi = (y / 2u) * p.parent_width + x / 2u;
    let cx = i32(x & 1u);
    let cy = i32(y & 1u);
    let s = parent_s[pi];
    let j = jitter(p.seed, p.level, p.origin_x + x, p.origin_y + y, p.jitter);
    let off_x = (cx << FRAC_BITS) + j.x;
    let off_y = (cy << FRAC_BITS) + j.y;
    var out: vec2<i32>;
    switch p.step {
        case STEP_PYRAMID: {
            out = clamp_exemplar(vec2<i32>(2 * s.x + off_x, 2 * s.y + off_y), 2 * s.x + (cx << FRAC_BITS));
        }
        case STEP_VIRTUAL: {
            out = vec2<i32>(s.x + (off_x << p.shift), s.y + (off_y << p.shift));
        }
        default: {
            out = vec2<i32>(wrap(s.x + off_x, p.min_x, p.max_x), wrap(s.y + off_y, p.min_y, p.max_y));
        }
    }
    let ci = y * p.child_width + x;
    child_s[ci] = out;
    child_v[ci] = parent_v[pi];
}
