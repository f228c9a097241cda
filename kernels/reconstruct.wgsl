// Stage `reconstruct`: the mirror of src/stages/reconstruct.rs — each
// level-0 pixel the mean of its 3×3 neighbours' smooth predictions
// μ(t(n) − Δ) + V(n) plus its own texel's detail E⁰ − μ, in database units
// with 8 fractional bits (sum of at most nine smooth predictions shifted
// once, floor division by their count, plus the detail shifted). Stage
// `repair_extrema` reads what this writes.

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
@group(0) @binding(4) var<storage, read> appearance: array<vec2<u32>>;
// Level-0 heights, two u16 per word (little-endian, the Rust slice's bytes).
@group(0) @binding(5) var<storage, read> heights: array<u32>;
@group(0) @binding(6) var<storage, read_write> blended: array<i32>;

// AtlasLevel::index.
fn atlas_index(x: i32, y: i32) -> u32 {
    let c = columns[x];
    return u32(c.base + y * i32(c.stride) + x);
}

// reconstruct::smooth_height: appearance mode 1 of atlas texel i (its low 16 bits,
// sign-extended), unbiased.
fn smooth_height(i: u32) -> i32 {
    return (bitcast<i32>(appearance[i].x << 16u) >> 16u) - MODE1_BIAS;
}

fn height(i: u32) -> i32 {
    return i32((heights[i >> 1u] >> ((i & 1u) * 16u)) & 0xFFFFu);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= p.width || gid.y >= p.height) {
        return;
    }
    let x = i32(gid.x);
    let y = i32(gid.y);
    var sum = 0;
    var count = 0;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let nx = x + dx;
            let ny = y + dy;
            if (nx < 0 || ny < 0 || nx >= i32(p.width) || ny >= i32(p.height)) {
                continue;
            }
            let n = u32(ny) * p.width + u32(nx);
            let s = state_s[n];
            sum += smooth_height(atlas_index(round_fixed(s.x) - dx, round_fixed(s.y) - dy)) + state_v[n];
            count += 1;
        }
    }
    let s = state_s[gid.y * p.width + gid.x];
    let own = atlas_index(round_fixed(s.x), round_fixed(s.y));
    blended[gid.y * p.width + gid.x] = div_floor(sum << 8u, count) + ((height(own) - smooth_height(own)) << 8u);
}
