// Stage `correct`, one subpass (paper eq. 3–7, and the controls of §5): the
// mirror of src/stages/correct/scalar.rs (`correct_pixel_guided`),
// function for function, one invocation per pixel of the parity class
// (p.px, p.py). Each control is on when its flag is set; without flags the
// guide binding is a placeholder and never read. See the Rust module docs of
// src/stages/correct.rs for the arithmetic (N_S kept ×3, h by floor
// division, residuals clamped to ±CLAMP so a κ = 2 score fits a u32, ties
// keep the earlier candidate).
//
// The Rust loops over small constant tables (the four diagonals, the nine
// neighbours, the candidates seen) are written out here, with structs
// where Rust has arrays: arrays indexed in loops went to the GPU's local
// memory, and each score read and wrote them. Measured on an H100 at
// 1024²: `correct` 3.4 → 1.3 ms of device time (a 128² level 0.40 →
// 0.18 ms), the same bytes (the `stages` and `backend` cross-checks there).

struct CorrectParams {
    width: u32,
    height: u32,
    px: u32,
    py: u32,
    // F_* bits: which controls apply.
    flags: u32,
    // The level index (salts the type-seeding hash).
    level: u32,
    // Types of the database (length of `seed_counts`).
    type_count: u32,
    // Height prior weight P (CorrectParams::prior).
    prior: u32,
    // Only pixels in [x0, x1) × [y0, y1) are corrected (Guide::window); with
    // F_COHERENCE the others take the previous result.
    x0: u32,
    y0: u32,
    x1: u32,
    y1: u32,
    // The level above (the prior's anchor), when has_parent is 1.
    parent_width: u32,
    parent_height: u32,
    has_parent: u32,
    // Absolute position of the state's pixel (0, 0) (Guide::origin): type
    // seeding hashes absolute coordinates.
    origin_x: u32,
    origin_y: u32,
    // Whether each source's C₂ competes (CorrectParams::similar; 0: C₁ only).
    similar: u32,
    pad1: u32,
    pad2: u32,
}

const F_TARGETS: u32 = 1u;
const F_ALLOWED: u32 = 2u;
const F_COHERENCE: u32 = 4u;

@group(0) @binding(0) var<uniform> p: CorrectParams;
@group(0) @binding(1) var<storage, read_write> state_s: array<vec2<i32>>;
@group(0) @binding(2) var<storage, read_write> state_v: array<i32>;
@group(0) @binding(3) var<storage, read> columns: array<Column>;
// Appearance texels: four i16 modes per u64, low word first (unpack_texel).
@group(0) @binding(4) var<storage, read> appearance: array<vec2<u32>>;
// C₂ per texel, packed x | y << 16.
@group(0) @binding(5) var<storage, read> similar: array<u32>;

// The level's type tables in one buffer (gpu::Level::type_data): seed
// counts per type (type_count words), then SEEDS_PER_TYPE seed texels per
// type (packed x | y << 16), then the type id per atlas texel (four u8 per
// word). One binding instead of three keeps the kernel within WebGPU's
// default of 8 storage buffers per stage.
@group(0) @binding(6) var<storage, read> type_data: array<u32>;

// Control inputs per pixel (uniform::GuideCell): the nudge::Target
// (height, tol), R^i, W^i, and the previous frame's S and V.
struct GuideCell {
    blend_target: vec2<i32>,
    allowed: u32,
    weight: u32,
    prev_s: vec2<i32>,
    prev_v: i32,
    pad0: i32,
}
@group(0) @binding(7) var<storage, read> guide: array<GuideCell>;
// The parent level's offsets V (a placeholder when has_parent is 0).
@group(0) @binding(8) var<storage, read> parent_v: array<i32>;

// The pixel's Prior::v and Prior::held (set once per invocation in `main`;
// every score of the pixel reads them, like the `prior` argument of the
// Rust scores).
var<private> prior_v: i32;
var<private> prior_held: bool;

// correct::parent_v: the parent's V at child (x, y), bilinear (9, 3, 3, 1
// of 16 from the parent under it and the three nearest, clamped at the
// level's edges), rounded to nearest with ties up (>> is arithmetic).
fn parent_offset(x: u32, y: u32) -> i32 {
    let px = x / 2u;
    let py = y / 2u;
    var qx = min(px + 1u, p.parent_width - 1u);
    if (x % 2u == 0u) {
        qx = max(px, 1u) - 1u;
    }
    var qy = min(py + 1u, p.parent_height - 1u);
    if (y % 2u == 0u) {
        qy = max(py, 1u) - 1u;
    }
    let w = p.parent_width;
    return (9 * parent_v[py * w + px] + 3 * parent_v[py * w + qx] + 3 * parent_v[qy * w + px]
        + parent_v[qy * w + qx] + 8) >> 4u;
}

// correct::{W_FREE, SEEDS_PER_ALLOWED_TYPE, SEED_SALT, FLAT.weight, FLAT_FIT.weight};
// types::SEEDS_PER_TYPE; nudge::{MAX_ERROR, KEEP_DETAIL, DETAIL_LEVELS,
// DETAIL_STEP}.
const W_FREE: u32 = 4u;
const SEEDS_PER_ALLOWED_TYPE: u32 = 9u;
const SEED_SALT: u32 = 2120089600u;
const SEEDS_PER_TYPE: u32 = 64u;
const MAX_ERROR: i32 = 16777216;
const KEEP_DETAIL: i32 = 65536;
const DETAIL_LEVELS: u32 = 2u;
const DETAIL_STEP: i32 = 2;
const FLAT_WEIGHT: i32 = 8;
const FLAT_FIT_WEIGHT: i32 = 44;

// correct::CLAMP.
const CLAMP: i32 = 9459;

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

// N_S of a pixel (×3), one field per diagonal in correct::DIAGONALS order:
// (−1, −1), (1, −1), (−1, 1), (1, 1). Fields, not an array: an array
// indexed in loops went to the GPU's local memory.
struct Hood {
    a: vec4<i32>,
    b: vec4<i32>,
    c: vec4<i32>,
    d: vec4<i32>,
}

// scalar::score: κ · min_h ‖N_S − N_E(q, h)‖² and the minimising h.
fn score(ns: Hood, qx: i32, qy: i32, kappa: u32) -> Scored {
    return score_with(ns, qx, qy, kappa, false, 0);
}

// One diagonal's share of a score: its height residual at offset h and its
// three slope/curvature residuals, each clamped to ±CLAMP and squared (u32
// sums wrap like the Rust ones, in any order).
fn residuals(d: vec4<i32>, h: i32) -> u32 {
    let r1 = clamp(d.x - 3 * h, -CLAMP, CLAMP);
    let r = clamp(d.yzw, vec3<i32>(-CLAMP), vec3<i32>(CLAMP));
    return u32(r1 * r1) + u32(r.x * r.x) + u32(r.y * r.y) + u32(r.z * r.z);
}

// scalar::score_with: h fixed to `fixed_h` when `fixed`.
fn score_with(ns: Hood, qx: i32, qy: i32, kappa: u32, fixed: bool, fixed_h: i32) -> Scored {
    let m0 = texel(qx - 1, qy - 1);
    let m1 = texel(qx + 1, qy - 1);
    let m2 = texel(qx - 1, qy + 1);
    let m3 = texel(qx + 1, qy + 1);
    let d0 = ns.a - 3 * m0;
    let d1 = ns.b - 3 * m1;
    let d2 = ns.c - 3 * m2;
    let d3 = ns.d - 3 * m3;
    let sum1 = d0.x + d1.x + d2.x + d3.x;
    // Prior::is_flat and Prior::fit: a flat candidate's offset is fitted
    // with FLAT_FIT's weight and priced with FLAT's, towards 0 — unless a
    // constraint holds the pixel, where it is any candidate.
    var w = i32(p.prior);
    var fit_w = w;
    var anchor = prior_v;
    if (w > 0 && !prior_held && m0.x == m1.x && m0.x == m2.x && m0.x == m3.x) {
        w = FLAT_WEIGHT;
        fit_w = FLAT_FIT_WEIGHT;
        anchor = 0;
    }
    // Prior::optimal and Prior::cost.
    let den = 12 + 3 * fit_w;
    var h = div_floor(sum1 + 3 * fit_w * anchor + den / 2, den);
    if (fixed) {
        h = fixed_h;
    }
    let rp = clamp(3 * (h - anchor), -CLAMP, CLAMP);
    let s = u32(w) * u32(rp * rp) + residuals(d0, h) + residuals(d1, h) + residuals(d2, h)
        + residuals(d3, h);
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

// Type id of atlas texel q (Level::types).
fn texel_type(q: vec2<i32>) -> u32 {
    let i = atlas_index(q.x, q.y);
    let at = p.type_count * (1u + SEEDS_PER_TYPE);
    return (type_data[at + (i >> 2u)] >> ((i & 3u) * 8u)) & 0xFFu;
}

// `mask >> t & 1 == 1` as Rust computes it in release builds (the shift
// amount wraps at 32; WGSL/SPIR-V leave larger shifts undefined).
fn has_type(mask: u32, t: u32) -> bool {
    return ((mask >> (t & 31u)) & 1u) == 1u;
}

// The best candidate so far (scalar::Best): cost, coordinate, offset, and
// its texel where `has_q` (not for a previous result taken as is).
struct Best {
    score: u32,
    s: vec2<i32>,
    h: i32,
    has_q: bool,
    q: vec2<i32>,
}

// The u already tried for a pixel, latest first: at most eight matter
// (the ninth neighbour's is never compared); unused fields hold UNSEEN,
// which no u equals.
struct Seen {
    s0: vec2<i32>,
    s1: vec2<i32>,
    s2: vec2<i32>,
    s3: vec2<i32>,
    s4: vec2<i32>,
    s5: vec2<i32>,
    s6: vec2<i32>,
    s7: vec2<i32>,
}

const UNSEEN = vec2<i32>(-2147483647 - 1, -2147483647 - 1);

fn is_seen(s: Seen, u: vec2<i32>) -> bool {
    return all(s.s0 == u) || all(s.s1 == u) || all(s.s2 == u) || all(s.s3 == u)
        || all(s.s4 == u) || all(s.s5 == u) || all(s.s6 == u) || all(s.s7 == u);
}

// Neighbour (x, y) + dl's coordinate shifted back by dl: the k-coherence
// source u (and the neighbour's fraction).
fn shifted(x: i32, y: i32, dl: vec2<i32>) -> Neighbour {
    let n = neighbour(x + dl.x, y + dl.y);
    return Neighbour(n.t - dl, n.frac, n.v);
}

// The two candidates of one source u (its own texel, clamped inside, and
// its most similar texel C₂ if p.similar), each scored if `admit` admits
// it; whether any was.
fn try_source(ns: Hood, n: Neighbour, admit: u32, best: ptr<function, Best>) -> bool {
    var admitted = false;
    let u = n.t;
    let c1 = clamp_interior(u);
    if (admit == ALL_TYPES || has_type(admit, texel_type(c1))) {
        admitted = true;
        let r1 = score(ns, c1.x, c1.y, 1u);
        if (r1.score < (*best).score) {
            *best = Best(r1.score, (c1 << vec2<u32>(FRAC_BITS)) + n.frac, r1.h, true, c1);
        }
    }
    if (p.similar == 0u) {
        return admitted;
    }
    let e = similar[atlas_index(u.x, u.y)];
    let c2 = vec2<i32>(i32(e & 0xFFFFu), i32(e >> 16u));
    if (admit == ALL_TYPES || has_type(admit, texel_type(c2))) {
        admitted = true;
        let r2 = score(ns, c2.x, c2.y, 2u);
        if (r2.score < (*best).score) {
            *best = Best(r2.score, (c2 << vec2<u32>(FRAC_BITS)) + n.frac, r2.h, true, c2);
        }
    }
    return admitted;
}

// Neighbour dl's source u, unless already `seen` (then nothing: the Rust
// loop skips a repeated u); else it joins `seen` and its two candidates
// are tried. Whether any candidate was admitted.
fn visit(
    ns: Hood, x: i32, y: i32, dl: vec2<i32>, seen: ptr<function, Seen>, admit: u32,
    best: ptr<function, Best>,
) -> bool {
    let n = shifted(x, y, dl);
    let s = *seen;
    if (is_seen(s, n.t)) {
        return false;
    }
    *seen = Seen(n.t, s.s0, s.s1, s.s2, s.s3, s.s4, s.s5, s.s6);
    return try_source(ns, n, admit, best);
}

// The k-coherence candidates of pixel (x, y) admitted by `admit` (the
// closure `candidates` of scalar::correct_pixel_guided); whether any was.
// The nine neighbours in stages::common::DELTAS order (the tie-break order),
// written out: a loop over an array of them kept its arrays in local memory.
fn candidates(ns: Hood, x: i32, y: i32, admit: u32, best: ptr<function, Best>) -> bool {
    var seen = Seen(UNSEEN, UNSEEN, UNSEEN, UNSEEN, UNSEEN, UNSEEN, UNSEEN, UNSEEN);
    var admitted = visit(ns, x, y, vec2<i32>(0, 0), &seen, admit, best);
    admitted = visit(ns, x, y, vec2<i32>(-1, -1), &seen, admit, best) || admitted;
    admitted = visit(ns, x, y, vec2<i32>(0, -1), &seen, admit, best) || admitted;
    admitted = visit(ns, x, y, vec2<i32>(1, -1), &seen, admit, best) || admitted;
    admitted = visit(ns, x, y, vec2<i32>(-1, 0), &seen, admit, best) || admitted;
    admitted = visit(ns, x, y, vec2<i32>(1, 0), &seen, admit, best) || admitted;
    admitted = visit(ns, x, y, vec2<i32>(-1, 1), &seen, admit, best) || admitted;
    admitted = visit(ns, x, y, vec2<i32>(0, 1), &seen, admit, best) || admitted;
    admitted = visit(ns, x, y, vec2<i32>(1, 1), &seen, admit, best) || admitted;
    return admitted;
}

// correct::weigh: ⌊score · w / 4⌋ without leaving 32 bits.
fn weigh(score: u32, w: u32) -> u32 {
    return (score >> 2u) * w + (((score & 3u) * w) >> 2u);
}

// The high word of a 32 × 32-bit product (from 16-bit halves).
fn mul_hi(a: u32, b: u32) -> u32 {
    let a0 = a & 0xFFFFu;
    let a1 = a >> 16u;
    let b0 = b & 0xFFFFu;
    let b1 = b >> 16u;
    let p00 = a0 * b0;
    let p01 = a0 * b1;
    let p10 = a1 * b0;
    let mid = (p00 >> 16u) + (p01 & 0xFFFFu) + (p10 & 0xFFFFu);
    return a1 * b1 + (p01 >> 16u) + (p10 >> 16u) + (mid >> 16u);
}

// hash::below: ⌊h · n / 2³²⌋.
fn below(h: u32, n: u32) -> u32 {
    return mul_hi(h, n);
}

// i32::saturating_sub.
fn saturating_sub(a: i32, b: i32) -> i32 {
    let d = a - b;
    if (((a ^ b) & (a ^ d)) < 0) {
        if (a < 0) {
            return bitcast<i32>(0x80000000u);
        }
        return 2147483647;
    }
    return d;
}

// nudge::phi: φ_d of eq. 9 with λ = ½ (the whole error where tol = 0), integer.
fn phi(x_in: i32, tol: i32) -> i32 {
    let x = clamp(x_in, -MAX_ERROR, MAX_ERROR);
    let a = u32(abs(x));
    let t = u32(tol);
    var mag = 0u;
    if (t == 0u) {
        mag = a;
    } else if (a > t) {
        mag = (3u * a - 2u * t + 3u) / 6u;
    } else if (a != 0u) {
        let r = (a << 15u) / t;
        let r2 = (r * r) >> 15u;
        mag = (a * r2 + 3u * (1u << 15u)) / (6u << 15u);
    }
    if (x < 0) {
        return -i32(mag);
    }
    return i32(mag);
}

// nudge::nudge (nudge::Target::tolerance: the low 16 bits of a tolerance).
fn nudge(v: i32, h_c: i32, goal: vec2<i32>) -> i32 {
    if (goal.y < 0) {
        return v;
    }
    return v + phi(saturating_sub(goal.x, h_c), goal.y & 0xFFFF);
}

// nudge::own_detail: the winner texel q's height h minus the floor of the
// mean of the 3×3 texels DETAIL_STEP apart around it, where the goal keeps
// detail at the finest levels; else 0.
fn own_detail(level: u32, goal: vec2<i32>, h: i32, q: vec2<i32>) -> i32 {
    if (level >= DETAIL_LEVELS || goal.y < 0 || (goal.y & KEEP_DETAIL) == 0) {
        return 0;
    }
    var sum = 0;
    for (var dy = -DETAIL_STEP; dy <= DETAIL_STEP; dy += DETAIL_STEP) {
        for (var dx = -DETAIL_STEP; dx <= DETAIL_STEP; dx += DETAIL_STEP) {
            sum += texel(q.x + dx, q.y + dy).x - MODE1_BIAS;
        }
    }
    return h - div_floor(sum, 9);
}

// One diagonal (dx, dy) of N_S at (x, y): the texel each of its three
// pixels (the diagonal, and its x and y neighbours towards the centre)
// predicts there, plus its offset.
fn diagonal(x: i32, y: i32, dx: i32, dy: i32) -> vec4<i32> {
    return predicted(x + dx, y + dy, 0, 0) + predicted(x + 2 * dx, y + dy, dx, 0)
        + predicted(x + dx, y + 2 * dy, 0, dy);
}

// Pixel (px, py)'s texel shifted by (−vx, −vy), plus its V in the height.
fn predicted(px: i32, py: i32, vx: i32, vy: i32) -> vec4<i32> {
    let n = neighbour(px, py);
    return texel(n.t.x - vx, n.t.y - vy) + vec4<i32>(n.v, 0, 0, 0);
}

// scalar::correct_pixel_guided, writing its result in place.
@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let ux = 2u * gid.x + p.px;
    let uy = 2u * gid.y + p.py;
    if (ux >= p.width || uy >= p.height) {
        return;
    }
    if (ux < p.x0 || uy < p.y0 || ux >= p.x1 || uy >= p.y1) {
        // Outside the window: the previous frame's result (correct::keep_outside).
        if ((p.flags & F_COHERENCE) != 0u) {
            let k = uy * p.width + ux;
            state_s[k] = guide[k].prev_s;
            state_v[k] = guide[k].prev_v;
        }
        return;
    }
    let x = i32(ux);
    let y = i32(uy);
    // Prior::at.
    prior_v = 0;
    if (p.has_parent != 0u) {
        prior_v = parent_offset(ux, uy);
    }
    prior_held = (p.flags & F_TARGETS) != 0u && guide[uy * p.width + ux].blend_target.y >= 0;

    let ns = Hood(
        diagonal(x, y, -1, -1),
        diagonal(x, y, 1, -1),
        diagonal(x, y, -1, 1),
        diagonal(x, y, 1, 1),
    );

    let i = uy * p.width + ux;
    var best = Best(0xFFFFFFFFu, vec2<i32>(0), 0, false, vec2<i32>(0));
    var allowed = ALL_TYPES;
    if ((p.flags & F_ALLOWED) != 0u) {
        allowed = guide[i].allowed;
    }
    if ((p.flags & F_COHERENCE) != 0u) {
        let s = guide[i].prev_s;
        let v = guide[i].prev_v;
        let q = vec2<i32>(round_fixed(s.x), round_fixed(s.y));
        let w = guide[i].weight;
        // A previous result of a type no longer allowed is no candidate,
        // unless frozen (freezing dominates).
        if (allowed == ALL_TYPES || w == 0u || has_type(allowed, texel_type(q))) {
            if (w == 0u) {
                best = Best(0u, s, v, false, q);
            } else if (w >= W_FREE) {
                let r = score(ns, q.x, q.y, 1u);
                best = Best(weigh(r.score, w), s, r.h, true, q);
            } else {
                let r = score_with(ns, q.x, q.y, 1u, true, v);
                best = Best(weigh(r.score, w), s, v, false, q);
            }
        }
    }
    if (!candidates(ns, x, y, allowed, &best)) {
        var seeded = false;
        for (var t = 0u; t < p.type_count; t++) {
            let count = type_data[t];
            if (!has_type(allowed, t) || count == 0u) {
                continue;
            }
            seeded = true;
            for (var k = 0u; k < SEEDS_PER_ALLOWED_TYPE; k++) {
                let salt = t * SEEDS_PER_ALLOWED_TYPE + k;
                let hash = hash4(SEED_SALT | p.level, salt, p.origin_x + ux, p.origin_y + uy);
                let c = type_data[p.type_count + t * SEEDS_PER_TYPE + below(hash, count)];
                let q = vec2<i32>(i32(c & 0xFFFFu), i32(c >> 16u));
                let r = score(ns, q.x, q.y, 1u);
                if (r.score < best.score) {
                    best = Best(r.score, q << vec2<u32>(FRAC_BITS), r.h, true, q);
                }
            }
        }
        if (!seeded) {
            // No exemplar texel of any allowed type at this level.
            _ = candidates(ns, x, y, ALL_TYPES, &best);
        }
    }
    var v = best.h;
    if (best.has_q && (p.flags & F_TARGETS) != 0u) {
        let goal = guide[i].blend_target;
        let h = texel(best.q.x, best.q.y).x - MODE1_BIAS;
        v = nudge(v, h + v - own_detail(p.level, goal, h, best.q), goal);
    }
    state_s[i] = best.s;
    state_v[i] = v;
}
