"""`openmotion.remote`: a small synchronous client of the remote API (docs/remote.md).

    from openmotion.remote import connect
    with connect("ws://127.0.0.1:8765/ws") as m:
        m.call("axis.servo", axis="x", on=True)
        m.call("axis.move", axis="x", kind="relative", distance=10.0, max_vel=50.0)
        m.subscribe(rate_hz=20)
        m.wait(lambda s: s["axes"]["x"]["state"] == "Standstill", timeout=5)

A reader thread receives every frame: responses wake their caller, `notify_status_update`
diffs are merged into `status`, scope pushes and events are kept in bounded queues. Errors
come back as `RemoteError` (a MotionError) with the JSON-RPC code and data; -32001 is
`ReloadError`.
"""

from __future__ import annotations

import itertools
import json
import threading
import time
from collections import deque
from collections.abc import Callable, Iterator
from contextlib import contextmanager, suppress
from typing import Any

from ..errors import MotionError

RELOAD = -32001


class RemoteError(MotionError):
    """An error answered by the server."""

    def __init__(self, code: int, message: str, data: Any = None) -> None:
        super().__init__(message)
        self.code = code
        self.message = message
        self.data = data


class ReloadError(RemoteError):
    """The configuration changed since this client read it (-32001): reload."""


def _merge(base: dict[str, Any], d: dict[str, Any]) -> None:
    for k, v in d.items():
        if isinstance(v, dict) and isinstance(base.get(k), dict):
            _merge(base[k], v)
        else:
            base[k] = v


class RemoteClient:
    """One WebSocket connection to an `openmotion ui` server."""

    def __init__(self, url: str, token: str | None = None, *, timeout: float = 10.0) -> None:
        from websockets.sync.client import connect as ws_connect

        if not isinstance(url, str) or not url.startswith(("ws://", "wss://")):
            raise MotionError(f"url must start with ws:// or wss://, got {url!r}")
        headers = {"Authorization": f"Bearer {token}"} if token else None
        self.timeout = timeout
        try:
            # entered as a context manager (closed in close()): websockets >= 17.1 warns
            # about a connection used without one
            self._ws = ws_connect(url, additional_headers=headers, open_timeout=timeout,
                                  max_size=64 << 20).__enter__()
        except Exception as exc:
            raise MotionError(f"cannot connect to {url}: {exc}") from None
        self._ids = itertools.count(1)
        self._pending: dict[Any, list[Any]] = {}
        self._cond = threading.Condition()
        self.status: dict[str, Any] = {}
        self.scope_pushes: deque[dict[str, Any]] = deque(maxlen=1000)
        self.events: deque[dict[str, Any]] = deque(maxlen=1000)
        self.notifications: deque[dict[str, Any]] = deque(maxlen=1000)
        self.config_version: int | None = None
        self.closed = False
        self._reader = threading.Thread(target=self._read, name="om-remote-reader",
                                        daemon=True)
        self._reader.start()

    # ------------------------------------------------------------------ reading
    def _read(self) -> None:
        try:
            for frame in self._ws:
                try:
                    msg = json.loads(frame)
                except ValueError:
                    continue
                if isinstance(msg, list):
                    with self._cond:
                        key = tuple(m.get("id") for m in msg if isinstance(m, dict))
                        self._pending[("batch", key)] = [msg]
                        self._cond.notify_all()
                    continue
                if "method" in msg:
                    self._on_notification(msg)
                    continue
                with self._cond:
                    self._pending[msg.get("id")] = [msg]
                    self._cond.notify_all()
        except Exception:  # connection closed or broken: callers see `closed`
            pass
        finally:
            with self._cond:
                self.closed = True
                self._cond.notify_all()

    def _on_notification(self, msg: dict[str, Any]) -> None:
        method, params = msg.get("method"), msg.get("params") or []
        with self._cond:
            if method == "notify_status_update" and params:
                _merge(self.status, params[0])
                cv = self.status.get("config_version")
                if isinstance(cv, int):
                    self.config_version = cv
            elif method == "notify_scope_data" and params:
                self.scope_pushes.append(params[0])
            elif method == "notify_event" and params:
                self.events.append(params[0])
            elif method == "notify_config_changed" and params:
                self.config_version = params[0].get("config_version")
            self.notifications.append(msg)
            self._cond.notify_all()

    # ------------------------------------------------------------------ calls
    def call(self, method: str, timeout: float | None = None, **params: Any) -> Any:
        """Call `method` with named parameters; its result, or RemoteError."""
        rid = next(self._ids)
        msg = self._send_and_wait(json.dumps({"jsonrpc": "2.0", "id": rid, "method": method,
                                              "params": params}), rid, timeout)
        if "error" in msg:
            e = msg["error"]
            cls = ReloadError if e.get("code") == RELOAD else RemoteError
            raise cls(e.get("code", 0), e.get("message", ""), e.get("data"))
        result = msg.get("result")
        if method == "machine.info" and isinstance(result, dict):
            self.config_version = result.get("config_version")
        return result

    def notify(self, method: str, **params: Any) -> None:
        """Send a notification (no answer)."""
        self._send(json.dumps({"jsonrpc": "2.0", "method": method, "params": params}))

    def raw(self, text: str | bytes, expect_id: Any = None, timeout: float | None = None
            ) -> Any:
        """Send one raw frame and return the parsed answer that carries `expect_id`
        (None: the answer to a frame that had no usable id). For tests of bad input."""
        return self._send_and_wait(text, expect_id, timeout)

    def raw_batch(self, items: list[dict[str, Any]], timeout: float | None = None) -> Any:
        key = ("batch", tuple(i.get("id") for i in items if "id" in i))
        return self._send_and_wait(json.dumps(items), key, timeout)

    def _send(self, text: str | bytes) -> None:
        if self.closed:
            raise MotionError("the connection is closed")
        try:
            self._ws.send(text)
        except Exception as exc:
            raise MotionError(f"the connection is closed: {exc}") from None

    def _send_and_wait(self, text: str | bytes, key: Any, timeout: float | None) -> Any:
        t_end = time.monotonic() + (self.timeout if timeout is None else timeout)
        with self._cond:
            self._pending.pop(key, None)
        self._send(text)
        with self._cond:
            while key not in self._pending:
                left = t_end - time.monotonic()
                if self.closed:
                    raise MotionError("the connection closed before the answer came")
                if left <= 0:
                    raise MotionError(f"no answer within {self.timeout:g} s")
                self._cond.wait(left)
            return self._pending.pop(key)[0]

    # ------------------------------------------------------------------ helpers
    def subscribe(self, rate_hz: float = 20.0, fields: list[str] | None = None,
                  idle_hz: float | None = None) -> str:
        """Subscribe to status pushes; `status` is kept current from then on. `idle_hz`:
        while only the clock moves, pushes at most this often (default `rate_hz`)."""
        params: dict[str, Any] = {"rate_hz": rate_hz}
        if idle_hz is not None:
            params["idle_hz"] = idle_hz
        if fields is not None:
            params["fields"] = fields
        res = self.call("status.subscribe", **params)
        with self._cond:
            _merge(self.status, res["status"])
        return res["subscription"]

    def wait(self, predicate: Callable[[dict[str, Any]], bool], timeout: float) -> bool:
        """Wait until `predicate(status)` holds (status pushes needed: `subscribe`)."""
        t_end = time.monotonic() + timeout
        with self._cond:
            while True:
                try:
                    if self.status and predicate(self.status):
                        return True
                except (KeyError, TypeError):
                    pass
                left = t_end - time.monotonic()
                if left <= 0 or self.closed:
                    return False
                self._cond.wait(min(left, 0.05))

    @contextmanager
    def jog(self, axis: str | int, direction: int, *, speed: float | None = None,
            ratio: float | None = None, confirm_s: float = 0.05) -> Iterator[str]:
        """Hold-to-jog: starts a jog, confirms it every `confirm_s` on a thread while the
        block runs, stops it on leaving the block (like releasing the key)."""
        params: dict[str, Any] = {"axis": axis, "direction": direction}
        if speed is not None:
            params["speed"] = speed
        if ratio is not None:
            params["ratio"] = ratio
        jog_id = self.call("jog.start", **params)["jog"]
        stop = threading.Event()

        def confirm() -> None:
            while not stop.wait(confirm_s):
                try:
                    self.notify("jog.confirm", jog=jog_id)
                except MotionError:
                    return

        th = threading.Thread(target=confirm, name="om-jog-confirm", daemon=True)
        th.start()
        try:
            yield jog_id
        finally:
            stop.set()
            th.join()
            if not self.closed:
                self.call("jog.stop", jog=jog_id)

    def close(self) -> None:
        with suppress(Exception):
            self._ws.close()
        self._reader.join(timeout=5.0)
        self.closed = True

    def __enter__(self) -> RemoteClient:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def connect(url: str = "ws://127.0.0.1:8765/ws", token: str | None = None, *,
            timeout: float = 10.0) -> RemoteClient:
    """Open a connection to an `openmotion ui` server."""
    return RemoteClient(url, token, timeout=timeout)
