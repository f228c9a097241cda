// Stage `reduce_types`: the mirror of src/stages/reduce_types.rs — each
// pixel's target set is the union of its 2×2 children's sets, leaving out
// children whose set is full (ALL_TYPES or every type of the database);
// no constrained child leaves the pixel unconstrained (ALL_TYPES). Children
// past the child level's edge (odd sizes) are absent.

struct ReduceTypesParams {
    width: u32,
    height: u32,
    child_width: u32,
    child_height: u32,
    full: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

@group(0) @binding(0) var<uniform> p: ReduceTypesParams;
@group(0) @binding(1) var<storage, read> child: array<u32>;
@group(0) @binding(2) var<storage, read_write> out: array<u32>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= p.width || gid.y >= p.height) {
        return;
    }
    var acc = 0u;
    for (var k = 0u; k < 4u; k++) {
        let cx = 2u * gid.x + (k & 1u);
        let cy = 2u * gid.y + (k >> 1u);
        if (cx < p.child_width && cy < p.child_height) {
            let r = child[cy * p.child_width + cx];
            if (r != ALL_TYPES && (r & p.full) != p.full) {
                acc |= r;
            }
        }
    }
    out[gid.y * p.width + gid.x] = select(ALL_TYPES, acc, acc != 0u);
}
