// Stage `reconstruct`: the mirror of src/synth/stages/reconstruct.rs —
// bilinear E⁰ at S⁰ plus V⁰, in database units with 8 fractional bits.
// The weighted sum of four u16 heights stays below 2^32 (a u32).

struct ReconstructParams {
    width: u32,
    height: u32,
    pad0: u32,
    pad1: u32,
}

@group(0) @binding(0) var<uniform> p: ReconstructParams;
@group(0) @binding(1) var<storage, read> state_s: array<vec2<i32>>;
@group(0) @binding(2) var<storage, read> state_v: array<i32>;
@group(0) @binding(3) var<storage, read> columns: array<Column>;
// Level-0 heights, two u16 per word (little-endian, the Rust slice's bytes).
@group(0) @binding(4) var<storage, read> heights: array<u32>;
@group(0) @binding(5) var<storage, read_write> out: array<i32>;

// AtlasLevel::index.
fn atlas_index(x: i32, y: i32) -> u32 {
    let c = columns[x];
    return u32(c.base + y * i32(c.stride) + x);
}

fn height(x: i32, y: i32) -> u32 {
    let i = atlas_index(x, y);
    return (heights[i >> 1u] >> ((i & 1u) * 16u)) & 0xFFFFu;
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= p.width || gid.y >= p.height) {
        return;
    }
    let i = gid.y * p.width + gid.x;
    let s = state_s[i];
    let x0 = s.x >> FRAC_BITS;
    let y0 = s.y >> FRAC_BITS;
    let fx = u32(s.x & (ONE - 1));
    let fy = u32(s.y & (ONE - 1));
    let one = u32(ONE);
    let top = height(x0, y0) * (one - fx) + height(x0 + 1, y0) * fx;
    let bottom = height(x0, y0 + 1) * (one - fx) + height(x0 + 1, y0 + 1) * fx;
    // >> (2·FRAC_BITS − HEIGHT_FRAC_BITS), truncating.
    let v = (top * (one - fy) + bottom * fy) >> 8u;
    out[i] = i32(v) + (state_v[i] << 8u);
}
