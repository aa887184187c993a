// Pieces shared by several pages: panels, I/O lamps, motion-parameter specs.

import { el } from "../dom.js";

export function panel(title, ...children) {
  return el("div", { class: "panel" }, title ? el("h3", {}, title) : null, ...children);
}

/** Motion Creator's I/O status lamps, in its order. `good` lamps light green. */
export const LAMPS = [
  ["alm", "ALM"], ["pel", "+EL"], ["mel", "-EL"], ["org", "ORG"], ["ez", "EZ"], ["inp", "INP", true],
  ["sd", "SD"], ["cmp", "CMP", true], ["rdy", "RDY", true], ["erc", "ERC"], ["emg", "EMG"], ["svon", "SVON", true],
];

export class Lamps {
  constructor(prefix) {
    this.node = el("div", { class: "lamps" });
    this.items = new Map();
    for (const [key, label, good] of LAMPS) {
      const box = el("span", { class: `lampbox${good ? " good" : ""}`, "data-lamp": key, id: `${prefix}-lamp-${key}`, "data-on": "null" },
        el("span", { class: "lamp" }), label);
      this.items.set(key, box);
      this.node.append(box);
    }
  }

  update(io) {
    for (const [key, box] of this.items) {
      const v = io ? io[key] : undefined;
      box.dataset.on = v === undefined || v === null ? "null" : String(Boolean(v));
    }
  }
}

/** StrVel / MaxVel / Tacc / Tdec / S-region specs, limited by the axis's info. */
export function motionSpecs(info) {
  const unit = info ? info.unit : "";
  const vmax = info && info.max_speed ? info.max_speed : undefined;
  const lim = (info && info.speed_limits) || {};
  const tacc = lim.tacc || [0, 100];
  return [
    { name: "str_vel", label: "Start velocity", unit: `${unit}/s`, min: 0, max: vmax, value: 0,
      check: (v, all) => (Number(all.max_vel) >= 0 && v > Number(all.max_vel) ? "Start velocity must be <= Maximum velocity" : "") },
    { name: "max_vel", label: "Maximum velocity", unit: `${unit}/s`, min: 0, minExclusive: true, max: vmax,
      value: vmax ? +(vmax / 4).toPrecision(3) : 10 },
    { name: "tacc", label: "Accel. time", unit: "s", min: tacc[0] || 0, minExclusive: !tacc[0], max: tacc[1] || 100, value: 0.1 },
    { name: "tdec", label: "Decel. time", unit: "s", min: tacc[0] || 0, minExclusive: !tacc[0], max: tacc[1] || 100, value: 0.1 },
    { name: "shape", label: "Vel. profile", kind: "select", options: [["T", "Trapezoidal"], ["S", "S-curve"]], value: "T" },
    { name: "vs_acc", label: "SVacc (S range)", unit: `${unit}/s`, min: 0, value: 0,
      check: (v, all) => (v > 0 && Number(all.max_vel) > 0 && 2 * v > Number(all.max_vel) - Number(all.str_vel || 0)
        ? "SVacc must be <= (MaxVel - StrVel) / 2" : "") },
    { name: "vs_dec", label: "SVdec (S range)", unit: `${unit}/s`, min: 0, value: 0,
      check: (v, all) => (v > 0 && Number(all.max_vel) > 0 && 2 * v > Number(all.max_vel) - Number(all.str_vel || 0)
        ? "SVdec must be <= (MaxVel - StrVel) / 2" : "") },
    // Motion Creator's Speed Range: "Fix" = the highest speed a change on the fly may reach;
    // "Not fix" = the move's own MaxVel (its velocity in Cont. move) is that limit.
    { name: "fix_range", label: "Fix speed range", kind: "bool", value: true },
    { name: "speed_range", label: "Speed range", unit: `${unit}/s`, min: 0, minExclusive: true, max: vmax,
      value: vmax || 100, disabled: (raw) => !raw.fix_range },
  ];
}

/** Drop keys whose value is null/undefined. */
export function compact(obj) {
  const out = {};
  for (const [k, v] of Object.entries(obj)) if (v !== null && v !== undefined) out[k] = v;
  return out;
}
