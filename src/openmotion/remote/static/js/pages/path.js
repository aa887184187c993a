// Path: the running (or last) program's path in XY / XZ / YZ or 3-D, coloured by speed,
// with the synchronized output firings (PSO, M62/M63) marked and the tool's position.

import { el, button, num } from "../dom.js";
import { PathView } from "../view3d.js";
import { panel } from "./common.js";

let app, root, view = null, timer = 0, pts = null, next = 0, info, legend, axes = "xyz";

export function mount(a, node) {
  app = a;
  root = node;
  const canvas = el("canvas", { class: "view", id: "path-canvas" });
  info = el("div", { class: "small muted", id: "path-info" });
  legend = el("div", { class: "row small" }, "slow", el("div", { class: "legend-bar" }), "fast", el("span", { id: "path-vmax" }));
  const views = el("div", { class: "row" }, ...["xy", "xz", "yz", "3d"].map((v) =>
    button(v.toUpperCase(), () => view.setView(v), { id: `path-view-${v}` })),
  button("Fit", () => view.fit()), button("Clear", () => reset(), { title: "forget the points shown (the server keeps them)" }));
  root.append(panel("Path of the group (coloured by speed; dots = output firings)", views, canvas, legend, info,
    el("div", { class: "small muted" }, "3-D: drag to orbit, shift-drag to pan, wheel to zoom, double click to fit.")));
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
      view.setMarkers(firings.map((f) => ({ x: f.point[0], y: f.point[1] ?? 0, z: f.point[2] ?? 0 })));
    }
    next = d.next;
    const first = (Array.isArray(axes) ? axes[0] : String(axes)[0] || "x").toLowerCase();
    const unit = (Array.isArray(d.units) ? d.units[0] : d.units) || (app.axisInfo(first) || {}).unit;
    $("#path-vmax", root).textContent = ` (0 … ${num(d.vmax ?? view.vmax, 3)} ${unit || ""}/s)`;
    info.textContent = `${pts.x.length} points · ${firings.length} firings · axes ${Array.isArray(axes) ? axes.join("") : axes}`;
    marker();
  } catch (err) {
    info.textContent = `path: ${err.message}`;
  } finally {
    busy = false;
  }
}

function $(sel, r) { return r.querySelector(sel); }

function marker() {
  const names = Array.isArray(axes) ? axes : String(axes).split("");
  const st = app.status && app.status.axes;
  if (!st || !names.length || !st[names[0]]) return;
  const pos = names.map((n) => (st[n] ? st[n].position : 0));
  view.setCurrent({ x: pos[0], y: pos[1] ?? 0, z: pos[2] ?? 0 });
}
