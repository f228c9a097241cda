// Drawing the controls over the preview, in screen pixels (crisp at any
// zoom): grid, frozen wash, sculpt strokes, pastes, curves with their
// envelope of effect and widgets, junctions, points with their handles,
// and the tools' strokes in progress.

import * as g from './geometry.js';
import * as C from './controls.js';

const COL = {
  line: '#141414',
  halo: 'rgba(255,255,255,0.85)',
  envelope: 'rgba(20,20,20,0.6)',
  widget: '#ffd60a',
  junction: '#e63ce6',
  point: '#00c8ff',
  paste: '#ff7800',
  freeze: 'rgba(120,190,255,1)',
  sculpt: 'rgb(255,170,60)',
  select: '#ffffff',
};

function path(ctx, map, pts, close) {
  ctx.beginPath();
  pts.forEach((p, i) => {
    const q = map.toScreen(p);
    if (i) ctx.lineTo(q[0], q[1]);
    else ctx.moveTo(q[0], q[1]);
  });
  if (close) ctx.closePath();
}

function dot(ctx, q, r, fill, stroke = COL.line) {
  ctx.beginPath();
  ctx.arc(q[0], q[1], r, 0, 2 * Math.PI);
  ctx.fillStyle = fill;
  ctx.fill();
  ctx.lineWidth = 1.5;
  ctx.strokeStyle = stroke;
  ctx.stroke();
}

function diamond(ctx, q, r, fill, selected) {
  ctx.beginPath();
  ctx.moveTo(q[0], q[1] - r);
  ctx.lineTo(q[0] + r, q[1]);
  ctx.lineTo(q[0], q[1] + r);
  ctx.lineTo(q[0] - r, q[1]);
  ctx.closePath();
  ctx.fillStyle = fill;
  ctx.fill();
  ctx.lineWidth = selected ? 2.5 : 1.5;
  ctx.strokeStyle = selected ? COL.select : COL.line;
  ctx.stroke();
}

/** A handle's stem: a light line from its control to the handle. */
function stem(ctx, q, r, width) {
  ctx.beginPath();
  ctx.moveTo(q[0], q[1]);
  ctx.lineTo(r[0], r[1]);
  ctx.lineWidth = width;
  ctx.strokeStyle = COL.halo;
  ctx.stroke();
}

function square(ctx, q, r, fill, selected) {
  ctx.fillStyle = fill;
  ctx.fillRect(q[0] - r, q[1] - r, 2 * r, 2 * r);
  ctx.lineWidth = selected ? 2.5 : 1.5;
  ctx.strokeStyle = selected ? COL.select : COL.line;
  ctx.strokeRect(q[0] - r, q[1] - r, 2 * r, 2 * r);
}

/** A vertical height bar beside screen point q with its knob at `value`. */
export function heightBar(ctx, ed, q, value, range, label) {
  const x = q[0] + C.HEIGHT_BAR.dx;
  ctx.fillStyle = 'rgba(20,20,20,0.75)';
  ctx.fillRect(x - 4, q[1] - C.HEIGHT_BAR.half - 2, 8, 2 * C.HEIGHT_BAR.half + 4);
  const k = C.barKnob(ed, q, value, range);
  ctx.fillStyle = COL.widget;
  ctx.fillRect(x - 7, k[1] - 3, 14, 6);
  ctx.strokeStyle = COL.line;
  ctx.strokeRect(x - 7, k[1] - 3, 14, 6);
  ctx.font = '11px system-ui';
  ctx.fillStyle = '#fff';
  ctx.strokeStyle = 'rgba(0,0,0,0.8)';
  ctx.lineWidth = 3;
  ctx.strokeText(label, x + 11, k[1] + 4);
  ctx.fillText(label, x + 11, k[1] + 4);
}

export function drawGrid(ctx, map, ed) {
  if (!ed.grid || !ed.doc) return;
  const [w, h] = ed.doc.size;
  const step = 2 ** Math.round(Math.log2(Math.max(w, h) / 8));
  ctx.strokeStyle = 'rgba(255,255,255,0.28)';
  ctx.lineWidth = 1;
  ctx.beginPath();
  for (let x = step; x < w; x += step) {
    const a = map.toScreen([x, 0]), b = map.toScreen([x, h]);
    ctx.moveTo(Math.round(a[0]) + 0.5, a[1]);
    ctx.lineTo(Math.round(b[0]) + 0.5, b[1]);
  }
  for (let y = step; y < h; y += step) {
    const a = map.toScreen([0, y]), b = map.toScreen([w, y]);
    ctx.moveTo(a[0], Math.round(a[1]) + 0.5);
    ctx.lineTo(b[0], Math.round(b[1]) + 0.5);
  }
  ctx.stroke();
}

/** Frozen regions: strokes painted in order (erasers cut), as a blue wash. */
export function drawFrozen(ctx, map, ed, layer) {
  const strokes = (ed.doc.freeze && ed.doc.freeze.strokes) || [];
  if (!strokes.length || !ed.handles) return;
  const c = layer;
  const { width, height } = ctx.canvas;
  if (c.width !== width || c.height !== height) {
    c.width = width;
    c.height = height;
  }
  const x = c.getContext('2d');
  x.setTransform(ctx.getTransform());
  x.clearRect(0, 0, width, height);
  x.lineCap = 'round';
  x.lineJoin = 'round';
  for (const s of strokes) {
    x.globalCompositeOperation = s.erase ? 'destination-out' : 'source-over';
    x.strokeStyle = x.fillStyle = COL.freeze;
    x.lineWidth = 2 * s.radius_px * map.s;
    if (s.points.length === 1) {
      const q = map.toScreen(s.points[0]);
      x.beginPath();
      x.arc(q[0], q[1], s.radius_px * map.s, 0, 2 * Math.PI);
      x.fill();
    } else {
      path(x, map, s.points, false);
      x.stroke();
    }
  }
  ctx.save();
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.globalAlpha = 0.33;
  ctx.drawImage(c, 0, 0);
  ctx.restore();
}

/**
 * Sculpt strokes after painting: each one's footprint (as wide as its
 * brush, faint) and its path, so a stroke can be found, picked and
 * deleted like any other control.
 */
export function drawSculpt(ctx, map, ed, sel) {
  ctx.lineCap = 'round';
  ctx.lineJoin = 'round';
  (ed.doc.sculpt || []).forEach((st, i) => {
    const selected = sel && sel.kind === 'sculpt' && sel.index === i;
    const pts = st.points.length > 1 ? st.points : [st.points[0], st.points[0]];
    path(ctx, map, pts, false);
    ctx.globalAlpha = selected ? 0.35 : 0.18;
    ctx.strokeStyle = COL.sculpt;
    ctx.lineWidth = 2 * st.radius_px * map.s;
    ctx.stroke();
    ctx.globalAlpha = 1;
    ctx.lineWidth = selected ? 3 : 1.5;
    ctx.strokeStyle = selected ? COL.select : COL.sculpt;
    ctx.stroke();
  });
}

export function drawPastes(ctx, map, ed, sel) {
  (ed.doc.pastes || []).forEach((p, i) => {
    const c = g.centroid(p.lasso);
    const off = [Math.round(p.to[0] - c[0]), Math.round(p.to[1] - c[1])];
    const pts = p.lasso.map((q) => g.add(q, off));
    path(ctx, map, pts, true);
    ctx.lineWidth = sel && sel.kind === 'paste' && sel.index === i ? 3 : 2;
    ctx.strokeStyle = COL.paste;
    ctx.stroke();
    if (p.source === 'terrain') {
      path(ctx, map, p.lasso, true);
      ctx.setLineDash([4, 4]);
      ctx.lineWidth = 1;
      ctx.stroke();
      ctx.setLineDash([]);
    }
  });
}

export function drawCurves(ctx, map, ed, sel) {
  (ed.doc.curves || []).forEach((c, i) => {
    const b = C.builtCurve(ed, c, i);
    const selected = sel && sel.kind === 'curve' && sel.index === i;
    if (b) {
      for (const loop of b.envelope) {
        path(ctx, map, loop, true);
        ctx.lineWidth = 1;
        ctx.strokeStyle = COL.envelope;
        ctx.setLineDash(selected ? [] : [5, 4]);
        ctx.stroke();
        ctx.setLineDash([]);
      }
    }
    const line = b ? b.line : c.points;
    path(ctx, map, line, false);
    ctx.lineCap = 'round';
    ctx.lineJoin = 'round';
    ctx.lineWidth = selected ? 6 : 4;
    ctx.strokeStyle = COL.halo;
    ctx.stroke();
    ctx.lineWidth = 2;
    ctx.strokeStyle = COL.line;
    ctx.stroke();
    c.widgets.forEach((w, k) => {
      const f = C.widgetFrame(ed, c, i, w);
      const q = map.toScreen(f.at);
      const wsel = selected && sel.widget === k;
      if (wsel) {
        for (const [side, sign] of [[0, 1], [1, -1]]) {
          const r = map.toScreen(g.add(f.at, g.scale(f.left, sign * w.reach_px[side])));
          stem(ctx, q, r, 1.5);
          square(ctx, r, 5, side === 0 ? '#9fe870' : '#70c8e8', false);
        }
        heightBar(ctx, ed, q, w.height_m, C.barRange(ed), `${Math.round(w.height_m)} m`);
      }
      diamond(ctx, q, wsel ? 9 : 7, COL.widget, wsel);
    });
  });
  for (const [k, j] of ((ed.frame && ed.frame.overlay.junctions) || []).entries()) {
    const q = map.toScreen(j.at);
    const jsel = sel && sel.kind === 'junction' && sel.index === k;
    square(ctx, q, jsel ? 7 : 5, COL.junction, jsel);
    if (jsel) {
      const e = C.junctionEntry(ed.doc, j.at);
      const h = e >= 0 ? ed.doc.junctions[e].height_m : j.height_m;
      heightBar(ctx, ed, q, h, C.barRange(ed), `${Math.round(h)} m`);
    }
  }
}

export function drawPoints(ctx, map, ed, sel) {
  (ed.doc.points || []).forEach((p, i) => {
    const q = map.toScreen(p.at);
    const selected = sel && sel.kind === 'point' && sel.index === i;
    ctx.beginPath();
    ctx.arc(q[0], q[1], p.radius_px * map.s, 0, 2 * Math.PI);
    ctx.lineWidth = selected ? 2.5 : 1.5;
    ctx.strokeStyle = COL.point;
    ctx.stroke();
    if (selected) {
      const t = map.toScreen(C.slopeTip(p));
      stem(ctx, q, t, 2);
      // The arrow points downhill.
      const a = Math.atan2(t[1] - q[1], t[0] - q[0]);
      ctx.beginPath();
      ctx.moveTo(t[0] + 8 * Math.cos(a), t[1] + 8 * Math.sin(a));
      ctx.lineTo(t[0] + 7 * Math.cos(a + 2.3), t[1] + 7 * Math.sin(a + 2.3));
      ctx.lineTo(t[0] + 7 * Math.cos(a - 2.3), t[1] + 7 * Math.sin(a - 2.3));
      ctx.closePath();
      ctx.fillStyle = COL.widget;
      ctx.fill();
      ctx.strokeStyle = COL.line;
      ctx.lineWidth = 1;
      ctx.stroke();
      heightBar(ctx, ed, q, p.height_m, C.barRange(ed), `${Math.round(p.height_m)} m`);
    }
    dot(ctx, q, selected ? 6 : 4.5, COL.point, selected ? COL.select : COL.line);
  });
}

/** A stroke in progress: a brush trail, a curve sketch or a lasso. */
export function drawStroke(ctx, map, stroke) {
  if (!stroke || stroke.points.length === 0) return;
  ctx.lineCap = 'round';
  ctx.lineJoin = 'round';
  if (stroke.radius) {
    ctx.globalAlpha = 0.45;
    ctx.strokeStyle = ctx.fillStyle = stroke.colour;
    ctx.lineWidth = 2 * stroke.radius * map.s;
    path(ctx, map, stroke.points.length > 1 ? stroke.points : [stroke.points[0], stroke.points[0]], false);
    ctx.stroke();
    ctx.globalAlpha = 1;
    return;
  }
  path(ctx, map, stroke.points, stroke.closed);
  ctx.lineWidth = 3;
  ctx.strokeStyle = stroke.colour;
  ctx.setLineDash(stroke.closed ? [6, 4] : []);
  ctx.stroke();
  ctx.setLineDash([]);
}

/** A paste not yet applied: the source pixels at their destination. */
export function drawPending(ctx, map, ed, p) {
  if (!p) return;
  const c = g.centroid(p.lasso);
  const off = [Math.round(p.to[0] - c[0]), Math.round(p.to[1] - c[1])];
  const pts = p.lasso.map((q) => g.add(q, off));
  if (p.image) {
    ctx.save();
    path(ctx, map, pts, true);
    ctx.clip();
    const o = map.toScreen(off);
    const sx = p.imageScale || 1;
    ctx.globalAlpha = 0.9;
    ctx.drawImage(p.image, o[0], o[1], (p.image.width / sx) * map.s, (p.image.height / sx) * map.s);
    ctx.restore();
  }
  path(ctx, map, pts, true);
  ctx.lineWidth = 2;
  ctx.strokeStyle = COL.paste;
  ctx.setLineDash([6, 4]);
  ctx.stroke();
  ctx.setLineDash([]);
  const q = map.toScreen(p.to);
  dot(ctx, q, 8, 'rgba(255,120,0,0.9)', '#fff');
  ctx.beginPath();
  ctx.moveTo(q[0] - 5, q[1]);
  ctx.lineTo(q[0] + 5, q[1]);
  ctx.moveTo(q[0], q[1] - 5);
  ctx.lineTo(q[0], q[1] + 5);
  ctx.strokeStyle = '#fff';
  ctx.lineWidth = 1.5;
  ctx.stroke();
  const r = ed.range().relief;
  heightBar(ctx, ed, q, p.delta_m, { lo: -r / 2, hi: r / 2 }, `δ ${Math.round(p.delta_m)} m`);
}

export function drawBrush(ctx, map, at, radius) {
  if (!at || !radius) return;
  const q = map.toScreen(at);
  ctx.beginPath();
  ctx.arc(q[0], q[1], radius * map.s, 0, 2 * Math.PI);
  ctx.lineWidth = 1.5;
  ctx.strokeStyle = 'rgba(255,255,255,0.9)';
  ctx.stroke();
}
