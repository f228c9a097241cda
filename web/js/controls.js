// The scene document's controls as the tools see them: defaults for new
// ones (presets), lookups by id, and the handles' hit areas. Positions are
// terrain pixels; the height bar lives in screen pixels beside its object.

import * as g from './geometry.js';

export const HEIGHT_BAR = { dx: 22, half: 45 };

// Presets, one line each (`rise` and `crest` in exemplar reliefs, `reach`
// in terrain sides; a side's slope runs from the crest down or up to the
// terrain's own height at the reach, never past it, so nothing digs a moat):
//  peak      raises the ground under it by a fifth of the relief, never lowers it
//  basin     lowers the ground under it by a fifth of the relief, never raises it
//  flatten   pins the ground's height where it is
//  ridge     a crest 5 % above the highest ground under the stroke; sides fall to the ground
//  valley    a floor 5 % below the lowest ground under the stroke; sides climb to the ground
//  cliff     the ground's mean height, level on the left, dropping steeply on the right
//  flat      the ground's mean height, level both sides (a road, a terrace)
export const POINT_PRESETS = {
  peak: { label: 'Peak (raise)', rise: 0.2 },
  basin: { label: 'Basin (lower)', rise: -0.2 },
  flatten: { label: 'Pin height (flat)', rise: 0 },
};

// `sides`: per side, the sign the slope may take (−1 falls away from the
// crest, +1 climbs, 0 level).
export const CURVE_PRESETS = {
  ridge: { label: 'Ridge', crest: 0.05, sides: [-1, -1], reach: [0.06, 0.06] },
  valley: { label: 'Valley / canyon', crest: -0.05, sides: [1, 1], reach: [0.05, 0.05] },
  cliff: { label: 'Cliff top (drops right)', crest: 0, sides: [0, -1], reach: [0.03, 0.04] },
  flat: { label: 'Road / terrace (flat)', crest: 0, sides: [0, 0], reach: [0.02, 0.02] },
};

/** A key no other item of the document uses ("point-3"). */
export function newId(doc, prefix) {
  const used = new Set();
  for (const list of [doc.points, doc.curves, doc.pastes]) {
    (list || []).forEach((item, i) => used.add(item.id || `${list === doc.points ? 'points' : list === doc.curves ? 'curves' : 'pastes'}[${i}]`));
  }
  for (let n = 1; ; n++) if (!used.has(`${prefix}-${n}`)) return `${prefix}-${n}`;
}

/** An item's id as the server names it (its default when it has none). */
export const pointKey = (p, i) => p.id || `points[${i}]`;
export const curveKey = (c, i) => c.id || `curves[${i}]`;

export const clampHeight = (h) => Math.max(-20000, Math.min(20000, h));
export const round = (v, k = 10) => Math.round(v * k) / k;

/** The heights the height bar spans: the exemplars' range and a quarter more each way. */
export function barRange(ed) {
  const { lo, hi, relief } = ed.range();
  return { lo: lo - 0.25 * relief, hi: hi + 0.25 * relief };
}

/** Screen position of a height bar's knob beside screen point q. */
export function barKnob(ed, q, value, range) {
  const f = (value - range.lo) / (range.hi - range.lo);
  const y = q[1] + HEIGHT_BAR.half - 2 * HEIGHT_BAR.half * Math.max(0, Math.min(1, f));
  return [q[0] + HEIGHT_BAR.dx, y];
}

/** The value a height bar beside q gives at screen y. */
export function barValue(q, y, range) {
  const f = (q[1] + HEIGHT_BAR.half - y) / (2 * HEIGHT_BAR.half);
  return range.lo + Math.max(0, Math.min(1, f)) * (range.hi - range.lo);
}

/** Where a point's slope handle sits (a quarter radius out at 0°, the ring at 80°). */
export function slopeTip(p) {
  const a = (p.slope_direction_deg || 0) * Math.PI / 180;
  const L = p.radius_px * (0.25 + 0.75 * (p.slope_deg || 0) / 80);
  return [p.at[0] + L * Math.cos(a), p.at[1] + L * Math.sin(a)];
}

/** The slope and direction a slope handle at `q` gives. */
export function slopeFrom(p, q) {
  const v = g.sub(q, p.at);
  const len = Math.hypot(v[0], v[1]);
  const slope = Math.max(0, Math.min(80, ((len / p.radius_px - 0.25) / 0.75) * 80));
  const dir = (Math.atan2(v[1], v[0]) * 180) / Math.PI;
  return { slope_deg: round(slope), slope_direction_deg: round(dir) };
}

/** The server's built curve for a document curve, if the last frame has it. */
export function builtCurve(ed, c, i) {
  const o = ed.frame && ed.frame.overlay;
  if (!o) return null;
  return o.curves.find((b) => b.id === curveKey(c, i)) || null;
}

/** A widget's position and left normal: on the built curve when there is one. */
export function widgetFrame(ed, c, i, w) {
  const b = builtCurve(ed, c, i);
  const line = b ? b.line : c.points;
  const p = g.pointAt(line, w.at);
  const q = g.pointAt(line, Math.min(1, w.at + 0.01));
  const r = g.pointAt(line, Math.max(0, w.at - 0.01));
  let d = g.sub(q, r);
  const n = Math.hypot(d[0], d[1]) || 1;
  d = [d[0] / n, d[1] / n];
  return { at: p, left: [d[1], -d[0]] };
}

/** Target heights along a stroke's samples, for presets. */
function sampled(ed, pts) {
  const hs = pts.map((p) => ed.heightAt(p)).filter((h) => h != null);
  if (!hs.length) {
    const { lo, hi } = ed.range();
    return [(lo + hi) / 2];
  }
  return hs;
}

/** Keeps a preset's height inside the exemplars' range (red means outside). */
function inRange(ed, h) {
  const { lo, hi, relief } = ed.range();
  return Math.max(lo + 0.03 * relief, Math.min(hi - 0.03 * relief, h));
}

export function newPoint(ed, doc, at, preset) {
  const { relief } = ed.range();
  const h0 = ed.heightAt(at) ?? (ed.range().lo + relief / 2);
  const side = Math.max(doc.size[0], doc.size[1]);
  const rise = POINT_PRESETS[preset].rise;
  // Kept in range, but never the other way: a basin on low ground lowers
  // it (or leaves it), it does not raise it to the range's floor.
  const h = inRange(ed, h0 + rise * relief);
  return {
    id: newId(doc, 'point'),
    at: g.r1p(at),
    height_m: round(rise < 0 ? Math.min(h0, h) : rise > 0 ? Math.max(h0, h) : h),
    slope_deg: 0,
    slope_direction_deg: 0,
    radius_px: round(Math.max(4, side * 0.06)),
  };
}

/**
 * The mean ground height at `reach` px to each side of a stroke (side 0 on
 * the left, as the curve's widgets count them), or null where the map has
 * no heights yet.
 */
function groundBeside(ed, pts, reach) {
  const sums = [[0, 0], [0, 0]];
  for (let i = 0; i < pts.length; i++) {
    const a = pts[Math.max(0, i - 1)], b = pts[Math.min(pts.length - 1, i + 1)];
    const d = g.sub(b, a), n = Math.hypot(d[0], d[1]);
    if (!n) continue;
    const left = [d[1] / n, -d[0] / n];
    for (const side of [0, 1]) {
      const h = ed.heightAt(g.add(pts[i], g.scale(left, (side === 0 ? 1 : -1) * reach[side])));
      if (h != null) sums[side] = [sums[side][0] + h, sums[side][1] + 1];
    }
  }
  return sums.map(([s, k]) => (k ? s / k : null));
}

export function newCurve(ed, doc, pts, preset) {
  const P = CURVE_PRESETS[preset];
  const hs = sampled(ed, pts);
  const { relief } = ed.range();
  const mean = hs.reduce((a, b) => a + b, 0) / hs.length;
  const crest = P.crest > 0 ? Math.max(...hs) : P.crest < 0 ? Math.min(...hs) : mean;
  const h = round(inRange(ed, crest + P.crest * relief));
  const side = Math.max(doc.size[0], doc.size[1]);
  const reach = P.reach.map((f) => round(Math.min(4096, Math.max(4, side * f))));
  // Each side's slope meets the ground at the reach (issue 43: fixed −30°
  // sides dug moats up to 1 km deep beside a ridge).
  const ground = groundBeside(ed, pts, reach);
  const slope = P.sides.map((sign, k) => {
    if (sign === 0 || ground[k] == null) return 0;
    const deg = (Math.atan((ground[k] - h) / (reach[k] * ed.cell())) * 180) / Math.PI;
    return round(sign < 0 ? Math.min(0, deg) : Math.max(0, deg));
  });
  return {
    id: newId(doc, 'curve'),
    points: pts.map(g.r1p),
    smoothing: 2,
    widgets: [{ at: 0.5, height_m: h, slope_deg: slope, reach_px: reach }],
  };
}

/** The junction override (doc.junctions entry) within 4 px of `at`. */
export function junctionEntry(doc, at) {
  return (doc.junctions || []).findIndex((j) => g.dist(j.at, at) <= 4);
}
