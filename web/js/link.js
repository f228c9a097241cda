// The page's hold on its server session: opening one (retrying while the
// slots are full or the server is away), the heartbeat that keeps it, the
// beacon that frees it when the page goes, and reconnecting after the
// server was gone. The document lives in the page, so a reconnect re-sends
// it and nothing the artist did is lost.

import { ApiError } from './api.js';

const $ = (id) => document.getElementById(id);
const pause = (ms) => new Promise((r) => setTimeout(r, ms));

/** fetch() rejects with a TypeError when the server cannot be reached. */
export const unreachable = (e) => e instanceof TypeError;

/** Worth trying again: the server away, or busy (503: slots, memory, loading). */
const transient = (e) => unreachable(e) || (e instanceof ApiError && e.status === 503);

/**
 * Opens a session on `doc` (the server's saved scene when null), retrying
 * what is transient; `say` shows why it waits.
 */
export async function open(api, doc, say) {
  for (;;) {
    try {
      return await api.create(doc);
    } catch (e) {
      if (!transient(e)) throw e;
      say(unreachable(e) ? 'server unreachable — retrying' : `${e.message} — retrying`);
      await pause(1000);
    }
  }
}

/** Closes the session when the page is hidden for good (reload, tab closed). */
export function closeOnHide(api) {
  window.addEventListener('pagehide', () => api.close());
}

export class Link {
  constructor(ed, onFrame) {
    this.ed = ed;
    this.onFrame = onFrame;
    this.reconnecting = null;
  }

  /**
   * Pings at the server's heartbeat; a missed ping means reconnecting, a
   * stale answer that another tab saved (the saver tells the artist).
   */
  heartbeat() {
    const every = (this.ed.info.sessions && this.ed.info.sessions.heartbeat_ms) || 2000;
    setInterval(() => {
      if (this.reconnecting) return;
      this.ed.api
        .ping()
        .then((r) => this.ed.saver.stale(r.stale))
        .catch((e) => this.lost(e));
    }, every);
  }

  /**
   * An error from the server: the session or the server gone starts a
   * reconnect (true); anything else is the caller's to show (false).
   */
  lost(e) {
    const gone = e instanceof ApiError && e.status === 404 && e.field === 'id';
    if (!gone && !unreachable(e)) return false;
    if (!this.reconnecting) {
      this.reconnecting = this.reconnect().finally(() => (this.reconnecting = null));
    }
    return true;
  }

  async reconnect() {
    const banner = $('offline');
    const say = (text) => {
      banner.textContent = text;
      banner.hidden = false;
    };
    const { ed } = this;
    for (;;) {
      try {
        const info = await ed.api.info();
        if (info.status === 'ready') {
          ed.info = info;
          break;
        }
      } catch (e) {
        if (!unreachable(e)) throw e;
      }
      say('server unreachable — retrying');
      await pause(1000);
    }
    // Whatever the artist did meanwhile is in ed.doc: send that.
    const sent = JSON.stringify(ed.doc);
    const frame = await open(ed.api, JSON.parse(sent), say);
    const mine = ed.doc;
    await this.onFrame(frame);
    if (JSON.stringify(mine) !== sent) {
      ed.doc = mine;
      ed.api.send(mine, { kind: 'reconnect' });
    }
    banner.hidden = true;
  }
}
