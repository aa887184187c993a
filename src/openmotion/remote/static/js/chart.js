// A live scope chart on the vendored uPlot: a ring of samples (time + N channels), a
// window that follows the newest sample, pause, drag-to-zoom (double click: back to live),
// a level/edge trigger, CSV export. Redraws at most once per animation frame, and not
// while hidden (setHidden: its page is not shown; the samples still arrive).

/* global uPlot */

const PALETTE = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b",
  "#e377c2", "#17becf", "#7f7f7f", "#bcbd22", "#393b79", "#637939"];

export class LiveChart {
  /**
   * channels: [{key, label, unit, scale}] (scale groups channels sharing a y axis).
   * windowS: seconds shown while live; capacity: samples kept in the browser.
   */
  constructor(container, { channels, windowS = 5, capacity = 60000, height = 320, title = "" }) {
    this.container = container;
    this.channels = channels.map((c, i) => ({ color: PALETTE[i % PALETTE.length], scale: c.unit || "y", ...c }));
    this.windowS = windowS;
    this.capacity = capacity;
    this.t = [];
    this.cols = this.channels.map(() => []);
    this.paused = false;
    this.hidden = false;
    this.zoomed = false;
    this.trigger = { mode: "off", channel: 0, level: 0, edge: "rising", pre: 0.2 };
    this.frozen = null;     // [t0, t1] while a trigger capture is shown
    this.armedFrom = 0;     // only samples after this time can trigger
    this.triggeredAt = null;
    this.onTrigger = null;
    this.samplesIn = 0;
    this._raf = 0;
    this.plot = new uPlot(this._opts(height, title), [[], ...this.channels.map(() => [])], container);
    this._observe();
  }

  _opts(height, title) {
    const scales = { x: { time: false } };
    const axes = [{ label: "t (s)" }];
    const seen = new Set();
    for (const c of this.channels) {
      if (seen.has(c.scale)) continue;
      seen.add(c.scale);
      scales[c.scale] = { auto: true };
      const side = seen.size === 1 ? 3 : 1;
      axes.push({ scale: c.scale, label: c.scale, side, show: seen.size <= 2, grid: { show: seen.size === 1 } });
    }
    return {
      title,
      width: Math.max(300, this.container.clientWidth || 600),
      height,
      scales,
      axes,
      legend: { live: true },
      cursor: { drag: { x: true, y: false, setScale: true } },
      series: [{ label: "t" }, ...this.channels.map((c) => ({
        label: c.unit ? `${c.label} (${c.unit})` : c.label, stroke: c.color, scale: c.scale, width: 1.5,
        points: { show: false }, show: c.show !== false,
      }))],
      hooks: {
        setSelect: [() => { this.zoomed = true; }],
      },
    };
  }

  _observe() {
    if (typeof ResizeObserver === "undefined") return;
    this._ro = new ResizeObserver(() => {
      const w = this.container.clientWidth;
      if (w > 0 && Math.abs(w - this.plot.width) > 4) this.plot.setSize({ width: w, height: this.plot.height });
    });
    this._ro.observe(this.container);
    this.plot.over.addEventListener("dblclick", () => { this.zoomed = false; this.frozen = null; this._schedule(); });
  }

  /** Replace the whole buffer (history loaded from the server). */
  setData(t, cols) {
    this.t = Array.from(t);
    this.cols = this.channels.map((c, i) => Array.from((cols && cols[i]) || []));
    this._trim();
    this._schedule();
  }

  /** Append samples: t = [..], cols = [[..] per channel]. Runs the trigger. */
  append(t, cols) {
    if (!t.length) return;
    const start = this.t.length;
    const last = start ? this.t[start - 1] : -Infinity;
    let from = 0;
    while (from < t.length && t[from] <= last) from += 1;   // drop overlaps (history + live)
    if (from >= t.length) return;
    for (let k = from; k < t.length; k++) this.t.push(t[k]);
    this.cols.forEach((col, i) => {
      const src = cols[i] || [];
      for (let k = from; k < t.length; k++) col.push(src[k] ?? null);
    });
    this.samplesIn += t.length - from;
    this._runTrigger(Math.max(1, start));
    this._trim();
    if (!this.paused) this._schedule();
  }

  _trim() {
    const extra = this.t.length - this.capacity;
    if (extra > 0) {
      this.t.splice(0, extra);
      for (const col of this.cols) col.splice(0, extra);
    }
  }

  clear() {
    this.t = [];
    this.cols = this.channels.map(() => []);
    this.frozen = null;
    this.triggeredAt = null;
    this._schedule();
  }

  setPaused(p) {
    this.paused = p;
    if (!p) { this.zoomed = false; this._schedule(); }
  }

  setWindow(s) { this.windowS = s; this._schedule(); }

  /** Hidden (its page not shown): samples are kept, nothing is drawn until shown again. */
  setHidden(h) {
    this.hidden = Boolean(h);
    if (!this.hidden) this._schedule();
  }

  setVisible(i, show) { this.plot.setSeries(i + 1, { show }); }

  /** mode: "off" | "normal" (re-arms after each capture) | "single" (stays frozen). */
  setTrigger(opts) {
    this.trigger = { ...this.trigger, ...opts };
    this.frozen = null;
    this.triggeredAt = null;
    this.armedFrom = this.t.length ? this.t[this.t.length - 1] : 0;
    this._schedule();
  }

  rearm() { this.setTrigger({}); }

  _runTrigger(from) {
    const tr = this.trigger;
    if (tr.mode === "off") return;
    if (this.frozen && (tr.mode === "single" || this.t[this.t.length - 1] < this.frozen[1] + this.windowS * 0.5)) return;
    const col = this.cols[tr.channel];
    if (!col) return;
    for (let k = from; k < this.t.length; k++) {
      if (this.t[k] <= this.armedFrom) continue;
      const a = col[k - 1], b = col[k];
      if (a === null || b === null || a === undefined || b === undefined) continue;
      const up = a < tr.level && b >= tr.level;
      const down = a > tr.level && b <= tr.level;
      if ((tr.edge === "rising" && up) || (tr.edge === "falling" && down) || (tr.edge === "either" && (up || down))) {
        // exact crossing time between the two samples
        const f = b === a ? 0 : (tr.level - a) / (b - a);
        const tc = this.t[k - 1] + f * (this.t[k] - this.t[k - 1]);
        this.triggeredAt = tc;
        this.frozen = [tc - tr.pre * this.windowS, tc + (1 - tr.pre) * this.windowS];
        this.armedFrom = this.frozen[1];
        if (this.onTrigger) this.onTrigger(tc);
        return;
      }
    }
  }

  _schedule() {
    if (this._raf || this.hidden) return;
    this._raf = requestAnimationFrame(() => { this._raf = 0; this.redraw(); });
  }

  redraw() {
    const n = this.t.length;
    this.plot.setData([this.t, ...this.cols], false);
    if (this.zoomed) return;
    let x0, x1;
    if (this.frozen) [x0, x1] = this.frozen;
    else {
      x1 = n ? this.t[n - 1] : this.windowS;
      x0 = x1 - this.windowS;
    }
    this.plot.setScale("x", { min: x0, max: x1 });
  }

  /** The visible (or whole) buffer as CSV text: t, then one column per channel. */
  toCsv({ visibleOnly = false } = {}) {
    let i0 = 0, i1 = this.t.length;
    if (visibleOnly) {
      const { min, max } = this.plot.scales.x;
      i0 = this.t.findIndex((x) => x >= min);
      if (i0 < 0) i0 = this.t.length;
      const j = this.t.findIndex((x) => x > max);
      i1 = j < 0 ? this.t.length : j;
    }
    const head = ["t_s", ...this.channels.map((c) => (c.unit ? `${c.key}_${c.unit}` : c.key).replace(/[^\w]+/g, "_"))];
    const lines = [head.join(",")];
    for (let k = i0; k < i1; k++) {
      lines.push([this.t[k], ...this.cols.map((c) => (c[k] === null || c[k] === undefined ? "" : c[k]))].join(","));
    }
    return lines.join("\n") + "\n";
  }

  destroy() {
    if (this._ro) this._ro.disconnect();
    this.plot.destroy();
  }
}

/** Offer `text` as a file download. */
export function download(name, text, type = "text/csv") {
  const url = URL.createObjectURL(new Blob([text], { type }));
  const a = document.createElement("a");
  a.href = url;
  a.download = name;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 1000);
}
