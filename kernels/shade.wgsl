// Stage `shade` (preview): the mirror of src/stages/shade.rs, function for
// function, one invocation per preview pixel. Integer arithmetic on 32-bit
// values only, with the bounds the Rust side documents and
// `ShadeParams::validate` checks before any dispatch.

const NODATA: i32 = -2147483647 - 1;
const SLOPE_ONE: i32 = 4096;
const MAX_SLOPE: i32 = 262144;
const NO_TYPE: u32 = 255u;
const FULL: u32 = 256u;

// shade::flags.
const F_CONTOURS: u32 = 1u;
const F_GRID: u32 = 2u;
const F_RANGE: u32 = 4u;
const F_SEA: u32 = 8u;
const F_TYPES: u32 = 16u;
const F_ASPECT_WEIGHTS: u32 = 32u;

// shade::ShadeParams.
struct ShadeParams {
    lights: array<vec4<i32>, 4>,
    width: u32,
    height: u32,
    flags: u32,
    light_count: u32,
    slope_x_mul: i32,
    slope_x_pre: u32,
    slope_x_post: u32,
    slope_x_clamp: i32,
    slope_y_mul: i32,
    slope_y_pre: u32,
    slope_y_post: u32,
    slope_y_clamp: i32,
    shade_floor: u32,
    shade_gain: u32,
    shade_max: u32,
    nodata_colour: u32,
    tint_lo: i32,
    tint_shift: u32,
    tint_len: u32,
    nodata_hatch: u32,
    water_level: i32,
    water_shift: u32,
    water_shallow: u32,
    water_deep: u32,
    range_lo: i32,
    range_hi: i32,
    range_colour: u32,
    coast_colour: u32,
    contour_base: i32,
    contour_interval: u32,
    contour_index_every: u32,
    contour_colour: u32,
    contour_half_width: u32,
    index_half_width: u32,
    coast_half_width: u32,
    index_colour: u32,
    contour_min_spacing: u32,
    grid_step_x: u32,
    grid_step_y: u32,
    grid_colour: u32,
}

@group(0) @binding(0) var<uniform> p: ShadeParams;
@group(0) @binding(1) var<storage, read> heights: array<i32>;
@group(0) @binding(2) var<storage, read> types: array<u32>;
@group(0) @binding(3) var<storage, read> tint: array<u32>;
@group(0) @binding(4) var<storage, read> type_colours: array<u32>;
@group(0) @binding(5) var<storage, read_write> out: array<u32>;

// i32::unsigned_abs (abs wraps at i32::MIN, whose bits are then 2^31).
fn uabs(v: i32) -> u32 {
    return bitcast<u32>(abs(v));
}

// i32::abs_diff.
fn abs_diff(a: i32, b: i32) -> u32 {
    if (a > b) {
        return bitcast<u32>(a) - bitcast<u32>(b);
    }
    return bitcast<u32>(b) - bitcast<u32>(a);
}

// shade::shr_sym.
fn shr_sym(v: i32, k: u32) -> i32 {
    let m = i32(uabs(v) >> k);
    return select(m, -m, v < 0);
}

// shade::shr_round.
fn shr_round(v: i32, k: u32) -> i32 {
    if (k == 0u) {
        return v;
    }
    let m = i32((uabs(v) + (1u << (k - 1u))) >> k);
    return select(m, -m, v < 0);
}

// shade::isqrt.
fn isqrt(n: u32) -> u32 {
    var rem = n;
    var root = 0u;
    var bit = 1u << 30u;
    while (bit != 0u) {
        let t = root + bit;
        let take = rem >= t;
        rem = select(rem, rem - t, take);
        root = (root >> 1u) + select(0u, bit, take);
        bit = bit >> 2u;
    }
    return root;
}

// shade::blend.
fn blend(a: u32, b: u32, t: u32) -> u32 {
    var c = 0u;
    for (var s = 0u; s < 24u; s += 8u) {
        c |= ((((a >> s) & 0xffu) * (FULL - t) + ((b >> s) & 0xffu) * t + 128u) >> 8u) << s;
    }
    return c;
}

// shade::alpha256.
fn alpha256(c: u32) -> u32 {
    let a = c >> 24u;
    return a + (a >> 7u);
}

// shade::apply_shade.
fn apply_shade(c: u32, factor: u32) -> u32 {
    if (factor <= FULL) {
        var o = 0u;
        for (var s = 0u; s < 24u; s += 8u) {
            o |= ((((c >> s) & 0xffu) * factor + 128u) >> 8u) << s;
        }
        return o;
    }
    return blend(c, 0x00ffffffu, factor - FULL);
}

// shade::slope.
fn slope(s: i32, mul: i32, pre: u32, post: u32, clamp_: i32) -> i32 {
    let t = clamp(shr_sym(s, pre), -clamp_, clamp_);
    return clamp(shr_round(t * mul, post), -MAX_SLOPE, MAX_SLOPE);
}

// The Lambert term of shade::hillshade.
fn lambert(n: vec3<i32>, l: vec4<i32>, recip: u32) -> u32 {
    let dot = n.x * l.x + n.y * l.y + n.z * l.z;
    return ((u32(max(dot, 0)) >> 12u) * recip) >> 18u;
}

// shade::hillshade.
fn hillshade(sx: i32, sy: i32) -> u32 {
    var nx = -sx;
    var ny = -sy;
    var nz = SLOPE_ONE;
    let m = max(max(uabs(nx), uabs(ny)), u32(nz));
    let bits = 32u - countLeadingZeros(m);
    if (bits > 15u) {
        let k = bits - 15u;
        nx = shr_sym(nx, k);
        ny = shr_sym(ny, k);
        nz = shr_sym(nz, k);
    } else {
        let k = 15u - bits;
        nx = nx << k;
        ny = ny << k;
        nz = nz << k;
    }
    let len = isqrt(u32(nx * nx) + u32(ny * ny) + u32(nz * nz));
    let recip = (1u << 30u) / len;
    let n = vec3<i32>(nx, ny, nz);

    let aspect = (p.flags & F_ASPECT_WEIGHTS) != 0u && (nx != 0 || ny != 0);
    var dx = nx;
    var dy = ny;
    if (aspect) {
        let m2 = max(uabs(dx), uabs(dy));
        let bits2 = 32u - countLeadingZeros(m2);
        if (bits2 > 8u) {
            dx = shr_sym(dx, bits2 - 8u);
            dy = shr_sym(dy, bits2 - 8u);
        } else {
            dx = dx << (8u - bits2);
            dy = dy << (8u - bits2);
        }
    }

    var sum = 0u;
    var wsum = 0u;
    for (var k = 0u; k < p.light_count; k++) {
        let l = p.lights[k];
        let lam = lambert(n, l, recip);
        var w: u32;
        if (aspect) {
            let cross = dx * shr_sym(l.y, 5u) - dy * shr_sym(l.x, 5u);
            w = (((u32(cross * cross)) >> 16u) * u32(l.w)) >> 8u;
        } else {
            w = u32(l.w);
        }
        sum += w * lam;
        wsum += w;
    }
    if (wsum == 0u) {
        sum = 0u;
        for (var k = 0u; k < p.light_count; k++) {
            let l = p.lights[k];
            sum += u32(l.w) * lambert(n, l, recip);
            wsum += u32(l.w);
        }
    }
    return sum / wsum;
}

// shade::Gradient.
struct Gradient {
    g: u32,
    k: u32,
}

fn gradient(gx: i32, gy: i32) -> Gradient {
    let m = max(uabs(gx), uabs(gy));
    let bits = 32u - countLeadingZeros(m);
    let k = select(0u, bits - 15u, bits > 15u);
    let x = shr_sym(gx, k);
    let y = shr_sym(gy, k);
    return Gradient(isqrt(u32(x * x) + u32(y * y)), k);
}

// Gradient::px256_below; 0xFFFFFFFF stands for `None` (a real result is
// below `limit` ≤ 2^13).
const NONE: u32 = 0xFFFFFFFFu;

fn px256_below(g: Gradient, units: u32, limit: u32) -> u32 {
    let u = units >> g.k;
    if (g.g == 0u || u >= (1u << 20u) || (u << 11u) >= limit * g.g) {
        return NONE;
    }
    return (u << 11u) / g.g;
}

// shade::Level.
struct Level {
    level: i32,
    dist: u32,
    index: bool,
    // False where shade::nearest_level returns `None`.
    some: bool,
}

// shade::nearest_level.
fn nearest_level(h: i32) -> Level {
    let interval = i32(p.contour_interval);
    let q = div_floor(h - p.contour_base, interval);
    let below = p.contour_base + q * interval;
    let r = h - below;
    var level = below;
    var k = q;
    if (!(r <= interval - r)) {
        level = below + interval;
        k = q + 1;
    }
    if ((p.flags & F_SEA) != 0u && level == p.contour_base) {
        return Level(0, 0u, false, false);
    }
    let index = p.contour_index_every != 0u && rem_floor(k, i32(p.contour_index_every)) == 0;
    return Level(level, abs_diff(h, level), index, true);
}

// shade::straddles.
fn straddles(lo: i32, hi: i32, level: i32) -> bool {
    return lo < level && level <= hi;
}

// shade::line_coverage.
fn line_coverage(g: Gradient, dist: u32, half_width: u32) -> u32 {
    let reach = half_width + 128u;
    let d = px256_below(g, dist, reach);
    if (d == NONE) {
        return 0u;
    }
    return min(reach - d, FULL);
}

// shade::contour.
fn contour(g: Gradient, l: Level, colour: u32) -> u32 {
    var half_width = p.contour_half_width;
    var line = p.contour_colour;
    if (l.index) {
        half_width = p.index_half_width;
        line = p.index_colour;
    }
    var cov = line_coverage(g, l.dist, half_width);
    if (cov == 0u) {
        return colour;
    }
    if (!l.index && p.contour_min_spacing > 0u) {
        let half = p.contour_min_spacing / 2u;
        var spacing = px256_below(g, p.contour_interval, p.contour_min_spacing);
        if (spacing == NONE) {
            spacing = p.contour_min_spacing;
        }
        let fade = min(select(0u, spacing - half, spacing > half) * FULL / max(half, 1u), FULL);
        cov = (cov * fade) >> 8u;
    }
    return blend(colour, line, (cov * alpha256(line)) >> 8u);
}

// shade::on_grid.
fn on_grid(x: u32, step: u32) -> bool {
    return x > 0u && (x * FULL + FULL - 1u) / step != (x * FULL - 1u) / step;
}

// The heights of the 3×3 neighbourhood read by shade::shade_pixel's `at`.
fn at(xx: u32, yy: u32, h: i32) -> i32 {
    let v = heights[yy * p.width + xx];
    return select(v, h, v == NODATA);
}

// shade::shade_pixel.
fn shade_pixel(x: u32, y: u32) -> u32 {
    let w = p.width;
    let i = y * w + x;
    let h = heights[i];
    if (h == NODATA) {
        return select(p.nodata_hatch, p.nodata_colour, (((x + y) >> 2u) & 1u) == 0u);
    }

    let xw = select(0u, x - 1u, x > 0u);
    let xe = select(x, x + 1u, x + 1u < w);
    let yn = select(0u, y - 1u, y > 0u);
    let ys = select(y, y + 1u, y + 1u < p.height);
    let nw = at(xw, yn, h);
    let n = at(x, yn, h);
    let ne = at(xe, yn, h);
    let we = at(xw, y, h);
    let ea = at(xe, y, h);
    let sw = at(xw, ys, h);
    let s = at(x, ys, h);
    let se = at(xe, ys, h);
    let lo = min(min(min(min(h, nw), min(n, ne)), min(min(we, ea), min(sw, s))), se);
    let hi = max(max(max(max(h, nw), max(n, ne)), max(max(we, ea), max(sw, s))), se);

    var gx = (ne + 2 * ea + se) - (nw + 2 * we + sw);
    var gy = (sw + 2 * s + se) - (nw + 2 * n + ne);
    if (xe - xw == 1u) {
        gx *= 2;
    }
    if (ys - yn == 1u) {
        gy *= 2;
    }
    let sx = slope(gx, p.slope_x_mul, p.slope_x_pre, p.slope_x_post, p.slope_x_clamp);
    let sy = slope(gy, p.slope_y_mul, p.slope_y_pre, p.slope_y_post, p.slope_y_clamp);

    let hs = hillshade(sx, sy);
    let factor = min(p.shade_floor + ((hs * p.shade_gain + (1u << 15u)) >> 16u), p.shade_max);

    let water = (p.flags & F_SEA) != 0u && h <= p.water_level;
    let out_of_range = (p.flags & F_RANGE) != 0u && (h < p.range_lo || h > p.range_hi);
    var colour: u32;
    if (out_of_range) {
        colour = p.range_colour;
    } else if (water) {
        let t = min(bitcast<u32>(p.water_level - h) >> p.water_shift, FULL);
        colour = blend(p.water_shallow, p.water_deep, t);
    } else {
        let d = bitcast<u32>(max(h, p.tint_lo) - p.tint_lo);
        colour = tint[min(d >> p.tint_shift, p.tint_len - 1u)];
    }
    if ((p.flags & F_TYPES) != 0u) {
        let t = (types[i >> 2u] >> ((i & 3u) * 8u)) & 0xffu;
        if (t != NO_TYPE) {
            let c = type_colours[t];
            colour = blend(colour, c, alpha256(c));
        }
    }
    colour = apply_shade(colour, factor);

    var cl = Level(0, 0u, false, false);
    if ((p.flags & F_CONTOURS) != 0u) {
        let sum = 4 * h + 2 * (n + s + we + ea) + (nw + ne + sw + se);
        cl = nearest_level(div_floor(sum, 16));
        if (cl.some && !straddles(lo, hi, cl.level)) {
            cl.some = false;
        }
    }
    let coast = (p.flags & F_SEA) != 0u && straddles(lo, hi, p.water_level + 1);
    if (cl.some || coast) {
        let g = gradient(gx, gy);
        if (cl.some) {
            colour = contour(g, cl, colour);
        }
        if (coast) {
            let cov = line_coverage(g, abs_diff(h, p.water_level + 1), p.coast_half_width);
            colour = blend(colour, p.coast_colour, (cov * alpha256(p.coast_colour)) >> 8u);
        }
    }
    if ((p.flags & F_GRID) != 0u && (on_grid(x, p.grid_step_x) || on_grid(y, p.grid_step_y))) {
        colour = blend(colour, p.grid_colour, alpha256(p.grid_colour));
    }
    return colour | 0xff000000u;
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= p.width || gid.y >= p.height) {
        return;
    }
    out[gid.y * p.width + gid.x] = shade_pixel(gid.x, gid.y);
}
