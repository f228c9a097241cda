// Stage `repair_extrema`: the mirror of src/stages/repair_extrema.rs — an
// interior pixel whose blended height (stage `reconstruct`) is strictly
// below (above) its eight neighbours' is judged by its texel's support in
// the exemplar: 8 keeps it, ≥ DIMPLE_SUPPORT keeps it no deeper (higher)
// than half the texel's least rise (drop) to its supporting neighbours,
// ≥ SUPPORT takes the plain mean of the nine neighbours' predictions,
// fewer the neighbours' lowest (highest) blend.
// Edge pixels keep their blend.

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
@group(0) @binding(5) var<storage, read> blended: array<i32>;
@group(0) @binding(6) var<storage, read_write> out: array<i32>;

// repair_extrema::SUPPORT.
const SUPPORT: u32 = 6u;
// repair_extrema::DIMPLE_SUPPORT.
const DIMPLE_SUPPORT: u32 = 7u;
// repair_extrema::DIMPLE_SHIFT.
const DIMPLE_SHIFT: u32 = 7u;

fn height(i: i32) -> i32 {
    let u = u32(i);
    return i32((heights[u >> 1u] >> ((u & 1u) * 16u)) & 0xFFFFu);
}

// The pixel's rounded texel: its atlas index and its exemplar's row stride.
fn texel(n: u32) -> vec2<i32> {
    let s = state_s[n];
    let x = round_fixed(s.x);
    let c = columns[x];
    return vec2<i32>(c.base + round_fixed(s.y) * i32(c.stride) + x, i32(c.stride));
}

// repair_extrema::mean: the plain mean of the nine predictions.
fn mean(x: u32, y: u32) -> i32 {
    var sum = 0;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let n = (y + u32(dy)) * p.width + x + u32(dx);
            let t = texel(n);
            sum += (height(t.x - dx - dy * t.y) + state_v[n]) << 8u;
        }
    }
    return div_floor(sum, 9);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= p.width || gid.y >= p.height) {
        return;
    }
    let i = gid.y * p.width + gid.x;
    let c = blended[i];
    if (gid.x == 0u || gid.y == 0u || gid.x + 1u >= p.width || gid.y + 1u >= p.height) {
        out[i] = c;
        return;
    }
    var lo = 2147483647;
    var hi = -2147483647 - 1;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            if (dx == 0 && dy == 0) {
                continue;
            }
            let b = blended[(gid.y + u32(dy)) * p.width + gid.x + u32(dx)];
            lo = min(lo, b);
            hi = max(hi, b);
        }
    }
    let pit = c < lo;
    if (!pit && c <= hi) {
        out[i] = c;
        return;
    }
    let t = texel(i);
    let e = height(t.x);
    var support = 0u;
    var rise = 2147483647;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            if (dx == 0 && dy == 0) {
                continue;
            }
            let n = height(t.x + dx + dy * t.y);
            if ((pit && n > e) || (!pit && n < e)) {
                support += 1u;
                rise = min(rise, abs(n - e));
            }
        }
    }
    if (support == 8u) {
        out[i] = c;
    } else if (support >= DIMPLE_SUPPORT && pit) {
        out[i] = max(c, lo - (rise << DIMPLE_SHIFT));
    } else if (support >= DIMPLE_SUPPORT) {
        out[i] = min(c, hi + (rise << DIMPLE_SHIFT));
    } else if (support >= SUPPORT) {
        out[i] = mean(gid.x, gid.y);
    } else if (pit) {
        out[i] = lo;
    } else {
        out[i] = hi;
    }
}
