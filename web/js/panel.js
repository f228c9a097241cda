// The side panel: the active tool's options (presets, the type palette,
// brush sizes, the paste source) and the selected control's values, as
// numbers and as a cross-section whose knobs can be dragged (height and
// slope; the map's handles do position and reach). A value changed here is
// one undo step, like a drag on the map.

import * as g from './geometry.js';
import * as C from './controls.js';

const h = (tag, attrs = {}, ...kids) => {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k.startsWith('on')) e.addEventListener(k.slice(2), v);
    else if (k === 'class') e.className = v;
    else e.setAttribute(k, v);
  }
  for (const k of kids) e.append(k);
  return e;
};

export class Panel {
  constructor(ed) {
    this.ed = ed;
    this.optsEl = document.getElementById('tool-options');
    this.inspEl = document.getElementById('inspector');
    this.key = null;
    this.fields = [];
    this.profile = null;
    this.exemplarImages = {};
  }

  refresh() {
    const ed = this.ed, t = ed.tools;
    if (!t) return;
    const s = t.sel;
    // The controls' counts are in the key: the Scene summary shows them
    // (issue 43: it said "0 freeze strokes" after three).
    const n = (list) => (list || []).length;
    const counts = [ed.doc.points, ed.doc.curves, ed.doc.pastes, ed.doc.types && ed.doc.types.strokes, ed.doc.freeze && ed.doc.freeze.strokes, ed.doc.sculpt].map(n);
    const key = JSON.stringify([t.tool, s, !!t.pending, t.opts, ed.doc.size, (ed.frame && ed.frame.overlay.junctions.length) || 0, counts]);
    if (key !== this.key) {
      this.key = key;
      this.build();
    } else {
      this.update();
    }
  }

  update() {
    for (const f of this.fields) {
      if (document.activeElement !== f.input) {
        const v = f.get();
        f.input.value = v == null ? '' : typeof v === 'number' ? String(C.round(v, 100)) : v;
      }
    }
    if (this.profile) this.profile.draw();
  }

  /**
   * A number field bound to a getter and a setter: one undo step per
   * change, or (`send` false) only a redraw.
   */
  num(label, get, set, { step = 1, min, max, kind = 'edit', send = true } = {}) {
    const input = h('input', { type: 'number', step: String(step) });
    if (min != null) input.min = String(min);
    if (max != null) input.max = String(max);
    input.addEventListener('change', () => {
      const v = Number(input.value);
      if (!Number.isFinite(v)) return;
      if (send) this.ed.change(() => set(v), { kind });
      else {
        set(v);
        this.ed.map.redraw();
      }
    });
    const f = { input, get };
    this.fields.push(f);
    input.value = String(C.round(get(), 100));
    return h('div', { class: 'row' }, h('label', {}, label), input);
  }

  build() {
    this.fields = [];
    this.profile = null;
    this.optsEl.replaceChildren(...this.toolOptions());
    this.inspEl.replaceChildren(...this.inspector());
    this.update();
  }

  toolOptions() {
    const ed = this.ed, t = ed.tools, o = t.opts;
    const select = (options, value, onchange) => {
      const s = h('select', { onchange: () => onchange(s.value) });
      for (const [k, v] of Object.entries(options)) s.append(h('option', { value: k }, v.label || v));
      s.value = value;
      return s;
    };
    const size = Math.max(...ed.doc.size);
    const radius = (key) => {
      const r = h('input', { type: 'range', min: '1', max: String(Math.max(8, Math.round(size / 4))), value: String(o[key]) });
      const out = h('span', {}, `${o[key]} px`);
      r.addEventListener('input', () => {
        o[key] = Number(r.value);
        out.textContent = `${o[key]} px`;
        ed.map.redraw();
      });
      return h('div', { class: 'row' }, h('label', {}, 'brush radius'), r, out);
    };
    switch (t.tool) {
      case 'point':
        return [h('h3', {}, 'Point'), h('div', { class: 'row' }, h('label', {}, 'new points'), select(C.POINT_PRESETS, o.pointPreset, (v) => (o.pointPreset = v))),
          h('p', { class: 'note' }, 'Click to place; drag the centre to move, the ring for the radius, the arrow for slope (downhill) and direction, the bar for height.')];
      case 'curve':
        return [h('h3', {}, 'Curve'), h('div', { class: 'row' }, h('label', {}, 'new curves'), select(C.CURVE_PRESETS, o.curvePreset, (v) => (o.curvePreset = v))),
          h('p', { class: 'note' }, 'Sketch a stroke. Start or end a stroke on a curve to reshape it (over-sketch). Shift+click a curve to add a widget; drag widgets along it, their squares for reach, the bar for height.')];
      case 'types': {
        const pal = h('div', { class: 'palette' });
        ed.info.database.types.forEach((ty, i) => {
          pal.append(h('button', { class: o.type === i ? 'active' : '', onclick: () => { o.type = i; this.refresh(); } },
            h('span', { class: 'swatch', style: `background: rgb(${ty.colour.join(',')})` }), ty.name));
        });
        pal.append(h('button', { class: o.type === 'erase' ? 'active' : '', onclick: () => { o.type = 'erase'; this.refresh(); } },
          h('span', { class: 'swatch', style: 'background: repeating-linear-gradient(45deg,#fff 0 3px,#888 3px 6px)' }), 'eraser'));
        return [h('h3', {}, 'Terrain types'), pal, radius('typeRadius'),
          h('p', { class: 'note' }, 'Paint where the synthesis draws from exemplar regions of this type ([ and ] resize the brush).')];
      }
      case 'freeze':
        return [h('h3', {}, 'Freeze'), h('div', { class: 'row' }, h('label', {}, 'brush'),
          select({ freeze: 'freeze (lock)', thaw: 'thaw (unlock)' }, o.thaw ? 'thaw' : 'freeze', (v) => { o.thaw = v === 'thaw'; })),
        radius('freezeRadius'), h('p', { class: 'note' }, 'Frozen terrain (blue) keeps its exact heights through later edits.')];
      case 'sculpt':
        return this.sculptOptions(select, radius);
      case 'lasso':
        return this.pasteOptions();
      default:
        return [];
    }
  }

  /** The sculpt brushes: which one, its radius, strength and falloff. */
  sculptOptions(select, radius) {
    const ed = this.ed, o = ed.tools.opts;
    const metres = ['raise', 'lower'].includes(o.brush);
    const slider = (label, min, max, step, get, set, unit) => {
      const r = h('input', { type: 'range', min: String(min), max: String(max), step: String(step), value: String(get()) });
      r.dataset.option = label;
      const out = h('span', {}, `${get()}${unit}`);
      r.addEventListener('input', () => {
        set(Number(r.value));
        out.textContent = `${get()}${unit}`;
      });
      return h('div', { class: 'row' }, h('label', {}, label), r, out);
    };
    const relief = Math.max(10, Math.round(ed.range().relief / 2));
    const brush = select({ raise: 'raise', lower: 'lower', smooth: 'smooth', flatten: 'flatten', erode: 'erode' }, o.brush, (v) => {
      o.brush = v;
      this.refresh();
    });
    brush.id = 'sculpt-brush';
    return [h('h3', {}, 'Sculpt'), h('div', { class: 'row' }, h('label', {}, 'brush'), brush), radius('sculptRadius'),
      metres
        ? slider('strength', 1, relief, 1, () => o.strength[o.brush], (v) => (o.strength[o.brush] = v), ' m')
        : slider('strength', 0.05, 1, 0.05, () => o.strength[o.brush], (v) => (o.strength[o.brush] = v), ''),
      slider('falloff', 0, 1, 0.05, () => o.falloff, (v) => (o.falloff = v), ''),
      h('p', { class: 'note' }, 'Paint a stroke: raise/lower by metres, smooth, flatten (to the height where the stroke starts) or erode. The stroke becomes a low-frequency target; the synthesis keeps the exemplar\'s texture on it.')];
  }

  pasteOptions() {
    const ed = this.ed, t = ed.tools, o = t.opts;
    const out = [h('h3', {}, 'Copy-paste')];
    const src = h('select', {
      onchange: () => {
        o.pasteSource = src.value;
        t.pending = null;
        this.refresh();
        ed.map.redraw();
      },
    }, h('option', { value: 'terrain' }, 'this terrain'));
    ed.info.database.exemplars.forEach((e) => src.append(h('option', { value: String(e.index) }, `exemplar: ${e.name}`)));
    src.value = String(o.pasteSource);
    out.push(h('div', { class: 'row' }, h('label', {}, 'copy from'), src));
    if (o.pasteSource !== 'terrain') out.push(this.exemplarCanvas(Number(o.pasteSource)));
    if (t.pending) {
      const P = t.pending;
      // These move the outline only: the button applies the paste.
      const only = { send: false };
      out.push(
        this.num('to x', () => P.to[0], (v) => (P.to[0] = v), only),
        this.num('to y', () => P.to[1], (v) => (P.to[1] = v), only),
        this.num('δ above the ground (m)', () => P.delta_m, (v) => (P.delta_m = v), only),
        h('div', { class: 'buttons' }, h('button', { id: 'apply-paste', onclick: () => t.applyPaste() }, 'Paste (Enter)'), h('button', { onclick: () => t.cancel() }, 'Cancel (Esc)')),
      );
    } else {
      out.push(h('p', { class: 'note' }, o.pasteSource === 'terrain'
        ? 'Draw a loop on the map, then drag its centre to move it and its bar to raise or lower it; Enter pastes.'
        : 'Draw a loop on the exemplar above, then place it on the map; Enter pastes.'));
    }
    return out;
  }

  /** An exemplar's relief, to draw a lasso on. */
  exemplarCanvas(i) {
    const ed = this.ed, t = ed.tools;
    const ex = ed.info.database.exemplars[i];
    const c = h('canvas', { class: 'exemplar', width: String(ex.size[0]), height: String(ex.size[1]) });
    const ctx = c.getContext('2d');
    let img = this.exemplarImages[i];
    let pts = null;
    const draw = () => {
      if (img) ctx.drawImage(img, 0, 0);
      // The loop being drawn, else the one waiting to be pasted.
      const P = t.pending;
      const loop = pts || (P && P.source === 'exemplar' && P.exemplar === i ? P.lasso : null);
      if (loop && loop.length > 1) {
        ctx.beginPath();
        loop.forEach((p, k) => (k ? ctx.lineTo(p[0], p[1]) : ctx.moveTo(p[0], p[1])));
        ctx.closePath();
        ctx.lineWidth = 3;
        ctx.strokeStyle = '#ff7800';
        ctx.stroke();
      }
    };
    if (!img) {
      fetch(`/api/exemplars/${i}/preview.png`).then((r) => r.blob()).then(createImageBitmap).then((b) => {
        img = this.exemplarImages[i] = b;
        draw();
      }).catch((e) => ed.error(e));
    } else {
      draw();
    }
    const at = (e) => {
      const r = c.getBoundingClientRect();
      return [((e.clientX - r.left) / r.width) * ex.size[0], ((e.clientY - r.top) / r.height) * ex.size[1]];
    };
    c.addEventListener('pointerdown', (e) => {
      c.setPointerCapture(e.pointerId);
      pts = [at(e)];
    });
    c.addEventListener('pointermove', (e) => {
      if (!pts) return;
      pts.push(at(e));
      draw();
    });
    c.addEventListener('pointerup', () => {
      if (pts && pts.length > 2) {
        const clamp = pts.map((p) => [Math.max(0, Math.min(ex.size[0], p[0])), Math.max(0, Math.min(ex.size[1], p[1]))]);
        t.finishLasso(clamp, i, img);
      }
      pts = null;
    });
    return c;
  }

  inspector() {
    const ed = this.ed, t = ed.tools, s = t.sel, doc = ed.doc;
    if (!s) {
      const count = (list, what) => `${(list || []).length} ${what}${(list || []).length === 1 ? '' : 's'}`;
      const strokes = (layer) => layer && layer.strokes;
      return [h('h3', {}, 'Scene'), h('p', { class: 'note' },
        `${count(doc.points, 'point')}, ${count(doc.curves, 'curve')}, ${count(doc.pastes, 'paste')}; ${count(strokes(doc.types), 'type stroke')}, ${count(strokes(doc.freeze), 'freeze stroke')}, ${count(doc.sculpt, 'sculpt stroke')}. Click a control to edit it.`)];
    }
    const del = (label) => h('div', { class: 'buttons' }, h('button', { onclick: () => t.remove() }, label));
    if (s.kind === 'point') {
      const p = doc.points[s.index];
      if (!p) return [];
      return [h('h3', {}, `Point ${p.id || ''}`),
        this.num('x (px)', () => p.at[0], (v) => (p.at[0] = v), { kind: 'point' }),
        this.num('y (px)', () => p.at[1], (v) => (p.at[1] = v), { kind: 'point' }),
        this.num('height (m)', () => p.height_m, (v) => (p.height_m = v), { kind: 'point' }),
        this.num('slope (°)', () => p.slope_deg || 0, (v) => (p.slope_deg = v), { min: 0, max: 80, kind: 'point' }),
        this.num('downhill direction (°)', () => p.slope_direction_deg || 0, (v) => (p.slope_direction_deg = v), { min: -360, max: 360, kind: 'point' }),
        this.num('radius (px)', () => p.radius_px, (v) => (p.radius_px = v), { min: 1, kind: 'point' }),
        this.profileCanvas(new PointProfile(ed, p)), del('Delete point')];
    }
    if (s.kind === 'curve') {
      const c = doc.curves[s.index];
      if (!c) return [];
      const out = [h('h3', {}, `Curve ${c.id || ''}`),
        this.num('smoothing', () => c.smoothing ?? 2, (v) => (c.smoothing = Math.round(v)), { min: 0, max: 8, kind: 'curve' })];
      const list = h('div', { class: 'buttons' });
      c.widgets.forEach((w, k) => list.append(h('button', { class: s.widget === k ? 'active' : '', onclick: () => t.setSel({ ...s, widget: k }) }, `widget ${k + 1}`)));
      out.push(list);
      const w = s.widget != null && c.widgets[s.widget];
      if (w) {
        out.push(
          this.num('at (fraction)', () => w.at, (v) => (w.at = v), { step: 0.01, min: 0, max: 1, kind: 'widget' }),
          this.num('height (m)', () => w.height_m, (v) => (w.height_m = v), { kind: 'widget' }),
          this.num('left slope (°)', () => w.slope_deg[0], (v) => (w.slope_deg[0] = v), { min: -85, max: 85, kind: 'widget' }),
          this.num('right slope (°)', () => w.slope_deg[1], (v) => (w.slope_deg[1] = v), { min: -85, max: 85, kind: 'widget' }),
          this.num('left reach (px)', () => w.reach_px[0], (v) => (w.reach_px[0] = v), { min: 1, kind: 'widget' }),
          this.num('right reach (px)', () => w.reach_px[1], (v) => (w.reach_px[1] = v), { min: 1, kind: 'widget' }),
          this.profileCanvas(new WidgetProfile(ed, c, s.index, w)),
          h('p', { class: 'note' }, 'Slope > 0 rises away from the curve (a valley), < 0 falls (a ridge). Left is left walking along the curve.'),
          del(c.widgets.length > 1 ? 'Delete widget' : 'Delete curve'));
      } else {
        out.push(del('Delete curve'));
      }
      return out;
    }
    if (s.kind === 'junction') {
      const j = ed.frame && ed.frame.overlay.junctions[s.index];
      if (!j) return [];
      const e = () => C.junctionEntry(doc, j.at);
      return [h('h3', {}, 'Junction'), h('p', { class: 'note' }, `Where ${j.curves.join(' and ')} cross (${j.at.join(', ')}): one shared height.`),
        this.num('height (m)', () => (e() >= 0 ? doc.junctions[e()].height_m : j.height_m), (v) => t.setJunction(j, v), { kind: 'junction' }),
        del('Automatic height')];
    }
    if (s.kind === 'paste') {
      const p = doc.pastes[s.index];
      if (!p) return [];
      return [h('h3', {}, `Paste ${p.id || ''}`),
        h('p', { class: 'note' }, `from ${p.source === 'terrain' ? 'this terrain' : `exemplar ${ed.info.database.exemplars[p.exemplar].name}`}. Pastes are permanent in a session: changing or deleting one re-synthesizes the terrain from scratch.`),
        this.num('to x', () => p.to[0], (v) => (p.to[0] = v), { kind: 'paste' }),
        this.num('to y', () => p.to[1], (v) => (p.to[1] = v), { kind: 'paste' }),
        this.num((p.lift || (doc.version === 2 ? 'ground' : 'source')) === 'ground' ? 'δ above the ground (m)' : 'δ above its source (m)', () => p.delta_m || 0, (v) => (p.delta_m = v), { kind: 'paste' }),
        del('Delete paste')];
    }
    if (s.kind === 'sculpt') {
      const st = (doc.sculpt || [])[s.index];
      if (!st) return [];
      return [h('h3', {}, `Sculpt stroke ${s.index + 1}`),
        h('p', { class: 'note' }, `${st.brush}, radius ${st.radius_px} px, strength ${st.strength}, falloff ${st.falloff ?? 0.5}. Its target heights were baked from the terrain it was painted on; deleting it lets the ground under it be synthesized again.`),
        del('Delete stroke')];
    }
    return [];
  }

  profileCanvas(profile) {
    this.profile = profile;
    return profile.canvas;
  }
}

/**
 * A cross-section with draggable knobs. Subclasses give the target
 * profile (distance → height), the terrain along the same line, and what
 * dragging each knob does.
 */
class Profile {
  constructor(ed) {
    this.ed = ed;
    this.canvas = h('canvas', { class: 'profile', width: '560', height: '260' });
    this.drag = null;
    this.canvas.addEventListener('pointerdown', (e) => {
      this.canvas.setPointerCapture(e.pointerId);
      const q = this.at(e);
      let best = null;
      for (const k of this.knobs()) {
        const s = this.toPx(k.x, k.y);
        const d = Math.hypot(s[0] - q[0], s[1] - q[1]);
        if (d < 24 && (!best || d < best.d)) best = { ...k, d };
      }
      this.drag = best;
    });
    this.canvas.addEventListener('pointermove', (e) => {
      if (!this.drag) return;
      const [x, y] = this.fromPx(this.at(e));
      this.drag.set(x, y);
      this.ed.change(() => {}, { commit: false, kind: `${this.kind}-drag` });
    });
    this.canvas.addEventListener('pointerup', () => {
      if (this.drag) this.ed.change(() => {}, { kind: this.kind });
      this.drag = null;
    });
  }

  at(e) {
    const r = this.canvas.getBoundingClientRect();
    return [((e.clientX - r.left) / r.width) * this.canvas.width, ((e.clientY - r.top) / r.height) * this.canvas.height];
  }

  frame() {
    const [x0, x1] = this.xs();
    const ys = [];
    for (let i = 0; i <= 40; i++) {
      const x = x0 + ((x1 - x0) * i) / 40;
      ys.push(this.target(x));
      const t = this.terrain(x);
      if (t != null) ys.push(t);
    }
    if (this.fixed) return { x0, x1, y0: this.fixed.lo, y1: this.fixed.hi };
    let y0 = Math.min(...ys), y1 = Math.max(...ys);
    const pad = Math.max(20, (y1 - y0) * 0.15);
    return { x0, x1, y0: y0 - pad, y1: y1 + pad };
  }

  toPx(x, y) {
    const f = this.f, W = this.canvas.width, H = this.canvas.height, m = 24;
    return [m + ((x - f.x0) / (f.x1 - f.x0)) * (W - 2 * m), H - m - ((y - f.y0) / (f.y1 - f.y0)) * (H - 2 * m)];
  }

  fromPx(q) {
    const f = this.f, W = this.canvas.width, H = this.canvas.height, m = 24;
    return [f.x0 + ((q[0] - m) / (W - 2 * m)) * (f.x1 - f.x0), f.y0 + ((H - m - q[1]) / (H - 2 * m)) * (f.y1 - f.y0)];
  }

  draw() {
    // While dragging, the vertical scale stays put (the knob follows the mouse).
    if (!this.drag) this.fixed = null;
    this.f = this.frame();
    if (this.drag && !this.fixed) this.fixed = { lo: this.f.y0, hi: this.f.y1 };
    const ctx = this.canvas.getContext('2d'), W = this.canvas.width, H = this.canvas.height;
    ctx.clearRect(0, 0, W, H);
    ctx.font = '18px system-ui';
    ctx.fillStyle = '#8e99a6';
    ctx.fillText(`${Math.round(this.f.y1)} m`, 4, 18);
    ctx.fillText(`${Math.round(this.f.y0)} m`, 4, H - 4);
    const [x0, x1] = [this.f.x0, this.f.x1];
    const line = (fn, colour, width) => {
      ctx.beginPath();
      let started = false;
      for (let i = 0; i <= 80; i++) {
        const x = x0 + ((x1 - x0) * i) / 80;
        const y = fn(x);
        if (y == null) continue;
        const q = this.toPx(x, y);
        if (started) ctx.lineTo(q[0], q[1]);
        else ctx.moveTo(q[0], q[1]);
        started = true;
      }
      ctx.strokeStyle = colour;
      ctx.lineWidth = width;
      ctx.stroke();
    };
    line((x) => this.terrain(x), '#6c7a89', 2);
    line((x) => this.target(x), '#ffd60a', 3);
    for (const k of this.knobs()) {
      const q = this.toPx(k.x, k.y);
      ctx.beginPath();
      ctx.arc(q[0], q[1], 9, 0, 2 * Math.PI);
      ctx.fillStyle = '#ffd60a';
      ctx.fill();
      ctx.strokeStyle = '#141414';
      ctx.lineWidth = 2;
      ctx.stroke();
    }
  }
}

/** Along a point's downhill direction: the target plane across its radius. */
class PointProfile extends Profile {
  constructor(ed, p) {
    super(ed);
    this.p = p;
    this.kind = 'point';
  }
  dir() {
    const a = ((this.p.slope_direction_deg || 0) * Math.PI) / 180;
    return [Math.cos(a), Math.sin(a)];
  }
  xs() {
    return [-this.p.radius_px, this.p.radius_px];
  }
  target(x) {
    return this.p.height_m - Math.tan(((this.p.slope_deg || 0) * Math.PI) / 180) * x * this.ed.cell();
  }
  terrain(x) {
    return this.ed.heightAt(g.add(this.p.at, g.scale(this.dir(), x)));
  }
  knobs() {
    const p = this.p, r = p.radius_px, cell = this.ed.cell();
    return [
      { x: 0, y: p.height_m, set: (_, y) => (p.height_m = C.round(C.clampHeight(y))) },
      {
        x: r,
        y: this.target(r),
        set: (_, y) => (p.slope_deg = C.round(Math.max(0, Math.min(80, (Math.atan((p.height_m - y) / (r * cell)) * 180) / Math.PI)))),
      },
    ];
  }
}

/** Across a curve at a widget: left side to the left, right to the right. */
class WidgetProfile extends Profile {
  constructor(ed, c, index, w) {
    super(ed);
    Object.assign(this, { c, index, w, kind: 'widget' });
  }
  xs() {
    return [-this.w.reach_px[0], this.w.reach_px[1]];
  }
  target(x) {
    const side = x < 0 ? 0 : 1;
    return this.w.height_m + Math.tan((this.w.slope_deg[side] * Math.PI) / 180) * Math.abs(x) * this.ed.cell();
  }
  terrain(x) {
    const f = C.widgetFrame(this.ed, this.c, this.index, this.w);
    return this.ed.heightAt(g.add(f.at, g.scale(f.left, -x)));
  }
  knobs() {
    const w = this.w, cell = this.ed.cell();
    const end = (side) => ({
      x: side ? w.reach_px[1] : -w.reach_px[0],
      y: this.target(side ? w.reach_px[1] : -w.reach_px[0]),
      set: (x, y) => {
        const reach = Math.max(1, Math.min(4096, Math.abs(x)));
        w.reach_px[side] = C.round(reach);
        w.slope_deg[side] = C.round(Math.max(-85, Math.min(85, (Math.atan((y - w.height_m) / (reach * cell)) * 180) / Math.PI)));
      },
    });
    return [{ x: 0, y: w.height_m, set: (_, y) => (w.height_m = C.round(C.clampHeight(y))) }, end(0), end(1)];
  }
}
