// The Motion Creator shell: connection and its lamp, the merged live status, the selected
// axis, page switching, the always-visible E-stop, the reload banner, the footer log.

import { Rpc, RpcError, defaultUrl } from "./rpc.js";
import { $, $$, el } from "./dom.js";
import { mergeDiff } from "./status.js";
import * as machine from "./pages/machine.js";
import * as iface from "./pages/interface.js";
import * as operation from "./pages/operation.js";
import * as homing from "./pages/homing.js";
import * as tuning from "./pages/tuning.js";
import * as scope from "./pages/scope.js";
import * as pathPage from "./pages/path.js";
import * as program from "./pages/program.js";
import * as simulation from "./pages/simulation.js";

const PAGES = { machine, interface: iface, operation, homing, tuning, scope, path: pathPage, program, simulation };

// Commands that must work whatever the tab's configuration version (safety first): they are
// sent without config_version, so a stale tab can always stop the machine.
const NEVER_STALE = new Set(["machine.estop", "axis.stop", "jog.stop", "program.abort", "pso.clear",
  "program.pause", "home.abort", "sim.estop", "scope.pause"]);
// Commands that take config_version (the server refuses unknown parameters on queries).
const COMMANDS = new Set(["interface.set", "home.set", "machine.load", "machine.save", "machine.reset",
  "axis.servo", "axis.reset", "axis.move", "axis.repeat", "axis.change_speed", "axis.change_position",
  "axis.set_position", "axis.reset_position", "home.start", "jog.start", "jog.step",
  "program.load", "program.run", "program.resume", "program.single_block", "program.feed_override",
  "sim.trip_limit", "sim.alarm", "sim.speed", "scope.configure", "scope.run", "scope.arm",
  "pso.set", "pso.clear", "tune.run", "tune.gains"]);

class App extends EventTarget {
  constructor() {
    super();
    this.rpc = new Rpc(defaultUrl("/ws"));
    this.info = null;
    this.status = null;
    this.configVersion = null;
    this.axis = null;
    this.page = null;
    this.token = new URLSearchParams(window.location.search).get("token");
    window.openmotion = this;   // for the browser tests and the curious
  }

  axisInfo(name = this.axis) {
    return this.info ? this.info.axes.find((a) => a.name === name) : null;
  }

  axisStatus(name = this.axis) {
    return this.status && this.status.axes ? this.status.axes[name] : null;
  }

  /** An HTTP address on this server, with the token when there is one. */
  url(path, params = {}) {
    const q = new URLSearchParams(params);
    if (this.token) q.set("token", this.token);
    const s = q.toString();
    return s ? `${path}?${s}` : path;
  }

  /** Call a method; commands carry this tab's config_version; errors go to the log. */
  async call(method, params = {}, { quiet = false, timeoutMs } = {}) {
    const p = { ...params };
    if (COMMANDS.has(method) && !NEVER_STALE.has(method) && this.configVersion !== null && !("config_version" in p)) {
      p.config_version = this.configVersion;
    }
    try {
      return await this.rpc.call(method, p, { timeoutMs });
    } catch (err) {
      if (err instanceof RpcError && err.code === -32001) this.staleConfig(err.data && err.data.config_version);
      if (!quiet) this.log(`${method}: ${err.message}`, true);
      throw err;
    }
  }

  log(msg, error = false) {
    const node = $("#log");
    node.textContent = msg;
    node.classList.toggle("error", error);
    node.title = msg;
    if (error) console.warn(msg);
  }

  /** Another client changed the configuration: offer a reload. Checked a moment later, so
   * that this tab's own change (whose answer carries the new version) does not count. */
  staleConfig(version) {
    if (this._staleTimer) return;
    this._staleTimer = setTimeout(() => {
      this._staleTimer = 0;
      if (typeof version === "number" && this.configVersion !== null && version <= this.configVersion) return;
      $("#reload-banner").hidden = false;
    }, 700);
  }

  async reloadConfig() {
    $("#reload-banner").hidden = true;
    clearTimeout(this._staleTimer);   // a check armed before the reload is answered by it
    this._staleTimer = 0;
    this.info = await this.call("machine.info");
    this.configVersion = this.info.config_version;
    // a check armed while machine.info was on its way compared with the old version
    clearTimeout(this._staleTimer);
    this._staleTimer = 0;
    $("#reload-banner").hidden = true;
    this._fillAxes();
    $("#machine-name").textContent = `${this.info.name}${this.info.file ? "  —  " + this.info.file : "  (not saved to a file)"}`;
    this.dispatchEvent(new CustomEvent("config"));
  }

  _fillAxes() {
    const sel = $("#axis-select");
    const names = this.info.axes.map((a) => a.name);
    const keep = names.includes(this.axis) ? this.axis : names[0];
    sel.replaceChildren(...names.map((n) => el("option", { value: n }, n)));
    sel.value = keep;
    this.axis = keep;
  }

  selectAxis(name) {
    if (!this.info || !this.axisInfo(name)) return;
    this.axis = name;
    $("#axis-select").value = name;
    this.dispatchEvent(new CustomEvent("axis"));
  }

  nextAxis() {
    const names = this.info.axes.map((a) => a.name);
    this.selectAxis(names[(names.indexOf(this.axis) + 1) % names.length]);
  }

  show(page) {
    if (!PAGES[page]) page = "operation";
    if (this.page === page) return;
    const prev = this.page;
    this.page = page;
    for (const s of $$(".page")) s.classList.toggle("active", s.dataset.page === page);
    for (const a of $$("#tabs a")) a.classList.toggle("active", a.dataset.page === page);
    if (prev && PAGES[prev].hide) PAGES[prev].hide(this);
    if (PAGES[page].show) PAGES[page].show(this);
  }

  async _onOpen() {
    try {
      await this.reloadConfig();
      // 20 pushes a second while anything moves or changes, 4 while only the clock does
      const sub = await this.call("status.subscribe", { rate_hz: 20, idle_hz: 4 });
      this.status = sub.status;
      this._statusChanged();
      this.dispatchEvent(new CustomEvent("connected"));
    } catch (err) {
      this.log(`could not load the machine: ${err.message}`, true);
    }
  }

  _statusChanged() {
    const s = this.status;
    if (!s) return;
    if (s.config_version !== undefined && this.configVersion !== null && s.config_version !== this.configVersion) {
      this.staleConfig(s.config_version);
    }
    const estop = $("#estop");
    estop.classList.toggle("active", Boolean(s.estop));
    const banner = $("#safety-banner");
    const faulted = Object.entries(s.axes || {}).filter(([, a]) => a.state === "ErrorStop");
    if (s.estop || faulted.length) {
      const text = (s.estop ? "E-STOP active: every axis is stopped. " : "") +
        (faulted.length ? `ErrorStop: ${faulted.map(([n, a]) => `${n}${a.fault ? ` (${a.fault})` : ""}`).join(", ")}. ` : "");
      if (banner.hidden || banner.dataset.text !== text) {
        banner.dataset.text = text;
        banner.replaceChildren(text,
          el("button", { type: "button", id: "estop-reset", onclick: () => this.call("machine.reset").catch(() => {}) }, "Reset"));
      }
      banner.hidden = false;
    } else banner.hidden = true;
    const p = s.program || {};
    const a = this.axisStatus();
    $("#status-line").textContent = `t = ${(s.time ?? 0).toFixed(2)} s · speed ×${s.speed ?? 1} · ` +
      `cycle ${s.cycle ? (s.cycle.busy_us ?? 0).toFixed(0) : "-"} µs, ${s.cycle ? s.cycle.overruns : "-"} overruns · program ${p.state || "-"}` +
      (a ? ` · ${this.axis}: ${a.state}` : "");
    this.dispatchEvent(new CustomEvent("status"));
  }

  start() {
    const lamp = $("#conn");
    this.rpc.addEventListener("state", (e) => {
      const { state, detail } = e.detail;
      lamp.dataset.state = state;
      $("#conn-text").textContent = { open: "connected", connecting: "connecting…", retrying: "reconnecting…", closed: "not connected" }[state];
      lamp.title = detail || state;
    });
    this.rpc.addEventListener("open", () => this._onOpen());
    this.rpc.addEventListener("lost", () => {
      this.log("connection lost: reconnecting", true);
      this.dispatchEvent(new CustomEvent("lost"));
    });
    this.rpc.on("notify_status_update", (params) => {
      if (!this.status) return;
      mergeDiff(this.status, params[0]);
      this._statusChanged();
    });
    this.rpc.on("notify_config_changed", (params) => {
      const v = params && params[0] ? params[0].config_version : null;
      if (v !== this.configVersion) this.staleConfig(v);
    });
    this.rpc.on("notify_event", (params) => {
      const ev = params[0] || {};
      this.dispatchEvent(new CustomEvent("event", { detail: ev }));
      if (ev.kind === "overrun") return;   // counted in the status line (cycle.overruns)
      this.log(`event: ${ev.kind}${ev.axis ? " " + ev.axis : ""}${ev.detail ? ": " + ev.detail : ""}`, ev.kind === "fault");
    });

    $("#axis-select").addEventListener("change", (e) => this.selectAxis(e.target.value));
    $("#next-axis").addEventListener("click", () => this.nextAxis());
    $("#estop").addEventListener("click", () => this.estop());
    $("#reload-config").addEventListener("click", () => this.reloadConfig());
    // AXIS's keys: F1 = E-stop; Escape = stop (abort the program, every axis decelerates)
    window.addEventListener("keydown", (e) => {
      if (e.key === "F1") { e.preventDefault(); this.estop(); } else if (e.key === "Escape") this.stopAll();
    });

    for (const [name, mod] of Object.entries(PAGES)) mod.mount(this, $(`#page-${name}`));
    const route = () => this.show(window.location.hash.slice(1) || "operation");
    window.addEventListener("hashchange", route);
    route();
    this.rpc.connect();
  }

  stopAll() {
    const p = this.status && this.status.program;
    if (p && (p.state === "running" || p.state === "paused")) this.rpc.call("program.abort").catch(() => {});
    this.rpc.call("axis.stop", {})
      .then(() => this.log("stop: every axis decelerates"))
      .catch((err) => this.log(`STOP FAILED: ${err.message}`, true));
  }

  estop() {
    // straight to the socket: no config_version, no await before sending
    this.rpc.call("machine.estop", { reason: "E-stop button in the browser" })
      .then(() => this.log("E-stop sent"))
      .catch((err) => this.log(`E-STOP FAILED: ${err.message}`, true));
  }
}

export { mergeDiff };
export const app = new App();
app.start();
