// Stage `fill_ssd` of the patch engine (round one of hole filling, seed 004
// §6.2): the mirror of src/stages/fill_ssd.rs (the sums under
// `fill_ssd_scalar`), one invocation per (candidate, transform). For
// d = (user − cand) & mask over the cells it writes s = Σd and s2 = Σd².
// Cells are centred and clamped to ±FILL_CLAMP on the host, so |d| < 2^14,
// d² < 2^28 and |s| < 2^24 for up to 1024 cells; s2 can pass 2^32, so it is
// kept as a 64-bit value in two u32 words with an explicit carry. The host
// finishes the DC-corrected SSD (k·s2 − s²) / k² in 64 bits, as the CPU
// path does (`fill_ssd::dc_ssd`): WGSL has no 64-bit division.

struct FillSsdParams {
    // Cells per candidate, (patch / COARSE)².
    cells: u32,
    candidates: u32,
    transforms: u32,
    pad0: u32,
}

@group(0) @binding(0) var<uniform> p: FillSsdParams;
// The user window's centred cells permuted into each transform's frame
// (`transforms` blocks of `cells`), then each block's mask (−1 valid, 0 not).
@group(0) @binding(1) var<storage, read> user: array<i32>;
// Every candidate's centred cells, contiguous (PreparedSource::fill_cells).
@group(0) @binding(2) var<storage, read> cand: array<i32>;
// Per candidate, per transform: (s as u32 bits, s2 low word, s2 high word, 0).
@group(0) @binding(3) var<storage, read_write> sums: array<vec4<u32>>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let k = gid.x;
    let v = gid.y;
    if (k >= p.candidates || v >= p.transforms) {
        return;
    }
    let ub = v * p.cells;
    let mb = (p.transforms + v) * p.cells;
    let cb = k * p.cells;
    var s = 0i;
    var lo = 0u;
    var hi = 0u;
    for (var i = 0u; i < p.cells; i++) {
        let d = (user[ub + i] - cand[cb + i]) & user[mb + i];
        s += d;
        let sq = u32(d * d);
        let next = lo + sq;
        if (next < lo) {
            hi += 1u;
        }
        lo = next;
    }
    sums[k * p.transforms + v] = vec4<u32>(bitcast<u32>(s), lo, hi, 0u);
}
