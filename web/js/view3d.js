// The 3D view: the heightfield as a WebGL mesh wearing the preview image
// the map shows, under a perspective camera with orbit (drag), zoom
// (wheel) and a vertical exaggeration. Positions are metres — x and y from
// the database's cell size, z the heights — so at 1× the relief has its
// true proportions. It takes the map's place in the page (toggled with it)
// and reuses the page's data: the height samples fetched after every frame
// and the patched preview, so it costs no request of its own. Drawing
// stays on the map; this view only looks.

/** At most this many vertices per side: every index fits 16 bits (WebGL 1 needs no extension). */
const SIDE = 256;

// Light from the north-west and above, like the preview's hillshade, so
// the mesh's own shading agrees with its texture.
const LIGHT = [-0.5, 0.5, 0.707];

const VERTEX = `
attribute vec3 a_pos;
attribute vec2 a_grad;
attribute vec2 a_uv;
uniform mat4 u_mvp;
uniform float u_ex;
uniform float u_base;
uniform vec3 u_light;
varying vec2 v_uv;
varying float v_light;
void main() {
  v_uv = a_uv;
  vec3 n = normalize(vec3(-a_grad * u_ex, 1.0));
  v_light = 0.6 + 0.4 * max(dot(n, u_light), 0.0) / max(u_light.z, 1e-3);
  gl_Position = u_mvp * vec4(a_pos.xy, (a_pos.z - u_base) * u_ex, 1.0);
}`;

const FRAGMENT = `
precision mediump float;
uniform sampler2D u_tex;
varying vec2 v_uv;
varying float v_light;
void main() {
  vec3 c = texture2D(u_tex, v_uv).rgb * min(v_light, 1.15);
  gl_FragColor = vec4(c, 1.0);
}`;

/** Floats per vertex: x, y, z (metres), dz/dx, dz/dy, u, v. */
const STRIDE = 7;

export class View3d {
  /**
   * `root` holds the canvas, the exaggeration slider and the message;
   * `source()` gives the page's data: {heights, image, revision, cell, size}.
   */
  constructor(root, source) {
    this.root = root;
    this.canvas = root.querySelector('canvas');
    this.message = root.querySelector('.message');
    this.slider = root.querySelector('input[type=range]');
    this.readout = root.querySelector('output');
    this.source = source;
    this.shown = false;
    this.gl = null;
    this.failed = null; // why there is no WebGL, once known
    this.mesh = null; // {heights, count, extent, lo, hi}
    this.textured = -1; // the revision of the uploaded image
    this.imageDirty = true;
    this.ex = Number(this.slider.value) || 1;
    this.cam = null; // {yaw, pitch, dist}, set from the first mesh
    this.drag = null;
    this.pending = false;
    this.draws = 0;
    new ResizeObserver(() => this.resize()).observe(root);
    this.slider.addEventListener('input', () => this.setExaggeration(Number(this.slider.value)));
    this.canvas.addEventListener('pointerdown', (e) => this.down(e));
    this.canvas.addEventListener('pointermove', (e) => this.move(e));
    this.canvas.addEventListener('pointerup', () => (this.drag = null));
    this.canvas.addEventListener('pointercancel', () => (this.drag = null));
    this.canvas.addEventListener('wheel', (e) => this.wheel(e), { passive: false });
    this.canvas.addEventListener('contextmenu', (e) => e.preventDefault());
    // A GPU reset or a driver update takes the context away: say so, and
    // rebuild everything when the browser gives it back.
    this.canvas.addEventListener('webglcontextlost', (e) => {
      e.preventDefault();
      this.gl = null;
      this.say('the 3D view lost its WebGL context; waiting for the browser to restore it…');
    });
    this.canvas.addEventListener('webglcontextrestored', () => {
      this.say(null);
      this.init();
      this.redraw();
    });
    this.setExaggeration(this.ex);
  }

  /** Shows or hides the view; the first showing creates the WebGL context. */
  show(on) {
    this.shown = on;
    this.root.hidden = !on;
    if (!on) return;
    if (!this.gl && !this.failed) this.init();
    this.resize();
  }

  /** New height samples: rebuild the mesh when next drawn. */
  heightsChanged() {
    if (this.shown) this.redraw();
  }

  /** The preview changed (a frame's tile or a new view): upload it when next drawn. */
  imageChanged() {
    this.imageDirty = true;
    if (this.shown) this.redraw();
  }

  setExaggeration(ex) {
    this.ex = Math.max(0, ex);
    this.slider.value = String(this.ex);
    this.readout.textContent = `${this.ex.toFixed(1)}×`;
    this.redraw();
  }

  /** The camera that shows the whole terrain from the south, 35° up. */
  reset() {
    if (!this.mesh) return;
    const [ex, ey] = this.mesh.extent;
    this.cam = { yaw: 0.35, pitch: 0.6, dist: 1.1 * Math.hypot(ex, ey) };
    this.redraw();
  }

  say(text) {
    this.message.hidden = !text;
    this.message.textContent = text || '';
  }

  init() {
    let gl = null;
    try {
      gl = this.canvas.getContext('webgl2', { antialias: true }) || this.canvas.getContext('webgl', { antialias: true });
    } catch (_) {
      /* reported below, like a null context */
    }
    if (!gl) {
      this.failed = 'no WebGL';
      this.say('The 3D view needs WebGL, which this browser does not offer (turned off, or no graphics driver). The map still works: press 3 or the 3D button to go back.');
      return;
    }
    try {
      this.program = link(gl, VERTEX, FRAGMENT);
    } catch (e) {
      this.failed = String(e.message || e);
      this.say(`The 3D view could not start: ${this.failed}`);
      return;
    }
    const p = this.program;
    this.loc = {
      pos: gl.getAttribLocation(p, 'a_pos'),
      grad: gl.getAttribLocation(p, 'a_grad'),
      uv: gl.getAttribLocation(p, 'a_uv'),
      mvp: gl.getUniformLocation(p, 'u_mvp'),
      ex: gl.getUniformLocation(p, 'u_ex'),
      base: gl.getUniformLocation(p, 'u_base'),
      light: gl.getUniformLocation(p, 'u_light'),
      tex: gl.getUniformLocation(p, 'u_tex'),
    };
    this.vbo = gl.createBuffer();
    this.ibo = gl.createBuffer();
    this.tex = gl.createTexture();
    this.webgl2 = typeof WebGL2RenderingContext !== 'undefined' && gl instanceof WebGL2RenderingContext;
    this.gl = gl;
    this.mesh = null;
    this.imageDirty = true;
    this.canvas.dataset.webgl = this.webgl2 ? '2' : '1';
  }

  resize() {
    if (!this.shown) return;
    const r = this.root.getBoundingClientRect();
    const dpr = window.devicePixelRatio || 1;
    this.canvas.width = Math.max(1, Math.round(r.width * dpr));
    this.canvas.height = Math.max(1, Math.round(r.height * dpr));
    this.canvas.style.width = `${r.width}px`;
    this.canvas.style.height = `${r.height}px`;
    this.redraw();
  }

  /** Draws on the next animation frame (many calls, one draw). */
  redraw() {
    if (this.pending || !this.shown) return;
    this.pending = true;
    requestAnimationFrame(() => {
      this.pending = false;
      this.draw();
    });
  }

  draw() {
    const gl = this.gl;
    const s = this.source();
    if (!gl || !this.shown || !s.heights || !s.image) return;
    if (!this.mesh || this.mesh.heights !== s.heights || this.mesh.cell !== s.cell) this.upload(s);
    if (this.imageDirty) this.texture(s);
    gl.viewport(0, 0, this.canvas.width, this.canvas.height);
    gl.clearColor(0.114, 0.129, 0.149, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    gl.useProgram(this.program);
    gl.uniformMatrix4fv(this.loc.mvp, false, this.matrix());
    gl.uniform1f(this.loc.ex, this.ex);
    gl.uniform1f(this.loc.base, this.mesh.lo);
    gl.uniform3fv(this.loc.light, LIGHT);
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D, this.tex);
    gl.uniform1i(this.loc.tex, 0);
    gl.bindBuffer(gl.ARRAY_BUFFER, this.vbo);
    const attrib = (loc, n, offset) => {
      gl.enableVertexAttribArray(loc);
      gl.vertexAttribPointer(loc, n, gl.FLOAT, false, STRIDE * 4, offset * 4);
    };
    attrib(this.loc.pos, 3, 0);
    attrib(this.loc.grad, 2, 3);
    attrib(this.loc.uv, 2, 5);
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, this.ibo);
    gl.drawElements(gl.TRIANGLES, this.mesh.count, gl.UNSIGNED_SHORT, 0);
    // For scripts and the browser test: what the last draw showed.
    this.draws += 1;
    const d = this.canvas.dataset;
    d.draws = String(this.draws);
    d.heightsRevision = String(s.heights.revision);
    d.imageRevision = String(this.textured);
  }

  /**
   * The mesh from the page's height samples, thinned to at most SIDE
   * vertices a side: positions in metres, the slope (for shading at any
   * exaggeration, in the shader) and where each vertex sits on the preview.
   */
  upload(s) {
    const gl = this.gl;
    const hs = s.heights;
    const k = Math.ceil(Math.max(hs.w, hs.h) / SIDE);
    const nx = Math.ceil(hs.w / k), ny = Math.ceil(hs.h / k);
    const [sw, sh] = s.size;
    const step = k * hs.stride; // terrain pixels between vertices
    const at = (i, j) => hs.data[j * k * hs.w + i * k];
    const v = new Float32Array(nx * ny * STRIDE);
    let lo = Infinity, hi = -Infinity;
    for (let j = 0; j < ny; j++) {
      for (let i = 0; i < nx; i++) {
        const z = at(i, j);
        lo = Math.min(lo, z);
        hi = Math.max(hi, z);
        const i0 = Math.max(0, i - 1), i1 = Math.min(nx - 1, i + 1);
        const j0 = Math.max(0, j - 1), j1 = Math.min(ny - 1, j + 1);
        const o = (j * nx + i) * STRIDE;
        // Rows run south: world y is minus the row, so north is +y.
        v[o] = i * step * s.cell;
        v[o + 1] = -j * step * s.cell;
        v[o + 2] = z;
        v[o + 3] = i1 > i0 ? (at(i1, j) - at(i0, j)) / ((i1 - i0) * step * s.cell) : 0;
        v[o + 4] = j1 > j0 ? -(at(i, j1) - at(i, j0)) / ((j1 - j0) * step * s.cell) : 0;
        v[o + 5] = (i * step + 0.5) / sw;
        v[o + 6] = (j * step + 0.5) / sh;
      }
    }
    const idx = new Uint16Array((nx - 1) * (ny - 1) * 6);
    let n = 0;
    for (let j = 0; j + 1 < ny; j++) {
      for (let i = 0; i + 1 < nx; i++) {
        const a = j * nx + i, b = a + 1, c = a + nx, d = c + 1;
        idx.set([a, c, b, b, c, d], n);
        n += 6;
      }
    }
    gl.bindBuffer(gl.ARRAY_BUFFER, this.vbo);
    gl.bufferData(gl.ARRAY_BUFFER, v, gl.STATIC_DRAW);
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, this.ibo);
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, idx, gl.STATIC_DRAW);
    const extent = [(nx - 1) * step * s.cell, (ny - 1) * step * s.cell];
    const first = !this.mesh;
    const resized = this.mesh && (this.mesh.extent[0] !== extent[0] || this.mesh.extent[1] !== extent[1]);
    this.mesh = { heights: hs, cell: s.cell, count: n, extent, lo: isFinite(lo) ? lo : 0, hi: isFinite(hi) ? hi : 0 };
    if (first || resized || !this.cam) this.reset();
  }

  texture(s) {
    const gl = this.gl;
    gl.bindTexture(gl.TEXTURE_2D, this.tex);
    gl.pixelStorei(gl.UNPACK_FLIP_Y_WEBGL, false);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, gl.RGBA, gl.UNSIGNED_BYTE, s.image);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
    // Mipmaps keep contours from shimmering far away; WebGL 1 has none for
    // images whose sides are not powers of two.
    const pot = (n) => (n & (n - 1)) === 0;
    if (this.webgl2 || (pot(s.image.width) && pot(s.image.height))) {
      gl.generateMipmap(gl.TEXTURE_2D);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR_MIPMAP_LINEAR);
    } else {
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR);
    }
    this.imageDirty = false;
    this.textured = s.revision;
  }

  /**
   * Projection × view: orbit around the terrain's centre at its true mid
   * height, whatever the exaggeration, so that the slider moves the relief
   * and not the camera.
   */
  matrix() {
    const m = this.mesh, c = this.cam;
    const target = [m.extent[0] / 2, -m.extent[1] / 2, (m.hi - m.lo) / 2];
    const cp = Math.cos(c.pitch);
    const eye = [
      target[0] + c.dist * Math.sin(c.yaw) * cp,
      target[1] - c.dist * Math.cos(c.yaw) * cp,
      target[2] + c.dist * Math.sin(c.pitch),
    ];
    const aspect = this.canvas.width / this.canvas.height;
    const reach = Math.hypot(m.extent[0], m.extent[1], (m.hi - m.lo) * this.ex);
    const proj = perspective(Math.PI / 4, aspect, c.dist / 100, c.dist + 2 * reach);
    return multiply(proj, lookAt(eye, target, [0, 0, 1]));
  }

  down(e) {
    this.canvas.setPointerCapture(e.pointerId);
    this.drag = [e.clientX, e.clientY];
  }

  move(e) {
    if (!this.drag || !this.cam) return;
    const [x, y] = this.drag;
    this.drag = [e.clientX, e.clientY];
    this.cam.yaw -= (e.clientX - x) * 0.008;
    this.cam.pitch = Math.min(1.55, Math.max(0.05, this.cam.pitch + (e.clientY - y) * 0.008));
    this.redraw();
  }

  wheel(e) {
    e.preventDefault();
    if (!this.cam || !this.mesh) return;
    const size = Math.hypot(...this.mesh.extent);
    this.cam.dist = Math.min(5 * size, Math.max(0.05 * size, this.cam.dist * Math.exp(e.deltaY * 0.0015)));
    this.redraw();
  }
}

function link(gl, vs, fs) {
  const shader = (type, src) => {
    const s = gl.createShader(type);
    gl.shaderSource(s, src);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(`shader: ${gl.getShaderInfoLog(s)}`);
    return s;
  };
  const p = gl.createProgram();
  gl.attachShader(p, shader(gl.VERTEX_SHADER, vs));
  gl.attachShader(p, shader(gl.FRAGMENT_SHADER, fs));
  gl.linkProgram(p);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(`program: ${gl.getProgramInfoLog(p)}`);
  return p;
}

// Column-major 4×4 matrices, as WebGL takes them.

function perspective(fovy, aspect, near, far) {
  const f = 1 / Math.tan(fovy / 2), nf = 1 / (near - far);
  return new Float32Array([f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) * nf, -1, 0, 0, 2 * far * near * nf, 0]);
}

function lookAt(eye, target, up) {
  const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const norm = (a) => {
    const l = Math.hypot(...a) || 1;
    return [a[0] / l, a[1] / l, a[2] / l];
  };
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const z = norm(sub(eye, target));
  const x = norm(cross(up, z));
  const y = cross(z, x);
  return new Float32Array([x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0, -dot(x, eye), -dot(y, eye), -dot(z, eye), 1]);
}

function multiply(a, b) {
  const out = new Float32Array(16);
  for (let c = 0; c < 4; c++) {
    for (let r = 0; r < 4; r++) {
      let s = 0;
      for (let k = 0; k < 4; k++) s += a[k * 4 + r] * b[c * 4 + k];
      out[c * 4 + r] = s;
    }
  }
  return out;
}
