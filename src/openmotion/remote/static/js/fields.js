// Form fields built from small specs, validated in the browser as the user types; the error
// (the browser's or the server's) is shown beside the field it belongs to.
//
// spec: {name, label, kind: "number"|"int"|"select"|"bool"|"text", unit, min, max,
//        minExclusive, maxExclusive, options: [[value, label], ...], value, help,
//        optional (empty allowed -> null), check(value, all) -> message or ""}

import { el } from "./dom.js";

export function fmtNum(v) {
  if (typeof v !== "number" || !Number.isFinite(v)) return String(v);
  return Number.isInteger(v) ? String(v) : String(+v.toPrecision(10));
}

/** Validate one raw string against a spec; returns [value, message]. */
export function parseField(spec, raw, all = {}) {
  const kind = spec.kind || "number";
  if (kind === "bool") return [Boolean(raw), ""];
  if (kind === "select") {
    const opt = (spec.options || []).find(([v]) => String(v) === String(raw));
    if (!opt) return [null, `${spec.label}: choose one of the listed values`];
    return [opt[0], ""];
  }
  const text = String(raw ?? "").trim();
  if (kind === "text") {
    if (!text && !spec.optional) return [null, `${spec.label} is required`];
    return [text, spec.check ? spec.check(text, all) || "" : ""];
  }
  if (text === "") {
    if (spec.optional) return [null, ""];
    return [null, `${spec.label} is required`];
  }
  if (!/^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$/.test(text)) {
    return [null, `${spec.label} must be a number`];
  }
  const v = Number(text);
  if (!Number.isFinite(v)) return [null, `${spec.label} must be finite`];
  const unit = spec.unit ? ` ${spec.unit}` : "";
  if (kind === "int" && !Number.isInteger(v)) return [null, `${spec.label} must be a whole number`];
  if (spec.min !== undefined) {
    if (spec.minExclusive ? v <= spec.min : v < spec.min) {
      return [null, `${spec.label} must be ${spec.minExclusive ? ">" : ">="} ${fmtNum(spec.min)}${unit}`];
    }
  }
  if (spec.max !== undefined) {
    if (spec.maxExclusive ? v >= spec.max : v > spec.max) {
      return [null, `${spec.label} must be ${spec.maxExclusive ? "<" : "<="} ${fmtNum(spec.max)}${unit}`];
    }
  }
  if (spec.check) {
    const msg = spec.check(v, all);
    if (msg) return [null, msg];
  }
  return [v, ""];
}

/** A set of fields in one container; `values()` returns null while any field is invalid. */
export class FieldSet {
  constructor(container, specs, { onChange } = {}) {
    this.container = container;
    this.specs = specs;
    this.inputs = new Map();
    this.errs = new Map();
    this.onChange = onChange;
    this.formErr = el("div", { class: "form-error", role: "alert" });
    for (const spec of specs) this._build(spec);
    container.append(this.formErr);
  }

  _build(spec) {
    const id = `f-${this.container.id || "x"}-${spec.name}`;
    let input;
    const kind = spec.kind || "number";
    if (kind === "select") {
      input = el("select", { id, name: spec.name },
        (spec.options || []).map(([v, label]) => el("option", { value: String(v) }, label)));
    } else if (kind === "bool") {
      input = el("input", { id, name: spec.name, type: "checkbox" });
    } else {
      input = el("input", { id, name: spec.name, type: "text", inputmode: kind === "text" ? "text" : "decimal",
        autocomplete: "off", spellcheck: "false" });
    }
    input.dataset.field = spec.name;
    const err = el("span", { class: "field-error", id: `${id}-err`, "aria-live": "polite" });
    input.setAttribute("aria-describedby", err.id);
    const row = el("div", { class: `field field-${kind}`, "data-name": spec.name },
      el("label", { for: id, title: spec.help || "" }, spec.label),
      el("span", { class: "field-input" }, input, spec.unit ? el("span", { class: "unit" }, spec.unit) : null),
      err);
    this.container.append(row);
    this.inputs.set(spec.name, input);
    this.errs.set(spec.name, err);
    const ev = kind === "select" || kind === "bool" ? "change" : "input";
    input.addEventListener(ev, () => {
      this.validate(spec.name);
      this.clearFormError();
      if (this.onChange) this.onChange(spec.name);
    });
    if (spec.value !== undefined) this.set(spec.name, spec.value);
  }

  spec(name) { return this.specs.find((s) => s.name === name); }

  raw() {
    const out = {};
    for (const [name, input] of this.inputs) out[name] = input.type === "checkbox" ? input.checked : input.value;
    return out;
  }

  set(name, value) {
    const input = this.inputs.get(name);
    if (!input) return;
    if (input.type === "checkbox") input.checked = Boolean(value);
    else input.value = value === null || value === undefined ? "" : (typeof value === "number" ? fmtNum(value) : String(value));
    this.showError(name, "");
  }

  setAll(obj) {
    for (const name of this.inputs.keys()) if (obj && name in obj) this.set(name, obj[name]);
  }

  showError(name, msg) {
    const err = this.errs.get(name);
    const input = this.inputs.get(name);
    if (!err) return false;
    err.textContent = msg || "";
    input.classList.toggle("invalid", Boolean(msg));
    input.setAttribute("aria-invalid", msg ? "true" : "false");
    return true;
  }

  clearFormError() { this.formErr.textContent = ""; }

  validate(name) {
    const spec = this.spec(name);
    const [, msg] = parseField(spec, this.raw()[name], this.raw());
    this.showError(name, msg);
    return !msg;
  }

  /** Parsed values of every field (or of `names`), or null (errors shown) when one is invalid. */
  values(names = null) {
    const raw = this.raw();
    const out = {};
    let ok = true;
    for (const spec of this.specs) {
      if (names && !names.includes(spec.name)) continue;
      if (spec.disabled && spec.disabled(raw)) continue;
      const [v, msg] = parseField(spec, raw[spec.name], raw);
      this.showError(spec.name, msg);
      if (msg) ok = false;
      else out[spec.name] = v;
    }
    if (!ok) this.formErr.textContent = "fix the marked fields first: nothing was sent";
    return ok ? out : null;
  }

  /** Show a server error beside the parameter it names (else under the form). */
  serverError(err, aliases = {}, { fallback = true } = {}) {
    const msg = err && err.message ? err.message : String(err);
    const param = findParam(err, [...this.inputs.keys()], aliases);
    if (param && this.showError(param, msg)) {
      this.formErr.textContent = "";
      return true;
    }
    if (fallback) this.formErr.textContent = msg;
    return false;
  }
}

/** The field a server error is about: err.data.param / field, else a name in its message. */
export function findParam(err, names, aliases = {}) {
  const data = (err && err.data) || {};
  let p = data.param || data.field || data.parameter || data.name;
  if (p && aliases[p]) p = aliases[p];
  if (p && names.includes(p)) return p;
  if (typeof p === "string") {
    // "changes.logic.pel", "axes.x.max_vel", "params.max_vel": the longest field name it ends with
    const hit = names.filter((n) => p.endsWith(`.${n}`)).sort((a, b) => b.length - a.length)[0];
    if (hit) return hit;
    const tail = p.split(".").pop();
    if (aliases[tail] && names.includes(aliases[tail])) return aliases[tail];
  }
  const msg = (err && err.message) || "";
  for (const [alias, name] of Object.entries(aliases)) {
    if (new RegExp(`\\b${alias}\\b`).test(msg) && names.includes(name)) return name;
  }
  const esc = (x) => x.replace(/[.*+?^${}()|[\]\\]/g, "\\$&");
  let best = null, at = Infinity;
  for (const name of names) {
    const m = new RegExp(`(^|[^\\w])${esc(name)}\\b`).exec(msg);
    if (m && (m.index < at || (m.index === at && name.length > best.length))) { best = name; at = m.index; }
  }
  if (best) return best;
  return null;
}

/** Show a server error beside its field in the first set that has it, else under `sets[0]`. */
export function serverError(err, sets, aliases = {}) {
  for (const fs of sets) if (fs.serverError(err, aliases, { fallback: false })) return;
  sets[0].serverError(err, aliases);
}
