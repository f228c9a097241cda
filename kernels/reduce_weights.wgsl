// Stage `reduce_weights`: the mirror of src/stages/reduce_weights.rs —
// a pixel is frozen (0) if any of its 2×2 children is, else it takes the
// most frequent child weight (clamped to 4), ties going to the larger.
// Children past the child level's edge are absent; a pixel with none gets 4
// (Rust's `max_by_key` over all-zero counts keeps the last, 4).
//
// Weights are u8 on the host and one u32 per pixel here (widened on upload,
// narrowed on download), so that each invocation writes a word of its own.

struct ReduceWeightsParams {
    width: u32,
    height: u32,
    child_width: u32,
    child_height: u32,
}

@group(0) @binding(0) var<uniform> p: ReduceWeightsParams;
@group(0) @binding(1) var<storage, read> child: array<u32>;
@group(0) @binding(2) var<storage, read_write> out: array<u32>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= p.width || gid.y >= p.height) {
        return;
    }
    var counts = array<u32, 5>(0u, 0u, 0u, 0u, 0u);
    var frozen = false;
    for (var k = 0u; k < 4u; k++) {
        let cx = 2u * gid.x + (k & 1u);
        let cy = 2u * gid.y + (k >> 1u);
        if (cx < p.child_width && cy < p.child_height) {
            let v = min(child[cy * p.child_width + cx], 4u);
            frozen = frozen || v == 0u;
            counts[v] += 1u;
        }
    }
    var best = 0u;
    if (!frozen) {
        // `max_by_key` keeps the last of equal maxima: `>=` walking upward.
        best = 1u;
        for (var v = 2u; v < 5u; v++) {
            if (counts[v] >= counts[best]) {
                best = v;
            }
        }
    }
    out[gid.y * p.width + gid.x] = best;
}
