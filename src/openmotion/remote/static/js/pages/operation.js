// Operation (Motion Creator 5.3.4): live counters, state, speed, I/O lamps, servo on,
// absolute / relative / velocity / home moves with their parameters, repeat between two
// positions, change of speed and position on the fly, stop, set / reset positions, jog.

import { el, button, num } from "../dom.js";
import { FieldSet, serverError } from "../fields.js";
import { LiveChart } from "../chart.js";
import { Jogger } from "../jog.js";
import { panel, Lamps, motionSpecs, compact } from "./common.js";
import { mergeDiff } from "../status.js";

let app, root, fsTarget, fsMotion, fsRepeat, fsSet, fsJog, lamps, chart, jogger;
const view = {};

function targetSpecs(info) {
  const unit = info ? info.unit : "";
  const vmax = info ? info.max_speed : undefined;
  return [
    { name: "mode", label: "Operation mode", kind: "select", value: "relative",
      options: [["absolute", "Absolute mode"], ["relative", "Relative mode"], ["velocity", "Cont. move (velocity)"]] },
    { name: "position1", label: "Position 1", unit, value: 0 },
    { name: "position2", label: "Position 2", unit, value: 10 },
    { name: "distance", label: "Distance", unit, value: 10, check: (v) => (v === 0 ? "Distance must not be 0" : "") },
    { name: "velocity", label: "Velocity (signed)", unit: `${unit}/s`, value: vmax ? +(vmax / 10).toPrecision(3) : 5,
      check: (v) => (v === 0 ? "Velocity must not be 0" : vmax && Math.abs(v) > vmax ? `|Velocity| must be <= ${vmax} ${unit}/s (the axis's max speed)` : "") },
  ];
}

const REPEAT_SPECS = [
  { name: "repeat", label: "Repeat mode", kind: "bool", value: false },
  { name: "delay_s", label: "Move delay", unit: "s", min: 0, max: 60, value: 0.5 },
  { name: "count", label: "Moves (0 = until stop)", kind: "int", min: 0, max: 1000000, value: 0 },
];

function jogSpecs() {
  return [
    { name: "ratio", label: "Jog speed", unit: "% of max", min: 0, minExclusive: true, max: 100, value: 10 },
    { name: "step", label: "Inching step", unit: app.axisInfo() ? app.axisInfo().unit : "", value: 1,
      check: (v) => (v === 0 ? "Inching step must not be 0" : "") },
  ];
}

export function mount(a, node) {
  app = a;
  root = node;
  root.append(el("p", { class: "muted" }, "Connecting to the controller…"));
  app.addEventListener("config", build);
  app.addEventListener("axis", build);
  app.addEventListener("status", update);
  jogger = new Jogger({
    start: async (axis, direction, opts) => (await app.call("jog.start", { axis, direction, ...opts })).jog,
    confirm: (jog) => app.rpc.notify("jog.confirm", { jog }),
    check: (jog) => app.rpc.call("jog.confirm", { jog }, { timeoutMs: 1000 }),
    stop: (jog) => app.call("jog.stop", { jog }),
  }, {
    onState: (active, err) => {
      for (const b of root.querySelectorAll("button.jog")) {
        b.classList.toggle("pressed", Boolean(active) && Number(b.dataset.dir) === active.dir);
      }
      if (err) { serverError(err, [fsJog]); app.log(err.message, true); }
    },
  });
  jogger.opts = () => {
    const v = fsJog ? fsJog.values(["ratio"]) : null;
    return v ? { ratio: v.ratio } : { ratio: 10 };
  };
  jogger.setKeys({ ArrowRight: [() => app.axis, 1], ArrowLeft: [() => app.axis, -1],
    PageUp: [() => app.axis, 1], PageDown: [() => app.axis, -1] });
  app.addEventListener("lost", () => jogger.release("connection lost"));
}

export function show() { if (chart) { chart.setHidden(false); chart.redraw(); } }
export function hide() {
  if (jogger) jogger.release("page left");
  if (chart) chart.setHidden(true);   // the curve keeps its samples, drawn when shown again
}

function build() {
  if (!app.info) return;
  const info = app.axisInfo();
  const keep = fsTarget ? { t: fsTarget.raw(), m: fsMotion.raw(), r: fsRepeat.raw(), j: fsJog.raw() } : null;
  const keepAxis = view.axis;
  view.axis = app.axis;
  if (chart) { chart.destroy(); chart = null; }
  root.replaceChildren();

  // counters
  const counters = el("table", { class: "kv counters" });
  for (const [key, label] of [["command", "Command"], ["feedback", "Feedback"], ["error", "Pos error"], ["target", "Target pos"],
    ["position", `Position (${info.unit})`], ["velocity", `Velocity (${info.unit}/s)`]]) {
    const cell = el("td", { class: "n", id: `op-${key}` }, "-");
    view[key] = cell;
    counters.append(el("tr", {}, el("th", {}, label), cell));
  }
  view.state = el("span", { class: "state", id: "op-state" }, "-");
  view.fault = el("div", { class: "small", id: "op-fault", style: "color: var(--bad)" });
  view.homing = el("div", { class: "small muted", id: "op-homing" });
  view.servo = el("input", { type: "checkbox", id: "op-servo", onchange: () => servo() });
  const servoLabel = el("label", { class: "row", title: "the SVON output (HSL_M_set_servo)" }, view.servo, "Servo On");
  view.reset = button("Reset axis", () => act("axis.reset", {}), { id: "op-reset", title: "clears ErrorStop" });
  fsSet = new FieldSet(el("div", { id: "op-setpos" }), [
    { name: "position", label: "Position", unit: info.unit, value: 0 }]);
  const posPanel = panel(`Axis ${app.axis} — position`, counters,
    el("div", { class: "row" }, "State ", view.state, servoLabel, view.reset),
    view.fault, view.homing,
    fsSet.container,
    el("div", { class: "row" },
      button("Set position", () => setPos(), { id: "op-set-position", title: "sets command and feedback to Position (at rest)" }),
      button("Reset counters", () => act("axis.reset_position", {}), { id: "op-reset-position", title: "command, feedback, error, target := 0" })));

  // I/O
  lamps = new Lamps("op");
  const ioPanel = panel("I/O status", lamps.node, el("p", { class: "small muted" }, "lit = active (logical level, after NO/NC)"));

  // motion
  fsTarget = new FieldSet(el("div", { id: "op-target" }), targetSpecs(info), { onChange: (n) => { if (n === "mode") relabel(); } });
  fsMotion = new FieldSet(el("div", { id: "op-motion", class: "fields-2" }), motionSpecs(info));
  fsRepeat = new FieldSet(el("div", { id: "op-repeat" }), REPEAT_SPECS);
  view.play1 = button("Play 1", () => play(1), { id: "op-play1", class: "primary" });
  view.play2 = button("Play 2", () => play(2), { id: "op-play2", class: "primary" });
  const movePanel = el("div", { class: "panel wide" }, el("h3", {}, "Operation mode"),
    el("div", { class: "move-grid" }, fsTarget.container, fsMotion.container, fsRepeat.container),
    el("div", { class: "row" }, view.play1, view.play2,
      button("Stop", () => stop("decel"), { id: "op-stop", class: "danger", title: "decelerate and stop (Decel. time)" }),
      button("Stop now", () => stop("immediate"), { id: "op-stop-now", class: "danger" }),
      el("span", { class: "spacer" }),
      button("Change velocity on the fly", () => changeSpeed(), { id: "op-vchange", title: "new speed = Maximum velocity (signed Velocity in Cont. move)" }),
      button("Change position on the fly", () => changePos(), { id: "op-pchange", title: "new target = Position 2" }),
      button("Home", () => act("home.start", {}), { id: "op-home", title: "home with the Homing page's settings" })));

  // jog
  fsJog = new FieldSet(el("div", { id: "op-jog" }), jogSpecs());
  const minus = el("button", { type: "button", class: "jog", id: "op-jog-minus", "data-dir": "-1", title: "hold to jog (key ←)" }, "◀ −");
  const plus = el("button", { type: "button", class: "jog", id: "op-jog-plus", "data-dir": "1", title: "hold to jog (key →)" }, "+ ▶");
  jogger.bindButton(minus, () => app.axis, -1);
  jogger.bindButton(plus, () => app.axis, 1);
  const kb = el("input", { type: "checkbox", id: "op-keyboard" });
  kb.checked = jogger.keyboardOn;
  kb.addEventListener("change", () => { jogger.keyboardOn = kb.checked; if (!kb.checked) jogger.release("keyboard off"); });
  const jogPanel = panel("Jog (hold)", fsJog.container,
    el("div", { class: "row" }, minus, plus,
      button("Step −", () => inch(-1), { id: "op-step-minus" }), button("Step +", () => inch(1), { id: "op-step-plus" })),
    el("label", { class: "row small" }, kb, "Keyboard jog: hold ", el("span", { class: "kbd" }, "←"), " ", el("span", { class: "kbd" }, "→"),
      " (stops on key up, on leaving the window, when the tab is hidden or the connection drops)"));

  // velocity curve
  const chartBox = el("div", { class: "chart", id: "op-chart" });
  const curvePanel = el("div", { class: "panel wide" },
    el("div", { class: "row" }, el("h3", { style: "margin:0" }, "Velocity curve"), el("span", { class: "spacer" }),
      button("Clear", () => chart && chart.clear(), { id: "op-chart-clear" }),
      el("a", { href: "#scope", class: "small" }, "Scope: every cycle, trigger, CSV →")),
    chartBox);

  root.append(el("div", { class: "grid" }, posPanel, ioPanel, jogPanel), el("div", { class: "grid", style: "margin-top:12px" }, movePanel, curvePanel));
  chart = new LiveChart(chartBox, { channels: [
    { key: "velocity", label: "velocity", unit: `${info.unit}/s` },
    { key: "position", label: "position", unit: info.unit },
  ], windowS: 10, capacity: 20000, height: 220 });
  chart.setHidden(app.page !== "operation");
  app.opChart = chart;
  if (keep && keepAxis === app.axis) {
    fsTarget.setAll(keep.t); fsMotion.setAll(keep.m); fsRepeat.setAll(keep.r); fsJog.setAll(keep.j);
  }
  relabel();
  update();
}

function relabel() {
  const mode = fsTarget.raw().mode;
  const labels = { absolute: ["◀ to Position 1", "to Position 2 ▶"], relative: ["◀ Backward", "Forward ▶"], velocity: ["◀ − velocity", "+ velocity ▶"] }[mode];
  view.play1.textContent = labels[0];
  view.play2.textContent = labels[1];
  for (const [name, modes] of [["position1", ["absolute"]], ["position2", ["absolute"]], ["distance", ["relative"]], ["velocity", ["velocity"]]]) {
    fsTarget.container.querySelector(`[data-name="${name}"]`).style.opacity = modes.includes(mode) ? "1" : "0.45";
  }
}

function update() {
  const s = app.axisStatus();
  if (!s || !view.command) return;
  const info = app.axisInfo();
  const digits = info && info.unit === "pulse" ? 0 : 4;
  for (const k of ["command", "feedback", "error", "target"]) view[k].textContent = num(s[k], 0);
  view.position.textContent = num(s.position, digits);
  view.velocity.textContent = num(s.velocity, digits > 0 ? 3 : 0);
  view.state.textContent = s.state + (s.repeat ? " (repeat)" : "") + (s.jog ? " (jog)" : "");
  view.state.dataset.state = s.state;
  view.fault.textContent = s.fault ? `fault: ${s.fault}` : "";
  const h = s.homing || {};
  view.homing.textContent = h.state && h.state !== "idle" ? `homing: ${h.state}${h.phase ? " · " + h.phase : ""}${h.reason ? " · " + h.reason : ""}` : "";
  if (!view.servoBusy) view.servo.checked = Boolean(s.servo);
  view.reset.disabled = s.state !== "ErrorStop";
  lamps.update(s.io || {});   // SVON: the servo-on output (io.svon, set by axis.servo)
  if (chart && app.status && typeof app.status.time === "number") chart.append([app.status.time], [[s.velocity], [s.position]]);
}

async function act(method, params, sets = [fsTarget, fsMotion]) {
  for (const fs of sets) fs.clearFormError();
  try {
    const axis = app.axis;
    const r = await app.call(method, { axis, ...params });
    app.log(`${method} ${axis}: ok`);
    // an AxisStatus answer (servo, reset, set/reset position) is newer than the last push
    if (r && typeof r === "object" && "state" in r && "command" in r && app.status && app.status.axes && app.status.axes[axis]) {
      mergeDiff(app.status.axes[axis], r);
      app.dispatchEvent(new CustomEvent("status"));
    }
    return r;
  } catch (err) {
    serverError(err, sets, { p1: "position1", p2: "position2", delay_s: "delay_s" });
    return null;
  }
}

async function servo() {
  view.servoBusy = true;
  try { await act("axis.servo", { on: view.servo.checked }, [fsSet]); } finally { view.servoBusy = false; update(); }
}

function motionParams() {
  const m = fsMotion.values();
  if (!m) return null;
  const { fix_range, ...rest } = m;
  return compact({ ...rest, vs_acc: m.shape === "S" ? m.vs_acc : undefined, vs_dec: m.shape === "S" ? m.vs_dec : undefined,
    speed_range: fix_range ? m.speed_range : undefined });
}

async function play(which) {
  const mode = fsTarget.raw().mode;
  const need = { absolute: ["position1", "position2"], relative: ["distance"], velocity: ["velocity"] }[mode];
  const t = fsTarget.values(["mode", ...need]);
  const m = motionParams();
  const r = fsRepeat.values();
  if (!t || !m || !r) return;
  const sets = [fsTarget, fsMotion, fsRepeat];
  if (mode === "velocity") {
    const { max_vel, ...rest } = m;   // eslint-disable-line no-unused-vars
    const v = which === 2 ? t.velocity : -t.velocity;
    return act("axis.move", { kind: "velocity", velocity: v, ...rest }, sets);
  }
  if (r.repeat) {
    let p1, p2;
    if (mode === "absolute") { p1 = which === 1 ? t.position1 : t.position2; p2 = which === 1 ? t.position2 : t.position1; }
    else {
      const here = app.axisStatus().position;
      p1 = here;
      p2 = here + (which === 2 ? t.distance : -t.distance);
    }
    const { speed_range, ...rm } = m;   // eslint-disable-line no-unused-vars (repeat has no speed range)
    return act("axis.repeat", { p1, p2, delay_s: r.delay_s, count: r.count, ...rm }, sets);
  }
  if (mode === "absolute") return act("axis.move", { kind: "absolute", position: which === 1 ? t.position1 : t.position2, ...m }, sets);
  return act("axis.move", { kind: "relative", distance: which === 2 ? t.distance : -t.distance, ...m }, sets);
}

function stop(mode) {
  const m = fsMotion.values(["tdec"]);
  return act("axis.stop", compact({ mode, tdec: mode === "decel" && m ? m.tdec : undefined }));
}

function changeSpeed() {
  const mode = fsTarget.raw().mode;
  const m = fsMotion.values(["max_vel", "tacc"]);
  if (!m) return;
  let velocity = m.max_vel;
  if (mode === "velocity") {
    const t = fsTarget.values(["velocity"]);
    if (!t) return;
    const s = app.axisStatus();
    velocity = s && s.velocity < 0 ? -Math.abs(t.velocity) : Math.abs(t.velocity);
  }
  const r = fsMotion.values(["fix_range", "speed_range"]);
  if (r && r.fix_range && Math.abs(velocity) > r.speed_range) {
    (mode === "velocity" ? fsTarget : fsMotion).showError(mode === "velocity" ? "velocity" : "max_vel",
      `the new speed must be <= the fixed speed range ${r.speed_range} ${app.axisInfo().unit}/s`);
    return;
  }
  return act("axis.change_speed", { velocity, tacc: m.tacc }, [mode === "velocity" ? fsTarget : fsMotion, fsMotion]);
}

function changePos() {
  const t = fsTarget.values(["position2"]);
  if (!t) return;
  return act("axis.change_position", { position: t.position2 }, [fsTarget]);
}

function setPos() {
  const v = fsSet.values();
  if (!v) return;
  return act("axis.set_position", { position: v.position }, [fsSet]);
}

function inch(dir) {
  const v = fsJog.values(["step"]);
  if (!v) return;
  const info = app.axisInfo();
  const r = fsJog.values(["ratio"]);
  return act("jog.step", compact({ distance: dir * Math.abs(v.step), speed: r && info ? info.max_speed * r.ratio / 100 : undefined }), [fsJog]);
}
