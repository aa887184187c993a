// Path: the running (or last) program's path, or the axes a PSO job watches, in XY / XZ /
// YZ or 3-D, coloured by speed, with the firings marked (PSO / compare jobs in magenta,
// the program's M62/M63 outputs in orange) and the tool's position; a PSO job is set up
// here too (pso.set: fire an output every distance along the path, or at table points).

import { el, button, num } from "../dom.js";
import { FieldSet } from "../fields.js";
import { PathView } from "../view3d.js";
import { panel } from "./common.js";

let app, root, view = null, timer = 0, pts = null, next = 0, info, legend, axes = "xyz";
let fsPso = null, psoInfo = null;

export function mount(a, node) {
  app = a;
  root = node;
  const canvas = el("canvas", { class: "view", id: "path-canvas" });
  info = el("div", { class: "small muted", id: "path-info" });
  legend = el("div", { class: "row small" }, "slow", el("div", { class: "legend-bar" }), "fast", el("span", { id: "path-vmax" }));
  const views = el("div", { class: "row" }, ...["xy", "xz", "yz", "3d"].map((v) =>
    button(v.toUpperCase(), () => view.setView(v), { id: `path-view-${v}` })),
  button("Fit", () => view.fit()), button("Clear", () => reset(), { title: "forget the points shown (the server keeps them)" }));
  const key = el("div", { class: "row small" },
    el("span", { class: "dot pso" }), "PSO / compare firing", el("span", { class: "dot sync" }), "M62/M63 output");
  psoInfo = el("div", { class: "small muted", id: "pso-info" });
  const psoBox = el("div", { id: "pso-form" });
  root.append(el("div", { class: "grid" },
    el("div", { class: "panel wide" }, el("h3", {}, "Path (coloured by speed; dots = firings)"), views, canvas, legend, key, info,
      el("div", { class: "small muted" }, "3-D: drag to orbit, shift-drag to pan, wheel to zoom, double click to fit.")),
    panel("PSO: fire an output along the path", psoBox, el("div", { class: "row" },
      button("Start PSO job", () => psoSet(), { id: "pso-set", class: "primary" }),
      button("Clear jobs", () => psoClear(), { id: "pso-clear" })), psoInfo,
      el("p", { class: "small muted" }, "Distance: a pulse every distance of path length over the axes (ZMotion HW_PSWITCH2 mode 4). Points: a pulse where the axes pass each point, within the window (x y pairs separated by ;). Then move the axes (Operation, jog, a program): the firings appear on the path."))));
  app.addEventListener("config", () => buildPso(psoBox));
  buildPso(psoBox);
  view = new PathView(canvas);
  app.pathView = view;
  app.addEventListener("status", () => { if (app.page === "path") marker(); });
}

function reset() {
  pts = { x: [], y: [], z: [], v: [] };
  next = 0;
  view.setPath(pts);
  view.setMarkers([]);
}

export function show() {
  if (!pts) reset();
  refreshPso();
  poll();
  timer = setInterval(poll, 250);
}

export function hide() { clearInterval(timer); timer = 0; }

let busy = false, firings = [];
async function poll() {
  if (busy || app.rpc.state !== "open") return;
  busy = true;
  try {
    let d = await app.call("path.get", { since: next, max_points: 20000 }, { quiet: true });
    if (d.next < next || (d.first > next && next > 0)) {   // a new program: start again
      reset();
      firings = [];
      d = await app.call("path.get", { since: 0, max_points: 20000 }, { quiet: true });
    }
    axes = d.axes || axes;
    if (d.points.length) {
      for (let k = 0; k < d.points.length; k++) {
        const p = d.points[k];
        pts.x.push(p[0]); pts.y.push(p[1] ?? 0); pts.z.push(p[2] ?? 0);
        pts.v.push(d.speed ? d.speed[k] : 0);
      }
      view.setPath(pts);
      if (d.vmax) view.vmax = d.vmax;
      if (view.view !== "3d") view.fit();
    }
    if (d.firings && d.firings.length) {
      firings = firings.concat(d.firings);
      view.setMarkers(firings.map((f) => ({ x: f.point[0], y: f.point[1] ?? 0, z: f.point[2] ?? 0,
        colour: f.kind === "M62/M63" ? "#e80" : "#c0c" })));   // PSO / CMP: compare firings
    }
    next = d.next;
    const first = (Array.isArray(axes) ? axes[0] : String(axes)[0] || "x").toLowerCase();
    const unit = (Array.isArray(d.units) ? d.units[0] : d.units) || (app.axisInfo(first) || {}).unit;
    $("#path-vmax", root).textContent = ` (0 … ${num(d.vmax ?? view.vmax, 3)} ${unit || ""}/s)`;
    const nSync = firings.filter((f) => f.kind === "M62/M63").length;
    const nCmp = firings.filter((f) => f.kind === "CMP").length;
    const nPso = firings.length - nSync - nCmp;
    info.textContent = `${pts.x.length} points · ${firings.length} firings (${nPso} PSO, ${nCmp ? `${nCmp} CMP, ` : ""}${nSync} M62/M63) · axes ${Array.isArray(axes) ? axes.join("") : axes}`;
    marker();
  } catch (err) {
    info.textContent = `path: ${err.message}`;
  } finally {
    busy = false;
  }
}

function $(sel, r) { return r.querySelector(sel); }

function buildPso(box) {
  if (!app.info) return;
  const names = app.info.axes.map((a) => a.name);
  const unit = "user units";   // of the axes named (mm, degree, pulse ...)
  const nOut = app.info.digital_outputs || 0;
  fsPso = new FieldSet(box, [
    { name: "kind", label: "Fire", kind: "select", value: "distance", options: [["distance", "every distance"], ["points", "at points"]] },
    { name: "axes", label: "Axes", kind: "text", value: names.slice(0, 2).join(" "),
      check: (v) => { const a = v.split(/[\s,]+/).filter(Boolean);
        if (!a.length || a.length > 3) return "Axes: 1 to 3 axis names";
        const bad = a.find((n) => !names.includes(n)); return bad ? `Axes: no axis named ${bad}` : ""; } },
    { name: "output", label: "Output DO", kind: "int", min: 0, max: Math.max(0, nOut - 1), value: 0 },
    { name: "every", label: "Every", unit, min: 0, minExclusive: true, value: 5, disabled: (raw) => raw.kind !== "distance" },
    { name: "points", label: "Points", kind: "text", value: "10 10; 20 20", disabled: (raw) => raw.kind !== "points",
      check: (v) => (v.split(";").filter((l) => l.trim()).every((l) => l.trim().split(/[\s,]+/).every((x) => /^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$/.test(x)))
        ? "" : "Points: numbers only, points separated by ;") },
    { name: "window", label: "Window ±", unit, min: 0, minExclusive: true, value: 0.5, disabled: (raw) => raw.kind !== "points" },
    { name: "pulse_ms", label: "Pulse width", unit: "ms", min: 0, minExclusive: true, max: 1000, value: 1 },
  ]);
  refreshPso();
}

async function psoSet() {
  const v = fsPso.values();
  if (!v) return;
  const params = { kind: v.kind, axes: v.axes.split(/[\s,]+/).filter(Boolean), output: v.output, pulse_s: v.pulse_ms / 1000 };
  if (v.kind === "distance") params.every = v.every;
  else {
    params.points = v.points.split(";").filter((l) => l.trim()).map((l) => l.trim().split(/[\s,]+/).map(Number));
    params.window = v.window;
  }
  try {
    const r = await app.call("pso.set", params);
    showPso(r);
    reset();
    firings = [];
    app.log(`PSO job ${r.job.id}: ${r.job.what}`);
  } catch (err) {
    fsPso.serverError(err, { pulse_s: "pulse_ms" });
  }
}

async function psoClear() {
  try { showPso(await app.call("pso.clear")); } catch { /* logged */ }
}

async function refreshPso() {
  try { showPso(await app.call("pso.get", {}, { quiet: true })); } catch { /* not connected */ }
}

function showPso(r) {
  if (!psoInfo || !r) return;
  const jobs = r.jobs.map((j) => `#${j.id} DO${j.output}: ${j.what}${j.active ? "" : " (done)"}`);
  const dropped = (r.dropped || []).map((d) => ` · dropped at the machine restart: ${d}`).join("");
  psoInfo.textContent = (jobs.length ? `${jobs.join(" · ")} · ${r.firings} firings` : `no PSO job · ${r.firings} firings`) + dropped;
}

function marker() {
  const names = Array.isArray(axes) ? axes : String(axes).split("");
  const st = app.status && app.status.axes;
  if (!st || !names.length || !st[names[0]]) return;
  const pos = names.map((n) => (st[n] ? st[n].position : 0));
  view.setCurrent({ x: pos[0], y: pos[1] ?? 0, z: pos[2] ?? 0 });
}
