// The editor page: boots a session, keeps the scene document, sends every
// edit, patches the preview with each frame's changed tile, and shows how
// long the loop took (server and here).

import { Api, ApiError } from './api.js';
import { MapView, isTyping } from './map.js';
import { Tools } from './tools.js';
import { Panel } from './panel.js';
import { View3d } from './view3d.js';
import { Link, open, closeOnHide } from './link.js';
import { Saver } from './save.js';

const $ = (id) => document.getElementById(id);

// Scripts (and the browser test) read the page's errors here.
window.__errors = [];
window.addEventListener('error', (e) => window.__errors.push(String(e.message)));
window.addEventListener('unhandledrejection', (e) => window.__errors.push(String(e.reason)));
// The server allows only its own files (Content-Security-Policy): anything
// else the page tried to load is an error too.
document.addEventListener('securitypolicyviolation', (e) => window.__errors.push(`blocked ${e.blockedURI} (${e.violatedDirective})`));

export const ed = {
  api: new Api(),
  map: new MapView($('map')),
  info: null,
  doc: null,
  frame: null,
  heights: null,
  view: { contours: true, types: true, range: true },
  grid: true,
  handles: true,
  base: null, // the preview, patched tile by tile
  latency: [], // {kind, ms, server_ms, synth_ms, render_ms, size}
  revision: -1,

  /** Mutates the document with `fn` and sends it. */
  change(fn, { commit = true, kind = 'edit' } = {}) {
    fn(this.doc);
    this.api.send(this.doc, { commit, kind });
    this.refresh();
  },

  refresh() {
    this.map.redraw();
    this.panel.refresh();
    this.updateBar();
  },

  /** Height at a terrain position from the last frame's samples. */
  heightAt(p) {
    const h = this.heights;
    if (!h) return null;
    const x = Math.min(h.w - 1, Math.max(0, Math.floor(p[0] / h.stride)));
    const y = Math.min(h.h - 1, Math.max(0, Math.floor(p[1] / h.stride)));
    return h.data[y * h.w + x];
  },

  range() {
    const r = this.info.database.range_m;
    return { lo: r[0], hi: r[1], relief: r[1] - r[0] };
  },

  size() {
    return this.doc.size;
  },

  cell() {
    return this.info.database.cell_size_m || 30;
  },

  error(e) {
    // The session or the server gone: the link reconnects and says so.
    if (this.link && this.link.lost(e)) return;
    const text = e instanceof ApiError ? `${e.message}` : `${e}`;
    $('status-error').textContent = text;
    $('status-error').title = text;
    console.warn(e);
  },
};

function setBusy(text) {
  const b = $('busy');
  b.hidden = !text;
  b.textContent = text || '';
}

/** Draws a frame: the changed tile (or the whole preview) onto the base. */
async function showFrame(frame, job) {
  const [w, h] = frame.size;
  ed.map.setSize(w, h);
  let bitmap = null;
  let rect = null;
  if (frame.tile && ed.base) {
    bitmap = await ed.api.tile(frame.tile.revision);
    rect = frame.tile.rect;
  }
  if (!bitmap && (frame.tile || !ed.base)) {
    bitmap = await ed.api.preview();
    rect = [0, 0, bitmap.width, bitmap.height];
  }
  if (bitmap) {
    const full = rect[0] === 0 && rect[1] === 0 && rect[2] === bitmap.width && rect[3] === bitmap.height;
    if (!ed.base || (full && (ed.base.width !== bitmap.width || ed.base.height !== bitmap.height))) {
      ed.base = document.createElement('canvas');
      ed.base.width = bitmap.width;
      ed.base.height = bitmap.height;
    }
    ed.base.getContext('2d').drawImage(bitmap, rect[0], rect[1]);
    bitmap.close();
  }
  ed.map.image = ed.base;
  ed.frame = frame;
  ed.revision = frame.revision;
  if (frame.scene) ed.doc = frame.scene;
  // Sculpt strokes the server baked: their targets join the document.
  for (const b of frame.baked || []) {
    const st = (ed.doc.sculpt || [])[b.index];
    if (st && !st.targets) st.targets = b.targets;
  }
  ed.map.draw();
  ed.view3d.imageChanged();
  if (job) {
    $('status-error').textContent = '';
    const ms = performance.now() - job.t0;
    ed.latency.push({
      kind: job.kind,
      ms,
      server_ms: frame.timing_ms.total,
      synth_ms: frame.timing_ms.synth,
      render_ms: frame.timing_ms.render,
      edits_ms: frame.timing_ms.edits,
      size: `${w}x${h}`,
      changed: frame.changed ? frame.changed.pixels : null,
    });
    ed.lastRoundTrip = ms;
  }
  document.body.dataset.revision = String(frame.revision);
  keep();
  ed.panel.refresh();
  ed.updateBar();
  status();
  scheduleHeights();
}

/** Where this tab keeps its document, so a reload loses no unsaved work. */
const kept = () => `terrasynth-doc-${ed.info.instance}`;

function keep() {
  try {
    sessionStorage.setItem(kept(), JSON.stringify(ed.doc));
  } catch (_) {
    /* storage full or off: reloading then starts from the server's scene */
  }
}

let heightsTimer = null;
function scheduleHeights() {
  clearTimeout(heightsTimer);
  heightsTimer = setTimeout(async () => {
    if (ed.api.busy()) return scheduleHeights();
    try {
      ed.heights = await ed.api.heights();
      ed.view3d.heightsChanged();
      // The cross-section draws the terrain from these samples.
      if (ed.panel.profile) ed.panel.profile.draw();
    } catch (e) {
      /* next frame retries */
    }
  }, 250);
}

function status() {
  const f = ed.frame;
  if (!f) return;
  const t = f.timing_ms;
  const parts = [
    `synthesis ${t.synth.toFixed(0)} ms`,
    `render ${t.render.toFixed(0)} ms`,
    `server ${t.total.toFixed(0)} ms`,
  ];
  if (ed.lastRoundTrip != null) parts.push(`edit → preview ${ed.lastRoundTrip.toFixed(0)} ms`);
  parts.push(`${f.size[0]}×${f.size[1]}`, `seed ${f.seed}`);
  if (f.changed) parts.push(`${f.changed.pixels.toLocaleString()} px changed`);
  if (f.rebuilt) parts.push(`new session: ${f.rebuilt}`);
  parts.push(`rev ${f.revision}`);
  $('status-main').textContent = parts.join(' · ');
}

ed.updateBar = function () {
  const f = ed.frame;
  $('undo').disabled = !f || f.history.undo === 0;
  $('redo').disabled = !f || f.history.redo === 0;
  if (ed.doc && document.activeElement !== $('seed')) $('seed').value = ed.doc.seed;
  if (ed.doc) $('size').value = String(ed.doc.size[0]);
};

async function undoRedo(which) {
  await ed.api.idle();
  try {
    setBusy(which === 'undo' ? 'undoing…' : 'redoing…');
    const { frame, job } = await ed.api.post(`/${which}`, which);
    ed.tools.afterUndo();
    await showFrame(frame, job);
    $('status-error').textContent = '';
  } catch (e) {
    ed.error(e);
  } finally {
    setBusy(null);
  }
}

/** Puts `text` on the status line, before the last edit's numbers. */
function news(text) {
  $('status-error').textContent = '';
  status();
  $('status-main').textContent = `${text} · ${$('status-main').textContent}`;
}

function download(url, name) {
  const a = document.createElement('a');
  a.href = url;
  if (name) a.download = name;
  document.body.appendChild(a);
  a.click();
  a.remove();
}

/** Scales every position and length of a document to a new size. */
function scaleDoc(doc, [w, h]) {
  const [ow, oh] = doc.size;
  const fx = w / ow, fy = h / oh, f = Math.sqrt(fx * fy);
  const p = (q) => [Math.min(w, q[0] * fx), Math.min(h, q[1] * fy)];
  for (const pt of doc.points || []) {
    pt.at = p(pt.at);
    pt.radius_px *= f;
  }
  for (const c of doc.curves || []) {
    c.points = c.points.map(p);
    for (const wd of c.widgets) wd.reach_px = wd.reach_px.map((r) => Math.min(4096, r * f));
  }
  for (const j of doc.junctions || []) j.at = p(j.at);
  for (const layer of [doc.types, doc.freeze]) {
    for (const s of (layer && layer.strokes) || []) {
      s.points = s.points.map(p);
      s.radius_px *= f;
    }
  }
  for (const st of doc.sculpt || []) {
    st.points = st.points.map(p);
    st.radius_px *= f;
    if (st.targets) {
      st.targets.at = p(st.targets.at);
      st.targets.step_px *= f;
    }
  }
  for (const ps of doc.pastes || []) {
    if (ps.source === 'terrain') ps.lasso = ps.lasso.map(p);
    ps.to = p(ps.to);
  }
  doc.size = [w, h];
}

/** Switches the stage between the map and the 3D view. */
function show3d(on) {
  ed.view3d.show(on);
  $('toggle-3d').classList.toggle('active', on);
}

/** Picks a tool; the tools draw on the map, so it comes back. */
function tool(name) {
  if (ed.view3d.shown) show3d(false);
  ed.tools.select(name);
}

/** Fits the map, or in 3D puts the camera back. */
function fit() {
  if (ed.view3d.shown) ed.view3d.reset();
  else ed.map.fit();
}

function wireBar() {
  $('undo').onclick = () => undoRedo('undo');
  $('redo').onclick = () => undoRedo('redo');
  $('save').onclick = () => ed.saver.save();
  $('download-scene').onclick = () => {
    const blob = new Blob([JSON.stringify(ed.doc, null, 2)], { type: 'application/json' });
    const url = URL.createObjectURL(blob);
    download(url, 'scene.json');
    setTimeout(() => URL.revokeObjectURL(url), 1000);
  };
  $('open-scene').onchange = async (e) => {
    const file = e.target.files[0];
    e.target.value = '';
    if (!file) return;
    try {
      const doc = JSON.parse(await file.text());
      ed.tools.cancel();
      ed.doc = doc;
      ed.api.send(doc, { kind: 'open' });
      ed.refresh();
    } catch (err) {
      ed.error(`${file.name}: ${err}`);
    }
  };
  const sel = $('export-format');
  for (const f of ed.info.export_formats) {
    const o = document.createElement('option');
    o.value = f;
    o.textContent = f;
    sel.appendChild(o);
  }
  sel.value = 'exr';
  $('export').onclick = () => {
    const f = sel.value;
    download(ed.api.url(`/export?format=${f}`));
    if (['png16', 'r16', 'r32'].includes(f)) {
      setTimeout(() => download(ed.api.url(`/export?format=${f}&sidecar=true`)), 300);
    }
  };
  $('export-preview').onclick = () => download(ed.api.url('/export?format=preview'));
  $('seed').onchange = () => {
    const s = Number($('seed').value);
    if (!Number.isInteger(s) || s < 0 || s > 4294967295) return ed.error('seed: expected an integer in 0..=4294967295');
    ed.change((d) => (d.seed = s), { kind: 'seed' });
  };
  $('size').onchange = () => {
    const n = Number($('size').value);
    ed.tools.cancel();
    ed.change((d) => scaleDoc(d, [n, n]), { kind: 'size' });
  };
  for (const k of ['contours', 'types', 'range']) {
    $(`v-${k}`).onchange = async () => {
      ed.view[k] = $(`v-${k}`).checked;
      try {
        await showFrame(await ed.api.view(ed.view));
      } catch (e) {
        ed.error(e);
      }
    };
  }
  $('v-grid').onchange = () => {
    ed.grid = $('v-grid').checked;
    ed.map.redraw();
  };
  $('v-handles').onchange = () => {
    ed.handles = $('v-handles').checked;
    ed.map.redraw();
  };
  $('fit').onclick = fit;
  $('toggle-3d').onclick = () => show3d(!ed.view3d.shown);
  for (const b of document.querySelectorAll('#tools button[data-tool]')) {
    b.onclick = () => tool(b.dataset.tool);
  }
  window.addEventListener('keydown', (e) => {
    if (isTyping(e)) return;
    const k = e.key.toLowerCase();
    if ((e.ctrlKey || e.metaKey) && k === 'z') {
      e.preventDefault();
      undoRedo(e.shiftKey ? 'redo' : 'undo');
    } else if ((e.ctrlKey || e.metaKey) && k === 'y') {
      e.preventDefault();
      undoRedo('redo');
    } else if ((e.ctrlKey || e.metaKey) && k === 's') {
      e.preventDefault();
      ed.saver.save();
    } else if (!e.ctrlKey && !e.metaKey && !e.altKey) {
      const tools = { v: 'select', p: 'point', c: 'curve', t: 'types', f: 'freeze', s: 'sculpt', l: 'lasso', h: 'pan' };
      if (tools[k]) tool(tools[k]);
      else if (k === '0') fit();
      else if (k === '3') show3d(!ed.view3d.shown);
      else ed.tools.key(e);
    }
  });
}

/**
 * Unsaved work the server autosaved before it stopped: a banner asks
 * whether to keep it (this tab then shows it, unsaved) or discard it.
 */
function offerRecovery() {
  const r = ed.info.recovery;
  if (!r) return;
  const banner = $('recovery');
  $('recovery-text').textContent = `Unsaved work from ${new Date(r.modified_ms).toLocaleString()} was recovered (${r.path}).`;
  const answer = async (keep) => {
    await ed.api.idle();
    try {
      const frame = await ed.api.recovery(keep);
      banner.hidden = true;
      if (keep) {
        ed.tools.cancel();
        await showFrame(frame, { kind: 'recovery', t0: performance.now() });
        ed.refresh();
      }
    } catch (e) {
      ed.error(e);
    }
  };
  $('recovery-keep').onclick = () => answer(true);
  $('recovery-discard').onclick = () => answer(false);
  banner.hidden = false;
}

async function boot() {
  const text = $('loading-text'), bar = $('loading-bar');
  for (;;) {
    try {
      ed.info = await ed.api.info();
    } catch (e) {
      text.textContent = 'server unreachable — retrying';
      await new Promise((r) => setTimeout(r, 1000));
      continue;
    }
    if (ed.info.status === 'ready') break;
    if (ed.info.status === 'failed') {
      $('loading').classList.add('failed');
      text.textContent = ed.info.error;
      bar.hidden = true;
      return;
    }
    const p = ed.info.progress;
    text.textContent = `loading the exemplar database${p.stage ? `: ${p.stage}` : ''}…`;
    if (p.total > 0) {
      bar.max = p.total;
      bar.value = p.done;
    }
    await new Promise((r) => setTimeout(r, 200));
  }
  const t0 = performance.now();
  const tick = setInterval(() => {
    text.textContent = `synthesizing the first frame… ${((performance.now() - t0) / 1000).toFixed(1)} s`;
  }, 100);
  bar.removeAttribute('value');
  let frame;
  closeOnHide(ed.api);
  const say = (why) => (text.textContent = why);
  try {
    const before = sessionStorage.getItem(kept());
    frame = before ? await open(ed.api, JSON.parse(before), say).catch(() => open(ed.api, null, say)) : await open(ed.api, null, say);
  } catch (e) {
    clearInterval(tick);
    $('loading').classList.add('failed');
    text.textContent = e.message;
    bar.hidden = true;
    return;
  }
  clearInterval(tick);
  ed.doc = frame.scene;
  ed.panel = new Panel(ed);
  ed.view3d = new View3d($('view3d'), () => ({
    heights: ed.heights,
    image: ed.base,
    revision: ed.revision,
    cell: ed.cell(),
    size: ed.frame.size,
  }));
  ed.tools = new Tools(ed);
  ed.saver = new Saver(ed, showFrame, news);
  wireBar();
  ed.api.onFrame = showFrame;
  // The session closed (its slot taken while the tab slept) or the server
  // gone: ed.error hands that to the link, which reopens from ed.doc.
  ed.api.onError = (e) => ed.error(e);
  ed.link = new Link(ed, showFrame);
  ed.link.heartbeat();
  ed.api.onIdle = () => setBusy(null);
  const slow = setInterval(() => {
    const j = ed.api.inFlight;
    if (j && performance.now() - j.t0 > 400) setBusy(`synthesizing… ${((performance.now() - j.t0) / 1000).toFixed(1)} s`);
  }, 100);
  window.addEventListener('pagehide', () => clearInterval(slow));
  await showFrame(frame, { kind: 'first', t0 });
  ed.map.fit();
  $('loading').hidden = true;
  ed.tools.select('select');
  offerRecovery();
  // For tests and scripts: the page's state and coordinate mapping.
  ed.undo = () => undoRedo('undo');
  ed.redo = () => undoRedo('redo');
  window.terrasynth = ed;
}

boot();
