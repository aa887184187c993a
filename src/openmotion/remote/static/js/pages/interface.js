// Interface I/O and pulse I/O per axis (Motion Creator 5.3.2 / 5.3.3): signal logic and
// responses, pulse output and input modes, move ratio. Validated here, saved by the server
// into the machine file (the responses in its [axes.<name>.responses] table) with `interface.set`.

import { el, button } from "../dom.js";
import { FieldSet } from "../fields.js";
import { panel } from "./common.js";

let app, root, sets = [], loaded = null, loadedAxis = null, choices = {};

const LABELS = {
  "logic.pel": "+EL logic", "logic.mel": "-EL logic", "logic.org": "ORG logic", "logic.sd": "SD logic",
  "logic.ltc": "LTC logic", "logic.ez": "EZ logic", "logic.alm": "ALM logic", "logic.inp": "INP logic",
  "logic.rdy": "RDY logic", "logic.emg": "EMG logic",
  pulse_mode: "Pulse output mode", pulse_width_us: "Pulse width", encoder_mode: "Pulse input (feedback) mode",
  invert_a: "Invert EA", invert_b: "Invert EB", invert_z: "Invert EZ", swap_ab: "Swap EA/EB", reverse: "Reverse count",
  move_ratio: "Move ratio (feedback/command)",
  "responses.el": "EL response", "responses.el_enabled": "EL enabled", "responses.el_direction_sensitive": "EL direction-sensitive",
  "responses.alm": "ALM response", "responses.erc_width_s": "ERC pulse width (0 = off)",
  "responses.sd.enabled": "SD enabled", "responses.sd.latched": "SD latched", "responses.sd.stop": "SD stops (else slows)",
  "responses.inp": "Wait for INP", "responses.rdy": "Refuse motion without RDY",
};

const OPTION_TEXT = {
  no: "normally open (active high)", nc: "normally closed (active low)",
  out_dir: "OUT/DIR: OUT falling edge, DIR+ high", out_dir_inv: "OUT/DIR: OUT rising edge, DIR+ high",
  out_dir_lo: "OUT/DIR: OUT falling edge, DIR+ low", out_dir_lo_inv: "OUT/DIR: OUT rising edge, DIR+ low",
  cw_ccw: "CW/CCW", ab_phase: "A/B phase",
  ab_x1: "1X A/B phase", ab_x2: "2X A/B phase", ab_x4: "4X A/B phase", pulse_dir: "pulse/direction",
  immediate: "stop immediately", decel: "decelerate to stop",
};

const NUMBERS = {
  pulse_width_us: { unit: "µs", min: 0, minExclusive: true, max: 1000 },
  move_ratio: { min: 0, minExclusive: true },
  "responses.erc_width_s": { unit: "s", min: 0 },
};

function flatten(obj, prefix = "", out = {}) {
  for (const [k, v] of Object.entries(obj || {})) {
    const name = prefix ? `${prefix}.${k}` : k;
    if (v !== null && typeof v === "object" && !Array.isArray(v)) flatten(v, name, out);
    else out[name] = v;
  }
  return out;
}

function nest(flat) {
  const out = {};
  for (const [name, v] of Object.entries(flat)) {
    const parts = name.split(".");
    let o = out;
    for (const p of parts.slice(0, -1)) o = o[p] = o[p] || {};
    o[parts[parts.length - 1]] = v;
  }
  return out;
}

/** The allowed values (or [min, max] range) of a field, whatever shape `choices` has. */
function choicesFor(name) {
  const parts = name.split(".");
  const nested = parts.reduce((o, p) => (o && typeof o === "object" ? o[p] : undefined), choices);
  for (const t of [nested, choices[name], parts[0] === "logic" ? undefined : choices[parts[parts.length - 1]]]) {
    if (Array.isArray(t)) return t;
  }
  return null;
}

function specFor(name, value) {
  const label = LABELS[name] || name;
  if (typeof value === "boolean") return { name, label, kind: "bool" };
  const ch = choicesFor(name);
  if (typeof value === "string") {
    const opts = ch || (name.startsWith("logic.") ? ["no", "nc"] : [value]);
    return { name, label, kind: "select", options: opts.map((v) => [v, OPTION_TEXT[v] ? `${v} — ${OPTION_TEXT[v]}` : v]) };
  }
  const spec = { name, label, kind: "number", ...(NUMBERS[name] || {}) };
  if (ch && ch.length === 2 && ch.every((x) => typeof x === "number")) { spec.min = ch[0]; spec.max = ch[1]; }
  return spec;
}

export function mount(a, node) {
  app = a;
  root = node;
  app.addEventListener("axis", () => { if (app.page === "interface") load(); });
  app.addEventListener("config", () => { if (app.page === "interface" || loaded) load(); });
}

export function show() { load(); }

let loadSeq = 0;
async function load() {
  if (!app.info) return;
  const seq = ++loadSeq;   // a newer load (another axis) wins over a late answer
  const axis = app.axis;
  let res;
  try {
    res = await app.call("interface.get", { axis });
    if (seq !== loadSeq) return;
  } catch (err) {
    root.replaceChildren(el("p", { class: "form-error" }, `could not read the interface of ${axis}: ${err.message}`));
    return;
  }
  choices = res.choices || {};
  const data = { ...res };
  delete data.choices;
  loaded = flatten(data);
  loadedAxis = axis;
  build();
}

function build() {
  const names = Object.keys(loaded);
  const group = (pred) => names.filter(pred).map((n) => specFor(n, loaded[n]));
  const logic = group((n) => n.startsWith("logic."));
  const responses = group((n) => n.startsWith("responses."));
  const pulse = group((n) => !n.startsWith("logic.") && !n.startsWith("responses."));
  sets = [
    new FieldSet(el("div", { id: "if-logic" }), logic),
    new FieldSet(el("div", { id: "if-responses" }), responses),
    new FieldSet(el("div", { id: "if-pulse" }), pulse),
  ];
  for (const fs of sets) fs.setAll(loaded);
  const saved = el("div", { class: "small muted", id: "if-saved" });
  const msg = el("div", { class: "form-error", id: "if-error", role: "alert" });
  root.replaceChildren(
    el("div", { class: "row" }, el("b", {}, `Axis ${loadedAxis}`),
      button("Save config", () => save(saved, msg), { id: "if-save", class: "primary", title: "writes the machine file" }),
      button("Reload", () => load(), { id: "if-reload", title: "read the settings back from the server" }),
      button("Next axis", () => app.nextAxis()),
      el("a", { href: "#operation" }, "Operate →"), saved, msg),
    el("div", { class: "grid" },
      panel("Interface I/O: signal logic", sets[0].container),
      panel("Interface I/O: responses", sets[1].container),
      panel("Pulse I/O", sets[2].container)));
}

async function save(saved, msg) {
  msg.textContent = "";
  const values = {};
  let ok = true;
  for (const fs of sets) {
    const v = fs.values();
    if (!v) ok = false;
    else Object.assign(values, v);
  }
  if (!ok) { msg.textContent = "fix the marked fields first: nothing was sent"; return; }
  const changed = {};
  for (const [k, v] of Object.entries(values)) if (v !== loaded[k]) changed[k] = v;
  if (!Object.keys(changed).length) { saved.textContent = "no change to save"; return; }
  try {
    const res = await app.call("interface.set", { axis: loadedAxis, changes: nest(changed) });
    if (res.config_version !== undefined) app.configVersion = res.config_version;
    loaded = flatten(res.interface || { ...nest(loaded), ...nest(changed) });
    for (const fs of sets) fs.setAll(loaded);
    saved.textContent = res.saved ? `saved to ${res.saved}` : "applied (no machine file yet: save one on the Machine page)";
    app.log(`interface ${loadedAxis}: ${Object.keys(changed).join(", ")} changed`);
  } catch (err) {
    let shown = false;
    for (const fs of sets) if (fs.serverError(err, {}, { fallback: false })) shown = true;
    if (!shown) msg.textContent = err.message;
  }
}
