// Program: load G-code (upload, paste or a file on the server), a decimated 3-D preview that
// stays responsive on a 20 MB program, run / pause / resume / abort, single block, continue
// after M0, feed override, the current line highlighted in a virtual listing.

import { el, button, num } from "../dom.js";
import { FieldSet, serverError } from "../fields.js";
import { PathView } from "../view3d.js";
import { panel } from "./common.js";

const ROW = 17, CHUNK = 1000;
let app, root, view, listing, spacer, rows, fsPaste, fsRun, stateBox, loadInfo, loadErr, follow, sbox, ovr, ovrNum;
// the server's single-block setting last seen: the box follows the server only when that
// changes (another tab, a run), never back to a value the user has just changed it from
let sbServer;
let autoScroll = false, total = 0, chunks = new Map(), pendingChunks = new Set(), current = 0, lastUserScroll = 0, fileName = null;

export function mount(a, node) {
  app = a;
  root = node;
  const file = el("input", { type: "file", id: "prog-file", accept: ".ngc,.nc,.gcode,.tap,.txt,.cnc" });
  file.addEventListener("change", () => file.files[0] && upload(file.files[0]));
  fsPaste = new FieldSet(el("div", { id: "prog-src" }), [
    { name: "path", label: "File on the server", kind: "text", optional: true, help: "a path the server can read" },
  ]);
  const paste = el("textarea", { id: "prog-text", rows: 5, style: "width:100%;font-family:monospace", placeholder: "or paste G-code here (at most 1 MiB)" });
  loadInfo = el("div", { class: "small", id: "prog-loaded" });
  loadErr = el("div", { class: "form-error", id: "prog-load-error", role: "alert" });
  fsRun = new FieldSet(el("div", { id: "prog-run" }), [
    { name: "repeat", label: "Repeat", kind: "int", min: 1, max: 100000, value: 1 },
    { name: "optional_stop", label: "Optional stop (M1)", kind: "bool", value: false },
  ]);
  sbox = el("input", { type: "checkbox", id: "prog-single" });
  // the setting lives on the server (kept for the next run, applied to a running one)
  sbox.addEventListener("change", () => app.call("program.single_block", { on: sbox.checked }).catch(() => {}));
  ovr = el("input", { type: "range", min: 1, max: 200, value: 100, id: "prog-ovr", style: "width:200px" });
  ovrNum = el("span", { id: "prog-ovr-val" }, "100 %");
  let ovrTimer = 0;
  ovr.addEventListener("input", () => {
    ovrNum.textContent = `${ovr.value} %`;
    clearTimeout(ovrTimer);
    ovrTimer = setTimeout(() => { if (isRunning()) app.call("program.feed_override", { percent: Number(ovr.value) }).catch(() => {}); }, 80);
  });
  stateBox = el("div", { id: "prog-state" });
  follow = el("input", { type: "checkbox", id: "prog-follow" });
  follow.checked = true;
  const canvas = el("canvas", { class: "view", id: "prog-canvas" });
  listing = el("div", { class: "listing", id: "prog-listing", tabindex: "0" });
  spacer = el("div", { style: "position:relative" });
  rows = el("div", { style: "position:absolute;left:0;right:0;top:0" });
  spacer.append(rows);
  listing.append(spacer);
  listing.addEventListener("scroll", () => {
    if (autoScroll) autoScroll = false;
    else lastUserScroll = performance.now();
    renderRows();
  });

  root.append(
    el("div", { class: "grid" },
      panel("Load G-code", el("div", { class: "row" }, file),
        fsPaste.container, button("Load server file", () => loadPath(), { id: "prog-load-path" }),
        paste, button("Load pasted text", () => loadText(paste.value), { id: "prog-load-text" }),
        loadInfo, loadErr),
      panel("Run", fsRun.container,
        el("label", { class: "row" }, sbox, "Single block"),
        el("div", { class: "row" }, "Feed override ", ovr, ovrNum),
        el("div", { class: "row" },
          button("Run", () => run(), { id: "prog-run-btn", class: "primary" }),
          button("Pause", () => app.call("program.pause").catch(() => {}), { id: "prog-pause" }),
          button("Resume / continue", () => app.call("program.resume").catch(() => {}), { id: "prog-resume", title: "also continues after M0/M1 and a single-block stop" }),
          button("Abort", () => app.call("program.abort").catch(() => {}), { id: "prog-abort", class: "danger" }),
          button("Servo on, all axes", () => servoAll(), { id: "prog-servo-all", title: "a program needs every axis enabled" })),
        stateBox)),
    el("div", { class: "grid two", style: "margin-top:12px" },
      panel("Preview (dashed = rapid, grey = done)",
        el("div", { class: "row" }, ...["xy", "xz", "yz", "3d"].map((v) => button(v.toUpperCase(), () => view.setView(v), { id: `prog-view-${v}` })), button("Fit", () => view.fit())),
        canvas, el("div", { class: "row small" }, "slow", el("div", { class: "legend-bar" }), "fast (programmed feed)")),
      panel("Listing", el("label", { class: "row small" }, follow, "follow the current line"), listing)));
  view = new PathView(canvas, { maxPoints: 150000 });
  app.programView = view;
  app.addEventListener("status", () => { if (app.page === "program" || current) update(); });
  app.addEventListener("connected", () => refresh());
}

export function show() { view.schedule(); renderRows(); update(); }

function isRunning() {
  const p = app.status && app.status.program;
  return p && (p.state === "running" || p.state === "paused");
}

async function refresh() {
  // after a (re)connect or in a second tab: a program may already be loaded on the server
  try {
    const st = await app.call("program.status", {}, { quiet: true });
    if (st.file && st.file !== fileName) await loaded({ file: st.file, lines: st.lines ?? (await countLines()) });
  } catch { /* nothing loaded */ }
}

/** Number of lines of the loaded program, found with program.lines (exponential search). */
async function countLines() {
  try {
    const r = await app.call("program.lines", { first: 1, count: 1 }, { quiet: true });
    if (typeof r.total === "number") return r.total;
  } catch { return 0; }
  const has = async (n) => {
    try { return (await app.call("program.lines", { first: n, count: 1 }, { quiet: true })).lines.length > 0; } catch { return false; }
  };
  if (!(await has(1))) return 0;
  let lo = 1, hi = 2;
  while (await has(hi)) { lo = hi; hi *= 2; }
  while (hi - lo > 1) {
    const mid = Math.floor((lo + hi) / 2);
    if (await has(mid)) lo = mid; else hi = mid;
  }
  return lo;
}

async function upload(f) {
  loadErr.textContent = "";
  loadInfo.textContent = `uploading ${f.name} (${(f.size / 1e6).toFixed(2)} MB)…`;
  try {
    const resp = await fetch(app.url("/api/program", { name: f.name }), { method: "POST", body: f,
      headers: app.token ? { Authorization: `Bearer ${app.token}` } : {} });
    const body = await resp.json().catch(() => ({}));
    if (!resp.ok || body.error) throw Object.assign(new Error((body.error && body.error.message) || `HTTP ${resp.status}`), { data: body.error && body.error.data });
    await loaded(body);
  } catch (err) {
    loadInfo.textContent = "";
    loadErr.textContent = err.message;
  }
}

async function loadText(text) {
  loadErr.textContent = "";
  if (!text.trim()) { loadErr.textContent = "paste some G-code first"; return; }
  if (new Blob([text]).size > 1048576) { loadErr.textContent = "pasted text is larger than 1 MiB: upload it as a file instead"; return; }
  try { await loaded(await app.call("program.load", { text, name: "pasted.ngc" }, { timeoutMs: 60000 })); } catch (err) { loadErr.textContent = err.message; }
}

async function loadPath() {
  loadErr.textContent = "";
  const v = fsPaste.values();
  if (!v) return;
  if (!v.path) { fsPaste.showError("path", "File on the server is required"); return; }
  try { await loaded(await app.call("program.load", { path: v.path }, { timeoutMs: 120000 })); } catch (err) { serverError(err, [fsPaste]); }
}

async function loaded(res) {
  fileName = res.file;
  chunks = new Map();
  pendingChunks = new Set();
  current = 0;
  total = res.lines ?? 0;
  loadInfo.textContent = `${res.file}: ${res.lines ?? "?"} lines, ${res.moves ?? "?"} moves` +
    (res.bounds ? ` · bounds ${res.bounds.min.map((x) => num(x, 2)).join(", ")} … ${res.bounds.max.map((x) => num(x, 2)).join(", ")}` : "");
  const pv = await app.call("program.preview", { max_points: 50000 }, { timeoutMs: 60000 });
  const n = pv.points.length;
  const x = new Float64Array(n), y = new Float64Array(n), z = new Float64Array(n), v = new Float64Array(n);
  const rapid = new Uint8Array(n), line = new Int32Array(n);
  for (let k = 0; k < n; k++) {
    const p = pv.points[k];
    x[k] = p[0]; y[k] = p[1] ?? 0; z[k] = p[2] ?? 0;
    rapid[k] = pv.rapid && pv.rapid[k] ? 1 : 0;
    line[k] = pv.line ? pv.line[k] : 0;
    v[k] = pv.feed ? pv.feed[k] : (rapid[k] ? 0 : 1);
  }
  view.setPath({ x, y, z, v, rapid, line });
  view.setProgress(-1);
  loadInfo.textContent += ` · preview ${n} points${pv.decimated ? " (decimated)" : ""}`;
  if (!total) total = await countLines();
  spacer.style.height = `${Math.max(1, total) * ROW}px`;
  listing.scrollTop = 0;
  renderRows();
}

function renderRows() {
  if (!total) { rows.replaceChildren(); return; }
  const first = Math.max(1, Math.floor(listing.scrollTop / ROW) + 1 - 5);
  const count = Math.ceil(listing.clientHeight / ROW) + 10;
  const last = Math.min(total, first + count);
  rows.style.top = `${(first - 1) * ROW}px`;
  const out = [];
  for (let n = first; n <= last; n++) {
    const c = Math.floor((n - 1) / CHUNK);
    const lines = chunks.get(c);
    if (!lines) fetchChunk(c);
    const text = lines ? lines[(n - 1) % CHUNK] ?? "" : "…";
    const cls = n === current ? "ln current" : n < current ? "ln done" : "ln";
    out.push(el("div", { class: cls, "data-line": n }, el("span", { class: "no" }, n), text));
  }
  rows.replaceChildren(...out);
}

async function fetchChunk(c) {
  if (pendingChunks.has(c)) return;
  pendingChunks.add(c);
  try {
    const r = await app.call("program.lines", { first: c * CHUNK + 1, count: CHUNK }, { quiet: true });
    chunks.set(c, r.lines);
    renderRows();
  } catch {
    pendingChunks.delete(c);
  }
}

function update() {
  const p = app.status && app.status.program;
  if (!p) return;
  stateBox.replaceChildren(
    el("div", {}, "State ", el("span", { class: "state", "data-state": p.state, id: "prog-state-name" }, p.state),
      ` · line `, el("b", { id: "prog-line" }, p.line ?? "-"), ` · ${num((p.progress || 0) * 100, 1)} %`,
      ` · ${num(p.elapsed_s || 0, 1)} s · override ${p.feed_override ?? "-"} %${p.single_block ? " · single block" : ""}`),
    p.message ? el("div", { class: "small", id: "prog-message" }, p.message) : null,
    el("progress", { max: 1, value: p.progress || 0, style: "width:100%" }));
  if (p.single_block !== undefined && p.single_block !== sbServer) {
    sbServer = p.single_block;
    sbox.checked = Boolean(p.single_block);
  }
  const line = p.line || 0;
  if (line !== current) {
    current = line;
    view.setProgress(current ? current - 1 : -1);
    if (follow.checked && total && performance.now() - lastUserScroll > 1500) {
      const top = (current - 1) * ROW;
      if (top < listing.scrollTop || top > listing.scrollTop + listing.clientHeight - 3 * ROW) {
        autoScroll = true;
        listing.scrollTop = Math.max(0, top - listing.clientHeight / 3);
      }
    }
    renderRows();
  }
}

async function run() {
  const v = fsRun.values();
  if (!v) return;
  try {
    await app.call("program.run", { feed_override: Number(ovr.value), single_block: sbox.checked, optional_stop: v.optional_stop, repeat: v.repeat });
  } catch (err) { serverError(err, [fsRun]); }
}

async function servoAll() {
  for (const a of app.info.axes) {
    const st = app.axisStatus(a.name);
    if (st && !st.servo) {
      try { await app.call("axis.servo", { axis: a.name, on: true }); } catch { return; }
    }
  }
}
