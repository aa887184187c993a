"""The HTTP / WebSocket server of `openmotion ui` (Starlette on uvicorn).

Routes: `/ws` (JSON-RPC 2.0), `/` and `/static/...` (the front end, shipped in
remote/static/), `/health`, `/api/scope.csv`, `POST /api/program`. A token, when set, gates
everything but /health (query `token=` or `Authorization: Bearer`). Each connection reads
frames, answers them in order per frame, and runs its subscriptions as tasks that push
diffs at a fixed rate. Commands run on one worker thread (so one at a time, in arrival
order, from every connection); queries on the default pool; neither blocks the event loop.
"""

from __future__ import annotations

import asyncio
import hmac
import itertools
import json
import logging
import threading
import time
import traceback
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any
from urllib.parse import parse_qs

from starlette.applications import Starlette
from starlette.requests import Request as HttpRequest
from starlette.responses import FileResponse, JSONResponse, PlainTextResponse, Response
from starlette.routing import Mount, Route, WebSocketRoute
from starlette.staticfiles import StaticFiles
from starlette.websockets import WebSocket, WebSocketDisconnect

from ..errors import MotionError
from .methods import Context, load_all
from .programs import MAX_FILE_BYTES
from .protocol import (
    BUSY,
    INTERNAL_ERROR,
    METHOD_NOT_FOUND,
    Params,
    Request,
    RpcError,
    dumps,
    error_response,
    notification,
    parse_frame,
    refused,
    response,
)
from .service import MachineService
from .status import diff, only_clock, snapshot

log = logging.getLogger("openmotion.remote")

STATIC_DIR = Path(__file__).parent / "static"
MAX_CONNECTIONS = 32
MAX_SUBSCRIPTIONS = 16
WS_HARD_LIMIT = 16 << 20
BUSY_S = 5.0
MIN_TOKEN = 16
#: requests of one connection answered at once (more wait for one to finish)
MAX_IN_FLIGHT = 64
#: answered on the event loop itself: the deadman's confirmations and releases
INLINE = frozenset({"jog.confirm", "jog.stop"})


class Connection:
    """One WebSocket client: its send lock and its subscriptions."""

    _ids = itertools.count(1)

    def __init__(self, server: RemoteServer, ws: WebSocket) -> None:
        self.server = server
        self.ws = ws
        self.id = next(self._ids)
        self.loop = asyncio.get_running_loop()
        self._send_lock = asyncio.Lock()
        self._subs: dict[str, asyncio.Future[Any]] = {}
        self._sub_ids = itertools.count(1)
        self.tasks: set[asyncio.Task[None]] = set()
        self.closed = False

    async def send(self, obj: Any) -> None:
        """Send a message (an object, or JSON text already serialised)."""
        if self.closed:
            return
        text = obj if isinstance(obj, str) else dumps(obj)
        async with self._send_lock:
            try:
                await self.ws.send_text(text)
            except Exception:  # the client went away: the reader loop ends the connection
                self.closed = True

    def send_soon(self, obj: Any) -> None:
        """Thread-safe: queue a push on this connection's loop."""
        if not self.closed and not self.loop.is_closed():
            asyncio.run_coroutine_threadsafe(self.send(obj), self.loop)

    # -- subscriptions (called from handler threads) -------------------------------------
    def _add(self, coro: Any) -> str:
        if len(self._subs) >= MAX_SUBSCRIPTIONS:
            coro.close()
            raise MotionError(f"at most {MAX_SUBSCRIPTIONS} subscriptions per connection")
        sid = f"sub-{self.id}-{next(self._sub_ids)}"
        self._subs[sid] = asyncio.run_coroutine_threadsafe(coro, self.loop)
        return sid

    def subscribe_status(self, rate: float, fields: tuple[str, ...],
                         idle_rate: float | None = None) -> tuple[str, dict[str, Any]]:
        """Status diffs at `rate`; while only the clock moved (`only_clock`), at most at
        `idle_rate` (default `rate`)."""
        snap = snapshot(self.server.svc, fields)
        idle = rate if idle_rate is None else min(idle_rate, rate)
        return self._add(self._status_loop(rate, fields, snap, idle)), snap

    def subscribe_scope(self, rate: float) -> tuple[str, int]:
        nxt = self.server.svc.scope.info()["next"]
        return self._add(self._scope_loop(rate, nxt)), nxt

    def unsubscribe(self, sid: str) -> None:
        fut = self._subs.pop(sid, None)
        if fut is None:
            raise MotionError(f"subscription {sid!r} is unknown")
        fut.cancel()

    def close(self) -> None:
        self.closed = True
        for fut in self._subs.values():
            fut.cancel()
        self._subs.clear()

    async def _ticks(self, rate: float) -> Any:
        period = 1.0 / rate
        t_next = self.loop.time()
        while not self.closed:
            t_next += period
            await asyncio.sleep(max(0.0, t_next - self.loop.time()))
            yield

    async def _status_loop(self, rate: float, fields: tuple[str, ...],
                           last: dict[str, Any], idle_rate: float) -> None:
        svc = self.server.svc
        idle_s = 1.0 / idle_rate - 0.5 / rate   # the tick nearest the idle period
        pushed = self.loop.time()
        async for _ in self._ticks(rate):
            try:
                snap = snapshot(svc, fields)
            except Exception as exc:  # a rebuild in progress: try again next tick
                log.debug("status snapshot failed: %r", exc)
                continue
            d = diff(last, snap)
            if d and only_clock(d) and self.loop.time() - pushed < idle_s:
                continue   # the next diff still holds this one's changes (from `last`)
            last = snap
            if d:
                pushed = self.loop.time()
                await self.send(notification("notify_status_update",
                                             [d, snap.get("time", svc.ctl.time)]))

    async def _scope_loop(self, rate: float, nxt: int) -> None:
        svc = self.server.svc
        version = svc.scope.version
        async for _ in self._ticks(rate):
            sc = svc.scope
            if sc.version != version:
                version, nxt = sc.version, 0
            if sc.n <= nxt:
                continue
            data = await asyncio.to_thread(sc.data, nxt, 100_000)
            nxt = data["next"]
            await self.send(notification("notify_scope_data", [data]))


class RemoteServer:
    """The Starlette app over one MachineService."""

    def __init__(self, svc: MachineService, token: str | None = None,
                 static_dir: Path = STATIC_DIR) -> None:
        self.svc = svc
        self.token = token
        self.static_dir = static_dir
        self.methods = load_all()
        self._commands = ThreadPoolExecutor(max_workers=1, thread_name_prefix="om-command")
        self._conns: set[Connection] = set()
        svc.add_listener(self._on_service)
        routes = [
            Route("/", self._index),
            Route("/health", self._health),
            Route("/api/scope.csv", self._scope_csv),
            Route("/api/program", self._program_upload, methods=["POST"]),
            WebSocketRoute("/ws", self._ws),
            Mount("/static", StaticFiles(directory=static_dir, check_dir=False)),
        ]
        self.app = _TokenGate(Starlette(routes=routes), token)

    def clients(self) -> int:
        return len(self._conns)

    # -- service pushes (from the real-time thread or a handler thread) -------------------
    def _on_service(self, kind: str, payload: dict[str, Any]) -> None:
        name = {"config": "notify_config_changed", "event": "notify_event"}.get(kind)
        if name is None:
            return
        msg = notification(name, [payload])
        for conn in tuple(self._conns):
            conn.send_soon(msg)

    # -- HTTP -----------------------------------------------------------------------------
    async def _index(self, request: HttpRequest) -> Response:
        index = self.static_dir / "index.html"
        if not index.is_file():
            return PlainTextResponse("openmotion ui: the front end is not installed "
                                     f"({index} is missing); the API is at /ws", 404)
        return FileResponse(index)

    async def _health(self, request: HttpRequest) -> Response:
        return JSONResponse({"status": "ok", "api": 1})

    async def _scope_csv(self, request: HttpRequest) -> Response:
        try:
            start = _float_arg(request, "start")
            end = _float_arg(request, "end")
            text = await asyncio.to_thread(self.svc.scope.csv, start, end)
        except MotionError as exc:
            return JSONResponse({"error": refused(exc).to_json()}, 400)
        return Response(text, media_type="text/csv", headers={
            "Content-Disposition": 'attachment; filename="openmotion-scope.csv"'})

    async def _program_upload(self, request: HttpRequest) -> Response:
        name = request.query_params.get("name", "upload.ngc")[:255] or "upload.ngc"
        body = bytearray()
        async for chunk in request.stream():
            body += chunk
            if len(body) > MAX_FILE_BYTES:
                return JSONResponse({"error": RpcError(
                    -32002, f"program exceeds {MAX_FILE_BYTES} bytes",
                    {"max_bytes": MAX_FILE_BYTES}).to_json()}, 413)
        text = bytes(body).decode("utf-8", errors="replace")
        svc = self.svc

        def load(ctx: Context, p: Params) -> Any:
            return svc.program.load(text, name)

        req = Request("program.load", {}, 0, False)
        res = json.loads(await asyncio.get_running_loop().run_in_executor(
            self._commands, self._run, load, Context(svc), req, time.monotonic()))
        if "error" in res:
            return JSONResponse({"error": res["error"]}, 400)
        return JSONResponse(res["result"])

    # -- WebSocket ------------------------------------------------------------------------
    async def _ws(self, ws: WebSocket) -> None:
        if len(self._conns) >= MAX_CONNECTIONS:
            await ws.accept()
            await ws.close(code=1013, reason=f"at most {MAX_CONNECTIONS} connections")
            return
        await ws.accept()
        conn = Connection(self, ws)
        self._conns.add(conn)
        ctx = Context(self.svc, conn)
        try:
            while True:
                msg = await ws.receive()
                if msg["type"] == "websocket.disconnect":
                    break
                frame = msg.get("text")
                if frame is None:
                    frame = msg.get("bytes") or b""
                # each frame is answered by its own task: a slow query (a long scope read)
                # never holds up the next frame (a jog confirmation) on this connection;
                # commands still reach the command thread in arrival order (each task
                # submits at its first step, tasks start in creation order)
                task = asyncio.create_task(self._answer(conn, ctx, frame))
                conn.tasks.add(task)
                task.add_done_callback(conn.tasks.discard)
                if len(conn.tasks) >= MAX_IN_FLIGHT:
                    await asyncio.wait(set(conn.tasks), return_when=asyncio.FIRST_COMPLETED)
        except WebSocketDisconnect:
            pass
        finally:
            conn.close()
            self._conns.discard(conn)
            try:
                self.svc.jogs.drop_owner(conn)
            except Exception as exc:  # pragma: no cover - logged, never raised
                log.error("dropping the jogs of a closed connection failed: %r", exc)

    async def _answer(self, conn: Connection, ctx: Context, frame: str | bytes) -> None:
        try:
            out = await self.handle_frame(ctx, frame)
        except Exception:  # pragma: no cover - handle_frame answers every error itself
            log.error("frame failed:\n%s", traceback.format_exc())
            return
        if out is not None:
            await conn.send(out)

    async def handle_frame(self, ctx: Context, frame: str | bytes) -> Any:
        """The response to one frame (None when it held only notifications)."""
        try:
            reqs, batch = parse_frame(frame)
        except RpcError as err:
            return dumps(error_response(None, err))
        out: list[str] = []
        for r in reqs:
            if isinstance(r, RpcError):
                out.append(dumps(error_response(r.req_id, r)))
                continue
            res = await self._call(ctx, r)
            if not r.notify:
                out.append(res)
        if not out:
            return None
        return "[" + ",".join(out) + "]" if batch else out[0]

    async def _call(self, ctx: Context, req: Request) -> str:
        """The JSON text of the response to one request."""
        m = self.methods.get(req.method)
        if m is None:
            return dumps(error_response(req.id, RpcError(
                METHOD_NOT_FOUND, f"method {req.method!r} is unknown", {"method": req.method})))
        if req.method in INLINE:   # tiny and urgent: on the loop, no thread hop
            return self._run(m.fn, ctx, req, None)
        if m.command:
            queued = time.monotonic()
            fut = asyncio.get_running_loop().run_in_executor(
                self._commands, self._run, m.fn, ctx, req, queued)
        else:
            fut = asyncio.get_running_loop().run_in_executor(
                None, self._run, m.fn, ctx, req, None)
        return await fut

    def _run(self, fn: Any, ctx: Context, req: Request, queued: float | None) -> str:
        """Run a handler (on a worker thread) and serialise its answer there too."""
        try:
            if queued is not None:
                if time.monotonic() - queued > BUSY_S:
                    raise RpcError(BUSY, f"the command waited more than {BUSY_S:g} s for "
                                   "the commands before it; try again")
                self.svc.check_version(req.params.get("config_version"))
            return dumps(response(req.id, fn(ctx, Params(req.params))))
        except RpcError as err:
            return dumps(error_response(req.id, err))
        except MotionError as exc:
            return dumps(error_response(req.id, refused(exc)))
        except Exception as exc:  # a server bug: answered, logged, the server goes on
            log.error("method %s failed:\n%s", req.method, traceback.format_exc())
            return dumps(error_response(req.id, RpcError(
                INTERNAL_ERROR, f"internal error in {req.method}: {type(exc).__name__}: {exc}")))

    def close(self) -> None:
        self.svc.remove_listener(self._on_service)
        self._commands.shutdown(wait=False, cancel_futures=True)


def _float_arg(request: HttpRequest, name: str) -> float | None:
    v = request.query_params.get(name)
    if v is None or v == "":
        return None
    try:
        return float(v)
    except ValueError:
        raise MotionError(f"{name} must be a number of seconds, got {v!r}") from None


class _TokenGate:
    """ASGI middleware: every request must carry the token but /health and the front end's
    static assets under /static/ (shipped in the package, no secrets: the page can load its
    styles and modules with plain URLs). `/`, every API route and the WebSocket stay gated."""

    def __init__(self, app: Any, token: str | None) -> None:
        self.app = app
        self.token = token

    def _ok(self, scope: dict[str, Any]) -> bool:
        if not self.token:
            return True
        qs = parse_qs(scope.get("query_string", b"").decode("latin-1"))
        given = (qs.get("token") or [""])[0]
        for k, v in scope.get("headers", []):
            if k == b"authorization" and v.lower().startswith(b"bearer "):
                given = v[7:].decode("latin-1").strip()
        return hmac.compare_digest(given.encode(), self.token.encode())

    async def __call__(self, scope: dict[str, Any], receive: Any, send: Any) -> None:
        if scope["type"] in ("http", "websocket") and not _open_path(scope) \
                and not self._ok(scope):
            if scope["type"] == "http":
                body = json.dumps({"error": "missing or wrong token"}).encode()
                await send({"type": "http.response.start", "status": 401,
                            "headers": [(b"content-type", b"application/json")]})
                await send({"type": "http.response.body", "body": body})
            else:
                await receive()   # websocket.connect
                await send({"type": "websocket.close", "code": 1008})
            return
        await self.app(scope, receive, send)


def _open_path(scope: dict[str, Any]) -> bool:
    """/health, or a GET of a static asset (no `..` segment: nothing outside /static/)."""
    path = scope.get("path", "")
    if path == "/health":
        return True
    return scope["type"] == "http" and scope.get("method") in ("GET", "HEAD") and \
        path.startswith("/static/") and ".." not in path.split("/")


# -- running it ---------------------------------------------------------------------------
def check_bind(host: str, token: str | None) -> None:
    """--host other than 127.0.0.1 needs a token of at least MIN_TOKEN characters."""
    if token is not None and len(token) < MIN_TOKEN:
        raise MotionError(f"--token must be at least {MIN_TOKEN} characters, got {len(token)}")
    if host not in ("127.0.0.1", "localhost", "::1") and not token:
        raise MotionError(f"--host {host} needs --token (anyone on the network could move "
                          "the machine otherwise)")


class ServerThread:
    """uvicorn serving a RemoteServer on a background thread (tests, scripts, the bench).

    `url` is the http address once `start()` returns; `stop()` shuts the server down
    (the MachineService is left running: stop it yourself)."""

    def __init__(self, server: RemoteServer, host: str = "127.0.0.1", port: int = 0) -> None:
        import uvicorn

        check_bind(host, server.token)
        self.server = server
        cfg = uvicorn.Config(server.app, host=host, port=port, ws_max_size=WS_HARD_LIMIT,
                             log_level="warning", lifespan="off", ws_ping_interval=None,
                             timeout_graceful_shutdown=2)
        self._uv = uvicorn.Server(cfg)
        self._thread = threading.Thread(target=self._uv.run, name="om-uvicorn", daemon=True)
        self.host = host
        self.port = port

    def start(self, timeout: float = 10.0) -> ServerThread:
        self._thread.start()
        t_end = time.monotonic() + timeout
        while not self._uv.started:
            if not self._thread.is_alive() or time.monotonic() > t_end:
                raise MotionError(f"the server did not start on {self.host}:{self.port}")
            time.sleep(0.01)
        sock = self._uv.servers[0].sockets[0]
        self.port = sock.getsockname()[1]
        return self

    @property
    def url(self) -> str:
        return f"http://{self.host}:{self.port}"

    @property
    def ws_url(self) -> str:
        return f"ws://{self.host}:{self.port}/ws"

    def stop(self) -> None:
        self._uv.should_exit = True
        self._thread.join(timeout=10.0)
        self.server.close()
