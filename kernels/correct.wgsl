// Stage `correct`, one subpass (paper eq. 3–7): the mirror of
// src/synth/stages/correct/scalar.rs, function for function, one invocation
// per pixel of the parity class (p.px, p.py). See the Rust module docs of
// src/synth/stages/correct.rs for the arithmetic (N_S kept ×3, h by floor
// division, residuals clamped to ±CLAMP so a κ = 2 score fits a u32, ties
// keep the earlier candidate).

struct CorrectParams {
    width: u32,
    height: u32,
    px: u32,
    py: u32,
}

@group(0) @binding(0) var<uniform> p: CorrectParams;
@group(0) @binding(1) var<storage, read_write> state_s: array<vec2<i32>>;
@group(0) @binding(2) var<storage, read_write> state_v: array<i32>;
@group(0) @binding(3) var<storage, read> columns: array<Column>;
// Appearance texels: four i16 modes per u64, low word first (unpack_texel).
@group(0) @binding(4) var<storage, read> appearance: array<vec2<u32>>;
// C₂ per texel, packed x | y << 16.
@group(0) @binding(5) var<storage, read> similar: array<u32>;

// correct::CLAMP.
const CLAMP: i32 = 11584;

// correct::DIAGONALS.
const DIAGONALS = array<vec2<i32>, 4>(
    vec2<i32>(-1, -1), vec2<i32>(1, -1), vec2<i32>(-1, 1), vec2<i32>(1, 1),
);

// correct::DELTAS, in evaluation (and tie-break) order.
const DELTAS = array<vec2<i32>, 9>(
    vec2<i32>(0, 0), vec2<i32>(-1, -1), vec2<i32>(0, -1), vec2<i32>(1, -1),
    vec2<i32>(-1, 0), vec2<i32>(1, 0), vec2<i32>(-1, 1), vec2<i32>(0, 1), vec2<i32>(1, 1),
);

// AtlasLevel::index.
fn atlas_index(x: i32, y: i32) -> u32 {
    let c = columns[x];
    return u32(c.base + y * i32(c.stride) + x);
}

// appearance::unpack_texel of AtlasLevel::appearance(x, y): sign-extended
// 16-bit fields by shifting up then arithmetically down.
fn texel(x: i32, y: i32) -> vec4<i32> {
    let t = appearance[atlas_index(x, y)];
    return vec4<i32>(
        bitcast<i32>(t.x << 16u) >> 16u,
        bitcast<i32>(t.x) >> 16u,
        bitcast<i32>(t.y << 16u) >> 16u,
        bitcast<i32>(t.y) >> 16u,
    );
}

// AtlasLevel::clamp_interior.
fn clamp_interior(u: vec2<i32>) -> vec2<i32> {
    let c = columns[u.x];
    return vec2<i32>(clamp(u.x, c.min_x, c.max_x), clamp(u.y, MARGIN, c.max_y));
}

// scalar::reflect: by 2 at the level border (keeps parity).
fn reflect(c: i32, n: i32) -> i32 {
    if (c < 0) {
        return c + 2;
    } else if (c >= n) {
        return c - 2;
    }
    return c;
}

struct Scored {
    score: u32,
    h: i32,
}

// scalar::score: κ · min_h ‖N_S − N_E(q, h)‖² and the minimising h.
fn score(ns_in: array<vec4<i32>, 4>, qx: i32, qy: i32, kappa: u32) -> Scored {
    var ns = ns_in;
    var diag = DIAGONALS;
    var d: array<vec4<i32>, 4>;
    var sum1 = 0;
    for (var k = 0; k < 4; k++) {
        let m = texel(qx + diag[k].x, qy + diag[k].y);
        d[k] = ns[k] - 3 * m;
        sum1 += d[k].x;
    }
    let h = div_floor(sum1 + 6, 12);
    var s = 0u;
    for (var k = 0; k < 4; k++) {
        let r1 = clamp(d[k].x - 3 * h, -CLAMP, CLAMP);
        s += u32(r1 * r1);
        for (var j = 1; j < 4; j++) {
            let r = clamp(d[k][j], -CLAMP, CLAMP);
            s += u32(r * r);
        }
    }
    return Scored(s * kappa, h);
}

// scalar::Neighbour.
struct Neighbour {
    t: vec2<i32>,
    frac: vec2<i32>,
    v: i32,
}

// scalar::neighbour: reflect, and extrapolate the coordinate of a pixel
// outside the level from its reflection.
fn neighbour(x: i32, y: i32) -> Neighbour {
    let w = i32(p.width);
    let h = i32(p.height);
    let rx = reflect(x, w);
    let ry = reflect(y, h);
    let i = u32(ry * w + rx);
    let s = state_s[i];
    let sx = round_fixed(s.x);
    let sy = round_fixed(s.y);
    let frac = vec2<i32>(s.x - (sx << FRAC_BITS), s.y - (sy << FRAC_BITS));
    var t = vec2<i32>(sx, sy);
    if (rx != x || ry != y) {
        let col = columns[sx];
        t = vec2<i32>(
            clamp(sx + x - rx, col.min_x - 1, col.max_x + 1),
            clamp(sy + y - ry, 1, col.max_y + 1),
        );
    }
    return Neighbour(t, frac, state_v[i]);
}

// scalar::correct_pixel, writing its result in place.
@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let ux = 2u * gid.x + p.px;
    let uy = 2u * gid.y + p.py;
    if (ux >= p.width || uy >= p.height) {
        return;
    }
    let x = i32(ux);
    let y = i32(uy);

    var diag = DIAGONALS;
    var ns: array<vec4<i32>, 4>;
    for (var k = 0; k < 4; k++) {
        let dx = diag[k].x;
        let dy = diag[k].y;
        var vs = array<vec2<i32>, 3>(vec2<i32>(0, 0), vec2<i32>(dx, 0), vec2<i32>(0, dy));
        var acc = vec4<i32>(0);
        for (var j = 0; j < 3; j++) {
            let v = vs[j];
            let n = neighbour(x + dx + v.x, y + dy + v.y);
            acc += texel(n.t.x - v.x, n.t.y - v.y) + vec4<i32>(n.v, 0, 0, 0);
        }
        ns[k] = acc;
    }

    var best_score = 0xFFFFFFFFu;
    var best_s = vec2<i32>(0);
    var best_h = 0;
    let unseen = bitcast<i32>(0x80000000u);
    var seen: array<vec2<i32>, 9>;
    for (var k = 0; k < 9; k++) {
        seen[k] = vec2<i32>(unseen, unseen);
    }
    var deltas = DELTAS;
    for (var k = 0; k < 9; k++) {
        let dl = deltas[k];
        let n = neighbour(x + dl.x, y + dl.y);
        let u = n.t - dl;
        var dup = false;
        for (var j = 0; j < k; j++) {
            if (all(seen[j] == u)) {
                dup = true;
            }
        }
        if (dup) {
            continue;
        }
        seen[k] = u;
        let c1 = clamp_interior(u);
        let r1 = score(ns, c1.x, c1.y, 1u);
        if (r1.score < best_score) {
            best_score = r1.score;
            best_s = (c1 << vec2<u32>(FRAC_BITS)) + n.frac;
            best_h = r1.h;
        }
        let e = similar[atlas_index(u.x, u.y)];
        let c2 = vec2<i32>(i32(e & 0xFFFFu), i32(e >> 16u));
        let r2 = score(ns, c2.x, c2.y, 2u);
        if (r2.score < best_score) {
            best_score = r2.score;
            best_s = (c2 << vec2<u32>(FRAC_BITS)) + n.frac;
            best_h = r2.h;
        }
    }
    let i = uy * p.width + ux;
    state_s[i] = best_s;
    state_v[i] = best_h;
}
