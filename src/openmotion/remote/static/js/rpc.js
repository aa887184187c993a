// JSON-RPC 2.0 over one WebSocket, with automatic reconnect and a connection state that the
// page shows as a lamp. Calls made while the socket is down fail at once (never queued: a
// command sent late to a machine is worse than a refused one).

export class RpcError extends Error {
  constructor(code, message, data) {
    super(message);
    this.code = code;
    this.data = data === undefined ? null : data;
  }
}

const RETRY_MS = [200, 400, 800, 1500, 3000];

export class Rpc extends EventTarget {
  constructor(url, { timeoutMs = 10000 } = {}) {
    super();
    this.url = url;
    this.timeoutMs = timeoutMs;
    this.ws = null;
    this.nextId = 1;
    this.pending = new Map();
    this.handlers = new Map();
    this.state = "closed";
    this.attempt = 0;
    this.stopped = false;
    this.opens = 0;
  }

  connect() {
    this.stopped = false;
    this._open();
  }

  close() {
    this.stopped = true;
    if (this.ws) this.ws.close();
  }

  _setState(state, detail = "") {
    this.state = state;
    this.dispatchEvent(new CustomEvent("state", { detail: { state, detail } }));
  }

  _open() {
    this._setState("connecting");
    let ws;
    try {
      ws = new WebSocket(this.url);
    } catch (e) {
      this._scheduleRetry(String(e));
      return;
    }
    this.ws = ws;
    ws.onopen = () => {
      this.attempt = 0;
      this.opens += 1;
      this._setState("open");
      this.dispatchEvent(new CustomEvent("open", { detail: { reconnect: this.opens > 1 } }));
    };
    ws.onmessage = (ev) => this._receive(ev.data);
    ws.onclose = (ev) => {
      if (this.ws !== ws) return;
      this.ws = null;
      this._failPending(new RpcError(-32000, "connection lost"));
      this.dispatchEvent(new CustomEvent("lost"));
      if (this.stopped) this._setState("closed");
      else this._scheduleRetry(ev.reason || `code ${ev.code}`);
    };
    ws.onerror = () => {};
  }

  _scheduleRetry(reason) {
    const delay = RETRY_MS[Math.min(this.attempt, RETRY_MS.length - 1)];
    this.attempt += 1;
    this._setState("retrying", `${reason}; retry in ${delay} ms`);
    setTimeout(() => { if (!this.stopped) this._open(); }, delay);
  }

  _failPending(err) {
    for (const { reject, timer } of this.pending.values()) {
      clearTimeout(timer);
      reject(err);
    }
    this.pending.clear();
  }

  _receive(text) {
    let msg;
    try {
      msg = JSON.parse(text);
    } catch {
      console.warn("rpc: unparsable frame", text);
      return;
    }
    for (const m of Array.isArray(msg) ? msg : [msg]) this._dispatch(m);
  }

  _dispatch(m) {
    if (m && m.id !== undefined && m.id !== null && this.pending.has(m.id)) {
      const { resolve, reject, timer } = this.pending.get(m.id);
      this.pending.delete(m.id);
      clearTimeout(timer);
      if (m.error) reject(new RpcError(m.error.code, m.error.message, m.error.data));
      else resolve(m.result);
      return;
    }
    if (m && m.method) {
      const list = this.handlers.get(m.method) || [];
      for (const fn of list) {
        try { fn(m.params); } catch (e) { console.error("rpc handler", m.method, e); }
      }
      this.dispatchEvent(new CustomEvent("notify", { detail: m }));
    }
  }

  /** Register a handler for a server notification (method name). */
  on(method, fn) {
    if (!this.handlers.has(method)) this.handlers.set(method, []);
    this.handlers.get(method).push(fn);
  }

  /** Call `method` with `params`; resolves to the result, rejects with an RpcError. */
  call(method, params = {}, { timeoutMs } = {}) {
    const ws = this.ws;
    if (!ws || ws.readyState !== WebSocket.OPEN) {
      return Promise.reject(new RpcError(-32000, "not connected to the controller"));
    }
    const id = this.nextId++;
    return new Promise((resolve, reject) => {
      const timer = setTimeout(() => {
        this.pending.delete(id);
        reject(new RpcError(-32001, `${method}: no answer within ${(timeoutMs || this.timeoutMs) / 1000} s`));
      }, timeoutMs || this.timeoutMs);
      this.pending.set(id, { resolve, reject, timer });
      ws.send(JSON.stringify({ jsonrpc: "2.0", id, method, params }));
    });
  }

  /** Fire-and-forget notification (no id, no answer): used for the jog deadman. */
  notify(method, params = {}) {
    const ws = this.ws;
    if (!ws || ws.readyState !== WebSocket.OPEN) return false;
    ws.send(JSON.stringify({ jsonrpc: "2.0", method, params }));
    return true;
  }
}

/** The WebSocket address of the server that served this page (token from ?token=). */
export function defaultUrl(path = "/ws") {
  const loc = window.location;
  const proto = loc.protocol === "https:" ? "wss:" : "ws:";
  const token = new URLSearchParams(loc.search).get("token");
  const q = token ? `?token=${encodeURIComponent(token)}` : "";
  return `${proto}//${loc.host}${path}${q}`;
}
