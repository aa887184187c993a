// Scope: channels recorded on the server at the control period (history kept there, so a
// reload or a second tab sees it), pushed at 20 Hz; trigger on a level or an edge (single:
// the server captures and stops; normal: the display re-arms while recording goes on),
// pause, zoom (drag; double click = live), CSV export.

import { el, button, num } from "../dom.js";
import { FieldSet, serverError } from "../fields.js";
import { LiveChart, download } from "../chart.js";
import { panel } from "./common.js";

let app, root, chart = null, cfg = null, all = [], picks, fsCfg, fsTrig, fsView, info, sub = null;
let version = null, nextSample = -1, pushes = [], built = false, loading = false;

export function mount(a, node) {
  app = a;
  root = node;
  app.rpc.on("notify_scope_data", (params) => onData(params[0]));
  app.addEventListener("connected", () => { sub = null; if (app.page === "scope") start(); else built = false; });
  app.addEventListener("lost", () => { sub = null; });
}

export function show() { start(); }

export function hide() {
  // keep the subscription: the history stays on the server anyway; stop pushes to save CPU
  if (sub !== null) { app.call("unsubscribe", { subscription: sub }, { quiet: true }).catch(() => {}); sub = null; }
}

async function start() {
  if (loading) return;
  loading = true;
  try {
    const [ch, get] = await Promise.all([app.call("scope.channels"), app.call("scope.get")]);
    all = ch.channels;
    cfg = get;
    build();
    await loadHistory();
    if (sub === null) {
      const r = await app.call("scope.subscribe", { rate_hz: 25 });
      sub = r.subscription;
    }
  } catch (err) {
    root.replaceChildren(el("p", { class: "form-error" }, `scope: ${err.message}`));
  } finally {
    loading = false;
  }
}

function unitOf(name) {
  const c = all.find((x) => x.name === name);
  return c ? c.unit : "";
}

function build() {
  built = true;
  const chosen = new Set(cfg.channels);
  // channel picker: one row per axis, one column per quantity
  picks = new Map();
  const groups = new Map();
  const quantities = [];
  const board = new Map();   // general lines: di.<n> / do.<n>, a table of their own
  for (const c of all) {
    const dot = c.name.indexOf(".");
    const head = dot > 0 ? c.name.slice(0, dot) : "";
    if (head === "di" || head === "do") {
      if (!board.has(head)) board.set(head, []);
      board.get(head).push(c);
      continue;
    }
    const g = dot > 0 ? c.name.slice(0, dot) : "";
    const q = dot > 0 ? c.name.slice(dot + 1) : c.name;
    if (!groups.has(g)) groups.set(g, new Map());
    groups.get(g).set(q, c);
    if (!quantities.includes(q)) quantities.push(q);
  }
  const short = (q) => q.replace(/^io\./, "").replace("command", "cmd").replace("feedback", "fb")
    .replace("velocity", "vel").replace("acceleration", "acc").replace("error", "err");
  const table = el("table", { class: "kv picks" },
    el("tr", {}, el("th", {}, ""), ...quantities.map((q) => el("th", { title: q }, short(q)))));
  for (const [g, byQ] of groups) {
    const row = el("tr", {}, el("th", {}, g || "-"));
    for (const q of quantities) {
      const c = byQ.get(q);
      if (!c) { row.append(el("td", {})); continue; }
      const box = el("input", { type: "checkbox", value: c.name, title: `${c.name}${c.unit ? ` (${c.unit})` : ""}` });
      box.checked = chosen.has(c.name);
      picks.set(c.name, box);
      row.append(el("td", {}, box));
    }
    table.append(row);
  }
  const lines = el("table", { class: "kv picks", id: "scope-board-picks" },
    el("tr", {}, el("th", { title: "general inputs (di) and outputs (do) of the board" }, "line"),
      ...(board.get("di") || board.get("do") || []).map((c, k) => el("th", {}, String(k)))));
  for (const [g, chans] of board) {
    const row = el("tr", {}, el("th", { title: g === "di" ? "general inputs (electrical level)" : "general outputs (level written)" }, g.toUpperCase()));
    for (const c of chans) {
      const box = el("input", { type: "checkbox", value: c.name, title: `${c.name} (0/1)` });
      box.checked = chosen.has(c.name);
      picks.set(c.name, box);
      row.append(el("td", {}, box));
    }
    lines.append(row);
  }
  const pickBox = el("div", { id: "scope-picks", style: "overflow-x:auto" }, table,
    board.size ? lines : "");
  const pickErr = el("div", { class: "form-error", id: "scope-pick-error" });
  const trig = cfg.trigger || {};
  fsCfg = new FieldSet(el("div", { id: "scope-cfg" }), [
    { name: "divider", label: "Sample every", unit: "cycles", kind: "int", min: 1, max: 1000, value: cfg.divider ?? 1 },
    { name: "seconds", label: "History kept", unit: "s", min: 1, max: 600, value: cfg.seconds ?? 30 },
  ]);
  fsTrig = new FieldSet(el("div", { id: "scope-trig" }), [
    { name: "mode", label: "Trigger", kind: "select", value: trig.mode && trig.mode !== "none" ? "single" : "off",
      options: [["off", "off (free run)"], ["single", "single (server captures, then stops)"], ["normal", "normal (display re-arms)"]] },
    { name: "channel", label: "Trigger channel", kind: "select", options: cfg.channels.map((c) => [c, c]), value: trig.channel || cfg.channels[0] },
    { name: "edge", label: "Edge", kind: "select", value: trig.mode && ["rising", "falling", "level"].includes(trig.mode) ? trig.mode : "rising",
      options: [["rising", "rising"], ["falling", "falling"], ["level", "level (either)"]] },
    { name: "level", label: "Level", value: trig.level ?? 0 },
    { name: "pre_s", label: "Pre-trigger", unit: "s", min: 0, value: trig.pre_s ?? 0.5,
      check: (v, raw) => (Number(raw.mode === "single") && v > Number(fsCfg ? fsCfg.raw().seconds : 600) ? "Pre-trigger must be <= History kept" : "") },
  ]);
  fsView = new FieldSet(el("div", { id: "scope-view" }), [
    { name: "window", label: "Window shown", unit: "s", min: 0.01, max: 600, value: 5 },
  ], { onChange: () => { const v = fsView.values(); if (v && chart) chart.setWindow(v.window); } });
  info = el("div", { class: "small muted", id: "scope-info" });
  const runBtn = button("Run", () => cmd("scope.run"), { id: "scope-run" });
  const pauseBtn = button("Pause", () => cmd("scope.pause"), { id: "scope-pause" });
  const freeze = el("input", { type: "checkbox", id: "scope-freeze" });
  freeze.addEventListener("change", () => chart && chart.setPaused(freeze.checked));
  const box = el("div", { class: "chart", id: "scope-chart" });
  root.replaceChildren(
    el("div", { class: "panel wide" },
      el("div", { class: "chart-tools" }, runBtn, pauseBtn,
        button("Arm trigger", () => arm(), { id: "scope-arm", title: "clears the history and waits for the trigger" }),
        el("label", {}, freeze, " freeze display"),
        button("Export CSV (history)", () => exportServer(), { id: "scope-csv" }),
        button("Export CSV (visible)", () => chart && download("scope-visible.csv", chart.toCsv({ visibleOnly: true })), { id: "scope-csv-visible" }),
        fsView.container, info),
      box,
      el("div", { class: "small muted" }, "Drag across the chart to zoom; double click to follow live again. Click a legend entry to hide a channel.")),
    el("div", { class: "grid", style: "margin-top:12px" },
      el("div", { class: "panel wide" }, el("h3", {}, "Channels (1 to 16)"), pickBox, pickErr),
      panel("Recording", fsCfg.container),
      panel("Trigger", fsTrig.container,
        el("div", { class: "row" }, button("Apply (clears the history)", () => configure(pickErr), { id: "scope-apply", class: "primary" })))));
  if (chart) chart.destroy();
  chart = new LiveChart(box, {
    channels: cfg.channels.map((name) => ({ key: name, label: name, unit: unitOf(name) })),
    windowS: Number(fsView.raw().window) || 5, capacity: 200000, height: 360,
  });
  app.scopeChart = chart;
  applyDisplayTrigger();
  fsTrig.onChange = () => applyDisplayTrigger();
}

function applyDisplayTrigger() {
  const raw = fsTrig.raw();
  if (!chart) return;
  const idx = cfg.channels.indexOf(raw.channel);
  const level = Number(raw.level);
  if (raw.mode === "normal" && idx >= 0 && Number.isFinite(level)) {
    const win = Number(fsView.raw().window) || 5;
    chart.setTrigger({ mode: "normal", channel: idx, level, edge: raw.edge === "level" ? "either" : raw.edge, pre: Math.min(0.9, (Number(raw.pre_s) || 0) / win) });
  } else chart.setTrigger({ mode: "off" });
}

async function loadHistory() {
  const d = await app.call("scope.data", { since: -1, max_points: 20000 });
  version = d.scope_version;
  nextSample = d.next;
  chart.setData(d.t, cfg.channels.map((c) => d.columns[c] || []));
  if (d.triggered_at !== null && d.triggered_at !== undefined) showCapture(d.triggered_at);
}

function showCapture(tAt) {
  if (!chart || !chart.t.length) return;
  chart.frozen = [chart.t[0], chart.t[chart.t.length - 1]];
  chart.triggeredAt = tAt;
  chart.redraw();
}

function onData(d) {
  if (!d || !chart || app.page !== "scope") return;
  const now = performance.now();
  pushes.push(now);
  while (pushes.length && pushes[0] < now - 2000) pushes.shift();
  if (d.scope_version !== version) { start(); return; }   // reconfigured (maybe by another tab)
  if (d.first !== undefined && nextSample >= 0 && d.first > nextSample) {
    // missed samples (the push was decimated or dropped): history is on the server
    loadHistory().catch(() => {});
    return;
  }
  nextSample = d.next;
  chart.append(d.t, cfg.channels.map((c) => d.columns[c] || []));
  if (d.triggered_at !== null && d.triggered_at !== undefined) showCapture(d.triggered_at);
  const rate = pushes.length / 2;
  info.textContent = `${rate.toFixed(1)} updates/s · ${chart.t.length} samples · ${chart.triggeredAt !== null ? `triggered at ${num(chart.triggeredAt, 4)} s` : ""}`;
  info.dataset.rate = String(rate);
}

async function cmd(method) {
  try { const r = await app.call(method); app.log(`${method}: ${r && r.running !== undefined ? (r.running ? "running" : "paused") : "ok"}`); } catch { /* logged */ }
}

async function arm() {
  try {
    await app.call("scope.arm");
    chart.clear();
  } catch (err) { serverError(err, [fsTrig]); }
}

async function configure(pickErr) {
  pickErr.textContent = "";
  const channels = [...picks].filter(([, b]) => b.checked).map(([n]) => n);
  if (channels.length < 1 || channels.length > 16) { pickErr.textContent = `choose 1 to 16 channels (${channels.length} chosen)`; return; }
  const c = fsCfg.values();
  const t = fsTrig.values();
  if (!c || !t) return;
  const params = { channels, divider: c.divider, seconds: c.seconds };
  if (t.mode === "single") {
    if (!channels.includes(t.channel)) { fsTrig.showError("channel", "Trigger channel must be one of the chosen channels"); return; }
    if (t.pre_s > c.seconds) { fsTrig.showError("pre_s", "Pre-trigger must be <= History kept"); return; }
    params.trigger = { channel: t.channel, mode: t.edge, level: t.level, pre_s: t.pre_s };
  }
  try {
    await app.call("scope.configure", params);
    await start();
  } catch (err) {
    if (err.data && err.data.param && String(err.data.param).startsWith("channels")) pickErr.textContent = err.message;
    else serverError(err, [fsCfg, fsTrig], { trigger: "channel" });
  }
}

async function exportServer() {
  try {
    const r = await app.call("scope.csv", {});
    download("scope.csv", r.csv);
  } catch { /* logged */ }
}
