// Machine (Motion Creator's main menu): axes, modules, versions, the machine file in use;
// save it (or save as) and load another one.

import { el, button, num } from "../dom.js";
import { FieldSet, serverError } from "../fields.js";
import { panel } from "./common.js";

let app, root, fsFile, serverInfo = null, fileMsg = "", typedPath = null;

export function mount(a, node) {
  app = a;
  root = node;
  app.addEventListener("config", () => build());
  app.addEventListener("connected", async () => {
    try { serverInfo = await app.call("server.info", {}, { quiet: true }); } catch { serverInfo = null; }
    build();
  });
}

export function show() { build(); }

function build() {
  const info = app.info;
  if (!info) return;
  const axes = el("table", { class: "kv", id: "machine-axes" },
    el("tr", {}, ...["axis", "unit", "pulses/unit", "max speed", "travel", "drive", "encoder counts/rev"].map((h) => el("th", {}, h))),
    ...info.axes.map((a) => el("tr", {},
      el("td", {}, el("b", {}, a.name)), el("td", {}, a.unit), el("td", { class: "n" }, num(a.pulses_per_unit, 4)),
      el("td", { class: "n" }, `${num(a.max_speed, 3)} ${a.unit}/s`),
      el("td", { class: "n" }, a.travel ? `${num(a.travel[0], 3)} … ${num(a.travel[1], 3)}` : "-"),
      el("td", {}, a.drive || "-"), el("td", { class: "n" }, a.encoder_counts_per_rev ?? "-"))));
  const versions = el("table", { class: "kv" }, ...Object.entries(info.versions || {}).map(([k, v]) => el("tr", {}, el("th", {}, k), el("td", {}, v ?? "-"))));
  const modules = el("ul", {}, ...(info.modules || []).map((m) => el("li", {}, el("code", {}, m.name), m.doc ? ` — ${m.doc}` : "")));
  fsFile = new FieldSet(el("div", { id: "machine-file-fields" }), [
    { name: "path", label: "Machine file", kind: "text", optional: true, value: info.file || "",
      check: (v) => (v && !/\.toml$/i.test(v) ? "Machine file must end in .toml" : "") },
  ], { onChange: () => { typedPath = fsFile.raw().path; } });
  if (typedPath !== null) fsFile.set("path", typedPath);   // a rebuild keeps what was typed
  const result = el("div", { class: "small", id: "machine-file-result" }, fileMsg);
  const toml = el("pre", { class: "file", id: "machine-toml" }, "…");
  root.replaceChildren(el("div", { class: "grid" },
    el("div", { class: "panel wide" }, el("h3", {}, "Machine"),
      el("div", { class: "row" }, el("b", { id: "machine-title" }, info.name), el("span", { class: "muted" }, info.file ? `file ${info.file}` : "not saved to a file yet"),
        el("span", { class: "muted" }, `control period ${num(info.period_s * 1000, 3)} ms`), el("span", { class: "muted" }, info.simulated ? "simulated" : "hardware"),
        el("span", { class: "muted", id: "machine-config-version" }, `configuration v${info.config_version}`)),
      axes),
    el("div", { class: "panel wide" }, el("h3", {}, "Machine file"), fsFile.container,
      el("div", { class: "row" },
        button("Save", () => save(result), { id: "machine-save", class: "primary", title: "write the machine file (to the path given: save as)" }),
        button("Load", () => load(result), { id: "machine-load", title: "load this machine file (every axis at rest)" }),
        button("Show file", () => showToml(toml))), result, toml),
    panel("Modules", modules, el("p", { class: "small muted" }, `digital inputs ${info.digital_inputs ?? "-"}, outputs ${info.digital_outputs ?? "-"}`)),
    panel("Versions", versions, serverInfo ? el("p", { class: "small muted", id: "server-info" },
      `server ${serverInfo.name} ${serverInfo.version} · API ${serverInfo.api} · ${serverInfo.clients} client(s) · ` +
      `deadman ${serverInfo.deadman_ms} ms · ${serverInfo.realtime ? "real time" : "as fast as possible"} ×${serverInfo.speed}`) : null,
      serverInfo && serverInfo.hook_errors && serverInfo.hook_errors.length
        ? el("div", { class: "form-error", id: "server-hook-errors" }, `server per-cycle work turned off: ${serverInfo.hook_errors.join("; ")}`) : null)));
  showToml(toml);
}

async function showToml(pre) {
  try { pre.textContent = (await app.call("machine.config", {}, { quiet: true })).toml; } catch (err) { pre.textContent = err.message; }
}

async function save(result) {
  const v = fsFile.values();
  if (!v) return;
  const params = v.path && v.path !== app.info.file ? { path: v.path } : {};
  try {
    const r = await app.call("machine.save", params);
    fileMsg = `saved ${r.file}`;
    result.textContent = fileMsg;
    typedPath = null;
    if (params.path) await app.reloadConfig();
  } catch (err) { serverError(err, [fsFile]); }
}

async function load(result) {
  const v = fsFile.values();
  if (!v) return;
  if (!v.path) { fsFile.showError("path", "Machine file is required to load"); return; }
  try {
    const r = await app.call("machine.load", { path: v.path });
    app.configVersion = r.config_version;
    fileMsg = `loaded ${r.file}`;
    result.textContent = fileMsg;
    typedPath = null;
    await app.reloadConfig();
  } catch (err) { serverError(err, [fsFile]); }
}
