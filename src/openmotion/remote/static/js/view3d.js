// A path view on a 2-D canvas: XY / XZ / YZ or an orbiting 3-D projection of a polyline
// coloured by speed, with markers (PSO firings), a progress split (done / to do) and the
// current position. Big paths are decimated once (at most `maxPoints` vertices kept, on a
// tolerance of the bounding box) so that dragging stays smooth on a 20 MB program.

const BUCKETS = 24;

/** Speed (0..1) -> colour, blue (slow) to red (fast). */
export function speedColour(f) {
  const x = Math.max(0, Math.min(1, f));
  const h = (1 - x) * 240;
  return `hsl(${h.toFixed(0)}, 85%, 45%)`;
}

/**
 * Decimate a polyline: drop a vertex closer than `tol` to the last kept one, unless its
 * kind (rapid/feed), source line group or a marker changes there. Returns index list.
 */
export function decimate(xs, ys, zs, tol, keep) {
  const n = xs.length;
  const out = [];
  if (!n) return out;
  let lx = xs[0], ly = ys[0], lz = zs[0];
  out.push(0);
  const t2 = tol * tol;
  for (let i = 1; i < n - 1; i++) {
    const dx = xs[i] - lx, dy = ys[i] - ly, dz = zs[i] - lz;
    if (dx * dx + dy * dy + dz * dz >= t2 || (keep && keep(i))) {
      out.push(i);
      lx = xs[i]; ly = ys[i]; lz = zs[i];
    }
  }
  if (n > 1) out.push(n - 1);
  return out;
}

export class PathView {
  constructor(canvas, { maxPoints = 150000 } = {}) {
    this.canvas = canvas;
    this.ctx = canvas.getContext("2d");
    this.maxPoints = maxPoints;
    this.view = "xy";
    this.yaw = -0.6;
    this.pitch = 0.9;
    this.zoom = 1;
    this.pan = [0, 0];
    this.data = null;
    this.markers = [];
    this.current = null;
    this.progress = -1;          // vertices with line <= progress are drawn as done
    this.vmax = 1;
    this._raf = 0;
    this._bind();
  }

  _bind() {
    let drag = null;
    this.canvas.addEventListener("pointerdown", (e) => {
      drag = { x: e.clientX, y: e.clientY, yaw: this.yaw, pitch: this.pitch, pan: [...this.pan], btn: e.button, shift: e.shiftKey };
      this.canvas.setPointerCapture(e.pointerId);
    });
    this.canvas.addEventListener("pointermove", (e) => {
      if (!drag) return;
      const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
      if (this.view === "3d" && drag.btn === 0 && !drag.shift) {
        this.yaw = drag.yaw + dx * 0.01;
        this.pitch = Math.max(-Math.PI / 2, Math.min(Math.PI / 2, drag.pitch + dy * 0.01));
      } else {
        this.pan = [drag.pan[0] + dx, drag.pan[1] + dy];
      }
      this.schedule();
    });
    const end = () => { drag = null; };
    this.canvas.addEventListener("pointerup", end);
    this.canvas.addEventListener("pointercancel", end);
    this.canvas.addEventListener("wheel", (e) => {
      e.preventDefault();
      this.zoom *= Math.exp(-e.deltaY * 0.001);
      this.schedule();
    }, { passive: false });
    this.canvas.addEventListener("dblclick", () => this.fit());
    if (typeof ResizeObserver !== "undefined") new ResizeObserver(() => this.schedule()).observe(this.canvas);
  }

  /**
   * points: {x: [], y: [], z: [], v: [] (speed), line: [] (source line), rapid: []}.
   * Arrays may be plain or typed; z/v/line/rapid are optional.
   */
  setPath(points) {
    const n = points.x.length;
    const x = points.x, y = points.y;
    const z = points.z || new Float64Array(n);
    const v = points.v || null;
    const line = points.line || null;
    const rapid = points.rapid || null;
    let idx = null;
    this.sourcePoints = n;
    if (n > this.maxPoints) {
      const b = bounds(x, y, z, null);
      const diag = Math.hypot(b[3] - b[0], b[4] - b[1], b[5] - b[2]) || 1;
      let tol = diag / 4000;
      const keep = rapid ? (i) => rapid[i] !== rapid[i - 1] : null;
      for (let round = 0; round < 8; round++) {
        idx = decimate(x, y, z, tol, keep);
        if (idx.length <= this.maxPoints) break;
        tol *= 2;
      }
    }
    const m = idx ? idx.length : n;
    const take = (src, T = Float64Array) => {
      if (!src) return null;
      const out = new T(m);
      for (let k = 0; k < m; k++) out[k] = src[idx ? idx[k] : k];
      return out;
    };
    this.data = { x: take(x), y: take(y), z: take(z), v: take(v), line: take(line, Int32Array), rapid: take(rapid, Uint8Array), n: m };
    let vmax = 0;
    if (this.data.v) for (let k = 0; k < m; k++) if (this.data.v[k] > vmax) vmax = this.data.v[k];
    this.vmax = vmax || 1;
    this.fit();
  }

  setMarkers(list) { this.markers = list || []; this.schedule(); }
  setCurrent(p) { this.current = p; this.schedule(); }
  setProgress(line) { if (line !== this.progress) { this.progress = line; this.schedule(); } }
  setView(v) { this.view = v; this.fit(); }

  fit() {
    this.zoom = 1;
    this.pan = [0, 0];
    this.schedule();
  }

  _basis() {
    if (this.view === "xy") return [[1, 0, 0], [0, 1, 0]];
    if (this.view === "xz") return [[1, 0, 0], [0, 0, 1]];
    if (this.view === "yz") return [[0, 1, 0], [0, 0, 1]];
    const cy = Math.cos(this.yaw), sy = Math.sin(this.yaw), cp = Math.cos(this.pitch), sp = Math.sin(this.pitch);
    // right vector and up vector of a camera orbiting around z
    return [[cy, sy, 0], [-sy * cp, cy * cp, sp]];
  }

  schedule() {
    if (this._raf) return;
    this._raf = requestAnimationFrame(() => { this._raf = 0; this.draw(); });
  }

  draw() {
    const c = this.canvas;
    const dpr = window.devicePixelRatio || 1;
    const w = c.clientWidth || 600, h = c.clientHeight || 400;
    if (c.width !== Math.round(w * dpr) || c.height !== Math.round(h * dpr)) {
      c.width = Math.round(w * dpr);
      c.height = Math.round(h * dpr);
    }
    const g = this.ctx;
    g.setTransform(dpr, 0, 0, dpr, 0, 0);
    g.clearRect(0, 0, w, h);
    const d = this.data;
    if (!d || !d.n) {
      g.fillStyle = "#888";
      g.fillText("no path", 10, 20);
      return;
    }
    const [r, u] = this._basis();
    const n = d.n;
    const px = new Float32Array(n), py = new Float32Array(n);
    let x0 = Infinity, x1 = -Infinity, y0 = Infinity, y1 = -Infinity;
    for (let k = 0; k < n; k++) {
      const a = d.x[k] * r[0] + d.y[k] * r[1] + d.z[k] * r[2];
      const b = d.x[k] * u[0] + d.y[k] * u[1] + d.z[k] * u[2];
      px[k] = a; py[k] = b;
      if (a < x0) x0 = a; if (a > x1) x1 = a; if (b < y0) y0 = b; if (b > y1) y1 = b;
    }
    const pad = 24;
    const sx = (w - 2 * pad) / ((x1 - x0) || 1), sy = (h - 2 * pad) / ((y1 - y0) || 1);
    const s = Math.min(sx, sy) * this.zoom;
    const cx = (x0 + x1) / 2, cy = (y0 + y1) / 2;
    const ox = w / 2 + this.pan[0], oy = h / 2 + this.pan[1];
    const X = (a) => ox + (a - cx) * s, Y = (b) => oy - (b - cy) * s;
    this._proj = { r, u, X, Y };
    // one path per colour bucket (and one for rapids) keeps a 150k-vertex draw fast
    const paths = Array.from({ length: BUCKETS }, () => new Path2D());
    const rapids = new Path2D();
    const done = new Path2D();
    for (let k = 1; k < n; k++) {
      const isRapid = d.rapid && d.rapid[k];
      const isDone = d.line && this.progress >= 0 && d.line[k] <= this.progress;
      let p;
      if (isDone) p = done;
      else if (isRapid) p = rapids;
      else {
        const f = d.v ? d.v[k] / this.vmax : 0.5;
        p = paths[Math.min(BUCKETS - 1, Math.max(0, Math.floor(f * BUCKETS)))];
      }
      p.moveTo(X(px[k - 1]), Y(py[k - 1]));
      p.lineTo(X(px[k]), Y(py[k]));
    }
    g.lineWidth = 1.2;
    g.setLineDash([4, 4]);
    g.strokeStyle = "#999";
    g.stroke(rapids);
    g.setLineDash([]);
    paths.forEach((p, i) => { g.strokeStyle = speedColour((i + 0.5) / BUCKETS); g.stroke(p); });
    g.lineWidth = 2;
    g.strokeStyle = "rgba(60,60,60,0.55)";
    g.stroke(done);
    // markers
    for (const m of this.markers) {
      const a = m.x * r[0] + m.y * r[1] + (m.z || 0) * r[2];
      const b = m.x * u[0] + m.y * u[1] + (m.z || 0) * u[2];
      g.fillStyle = m.colour || "#000";
      g.beginPath();
      g.arc(X(a), Y(b), 2.5, 0, 2 * Math.PI);
      g.fill();
    }
    if (this.current) {
      const m = this.current;
      const a = m.x * r[0] + m.y * r[1] + (m.z || 0) * r[2];
      const b = m.x * u[0] + m.y * u[1] + (m.z || 0) * u[2];
      g.strokeStyle = "#e00";
      g.lineWidth = 2;
      g.beginPath();
      g.arc(X(a), Y(b), 6, 0, 2 * Math.PI);
      g.moveTo(X(a) - 9, Y(b)); g.lineTo(X(a) + 9, Y(b));
      g.moveTo(X(a), Y(b) - 9); g.lineTo(X(a), Y(b) + 9);
      g.stroke();
    }
    this._axes(g, r, u, h);
  }

  _axes(g, r, u, h) {
    const o = [34, h - 34];
    const names = ["X", "Y", "Z"];
    const cols = ["#c00", "#080", "#00c"];
    for (let i = 0; i < 3; i++) {
      const a = r[i], b = u[i];
      if (Math.abs(a) < 1e-9 && Math.abs(b) < 1e-9) continue;
      g.strokeStyle = cols[i];
      g.fillStyle = cols[i];
      g.lineWidth = 1.5;
      g.beginPath();
      g.moveTo(o[0], o[1]);
      g.lineTo(o[0] + a * 22, o[1] - b * 22);
      g.stroke();
      g.fillText(names[i], o[0] + a * 28 - 3, o[1] - b * 28 + 3);
    }
  }
}

function bounds(x, y, z) {
  let b = [Infinity, Infinity, Infinity, -Infinity, -Infinity, -Infinity];
  for (let k = 0; k < x.length; k++) {
    if (x[k] < b[0]) b[0] = x[k]; if (y[k] < b[1]) b[1] = y[k]; if (z[k] < b[2]) b[2] = z[k];
    if (x[k] > b[3]) b[3] = x[k]; if (y[k] > b[4]) b[4] = y[k]; if (z[k] > b[5]) b[5] = z[k];
  }
  return b;
}
