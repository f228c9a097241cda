// Saving to the server's scene file, and what the page offers when another
// tab saved since this one loaded — learnt from the heartbeat, or from a
// refused save (409, field `revision`): reload the file's version, merge
// this tab's changes on top of it and save, or save anyway. Never a silent
// overwrite; and a reload is an undo step, so Undo brings this tab's
// version back.

import { ApiError } from './api.js';

const $ = (id) => document.getElementById(id);

export class Saver {
  /**
   * `showFrame(frame, job)` draws a frame; `news(text)` puts a line on the
   * status bar.
   */
  constructor(ed, showFrame, news) {
    this.ed = ed;
    this.showFrame = showFrame;
    this.news = news;
    // Told already that another tab saved: the heartbeat says it once.
    this.told = false;
    $('conflict-merge').onclick = () => this.reload(true);
    $('conflict-reload').onclick = () => this.reload(false);
    $('conflict-overwrite').onclick = () => this.save(true);
    $('conflict-cancel').onclick = () => this.shown(null);
  }

  /** Saves (`force`: even over another tab's save); true when saved. */
  async save(force = false) {
    await this.ed.api.idle();
    try {
      const r = await this.ed.api.save(force);
      this.shown(null);
      this.news(`saved ${r.path}`);
      return true;
    } catch (e) {
      if (e instanceof ApiError && e.status === 409 && e.field === 'revision') this.shown(e.message);
      else this.ed.error(e);
      return false;
    }
  }

  /** The heartbeat's news: whether another tab saved since this one loaded. */
  stale(stale) {
    if (!stale) this.told = false;
    else if (!this.told) {
      this.told = true;
      const file = this.ed.info.scene_file || 'the scene file';
      this.shown(`${file} was saved from another tab after this one opened it. Merge to keep both tabs' work, or reload to take the saved version.`);
    }
  }

  /** Takes the saved file's version, or merges this tab's changes into it and saves. */
  async reload(merge) {
    const { ed } = this;
    await ed.api.idle();
    try {
      const t0 = performance.now();
      const frame = await ed.api.reload(merge);
      this.shown(null);
      ed.tools.cancel();
      await this.showFrame(frame, { kind: merge ? 'merge' : 'reload', t0 });
      ed.refresh();
      if (merge) await this.save();
      else this.news("reloaded the saved file (Undo brings this tab's version back)");
    } catch (e) {
      ed.error(e);
    }
  }

  /** Shows the conflict banner with `message`, or hides it (null). */
  shown(message) {
    $('conflict').hidden = !message;
    $('conflict-text').textContent = message || '';
    // For scripts and the browser test.
    document.body.dataset.conflict = message ? 'open' : 'none';
  }
}
