// Plane geometry on [x, y] pairs (terrain pixels, y down).

export const sub = (a, b) => [a[0] - b[0], a[1] - b[1]];
export const add = (a, b) => [a[0] + b[0], a[1] + b[1]];
export const scale = (a, k) => [a[0] * k, a[1] * k];
export const dot = (a, b) => a[0] * b[0] + a[1] * b[1];
export const dist = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1]);

/** Closest point of segment a–b to p: {point, t, d}. */
export function onSegment(p, a, b) {
  const d = sub(b, a);
  const len2 = dot(d, d);
  const t = len2 > 0 ? Math.min(1, Math.max(0, dot(sub(p, a), d) / len2)) : 0;
  const point = add(a, scale(d, t));
  return { point, t, d: dist(p, point) };
}

/** Cumulative arc length of a polyline. */
export function arcLengths(pts) {
  const cum = [0];
  for (let i = 1; i < pts.length; i++) cum.push(cum[i - 1] + dist(pts[i - 1], pts[i]));
  return cum;
}

/**
 * Closest point of a polyline to p: {point, d, index (segment), t,
 * s (arc length), frac (of the total length)}.
 */
export function onPolyline(p, pts) {
  const cum = arcLengths(pts);
  const total = cum[cum.length - 1] || 1;
  let best = { point: pts[0], d: dist(p, pts[0]), index: 0, t: 0, s: 0 };
  for (let i = 0; i + 1 < pts.length; i++) {
    const h = onSegment(p, pts[i], pts[i + 1]);
    if (h.d < best.d) {
      best = { point: h.point, d: h.d, index: i, t: h.t, s: cum[i] + h.t * (cum[i + 1] - cum[i]) };
    }
  }
  best.frac = Math.min(1, Math.max(0, best.s / total));
  return best;
}

/** The point at fraction f of a polyline's arc length. */
export function pointAt(pts, f) {
  const cum = arcLengths(pts);
  const s = f * cum[cum.length - 1];
  for (let i = 0; i + 1 < pts.length; i++) {
    if (s <= cum[i + 1] || i + 2 === pts.length) {
      const seg = cum[i + 1] - cum[i];
      const t = seg > 0 ? Math.min(1, Math.max(0, (s - cum[i]) / seg)) : 0;
      return add(pts[i], scale(sub(pts[i + 1], pts[i]), t));
    }
  }
  return pts[0];
}

/** Area centroid (vertex mean without area), as the server computes it. */
export function centroid(pts) {
  let a = 0, cx = 0, cy = 0;
  const n = pts.length;
  for (let k = 0; k < n; k++) {
    const p = pts[k], q = pts[(k + 1) % n];
    const c = p[0] * q[1] - p[1] * q[0];
    a += c;
    cx += (p[0] + q[0]) * c;
    cy += (p[1] + q[1]) * c;
  }
  if (Math.abs(a) < 1e-9) {
    return [pts.reduce((s, p) => s + p[0], 0) / n, pts.reduce((s, p) => s + p[1], 0) / n];
  }
  return [cx / (3 * a), cy / (3 * a)];
}

/** Even-odd point in polygon. */
export function inside(poly, p) {
  let odd = false;
  for (let i = 0, j = poly.length - 1; i < poly.length; j = i++) {
    const a = poly[i], b = poly[j];
    if ((a[1] > p[1]) !== (b[1] > p[1]) && p[0] < a[0] + ((p[1] - a[1]) * (b[0] - a[0])) / (b[1] - a[1])) {
      odd = !odd;
    }
  }
  return odd;
}

/** Drops points closer than `step` to the last kept one (keeps the last). */
export function thin(pts, step) {
  if (pts.length < 2) return pts.slice();
  const out = [pts[0]];
  for (let i = 1; i < pts.length - 1; i++) {
    if (dist(pts[i], out[out.length - 1]) >= step) out.push(pts[i]);
  }
  const last = pts[pts.length - 1];
  if (dist(last, out[out.length - 1]) > 0 || out.length === 1) out.push(last);
  return out;
}

/** Rounds to 0.1 px (scene files stay readable). */
export const r1 = (v) => Math.round(v * 10) / 10;
export const r1p = (p) => [r1(p[0]), r1(p[1])];

/**
 * Over-sketching (paper §3): a stroke that starts and/or ends near an
 * existing polyline reshapes it. Returns the new polyline, or null when the
 * stroke touches it at neither end. `near` is in terrain pixels.
 * - both ends near: the part between them is replaced by the stroke;
 * - start near the last point (end near the first): the stroke extends it;
 * - one end near an inside point: the polyline is cut there and continues
 *   along the stroke.
 */
export function overSketch(pts, stroke, near) {
  if (stroke.length < 2) return null;
  const a = onPolyline(stroke[0], pts);
  const b = onPolyline(stroke[stroke.length - 1], pts);
  const pos = (h) => h.index + h.t; // position along the vertex list
  const before = (h) => pts.slice(0, h.index + 1).concat([h.point]);
  const after = (h) => [h.point].concat(pts.slice(h.index + 1));
  const last = pts.length - 1;
  const atEnd = (h) => pos(h) >= last - 1e-9 || dist(h.point, pts[last]) < near * 0.5;
  const atStart = (h) => pos(h) <= 1e-9 || dist(h.point, pts[0]) < near * 0.5;
  const aNear = a.d <= near, bNear = b.d <= near;
  if (aNear && bNear) {
    if (Math.abs(pos(a) - pos(b)) < 1e-6) return null;
    const [lo, hi, s] = pos(a) < pos(b) ? [a, b, stroke] : [b, a, stroke.slice().reverse()];
    return dedupe(before(lo).concat(s, after(hi)));
  }
  if (aNear) {
    if (atStart(a) && !atEnd(a)) return dedupe(stroke.slice().reverse().concat(pts));
    return dedupe(before(a).concat(stroke));
  }
  if (bNear) {
    if (atEnd(b) && !atStart(b)) return dedupe(pts.concat(stroke.slice().reverse()));
    return dedupe(stroke.concat(after(b)));
  }
  return null;
}

function dedupe(pts) {
  const out = [];
  for (const p of pts) if (!out.length || dist(p, out[out.length - 1]) > 0.05) out.push(p);
  return out;
}
