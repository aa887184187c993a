// Jog that cannot run away: a jog runs only while a button is held or a key is down. While
// it runs the page confirms it every CONFIRM_MS (the server's deadman stops the axis when
// the confirmations stop); release, key-up, window blur, a hidden tab or a lost connection
// stop it at once.

export const CONFIRM_MS = 25;      // 10x inside the server's 250 ms deadman (a loaded box)
const ASK_EVERY = 8;               // every 8th confirmation asks whether the jog still runs

export class Jogger {
  /**
   * api: {start(axis, dir, opts) -> Promise<handle>, confirm(handle), stop(handle, axis)}
   * onState(active: {axis, dir} | null, error?)
   */
  constructor(api, { onState = () => {} } = {}) {
    this.api = api;
    this.onState = onState;
    this.active = null;
    this.timer = 0;
    this.keys = new Map();   // key -> [axis, dir]
    this.keyboardOn = false;
    this.opts = () => ({});
    window.addEventListener("blur", () => this.release("window lost focus"));
    document.addEventListener("visibilitychange", () => { if (document.hidden) this.release("tab hidden"); });
    window.addEventListener("pagehide", () => this.release("page closed"));
    window.addEventListener("keydown", (e) => this._key(e, true));
    window.addEventListener("keyup", (e) => this._key(e, false));
  }

  /** Wire a hold-to-jog button. */
  bindButton(btn, axis, dir) {
    btn.addEventListener("pointerdown", (e) => {
      if (e.button !== 0) return;
      btn.setPointerCapture(e.pointerId);
      this.press(typeof axis === "function" ? axis() : axis, dir, "button");
    });
    for (const ev of ["pointerup", "pointercancel", "lostpointercapture"]) {
      btn.addEventListener(ev, () => this.release("released"));
    }
    btn.addEventListener("contextmenu", (e) => e.preventDefault());
  }

  setKeys(map) { this.keys = new Map(Object.entries(map)); }

  _key(e, down) {
    if (!this.keyboardOn) return;
    const t = e.target;
    if (t && (t.tagName === "INPUT" || t.tagName === "SELECT" || t.tagName === "TEXTAREA")) return;
    const hit = this.keys.get(e.key);
    if (!hit) return;
    e.preventDefault();
    if (down) {
      if (e.repeat) return;
      const [axis, dir] = hit;
      this.press(typeof axis === "function" ? axis() : axis, dir, `key ${e.key}`);
    } else if (this.active && this.active.source === `key ${e.key}`) {
      this.release("key up");
    }
  }

  async press(axis, dir, source) {
    if (this.active) await this.release("another jog");
    const me = { axis, dir, source, handle: null, stopped: false };
    this.active = me;
    this.onState(me);
    try {
      me.handle = await this.api.start(axis, dir, this.opts());
    } catch (err) {
      if (this.active === me) this.active = null;
      this.onState(null, err);
      return;
    }
    if (me.stopped) {             // released before the start was acknowledged
      this.api.stop(me.handle, axis).catch(() => {});
      return;
    }
    let n = 0;
    this.timer = setInterval(async () => {
      if (this.active !== me) return;
      n += 1;
      if (n % ASK_EVERY !== 0 || !this.api.check) { this.api.confirm(me.handle, axis); return; }
      // a jog the server ended (limit ahead, deadman, fault) is released here too, with why
      try {
        const r = await this.api.check(me.handle, axis);
        if (r && r.active === false && this.active === me) {
          this.active = null;
          me.stopped = true;
          clearInterval(this.timer);
          this.timer = 0;
          this.onState(null, { message: `jog ended by the controller: ${r.reason || "stopped"}` });
        }
      } catch { /* the next confirmation or the lost-connection release handles it */ }
    }, CONFIRM_MS);
  }

  async release(why) {
    const me = this.active;
    if (!me) return;
    this.active = null;
    me.stopped = true;
    clearInterval(this.timer);
    this.timer = 0;
    this.onState(null);
    if (me.handle !== null) {
      try { await this.api.stop(me.handle, me.axis, why); } catch (err) { this.onState(null, err); }
    }
  }
}
