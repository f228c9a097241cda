// The map: the server's preview image under the page's own drawing of the
// controls, with pan (middle or right drag, Space + drag, the Pan tool) and
// zoom (wheel, around the cursor). Pointer events reach the tools in
// terrain pixels.

export class MapView {
  constructor(canvas) {
    this.canvas = canvas;
    this.ctx = canvas.getContext('2d');
    this.size = [1, 1];
    this.image = null;
    this.s = 1;
    this.ox = 0;
    this.oy = 0;
    this.handler = null; // {down, move, up, hover}
    this.layers = []; // functions (ctx, map) drawn over the image
    this.panning = null;
    this.space = false;
    this.panTool = false;
    this.fitted = false;
    this.pending = false;
    new ResizeObserver(() => this.resize()).observe(canvas.parentElement);
    canvas.addEventListener('wheel', (e) => this.wheel(e), { passive: false });
    canvas.addEventListener('pointerdown', (e) => this.down(e));
    canvas.addEventListener('pointermove', (e) => this.move(e));
    canvas.addEventListener('pointerup', (e) => this.up(e));
    canvas.addEventListener('pointercancel', (e) => this.up(e));
    canvas.addEventListener('contextmenu', (e) => e.preventDefault());
    window.addEventListener('keydown', (e) => {
      if (e.code === 'Space' && !isTyping(e)) {
        this.space = true;
        e.preventDefault();
      }
    });
    window.addEventListener('keyup', (e) => {
      if (e.code === 'Space') this.space = false;
    });
    this.resize();
  }

  resize() {
    const r = this.canvas.parentElement.getBoundingClientRect();
    const dpr = window.devicePixelRatio || 1;
    this.canvas.width = Math.max(1, Math.round(r.width * dpr));
    this.canvas.height = Math.max(1, Math.round(r.height * dpr));
    this.canvas.style.width = `${r.width}px`;
    this.canvas.style.height = `${r.height}px`;
    this.ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    if (!this.fitted) this.fit();
    this.redraw();
  }

  /** Shows the whole terrain, centred. */
  fit() {
    const r = this.canvas.getBoundingClientRect();
    if (!r.width || !r.height) return;
    const m = 16;
    this.s = Math.min((r.width - 2 * m) / this.size[0], (r.height - 2 * m) / this.size[1]);
    this.ox = (r.width - this.size[0] * this.s) / 2;
    this.oy = (r.height - this.size[1] * this.s) / 2;
    this.fitted = true;
    this.redraw();
  }

  setSize(w, h) {
    if (w !== this.size[0] || h !== this.size[1]) {
      this.size = [w, h];
      this.fitted = false;
      this.fit();
    }
  }

  toScreen(p) {
    return [p[0] * this.s + this.ox, p[1] * this.s + this.oy];
  }

  toTerrain(q) {
    return [(q[0] - this.ox) / this.s, (q[1] - this.oy) / this.s];
  }

  /** Terrain pixels per screen pixel (for hit tolerances). */
  px(screen) {
    return screen / this.s;
  }

  eventPoint(e) {
    const r = this.canvas.getBoundingClientRect();
    return this.toTerrain([e.clientX - r.left, e.clientY - r.top]);
  }

  wheel(e) {
    e.preventDefault();
    const r = this.canvas.getBoundingClientRect();
    const q = [e.clientX - r.left, e.clientY - r.top];
    const p = this.toTerrain(q);
    const k = Math.exp(-e.deltaY * 0.0015);
    this.s = Math.min(64, Math.max(0.05, this.s * k));
    this.ox = q[0] - p[0] * this.s;
    this.oy = q[1] - p[1] * this.s;
    this.redraw();
  }

  down(e) {
    this.canvas.setPointerCapture(e.pointerId);
    if (e.button === 1 || e.button === 2 || this.space || this.panTool) {
      this.panning = [e.clientX, e.clientY, this.ox, this.oy];
      this.canvas.classList.add('panning');
      return;
    }
    if (e.button === 0 && this.handler) this.handler.down(this.eventPoint(e), e);
  }

  move(e) {
    if (this.panning) {
      const [x, y, ox, oy] = this.panning;
      this.ox = ox + e.clientX - x;
      this.oy = oy + e.clientY - y;
      this.redraw();
      return;
    }
    const p = this.eventPoint(e);
    if (this.handler) {
      if (e.buttons & 1) this.handler.move(p, e);
      else this.handler.hover(p, e);
    }
  }

  up(e) {
    if (this.panning) {
      this.panning = null;
      this.canvas.classList.remove('panning');
      return;
    }
    if (e.button === 0 && this.handler) this.handler.up(this.eventPoint(e), e);
  }

  /** Redraws on the next animation frame (many calls, one draw). */
  redraw() {
    if (this.pending) return;
    this.pending = true;
    requestAnimationFrame(() => {
      this.pending = false;
      this.draw();
    });
  }

  draw() {
    const ctx = this.ctx;
    const r = this.canvas.getBoundingClientRect();
    ctx.clearRect(0, 0, r.width, r.height);
    ctx.fillStyle = '#1d2126';
    ctx.fillRect(0, 0, r.width, r.height);
    const [w, h] = this.size;
    if (this.image) {
      ctx.imageSmoothingEnabled = this.s * (w / this.image.width) < 2;
      ctx.drawImage(this.image, this.ox, this.oy, w * this.s, h * this.s);
    }
    ctx.strokeStyle = '#555';
    ctx.lineWidth = 1;
    ctx.strokeRect(this.ox - 0.5, this.oy - 0.5, w * this.s + 1, h * this.s + 1);
    for (const layer of this.layers) {
      ctx.save();
      layer(ctx, this);
      ctx.restore();
    }
  }
}

/** Whether a key event is typing into a form field. */
export function isTyping(e) {
  const t = e.target;
  return t && (t.tagName === 'INPUT' || t.tagName === 'SELECT' || t.tagName === 'TEXTAREA');
}
