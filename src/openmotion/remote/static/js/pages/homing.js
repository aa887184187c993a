// Homing (Motion Creator's Home Mode Configuration): mode, direction, speeds, offsets, with a
// drawing of the selected mode's sequence made from the phases the server returns.

import { el, button, num } from "../dom.js";
import { FieldSet, serverError } from "../fields.js";
import { panel } from "./common.js";

const SVGNS = "http://www.w3.org/2000/svg";
let app, root, fs, loaded = null, axis = null, sequence = [], drawing, seqNote, status, savedNote;
const seqCache = new Map();   // mode -> sequence (from the server)

function specs(info, choices) {
  const unit = info ? info.unit : "";
  const vmax = info ? info.max_speed : undefined;
  const modes = (choices.mode || [...Array(13).keys()]).map((m) => [m, typeof m === "number" ? `mode ${m}` : m]);
  const pos = (name, label) => ({ name, label, unit: `${unit}/s`, min: 0, minExclusive: true, max: vmax });
  return [
    { name: "mode", label: "Mode", kind: "select", options: modes },
    { name: "direction", label: "Direction", kind: "select", options: [[-1, "− (negative)"], [1, "+ (positive)"]] },
    { ...pos("str_vel", "StrVel"), check: (v, all) => (Number(all.max_vel) > 0 && v > Number(all.max_vel) ? "StrVel must be <= MaxVel" : "") },
    pos("max_vel", "MaxVel"),
    { name: "tacc", label: "Accel. time", unit: "s", min: 0, minExclusive: true, max: 100 },
    { name: "tdec", label: "Decel. time", unit: "s", min: 0, minExclusive: true, max: 100 },
    { name: "ez_count", label: "EZ count", kind: "int", min: 0, max: (choices.ez_count && choices.ez_count[1]) || 15 },
    { name: "org_offset", label: "ORG offset (back-off)", unit, min: 0 },
    { name: "home_offset", label: "Home offset", unit },
    { name: "final", label: "At the end", kind: "select", options: (choices.final || ["mark", "stay"]).map((v) => [v, v === "mark" ? "mark: move to the home (+ offset)" : v === "stay" ? "stay: counters read 0 where it stopped" : v]) },
    { name: "el_stop", label: "EL stop", kind: "select", options: (choices.el_stop || ["decel", "immediate"]).map((v) => [v, v]) },
    { name: "auto_search", label: "Auto search (reverse at EL)", kind: "bool" },
    { name: "timeout_s", label: "Timeout", unit: "s", min: 0, minExclusive: true, max: 3600 },
  ];
}

export function mount(a, node) {
  app = a;
  root = node;
  app.addEventListener("axis", () => { if (app.page === "homing") load(); });
  app.addEventListener("config", () => { if (app.page === "homing") load(); });
  app.addEventListener("status", () => { if (status) showStatus(); });
}

export function show() { load(); }

let loadSeq = 0;
async function load() {
  if (!app.info) return;
  const seq = ++loadSeq;   // a newer load (another axis) wins over a late answer
  const ax = app.axis;
  let res;
  try {
    res = await app.call("home.get", { axis: ax });
    if (seq !== loadSeq) return;
  } catch (err) {
    root.replaceChildren(el("p", { class: "form-error" }, `could not read the homing settings of ${axis}: ${err.message}`));
    return;
  }
  axis = ax;
  loaded = res.config;
  sequence = res.sequence || [];
  seqCache.clear();
  seqCache.set(String(loaded.mode), sequence);
  build(res.choices || {});
}

function build(choices) {
  fs = new FieldSet(el("div", { id: "home-fields", class: "fields-2" }), specs(app.axisInfo(axis), choices), {
    onChange: (name) => {
      if (name === "mode") applyMode();
      else if (name === "direction" || name === "ez_count" || name === "final") redraw();
    },
  });
  fs.setAll(loaded);
  drawing = document.createElementNS(SVGNS, "svg");
  drawing.setAttribute("class", "homing-drawing");
  drawing.id = "home-drawing";
  seqNote = el("div", { class: "small muted", id: "home-seq-note" });
  status = el("div", { id: "home-status" });
  savedNote = el("div", { class: "small muted", id: "home-saved" });
  root.replaceChildren(
    el("div", { class: "grid two" },
      panel(`Home mode configuration — axis ${axis}`, fs.container,
        el("div", { class: "row" },
          button("Save config", () => save(), { id: "home-save", class: "primary" }),
          button("Home", () => start(), { id: "home-start", title: "saves first when a setting changed" }),
          button("Abort", () => app.call("home.abort", { axis }).catch(() => {}), { id: "home-abort", class: "danger" })),
        savedNote, status),
      panel("Sequence of the selected mode", drawing, seqNote)));
  redraw();
  showStatus();
}

function showStatus() {
  const s = app.axisStatus(axis);
  if (!s) return;
  const h = s.homing || {};
  // the phase running now is drawn thicker, in orange
  for (const line of drawing.querySelectorAll("line.phase")) {
    const on = h.state === "running" && line.getAttribute("data-phase") === h.phase;
    line.setAttribute("stroke", on ? "#ff7f0e" : "#1f5fbf");
    line.setAttribute("stroke-width", on ? "4" : "2");
  }
  status.replaceChildren(
    el("div", {}, "Homing: ", el("span", { class: "state", "data-state": h.state || "idle", id: "home-state" }, h.state || "idle"),
      h.phase ? ` · ${h.phase}` : "", h.reason ? ` · ${h.reason}` : ""),
    el("div", { class: "small" }, `position ${num(s.position, 4)} · command ${s.command} · ORG ${s.io && s.io.org ? "on" : "off"} · state ${s.state}`));
}

function changes() {
  const v = fs.values();
  if (!v) return null;
  const out = {};
  for (const [k, x] of Object.entries(v)) if (x !== loaded[k]) out[k] = x;
  return out;
}

async function save() {
  const ch = changes();
  if (ch === null) return false;
  if (!Object.keys(ch).length) { savedNote.textContent = "no change to save"; return true; }
  try {
    const res = await app.call("home.set", { axis, changes: ch });
    if (res.config_version !== undefined) app.configVersion = res.config_version;
    loaded = res.config;
    sequence = res.sequence || sequence;
    seqCache.set(String(loaded.mode), sequence);
    fs.setAll(loaded);
    redraw();
    savedNote.textContent = res.saved ? `saved to ${res.saved}` : "applied (no machine file yet)";
    return true;
  } catch (err) {
    serverError(err, [fs]);
    return false;
  }
}

async function start() {
  if (!(await save())) return;
  try { await app.call("home.start", { axis }); } catch (err) { serverError(err, [fs]); }
}

/** Selecting a mode draws its sequence at once (`home.get {mode}`: nothing applied; Save
 * applies it with the other fields). */
async function applyMode() {
  const v = fs.values(["mode"]);
  if (!v || String(v.mode) === String(loaded.mode)) { redraw(); return; }
  if (!seqCache.has(String(v.mode))) {
    try {
      const res = await app.call("home.get", { axis, mode: v.mode });
      seqCache.set(String(v.mode), res.sequence || []);
    } catch (err) {
      serverError(err, [fs]);
      return;
    }
  }
  redraw();
}

function redraw() {
  const raw = fs.raw();
  const mode = raw.mode;
  const seq = seqCache.get(String(mode));
  const dirNow = Number(raw.direction) || loaded.direction;
  if (!seq) {
    draw([], dirNow);
    seqNote.textContent = `Save to draw mode ${mode}.`;
    return;
  }
  // the server's directions are for the saved direction: flip them for an unsaved one
  const flip = dirNow !== loaded.direction ? -1 : 1;
  const s = seq.map((p) => ({ ...p, direction: p.direction * flip }));
  draw(s, dirNow);
  const unit = app.axisInfo(axis) ? app.axisInfo(axis).unit : "";
  seqNote.replaceChildren(...s.map((p, i) => el("div", {},
    `${i + 1}. ${p.phase}: ${p.direction > 0 ? "+" : "−"} at ${num(p.speed, 3)} ${unit}/s until ${p.signal.toUpperCase()} ${p.edge || ""}, then ${p.reaction}${p.mark ? " — home mark" : ""}`)));
}

function svg(tag, attrs, text) {
  const n = document.createElementNS(SVGNS, tag);
  for (const [k, v] of Object.entries(attrs)) n.setAttribute(k, String(v));
  if (text !== undefined) n.textContent = text;
  return n;
}

/** Schematic drawing: EL and ORG on the home side, EZ ticks, one arrow per phase. */
function draw(seq, homeDir) {
  const W = 640, H = 60 + 34 * Math.max(1, seq.length + 1);
  drawing.setAttribute("viewBox", `0 0 ${W} ${H}`);
  drawing.style.height = `${H}px`;
  drawing.replaceChildren();
  const defs = svg("defs", {});
  const marker = svg("marker", { id: "arr", viewBox: "0 0 10 10", refX: 9, refY: 5, markerWidth: 7, markerHeight: 7, orient: "auto-start-reverse" });
  marker.append(svg("path", { d: "M0,0 L10,5 L0,10 z", fill: "#1f5fbf" }));
  defs.append(marker);
  drawing.append(defs);
  // schematic coordinates 0..100, home side on the left for direction -1
  const X = (u) => 20 + (homeDir < 0 ? u : 100 - u) * 6;
  const EL = 4, ORG = [26, 40], EZ = [];
  for (let u = 12; u < 100; u += 11) EZ.push(u);
  const yTop = 22;
  drawing.append(svg("line", { x1: 10, y1: yTop + 14, x2: W - 10, y2: yTop + 14, stroke: "#999" }));
  drawing.append(svg("rect", { x: Math.min(X(ORG[0]), X(ORG[1])), y: yTop, width: Math.abs(X(ORG[1]) - X(ORG[0])), height: 14, fill: "#ffe58a", stroke: "#c9a400" }));
  drawing.append(svg("text", { x: (X(ORG[0]) + X(ORG[1])) / 2, y: yTop - 4, "text-anchor": "middle", "font-size": 11 }, "ORG"));
  drawing.append(svg("rect", { x: X(EL) - 4, y: yTop - 4, width: 8, height: 22, fill: "#f08080" }));
  drawing.append(svg("text", { x: X(EL), y: yTop - 8, "text-anchor": "middle", "font-size": 11 }, homeDir < 0 ? "−EL" : "+EL"));
  for (const u of EZ) drawing.append(svg("line", { x1: X(u), y1: yTop + 10, x2: X(u), y2: yTop + 18, stroke: "#2ca02c", "stroke-width": 2 }));
  drawing.append(svg("text", { x: W - 12, y: yTop + 30, "text-anchor": "end", "font-size": 10, fill: "#2ca02c" }, "EZ (index) ticks"));
  if (!seq.length) return;
  const ezCount = Number(fs.raw().ez_count) || 0;
  // walk the phases in schematic units: u is the distance from the home end (EL at 4)
  let u = 92, row = 0, markU = null;
  for (const p of seq) {
    const step = p.direction === homeDir ? -1 : 1;   // du of this phase's motion
    let target;
    if (p.signal === "el") target = EL;
    else if (p.signal === "org") {
      const inside = u > ORG[0] && u < ORG[1];
      const wantOff = p.edge ? p.edge === "off" : inside;
      if (wantOff) target = step < 0 ? ORG[0] : ORG[1];
      else target = step < 0 ? ORG[1] : ORG[0];
    } else {
      const n = /count/i.test(p.phase) ? ezCount + 1 : 1;
      const ticks = step < 0 ? EZ.filter((t) => t < u - 0.5).sort((x, y) => y - x) : EZ.filter((t) => t > u + 0.5);
      target = ticks.length ? ticks[Math.min(n, ticks.length) - 1] : u;
    }
    const y = yTop + 44 + row * 34;
    const stopAfter = p.reaction === "stop" || p.reaction === "el";
    const end = stopAfter ? target + step * 2.5 : target;
    drawing.append(svg("line", { x1: X(u), y1: y, x2: X(end), y2: y, stroke: "#1f5fbf", "stroke-width": 2, "marker-end": "url(#arr)",
      "stroke-dasharray": p.speed && loaded && p.speed < loaded.max_vel * 0.5 ? "5,3" : "", "data-phase": p.phase, class: "phase" }));
    drawing.append(svg("text", { x: Math.min(X(u), X(end)), y: y - 5, "font-size": 11 },
      `${row + 1}. ${p.phase} (${p.reaction})`));
    if (p.mark) {
      markU = target;
      drawing.append(svg("line", { x1: X(target), y1: yTop - 6, x2: X(target), y2: y + 6, stroke: "#d62728", "stroke-dasharray": "3,2" }));
    }
    u = end;
    row += 1;
  }
  if (markU !== null && (fs.raw().final || loaded.final) === "mark") {
    const y = yTop + 44 + row * 34;
    drawing.append(svg("line", { x1: X(u), y1: y, x2: X(markU), y2: y, stroke: "#d62728", "stroke-width": 2, "marker-end": "url(#arr)" }));
    drawing.append(svg("text", { x: Math.min(X(u), X(markU)), y: y - 5, "font-size": 11, fill: "#d62728" }, "final move to the home mark (+ home offset): counters := 0"));
  } else if (markU !== null) {
    drawing.append(svg("text", { x: X(markU), y: yTop + 44 + row * 34, "font-size": 11, fill: "#d62728" }, "home mark"));
  }
}
