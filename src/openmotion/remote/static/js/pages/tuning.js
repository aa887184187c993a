// Tuning (what a vendor's servo tuning tool offers): a test move with chosen speed, ramps
// and S-curve (there and back), recorded every control cycle on the server: commanded vs
// actual position and velocity, following error, and the figures (peak / RMS following
// error, overshoot, settling time). For an axis whose servo loop runs in the controller
// (the HCTL-1100 lead filter K/A/B, or PID + feed-forward) its gains are edited, applied
// at once and saved in the machine file, and a set-point step shows the step response
// (rise time, overshoot, settling time).

import { el, button, num } from "../dom.js";
import { FieldSet } from "../fields.js";
import { LiveChart } from "../chart.js";
import { panel, motionSpecs } from "./common.js";

let app, root, info = null, fsMove, fsLoop = null, fsStep = null, charts = [], stateBox, figBox;
let polling = 0, lastId = null, building = false;

const MOVE_KEYS = ["max_vel", "tacc", "tdec", "shape", "vs_acc", "vs_dec"];

export function mount(a, node) {
  app = a;
  root = node;
  app.addEventListener("config", () => { if (app.page === "tuning") build(); else info = null; });
  app.addEventListener("axis", () => { if (app.page === "tuning") build(); else info = null; });
}

export function show() { if (!info || info.axis !== app.axis) build(); else fetchResult(); }

export function hide() { clearTimeout(polling); polling = 0; }

async function build() {
  if (building || !app.info) return;
  building = true;
  try {
    info = await app.call("tune.get", { axis: app.axis });
    render();
    await fetchResult();
  } catch (err) {
    root.replaceChildren(el("p", { class: "form-error" }, `tuning: ${err.message}`));
  } finally {
    building = false;
  }
}

function render() {
  const ax = app.axisInfo(info.axis) || {};
  const unit = info.unit;
  const specs = motionSpecs(ax).filter((s) => MOVE_KEYS.includes(s.name));
  fsMove = new FieldSet(el("div", { id: "tune-move" }), [
    { name: "distance", label: "Distance", unit, value: ax.max_speed ? +(ax.max_speed / 20).toPrecision(2) : 10,
      check: (v) => (v === 0 ? "Distance must not be 0" : "") },
    ...specs,
    { name: "back", label: "Move back", kind: "bool", value: true },
    { name: "settle_s", label: "Settle time", unit: "s", min: 0, max: 10, value: 0.3 },
    { name: "band", label: "Settling band ±", unit, min: 0, minExclusive: true, optional: true, value: "",
      help: "empty: the drive's in-position band" },
  ]);
  const movePanel = panel(`Test move — axis ${info.axis}`, fsMove.container,
    el("div", { class: "row" },
      button("Run test move", () => runMove(), { id: "tune-run", class: "primary" }),
      button("Stop", () => app.call("axis.stop", { axis: info.axis }).catch(() => {}), { id: "tune-stop" })),
    el("p", { class: "small muted" }, "Servo On first (Operation page). The move runs from where the axis is; every control cycle is recorded."));
  let loopPanel;
  if (info.servo_loop && info.loop) {
    const L = info.loop;
    const lead = (raw) => raw.compensator !== "lead";
    const pid = (raw) => raw.compensator !== "pid";
    fsLoop = new FieldSet(el("div", { id: "tune-loop" }), [
      { name: "compensator", label: "Compensator", kind: "select", value: L.compensator,
        options: [["lead", "HCTL-1100 lead filter (K, A, B)"], ["pid", "PID + feed-forward"]] },
      { name: "k", label: "K (gain)", kind: "int", min: 0, max: 255, value: L.k, disabled: lead, help: "gain K/4" },
      { name: "a", label: "A (zero)", kind: "int", min: 0, max: 255, value: L.a, disabled: lead, help: "zero A/256" },
      { name: "b", label: "B (pole)", kind: "int", min: 0, max: 255, value: L.b, disabled: lead, help: "pole B/256" },
      { name: "kp", label: "Kp", min: 0, value: L.kp, disabled: pid, check: (v, raw) => (raw.compensator === "pid" && v <= 0 ? "Kp must be > 0 for PID" : "") },
      { name: "ki", label: "Ki", min: 0, value: L.ki, disabled: pid },
      { name: "kd", label: "Kd", min: 0, value: L.kd, disabled: pid },
      { name: "kvff", label: "Kvff", value: L.kvff, disabled: pid },
      { name: "kaff", label: "Kaff", value: L.kaff, disabled: pid },
      { name: "following_error", label: "Following error limit", unit: "counts", min: 0, minExclusive: true, value: L.following_error },
    ]);
    fsStep = new FieldSet(el("div", { id: "tune-step" }), [
      { name: "amplitude", label: "Step", unit: "counts", min: -100000, max: 100000, value: 100,
        check: (v) => (v === 0 ? "Step must not be 0" : "") },
      { name: "duration_s", label: "Record", unit: "s", min: 0.01, max: 10, value: 0.2 },
    ]);
    loopPanel = panel(`Servo loop of axis ${info.axis} (${info.loop.samples_per_cycle} samples per cycle)`, fsLoop.container,
      el("div", { class: "row" }, button("Apply gains", () => applyGains(), { id: "tune-apply", class: "primary", title: "applied at once and saved in the machine file" })),
      fsStep.container,
      el("div", { class: "row" }, button("Step response", () => runStep(), { id: "tune-step-run" })));
  } else {
    fsLoop = fsStep = null;
    loopPanel = panel("Servo loop", el("p", { class: "muted", id: "tune-no-loop" },
      `Axis ${info.axis} (drive ${info.drive}) has no position loop in the controller: its drive closes the loop, so the gains are the drive's. ` +
      "The test move still shows how it follows. A dc_servo axis, or [axes.<name>.loop] in the machine file, has gains to tune here."));
  }
  stateBox = el("div", { id: "tune-state", "data-state": "idle" }, "no run yet");
  figBox = el("div", { id: "tune-figures" });
  const boxes = [0, 1, 2].map((k) => el("div", { class: "chart", id: `tune-chart-${k}`, "data-kind": k === 1 ? "velocity" : null }));
  root.replaceChildren(el("div", { class: "grid" }, movePanel, loopPanel,
    el("div", { class: "panel wide" }, el("h3", {}, "Result"), stateBox, figBox, ...boxes)));
  charts = [
    new LiveChart(boxes[0], { channels: [{ key: "command", label: "commanded", unit }, { key: "actual", label: "actual", unit }], windowS: 1, height: 220, title: "position" }),
    new LiveChart(boxes[1], { channels: [{ key: "velocity_command", label: "commanded", unit: `${unit}/s` }, { key: "velocity_actual", label: "actual", unit: `${unit}/s` }], windowS: 1, height: 200, title: "velocity" }),
    new LiveChart(boxes[2], { channels: [{ key: "error", label: "following error", unit: "counts" }], windowS: 1, height: 180, title: "following error" }),
  ];
}

async function runMove() {
  const v = fsMove.values();
  if (!v) return;
  const params = { axis: info.axis, kind: "move", distance: v.distance, back: v.back, settle_s: v.settle_s };
  for (const k of MOVE_KEYS) if (v[k] !== undefined && v[k] !== null) params[k] = v[k];
  if (v.band !== null && v.band !== undefined) params.band = v.band;
  await start(params, fsMove);
}

async function runStep() {
  const v = fsStep.values();
  if (!v) return;
  await start({ axis: info.axis, kind: "step", amplitude: v.amplitude, duration_s: v.duration_s }, fsStep);
}

async function start(params, fs) {
  try {
    const r = await app.call("tune.run", params);
    lastId = r.id;
    setState("running", `run ${r.id}: running…`);
    poll();
  } catch (err) {
    fs.serverError(err);
  }
}

async function applyGains() {
  const v = fsLoop.values();
  if (!v) return;
  const changes = {};
  for (const [k, val] of Object.entries(v)) if (info.loop[k] !== val) changes[k] = val;
  if (!Object.keys(changes).length) { app.log("the gains are unchanged: nothing sent"); return; }
  try {
    const r = await app.call("tune.gains", { axis: info.axis, changes });
    if (r.config_version) app.configVersion = r.config_version;
    info = { ...info, loop: r.loop };
    app.log(`gains applied${r.saved ? ` and saved to ${r.saved}` : " (no machine file: Machine page, Save)"}`);
  } catch (err) {
    fsLoop.serverError(err);
  }
}

function poll() {
  clearTimeout(polling);
  polling = setTimeout(async () => {
    const r = await fetchResult();
    if (r && r.state === "running" && app.page === "tuning") poll();
  }, 200);
}

async function fetchResult() {
  try {
    const r = await app.call("tune.result", { max_points: 4000 }, { quiet: true });
    showResult(r);
    if (r.state === "running" && !polling) poll();
    return r;
  } catch {
    return null;
  }
}

function setState(state, text) {
  stateBox.dataset.state = state;
  stateBox.textContent = text;
}

function showResult(r) {
  if (!stateBox) return;
  if (!r || r.id === null) { setState("idle", "no run yet"); return; }
  polling = r.state === "running" ? polling : 0;
  const what = r.kind === "step" ? `step of ${r.params.amplitude} counts` : `move of ${r.params.distance} ${r.unit}${r.params.back ? " and back" : ""}`;
  setState(r.state, `run ${r.id} on axis ${r.axis}: ${what} — ${r.state}${r.message ? `: ${r.message}` : ""}`);
  figBox.replaceChildren(figures(r));
  if (r.state === "running") return;
  const t = r.t;
  const dur = t.length ? t[t.length - 1] - t[0] : 1;
  const step = r.kind === "step";
  setMiddleChart(step ? "duty" : "velocity");
  const sets = step
    ? [[r.columns.command, r.columns.actual], [r.columns.duty.map((d) => d * 100)], [r.columns.error]]
    : [[r.columns.command, r.columns.actual], [r.columns.velocity_command, r.columns.velocity_actual], [r.columns.error]];
  charts.forEach((c, i) => { c.setWindow(Math.max(dur, 0.001)); c.setData(t, sets[i]); });
  app.tuneCharts = charts;
}

/** The middle chart: velocities of a test move, or the amplifier duty of a step. */
function setMiddleChart(kind) {
  const box = root.querySelector("#tune-chart-1");
  if (!box || box.dataset.kind === kind) return;
  box.dataset.kind = kind;
  if (charts[1]) charts[1].destroy();
  box.replaceChildren();
  const unit = info.unit;
  charts[1] = kind === "duty"
    ? new LiveChart(box, { channels: [{ key: "duty", label: "amplifier duty", unit: "%" }], windowS: 1, height: 200, title: "loop output" })
    : new LiveChart(box, { channels: [{ key: "velocity_command", label: "commanded", unit: `${unit}/s` }, { key: "velocity_actual", label: "actual", unit: `${unit}/s` }], windowS: 1, height: 200, title: "velocity" });
}

function figures(r) {
  const rows = r.figures || [];
  if (!rows.length) return el("p", { class: "muted" }, r.state === "running" ? "recording…" : "no figures");
  const u = r.unit;
  const fmt = (v, d = 3) => (v === null || v === undefined ? "not settled" : num(v, d));
  const head = r.kind === "step"
    ? ["step", "rise 10-90 %", "overshoot", "settling time", "band", "peak error", "final error"]
    : ["move", "move time", "peak following error", "RMS following error", "overshoot", "settling time", "band", "final error"];
  const body = rows.map((f) => (r.kind === "step"
    ? [`${f.amplitude} counts`, `${fmt(f.rise_time_s * 1000, 1)} ms`, `${num(f.overshoot, 1)} counts (${num(f.overshoot_pct, 1)} %)`,
      f.settling_time_s === null ? "not settled" : `${num(f.settling_time_s * 1000, 1)} ms`, `±${num(f.band, 1)} counts`,
      `${num(f.peak_following_error, 0)} counts`, `${num(f.final_error, 0)} counts`]
    : [`${f.segment}: ${num(f.distance, 3)} ${u}`, `${num(f.move_time_s, 3)} s`, `${num(f.peak_following_error, 0)} counts`,
      `${num(f.rms_following_error, 1)} counts`, `${num(f.overshoot, 4)} ${u} (${num(f.overshoot_pct, 2)} %)`,
      f.settling_time_s === null ? "not settled" : `${num(f.settling_time_s * 1000, 1)} ms`, `±${num(f.band, 4)} ${u}`,
      f.final_error === null ? "-" : `${num(f.final_error, 4)} ${u}`]));
  return el("table", { class: "kv figures", id: "tune-figure-table" },
    el("tr", {}, ...head.map((h) => el("th", {}, h))),
    ...body.map((cells, i) => el("tr", { "data-segment": String(i + 1) }, ...cells.map((c) => el("td", {}, c)))));
}
