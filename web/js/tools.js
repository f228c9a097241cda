// The tools: what a click or a drag on the map does. Handles of the
// selected control win over the active tool, so a widget can be dragged
// whatever tool is on. A drag sends a document per move (not an undo step,
// coalesced: latest wins) and one committed document when it ends.

import * as g from './geometry.js';
import * as C from './controls.js';
import * as D from './draw.js';

const TOL = 9; // screen pixels

export class Tools {
  constructor(ed) {
    this.ed = ed;
    this.map = ed.map;
    this.tool = 'select';
    this.sel = null;
    this.drag = null;
    this.stroke = null;
    this.pending = null;
    this.cursor = null;
    const side = Math.max(...ed.doc.size);
    this.opts = {
      pointPreset: 'peak',
      curvePreset: 'ridge',
      type: 0,
      typeRadius: Math.round(side * 0.04),
      freezeRadius: Math.round(side * 0.05),
      thaw: false,
      pasteSource: 'terrain',
      brush: 'raise',
      sculptRadius: Math.round(side * 0.05),
      // Per brush: metres for raise/lower, a share 0–1 for the others.
      strength: { raise: 150, lower: 150, smooth: 0.8, flatten: 0.8, erode: 1 },
      // Hills, not mesas: the effect fades over most of the radius.
      falloff: 0.8,
    };
    this.frozenLayer = document.createElement('canvas');
    this.map.handler = this;
    this.map.layers.push(
      (ctx, m) => D.drawGrid(ctx, m, ed),
      (ctx, m) => D.drawFrozen(ctx, m, ed, this.frozenLayer),
      (ctx, m) => this.drawControls(ctx, m),
    );
  }

  select(tool) {
    if (tool !== 'lasso') this.pending = null;
    this.tool = tool;
    this.map.panTool = tool === 'pan';
    this.map.canvas.classList.toggle('grab', tool === 'pan');
    for (const b of document.querySelectorAll('#tools button[data-tool]')) {
      b.classList.toggle('active', b.dataset.tool === tool);
    }
    this.ed.panel.refresh();
    this.map.redraw();
  }

  drawControls(ctx, map) {
    const ed = this.ed;
    if (ed.handles) {
      D.drawSculpt(ctx, map, ed, this.sel);
      D.drawPastes(ctx, map, ed, this.sel);
      D.drawCurves(ctx, map, ed, this.sel);
      D.drawPoints(ctx, map, ed, this.sel);
    }
    D.drawStroke(ctx, map, this.stroke);
    D.drawPending(ctx, map, ed, this.pending);
    if (this.tool === 'types') D.drawBrush(ctx, map, this.cursor, this.opts.typeRadius);
    if (this.tool === 'freeze') D.drawBrush(ctx, map, this.cursor, this.opts.freezeRadius);
    if (this.tool === 'sculpt') D.drawBrush(ctx, map, this.cursor, this.opts.sculptRadius);
  }

  /**
   * The handle under terrain point p, most specific first. With `all`
   * false (the brushes), only the selection's own handles count, so
   * painting over a control does not grab it.
   */
  hit(p, all = true) {
    const ed = this.ed, map = this.map, doc = ed.doc;
    const tol = map.px(TOL);
    const q = map.toScreen(p);
    const near = (a) => g.dist(p, a) <= tol;
    const onBar = (at, value, range) => {
      const k = C.barKnob(ed, map.toScreen(at), value, range);
      return Math.abs(q[0] - k[0]) <= 9 && Math.abs(q[1] - k[1]) <= 7;
    };
    const P = this.pending;
    if (P) {
      const r = ed.range().relief;
      if (onBar(P.to, P.delta_m, { lo: -r / 2, hi: r / 2 })) return { kind: 'paste-delta' };
      if (near(P.to)) return { kind: 'paste-move' };
    }
    const s = this.sel;
    if (s && s.kind === 'point' && doc.points[s.index]) {
      const pt = doc.points[s.index];
      if (onBar(pt.at, pt.height_m, C.barRange(ed))) return { kind: 'point-height', index: s.index };
      if (near(C.slopeTip(pt))) return { kind: 'point-slope', index: s.index };
    }
    if (s && s.kind === 'curve' && s.widget != null && doc.curves[s.index]) {
      const c = doc.curves[s.index], w = c.widgets[s.widget];
      if (w) {
        const f = C.widgetFrame(ed, c, s.index, w);
        if (onBar(f.at, w.height_m, C.barRange(ed))) return { ...s, kind: 'widget-height' };
        for (const [side, sign] of [[0, 1], [1, -1]]) {
          if (near(g.add(f.at, g.scale(f.left, sign * w.reach_px[side])))) return { ...s, kind: 'widget-reach', side };
        }
      }
    }
    if (s && s.kind === 'junction' && ed.frame) {
      const j = ed.frame.overlay.junctions[s.index];
      if (j) {
        const e = C.junctionEntry(doc, j.at);
        const h = e >= 0 ? doc.junctions[e].height_m : j.height_m;
        if (onBar(j.at, h, C.barRange(ed))) return { kind: 'junction-height', index: s.index };
      }
    }
    if (!ed.handles || !all) return null;
    for (let i = doc.points.length - 1; i >= 0; i--) {
      if (near(doc.points[i].at)) return { kind: 'point-move', index: i };
    }
    for (let i = (doc.curves || []).length - 1; i >= 0; i--) {
      const c = doc.curves[i];
      for (let k = c.widgets.length - 1; k >= 0; k--) {
        if (near(C.widgetFrame(ed, c, i, c.widgets[k]).at)) return { kind: 'widget-move', index: i, widget: k };
      }
    }
    const js = (ed.frame && ed.frame.overlay.junctions) || [];
    for (let k = 0; k < js.length; k++) if (near(js[k].at)) return { kind: 'junction', index: k };
    if (s && s.kind === 'point' && doc.points[s.index]) {
      const pt = doc.points[s.index];
      if (Math.abs(g.dist(p, pt.at) - pt.radius_px) <= tol) return { kind: 'point-radius', index: s.index };
    }
    for (let i = (doc.curves || []).length - 1; i >= 0; i--) {
      const c = doc.curves[i];
      const b = C.builtCurve(ed, c, i);
      const h = g.onPolyline(p, b ? b.line : c.points);
      if (h.d <= tol) return { kind: 'curve', index: i, frac: h.frac };
    }
    for (let i = (doc.sculpt || []).length - 1; i >= 0; i--) {
      if (g.onPolyline(p, doc.sculpt[i].points).d <= tol) return { kind: 'sculpt', index: i };
    }
    for (let i = (doc.pastes || []).length - 1; i >= 0; i--) {
      const ps = doc.pastes[i];
      const c = g.centroid(ps.lasso);
      const off = [Math.round(ps.to[0] - c[0]), Math.round(ps.to[1] - c[1])];
      if (g.inside(ps.lasso.map((v) => g.add(v, off)), p)) return { kind: 'paste', index: i };
    }
    return null;
  }

  selection(h) {
    if (!h) return null;
    if (h.kind.startsWith('point')) return { kind: 'point', index: h.index };
    if (h.kind.startsWith('widget')) return { kind: 'curve', index: h.index, widget: h.widget };
    if (h.kind === 'curve') return { kind: 'curve', index: h.index, widget: null };
    if (h.kind.startsWith('junction')) return { kind: 'junction', index: h.index };
    if (h.kind === 'paste' || h.kind === 'sculpt') return { kind: h.kind, index: h.index };
    return this.sel;
  }

  setSel(s) {
    this.sel = s;
    this.ed.panel.refresh();
    this.map.redraw();
  }

  down(p, e) {
    const ed = this.ed;
    const h = this.hit(p, !['types', 'freeze', 'lasso', 'sculpt'].includes(this.tool));
    const draggable = h && !['curve', 'paste', 'junction', 'sculpt'].includes(h.kind);
    if (h && (draggable || this.tool === 'select' || this.tool === 'point')) {
      if (h.kind === 'curve' && e.shiftKey) return this.addWidget(h);
      this.setSel(this.selection(h));
      if (draggable) this.drag = { h, p0: p, moved: false };
      return;
    }
    switch (this.tool) {
      case 'select':
        this.setSel(null);
        break;
      case 'point': {
        const pt = C.newPoint(ed, ed.doc, p, this.opts.pointPreset);
        ed.doc.points.push(pt);
        const index = ed.doc.points.length - 1;
        this.setSel({ kind: 'point', index });
        // Placing is one step: the drag that may follow moves it.
        this.drag = { h: { kind: 'point-move', index }, p0: p, moved: true, kind: 'point' };
        ed.api.send(ed.doc, { commit: false, kind: 'point' });
        break;
      }
      case 'curve':
        this.stroke = { points: [p], colour: '#ffd60a' };
        break;
      case 'types':
      case 'freeze':
        this.startBrush(p);
        break;
      case 'sculpt':
        this.stroke = { points: [p], radius: this.opts.sculptRadius, colour: 'rgba(255,170,60,0.5)', sculpt: true };
        break;
      case 'lasso':
        if (this.opts.pasteSource === 'terrain') {
          this.pending = null;
          this.stroke = { points: [p], colour: '#ff7800', closed: true };
        }
        break;
    }
    this.map.redraw();
  }

  move(p, e) {
    this.cursor = p;
    const ed = this.ed;
    if (this.drag) {
      this.drag.moved = true;
      this.dragTo(this.drag.h, p, e);
      ed.panel.refresh();
      this.map.redraw();
      return;
    }
    if (this.stroke) {
      const step = this.stroke.radius ? this.stroke.radius / 3 : this.map.px(3);
      const last = this.stroke.points[this.stroke.points.length - 1];
      if (g.dist(last, p) >= step) {
        this.stroke.points.push(p);
        if (this.stroke.layer) this.updateBrush(false);
      }
      this.map.redraw();
    }
  }

  hover(p) {
    this.cursor = p;
    const h = this.hit(p);
    this.map.canvas.classList.toggle('move', !!h && !['curve', 'paste'].includes(h.kind));
    const hm = this.ed.heightAt(p);
    document.getElementById('status-cursor').textContent =
      `(${Math.round(p[0])}, ${Math.round(p[1])})${hm != null ? ` ${Math.round(hm)} m` : ''}`;
    if (['types', 'freeze', 'sculpt'].includes(this.tool)) this.map.redraw();
  }

  up(p) {
    const ed = this.ed;
    if (this.drag) {
      const d = this.drag;
      this.drag = null;
      if (d.h.kind.startsWith('paste')) return this.map.redraw();
      if (d.moved) ed.api.send(ed.doc, { commit: true, kind: d.kind || d.h.kind.split('-')[0] });
      return;
    }
    const s = this.stroke;
    if (!s) return;
    this.stroke = null;
    if (s.layer) return this.updateBrush(true);
    if (s.sculpt) return this.finishSculpt(s);
    if (this.tool === 'curve') this.finishCurve(s.points, p);
    else if (this.tool === 'lasso') this.finishLasso(s.points);
    this.map.redraw();
  }

  dragTo(h, p) {
    const ed = this.ed, doc = ed.doc;
    const q = this.map.toScreen(p);
    const [w, hh] = doc.size;
    const clampXY = (v) => [Math.max(0, Math.min(w, v[0])), Math.max(0, Math.min(hh, v[1]))];
    const send = () => ed.api.send(doc, { commit: false, kind: `${h.kind.split('-')[0]}-drag` });
    switch (h.kind) {
      case 'point-move':
        doc.points[h.index].at = g.r1p(clampXY(p));
        return send();
      case 'point-radius':
        doc.points[h.index].radius_px = C.round(Math.max(1, Math.min(4096, g.dist(p, doc.points[h.index].at))));
        return send();
      case 'point-slope':
        Object.assign(doc.points[h.index], C.slopeFrom(doc.points[h.index], p));
        return send();
      case 'point-height': {
        const pt = doc.points[h.index];
        pt.height_m = C.round(C.barValue(this.map.toScreen(pt.at), q[1], C.barRange(ed)));
        return send();
      }
      case 'widget-move': {
        const c = doc.curves[h.index];
        const b = C.builtCurve(ed, c, h.index);
        c.widgets[h.widget].at = Math.round(g.onPolyline(p, b ? b.line : c.points).frac * 1000) / 1000;
        return send();
      }
      case 'widget-reach': {
        const c = doc.curves[h.index], wd = c.widgets[h.widget];
        const f = C.widgetFrame(ed, c, h.index, wd);
        const along = g.dot(g.sub(p, f.at), f.left) * (h.side === 0 ? 1 : -1);
        wd.reach_px[h.side] = C.round(Math.max(1, Math.min(4096, along)));
        return send();
      }
      case 'widget-height': {
        const c = doc.curves[h.index], wd = c.widgets[h.widget];
        const f = C.widgetFrame(ed, c, h.index, wd);
        wd.height_m = C.round(C.barValue(this.map.toScreen(f.at), q[1], C.barRange(ed)));
        return send();
      }
      case 'junction-height': {
        const j = ed.frame.overlay.junctions[h.index];
        this.setJunction(j, C.barValue(this.map.toScreen(j.at), q[1], C.barRange(ed)));
        return send();
      }
      case 'paste-move':
        this.pending.to = g.r1p(clampXY(p));
        return;
      case 'paste-delta': {
        const r = ed.range().relief;
        this.pending.delta_m = C.round(C.barValue(this.map.toScreen(this.pending.to), q[1], { lo: -r / 2, hi: r / 2 }));
        return;
      }
    }
  }

  setJunction(j, height) {
    const doc = this.ed.doc;
    doc.junctions = doc.junctions || [];
    const e = C.junctionEntry(doc, j.at);
    const entry = { at: j.at, height_m: C.round(C.clampHeight(height)) };
    if (e >= 0) doc.junctions[e] = entry;
    else doc.junctions.push(entry);
  }

  addWidget(h) {
    const ed = this.ed, c = ed.doc.curves[h.index];
    let near = c.widgets[0];
    for (const w of c.widgets) if (Math.abs(w.at - h.frac) < Math.abs(near.at - h.frac)) near = w;
    c.widgets.push({ ...JSON.parse(JSON.stringify(near)), at: Math.round(h.frac * 1000) / 1000 });
    this.sel = { kind: 'curve', index: h.index, widget: c.widgets.length - 1 };
    ed.change(() => {}, { kind: 'widget' });
  }

  startBrush(p) {
    const ed = this.ed, doc = ed.doc;
    const layer = this.tool === 'types' ? 'types' : 'freeze';
    if (doc[layer] && !doc[layer].strokes) {
      ed.error(`${layer}: this scene paints with an image file; the editor paints strokes (remove the image in the scene file first)`);
      return;
    }
    doc[layer] = doc[layer] || { strokes: [] };
    const radius = layer === 'types' ? this.opts.typeRadius : this.opts.freezeRadius;
    const s = { points: [g.r1p(p)], radius_px: radius };
    let colour = 'rgba(120,190,255,1)';
    if (layer === 'types') {
      if (this.opts.type === 'erase') s.erase = true;
      else {
        const t = ed.info.database.types[this.opts.type];
        s.type = t.name;
        colour = `rgb(${t.colour.join(',')})`;
      }
    } else if (this.opts.thaw) {
      s.erase = true;
    }
    if (s.erase) colour = 'rgba(255,255,255,0.8)';
    doc[layer].strokes.push(s);
    this.stroke = { points: [p], radius, colour, layer, doc: s };
    this.updateBrush(false);
  }

  updateBrush(commit) {
    const s = this.stroke || this.lastBrush;
    if (!s) return;
    this.lastBrush = commit ? null : s;
    s.doc.points = g.thin(s.points, Math.max(1, s.radius / 3)).map(g.r1p);
    this.ed.api.send(this.ed.doc, { commit, kind: s.layer === 'types' ? 'type' : 'freeze' });
    if (commit) this.ed.refresh();
  }

  /**
   * A sculpt stroke, sent without targets: the server bakes them from the
   * terrain shown and the frame brings them back (`baked`), so the
   * document keeps them.
   */
  finishSculpt(s) {
    const o = this.opts;
    const item = {
      brush: o.brush,
      points: g.thin(s.points, Math.max(1, s.radius / 3)).map(g.r1p),
      radius_px: s.radius,
      strength: o.strength[o.brush],
      falloff: o.falloff,
    };
    this.ed.change((d) => (d.sculpt = (d.sculpt || []).concat([item])), { kind: 'sculpt' });
  }

  finishCurve(pts, end) {
    const ed = this.ed, doc = ed.doc;
    if (pts.length < 2 || g.dist(pts[0], end) + g.arcLengths(pts).pop() < this.map.px(6)) {
      // A click: select what is under it.
      return this.setSel(this.selection(this.hit(end)));
    }
    const stroke = g.thin(pts, this.map.px(4)).map(g.r1p);
    doc.curves = doc.curves || [];
    const order = [];
    if (this.sel && this.sel.kind === 'curve') order.push(this.sel.index);
    doc.curves.forEach((_, i) => order.includes(i) || order.push(i));
    for (const i of order) {
      const c = doc.curves[i];
      const reshaped = g.overSketch(c.points, stroke, this.map.px(14));
      if (reshaped && reshaped.length >= 2) {
        // Widgets stay where they were on the map.
        for (const w of c.widgets) {
          const at = g.pointAt(c.points, w.at);
          w.at = Math.round(g.onPolyline(at, reshaped).frac * 1000) / 1000;
        }
        c.points = reshaped.map(g.r1p);
        this.sel = { kind: 'curve', index: i, widget: null };
        return ed.change(() => {}, { kind: 'curve' });
      }
    }
    doc.curves.push(C.newCurve(ed, doc, stroke, this.opts.curvePreset));
    this.sel = { kind: 'curve', index: doc.curves.length - 1, widget: 0 };
    ed.change(() => {}, { kind: 'curve' });
  }

  /** A lasso closed on the terrain or an exemplar: a paste to place. */
  finishLasso(pts, exemplar = null, image = null) {
    const lasso = g.thin(pts, exemplar == null ? this.map.px(3) : 2).map(g.r1p);
    if (lasso.length < 3) return;
    const c = g.centroid(lasso);
    const [w, h] = this.ed.doc.size;
    const to = exemplar == null ? c : this.map.toTerrain([this.map.canvas.clientWidth / 2, this.map.canvas.clientHeight / 2]);
    this.pending = {
      source: exemplar == null ? 'terrain' : 'exemplar',
      exemplar,
      lasso,
      to: g.r1p([Math.max(0, Math.min(w, to[0])), Math.max(0, Math.min(h, to[1]))]),
      delta_m: 0,
      image: image || this.ed.base,
      imageScale: image ? 1 : this.ed.base.width / w,
    };
    this.ed.panel.refresh();
    this.map.redraw();
  }

  applyPaste() {
    const P = this.pending;
    if (!P) return;
    this.pending = null;
    // Explicit, so that a paste added to a version-1 scene lands on the ground too.
    const item = { id: C.newId(this.ed.doc, 'paste'), source: P.source, lasso: P.lasso, to: P.to, delta_m: P.delta_m, lift: 'ground' };
    if (P.source === 'exemplar') item.exemplar = P.exemplar;
    this.ed.change((d) => (d.pastes = (d.pastes || []).concat([item])), { kind: 'paste' });
    this.sel = { kind: 'paste', index: this.ed.doc.pastes.length - 1 };
  }

  /** Removes the selected control (or widget, or junction height). */
  remove() {
    const s = this.sel, ed = this.ed;
    if (!s) return;
    this.sel = null;
    ed.change((d) => {
      if (s.kind === 'point') d.points.splice(s.index, 1);
      else if (s.kind === 'curve') {
        const c = d.curves[s.index];
        if (s.widget != null && c.widgets.length > 1) c.widgets.splice(s.widget, 1);
        else d.curves.splice(s.index, 1);
      } else if (s.kind === 'junction') {
        const j = ed.frame.overlay.junctions[s.index];
        const e = j ? C.junctionEntry(d, j.at) : -1;
        if (e >= 0) d.junctions.splice(e, 1);
      } else if (s.kind === 'paste') d.pastes.splice(s.index, 1);
      else if (s.kind === 'sculpt') d.sculpt.splice(s.index, 1);
    }, { kind: 'remove' });
  }

  cancel() {
    this.pending = null;
    this.stroke = null;
    this.drag = null;
    this.sel = null;
    this.ed.panel.refresh();
    this.map.redraw();
  }

  /** After undo/redo the document changed under the selection. */
  afterUndo() {
    this.pending = null;
    this.sel = null;
  }

  key(e) {
    if (e.key === 'Delete' || e.key === 'Backspace') this.remove();
    else if (e.key === 'Escape') this.cancel();
    else if (e.key === 'Enter') this.applyPaste();
    else if (e.key === '[' || e.key === ']') {
      const k = e.key === ']' ? 1.25 : 0.8;
      const key = { freeze: 'freezeRadius', sculpt: 'sculptRadius' }[this.tool] || 'typeRadius';
      this.opts[key] = Math.max(1, Math.min(4096, Math.round(this.opts[key] * k)));
      this.ed.panel.refresh();
      this.map.redraw();
    }
  }
}
