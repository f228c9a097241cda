// The editor's HTTP API (see src/server/api/routes.rs), with the page's side
// of coalescing: at most one scene document in flight; a newer one waits
// in a single slot, replacing any older waiting one (latest wins), so a
// drag never queues stale work.

export class ApiError extends Error {
  constructor(status, field, message) {
    super(field && field !== '$' ? `${field}: ${message}` : message);
    this.status = status;
    this.field = field;
  }
}

async function check(res) {
  if (res.ok) return res;
  let body = null;
  try {
    body = await res.json();
  } catch (_) {
    /* not JSON */
  }
  const e = body && body.error;
  throw new ApiError(res.status, e ? e.field : '$', e ? e.message : `${res.status} ${res.statusText}`);
}

const JSON_HEADERS = { 'Content-Type': 'application/json' };

export class Api {
  constructor() {
    this.session = null;
    this.inFlight = null; // {doc, commit, kind, t0}
    this.waiting = null;
    this.onFrame = () => {};
    this.onError = () => {};
    this.onIdle = () => {};
    this.idleWaiters = [];
  }

  async info() {
    return (await check(await fetch('/api/info'))).json();
  }

  url(path) {
    return `/api/sessions/${this.session}${path}`;
  }

  async create(doc) {
    const init = { method: 'POST' };
    if (doc) {
      init.headers = JSON_HEADERS;
      init.body = JSON.stringify({ scene: doc });
    }
    // For scripts and the browser test: a session request in flight.
    document.body.dataset.session = 'opening';
    try {
      const frame = await (await check(await fetch('/api/sessions', init))).json();
      this.session = frame.session;
      return frame;
    } finally {
      document.body.dataset.session = this.session ? 'open' : 'none';
    }
  }

  /**
   * Sends a scene document. `kind` names the edit (for latency logs);
   * `commit` makes it an undo step (false while dragging).
   */
  send(doc, { commit = true, kind = 'edit' } = {}) {
    // Serialized now: the page keeps editing its document meanwhile.
    const job = { body: JSON.stringify(doc), commit, kind, t0: performance.now() };
    if (this.inFlight) {
      // A commit that is replaced is committed by its replacement.
      if (this.waiting) job.commit = job.commit || this.waiting.commit;
      this.waiting = job;
      return;
    }
    this.run(job);
  }

  busy() {
    return !!(this.inFlight || this.waiting);
  }

  /** Resolves once nothing is in flight or waiting. */
  idle() {
    if (!this.busy()) return Promise.resolve();
    return new Promise((resolve) => this.idleWaiters.push(resolve));
  }

  async run(job) {
    this.inFlight = job;
    try {
      const res = await fetch(this.url(`/scene?commit=${job.commit}`), {
        method: 'PUT',
        headers: JSON_HEADERS,
        body: job.body,
      });
      const frame = await (await check(res)).json();
      if (!frame.superseded) await this.onFrame(frame, job);
    } catch (e) {
      this.onError(e, job);
    }
    this.inFlight = null;
    const next = this.waiting;
    this.waiting = null;
    if (next) {
      this.run(next);
    } else {
      this.onIdle();
      for (const w of this.idleWaiters.splice(0)) w();
    }
  }

  async post(path, kind) {
    const t0 = performance.now();
    const frame = await (await check(await fetch(this.url(path), { method: 'POST' }))).json();
    return { frame, job: { kind, t0, commit: true } };
  }

  async view(view) {
    const res = await fetch(this.url('/view'), { method: 'PUT', headers: JSON_HEADERS, body: JSON.stringify(view) });
    return (await check(res)).json();
  }

  /** Keeps (→ a frame showing it) or discards the unsaved work found at start. */
  async recovery(keep) {
    return (await check(await fetch(this.url(`/recovery?keep=${keep}`), { method: 'POST' }))).json();
  }

  /**
   * After a refused save: the saved file's version (`merge` false), or
   * this tab's changes on top of it (true), as a frame with its `scene`.
   */
  async reload(merge) {
    return (await check(await fetch(this.url(`/reload?merge=${merge}`), { method: 'POST' }))).json();
  }

  /** Saves; `force` replaces a file another tab saved since this one loaded. */
  async save(force = false) {
    return (await check(await fetch(this.url(force ? '/save?force=true' : '/save'), { method: 'POST' }))).json();
  }

  async preview() {
    const res = await check(await fetch(this.url('/preview.png'), { cache: 'no-store' }));
    return createImageBitmap(await res.blob());
  }

  /** A frame's changed part of the preview, or null when it is gone. */
  async tile(revision) {
    const res = await fetch(this.url(`/tile.png?revision=${revision}`), { cache: 'no-store' });
    if (res.status === 404) return null;
    return createImageBitmap(await (await check(res)).blob());
  }

  /** The last frame's height samples and the revision they belong to. */
  async heights() {
    const res = await check(await fetch(this.url('/heights'), { cache: 'no-store' }));
    const buf = await res.arrayBuffer();
    const head = new Uint32Array(buf, 0, 3);
    const revision = Number(res.headers.get('x-revision'));
    return { w: head[0], h: head[1], stride: head[2], data: new Float32Array(buf, 12), revision };
  }

  /**
   * The heartbeat → {stale}: whether another tab saved since this one
   * loaded. Rejects when the session or the server is gone.
   */
  async ping() {
    return (await check(await fetch(this.url('/ping'), { method: 'POST' }))).json();
  }

  close() {
    if (this.session) navigator.sendBeacon(this.url('/close'));
  }
}
