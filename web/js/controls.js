// The scene document's controls as the tools see them: defaults for new
// ones (presets), lookups by id, and the handles' hit areas. Positions are
// terrain pixels; the height bar lives in screen pixels beside its object.

import * as g from './geometry.js';

export const HEIGHT_BAR = { dx: 22, half: 45 };

export const POINT_PRESETS = {
  peak: { label: 'Peak (raise)', rise: 0.2 },
  basin: { label: 'Basin (lower)', rise: -0.2 },
  flatten: { label: 'Pin height (flat)', rise: 0 },
};

export const CURVE_PRESETS = {
  ridge: { label: 'Ridge', slope: [-30, -30], reach: [0.06, 0.06] },
  valley: { label: 'Valley / canyon', slope: [25, 25], reach: [0.05, 0.05] },
  cliff: { label: 'Cliff top (drops right)', slope: [0, -60], reach: [0.03, 0.04] },
  flat: { label: 'Road / terrace (flat)', slope: [0, 0], reach: [0.02, 0.02] },
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
  return {
    id: newId(doc, 'point'),
    at: g.r1p(at),
    height_m: round(inRange(ed, h0 + POINT_PRESETS[preset].rise * relief)),
    slope_deg: 0,
    slope_direction_deg: 0,
    radius_px: round(Math.max(4, side * 0.06)),
  };
}

export function newCurve(ed, doc, pts, preset) {
  const P = CURVE_PRESETS[preset];
  const hs = sampled(ed, pts);
  const { relief } = ed.range();
  const mean = hs.reduce((a, b) => a + b, 0) / hs.length;
  const h = preset === 'ridge' ? Math.max(...hs) + 0.05 * relief : preset === 'valley' ? Math.min(...hs) - 0.05 * relief : mean;
  const side = Math.max(doc.size[0], doc.size[1]);
  return {
    id: newId(doc, 'curve'),
    points: pts.map(g.r1p),
    smoothing: 2,
    widgets: [{
      at: 0.5,
      height_m: round(inRange(ed, h)),
      slope_deg: P.slope.slice(),
      reach_px: P.reach.map((f) => round(Math.min(4096, Math.max(4, side * f)))),
    }],
  };
}

/** The junction override (doc.junctions entry) within 4 px of `at`. */
export function junctionEntry(doc, at) {
  return (doc.junctions || []).findIndex((j) => g.dist(j.at, at) <= 4);
}
