// Simulation (when the back end is the simulator): trip a limit, raise an alarm, press the
// E-stop button, run in real time or faster.

import { el, button, num } from "../dom.js";
import { FieldSet } from "../fields.js";
import { panel, Lamps } from "./common.js";

let app, root, table, fsSpeed, estopBox, cycleBox, lampsByAxis = new Map();
let speedSeen;   // the server's speed factor last seen (the field follows its changes only)
const SIGNALS = [["pel", "+EL"], ["mel", "-EL"], ["org", "ORG"], ["sd", "SD"]];

export function mount(a, node) {
  app = a;
  root = node;
  app.addEventListener("config", build);
  app.addEventListener("status", update);
}

export function show() { update(); }

function build() {
  if (!app.info) return;
  if (app.info.simulated === false) {
    root.replaceChildren(el("p", {}, "The back end is real hardware: the simulation controls are not available."));
    return;
  }
  table = el("table", { class: "kv", id: "sim-table" });
  table.append(el("tr", {}, el("th", {}, "axis"), el("th", {}, "switches (click to put under / take away)"), el("th", {}, "drive"), el("th", {}, "lamps")));
  lampsByAxis = new Map();
  for (const ax of app.info.axes) {
    const sw = el("div", { class: "row" }, ...SIGNALS.map(([sig, label]) => {
      const b = button(label, () => trip(ax.name, sig, b), { id: `sim-${ax.name}-${sig}`, "data-active": "false" });
      return b;
    }));
    const alm = button("ALM", () => alarm(ax.name, alm), { id: `sim-${ax.name}-alm`, "data-active": "false" });
    const lamps = new Lamps(`sim-${ax.name}`);
    lampsByAxis.set(ax.name, lamps);
    table.append(el("tr", {}, el("td", {}, el("b", {}, ax.name)), el("td", {}, sw), el("td", {}, alm), el("td", {}, lamps.node)));
  }
  fsSpeed = new FieldSet(el("div", { id: "sim-speed" }), [
    { name: "factor", label: "Speed (× real time)", min: 1, max: 20, value: 1 },
  ]);
  estopBox = el("div", { id: "sim-estop-state" });
  cycleBox = el("div", { class: "small muted", id: "sim-cycle" });
  const press = button("Press E-stop button (EMG)", () => app.call("sim.estop", { pressed: true }).catch(() => {}), { id: "sim-estop-press", class: "danger" });
  const release = button("Release E-stop button", () => app.call("sim.estop", { pressed: false }).catch(() => {}), { id: "sim-estop-release" });
  const nIn = app.info.digital_inputs || 0, nOut = app.info.digital_outputs || 0;
  const lamp = (id, label, good) => el("span", { class: `lampbox${good ? " good" : ""}`, id, "data-on": "null" }, el("span", { class: "lamp" }), label);
  const dis = el("div", { class: "lamps", style: "grid-template-columns: repeat(8, auto)" },
    ...Array.from({ length: nIn }, (_, i) => {
      const b = el("button", { type: "button", class: "small", id: `sim-di-${i}`, title: `drive general input ${i} (sim.input)`,
        onclick: () => app.call("sim.input", { index: i, level: !boardLevel("di", i) }).catch(() => {}) }, lamp(`sim-di-lamp-${i}`, `DI${i}`, true));
      return b;
    }));
  const dos = el("div", { class: "lamps", style: "grid-template-columns: repeat(8, auto)" },
    ...Array.from({ length: nOut }, (_, i) => lamp(`sim-do-lamp-${i}`, `DO${i}`, true)));
  root.replaceChildren(el("div", { class: "grid" },
    el("div", { class: "panel wide" }, el("h3", {}, "Switches and drive alarms"), table),
    panel("E-stop", el("div", { class: "row" }, press, release,
      button("Reset axes", () => app.call("machine.reset").catch(() => {}), { id: "sim-reset" })), estopBox,
      el("p", { class: "small muted" }, "The red E-STOP button in the header is the software E-stop (machine.estop); this one is the EMG input of the simulated machine.")),
    el("div", { class: "panel wide" }, el("h3", {}, "General inputs (click to switch) and outputs (M62-M65)"),
      dis, el("div", { style: "height:8px" }), dos),
    panel("Time", fsSpeed.container,
      el("div", { class: "row" }, button("Apply", () => speed(), { id: "sim-speed-apply" }),
        ...[[1, "Real time"], [5, "×5"], [20, "×20"]].map(([f, label]) =>
          button(label, () => { fsSpeed.set("factor", f); speed(); }, { id: `sim-speed-${f}` }))), cycleBox)));
  update();
}

async function trip(axis, signal, b) {
  const active = b.dataset.active !== "true";
  try {
    await app.call("sim.trip_limit", { axis, signal, active });
    b.dataset.active = String(active);
    b.classList.toggle("on", active);
  } catch { /* logged */ }
}

async function alarm(axis, b) {
  const active = b.dataset.active !== "true";
  try {
    await app.call("sim.alarm", { axis, active });
    b.dataset.active = String(active);
    b.classList.toggle("on", active);
  } catch { /* logged */ }
}

async function speed() {
  const v = fsSpeed.values();
  if (!v) return;
  try {
    const r = await app.call("sim.speed", { factor: v.factor });
    app.log(`simulation speed ×${r.speed}`);
  } catch (err) { fsSpeed.serverError(err, { factor: "factor" }); }
}

function boardLevel(kind, i) {
  const b = app.status && app.status.board;
  return Boolean(b && b[kind] && b[kind][i]);
}

function update() {
  const s = app.status;
  if (!s || !table) return;
  if (s.board) {
    for (const kind of ["di", "do"]) {
      (s.board[kind] || []).forEach((v, i) => {
        const n = document.getElementById(`sim-${kind}-lamp-${i}`);
        if (n) n.dataset.on = String(Boolean(v));
      });
    }
  }
  for (const [name, lamps] of lampsByAxis) {
    const a = s.axes && s.axes[name];
    if (!a) continue;
    lamps.update(a.io || {});
    for (const [sig] of SIGNALS) {
      const b = document.getElementById(`sim-${name}-${sig}`);
      if (b && b.dataset.active === "true" && a.io && a.io[sig] === false && sig !== "org") b.title = "switch put under the axis (logic may invert the lamp)";
    }
  }
  estopBox.textContent = s.estop ? "E-stop ACTIVE" : "E-stop released";
  estopBox.style.color = s.estop ? "var(--bad)" : "var(--ok)";
  cycleBox.textContent = `speed ×${s.speed ?? 1} · cycle busy ${s.cycle ? num(s.cycle.busy_us, 0) : "-"} µs · overruns ${s.cycle ? s.cycle.overruns : "-"} · t = ${num(s.time, 2)} s`;
  // the field follows the server's factor only when that changes (another tab, a button):
  // a push between typing a factor and clicking Apply must not put the old one back
  if (s.speed !== undefined && s.speed !== speedSeen && fsSpeed) {
    speedSeen = s.speed;
    if (document.activeElement !== fsSpeed.inputs.get("factor")) fsSpeed.set("factor", s.speed);
  }
}
