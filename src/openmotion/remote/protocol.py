"""JSON-RPC 2.0 framing for the remote API: error codes, request parsing, parameter checks.

Nothing here knows the controller: a frame becomes a list of `Request`s (or an error
response), a handler's parameters are read through `Params`, which refuses a missing,
unknown or mistyped parameter with `RpcError(INVALID_PARAMS)` naming it.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from ..errors import MotionError

PARSE_ERROR = -32700
INVALID_REQUEST = -32600
METHOD_NOT_FOUND = -32601
INVALID_PARAMS = -32602
INTERNAL_ERROR = -32603
REFUSED = -32000
RELOAD = -32001
TOO_LARGE = -32002
BUSY = -32003

MAX_MESSAGE_BYTES = 1 << 20
MAX_BATCH = 32


class RpcError(Exception):
    """An error answered to the client: JSON-RPC code, message and optional data."""

    def __init__(self, code: int, message: str, data: dict[str, Any] | None = None) -> None:
        super().__init__(message)
        self.code = code
        self.message = message
        self.data = data
        self.req_id: str | int | None = None   # the request's id, when it was readable

    def to_json(self) -> dict[str, Any]:
        err: dict[str, Any] = {"code": self.code, "message": self.message}
        if self.data is not None:
            err["data"] = self.data
        return err


@dataclass(frozen=True)
class Request:
    """One parsed request; `id` is None for a notification (`notify` True)."""

    method: str
    params: dict[str, Any]
    id: str | int | None
    notify: bool


def response(req_id: str | int | None, result: Any) -> dict[str, Any]:
    return {"jsonrpc": "2.0", "id": req_id, "result": result}


def error_response(req_id: str | int | None, err: RpcError) -> dict[str, Any]:
    return {"jsonrpc": "2.0", "id": req_id, "error": err.to_json()}


def notification(method: str, params: list[Any] | dict[str, Any]) -> dict[str, Any]:
    return {"jsonrpc": "2.0", "method": method, "params": params}


def dumps(obj: Any) -> str:
    """JSON text with non-finite floats sent as null (JSON has no NaN / Infinity) and numpy
    scalars as plain numbers."""
    return json.dumps(_finite(obj), separators=(",", ":"), allow_nan=False, default=_scalar)


def _scalar(obj: Any) -> Any:
    item = getattr(obj, "item", None)   # numpy scalars
    if callable(item) and getattr(obj, "shape", None) == ():
        return _finite(item())
    raise TypeError(f"{type(obj).__name__} is not JSON serialisable")


def _finite(obj: Any) -> Any:
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: _finite(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_finite(v) for v in obj]
    return obj


def parse_frame(text: str | bytes) -> tuple[list[Request | RpcError], bool]:
    """The requests of one frame (each a Request or the RpcError that refused it) and
    whether the frame was a batch. Raises RpcError for a frame that is no request at all."""
    if isinstance(text, bytes):
        raise RpcError(INVALID_REQUEST, "binary frames are not accepted: send JSON text")
    if len(text.encode("utf-8", "surrogatepass")) > MAX_MESSAGE_BYTES:
        raise RpcError(TOO_LARGE, f"message exceeds the limit of {MAX_MESSAGE_BYTES} bytes",
                       {"max_bytes": MAX_MESSAGE_BYTES})
    try:
        obj = json.loads(text)
    except (ValueError, RecursionError) as exc:
        raise RpcError(PARSE_ERROR, f"parse error: {exc}") from None
    if isinstance(obj, list):
        if not obj:
            raise RpcError(INVALID_REQUEST, "a batch must hold at least one request")
        if len(obj) > MAX_BATCH:
            raise RpcError(INVALID_REQUEST, f"a batch holds at most {MAX_BATCH} requests, "
                           f"got {len(obj)}")
        return [_request(o) for o in obj], True
    return [_request(obj)], False


def _request(obj: Any) -> Request | RpcError:
    if not isinstance(obj, dict):
        return RpcError(INVALID_REQUEST, "a request must be a JSON object")
    if obj.get("jsonrpc") != "2.0":
        return RpcError(INVALID_REQUEST, 'jsonrpc must be "2.0"')
    extra = set(obj) - {"jsonrpc", "method", "params", "id"}
    if extra:
        return RpcError(INVALID_REQUEST, f"unknown request member(s): {', '.join(sorted(extra))}")
    method = obj.get("method")
    if not isinstance(method, str) or not method:
        return RpcError(INVALID_REQUEST, "method must be a non-empty string")
    notify = "id" not in obj
    rid = obj.get("id")
    if not notify and (isinstance(rid, bool) or not isinstance(rid, (str, int))):
        return RpcError(INVALID_REQUEST, "id must be a string or an integer")
    params = obj.get("params", {})
    if not isinstance(params, dict):
        err = RpcError(INVALID_PARAMS, "params must be an object of named parameters "
                       "(positional arrays are not accepted)")
        err.req_id = rid   # the id is valid: the answer carries it
        return err
    return Request(method, params, None if notify else rid, notify)


#: the parameter a library message starts with: "max_vel on axis x must ...",
#: "axes.x.pulse_mode must ...", "changes.colour: unknown key", "trigger.channel must ..."
_PARAM = re.compile(r"^([A-Za-z_][\w]*(?:\.[\w]+|\[\d+\])*)(?=(?: on axis \w+)? must |: )")


def refused(exc: MotionError) -> RpcError:
    """A MotionError from the controller as a -32000 Refused error; `data.param` is the
    parameter (or field path) its message names first, when it names one."""
    text = str(exc)
    m = _PARAM.match(text)
    return RpcError(REFUSED, text, {"type": type(exc).__name__,
                                    "param": m.group(1) if m else None})


_MISSING = object()


class Params:
    """Typed access to a request's named parameters; `done()` refuses leftovers."""

    def __init__(self, params: dict[str, Any]) -> None:
        self._p = params
        self._used: set[str] = {"config_version"}

    def _get(self, name: str, default: Any) -> Any:
        self._used.add(name)
        if name in self._p:
            return self._p[name]
        if default is _MISSING:
            raise RpcError(INVALID_PARAMS, f"params.{name} is required", {"param": name})
        return default

    def has(self, name: str) -> bool:
        return name in self._p

    @staticmethod
    def _bad(name: str, rule: str, value: Any) -> RpcError:
        return RpcError(INVALID_PARAMS, f"params.{name} must be {rule}, got {value!r}",
                        {"param": name})

    def number(self, name: str, default: Any = _MISSING, *, lo: float | None = None,
               hi: float | None = None, lo_open: bool = False) -> Any:
        v = self._get(name, default)
        if v is None and default is None:
            return None
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise self._bad(name, "a finite number", v)
        if lo is not None and (v < lo or (lo_open and v == lo)):
            raise self._bad(name, f"{'>' if lo_open else '>='} {lo:g}", v)
        if hi is not None and v > hi:
            raise self._bad(name, f"<= {hi:g}", v)
        return float(v)

    def integer(self, name: str, default: Any = _MISSING, *, lo: int | None = None,
                hi: int | None = None) -> Any:
        v = self._get(name, default)
        if v is None and default is None:
            return None
        if isinstance(v, bool) or not isinstance(v, int):
            raise self._bad(name, "an integer", v)
        if (lo is not None and v < lo) or (hi is not None and v > hi):
            raise self._bad(name, f"in [{lo}, {hi}]" if hi is not None else f">= {lo}", v)
        return v

    def boolean(self, name: str, default: Any = _MISSING) -> Any:
        v = self._get(name, default)
        if not isinstance(v, bool):
            raise self._bad(name, "true or false", v)
        return v

    def string(self, name: str, default: Any = _MISSING, *, max_len: int = 4096) -> Any:
        v = self._get(name, default)
        if v is None and default is None:
            return None
        if not isinstance(v, str):
            raise self._bad(name, "a string", v)
        if len(v) > max_len:
            raise RpcError(INVALID_PARAMS, f"params.{name} must be at most {max_len} "
                           f"characters, got {len(v)}", {"param": name})
        return v

    def choice(self, name: str, choices: Iterable[Any], default: Any = _MISSING) -> Any:
        v = self._get(name, default)
        opts = tuple(choices)
        if isinstance(v, bool) or v not in opts:
            raise self._bad(name, "one of " + ", ".join(json.dumps(c) for c in opts), v)
        return v

    def obj(self, name: str, default: Any = _MISSING) -> Any:
        v = self._get(name, default)
        if v is None and default is None:
            return None
        if not isinstance(v, dict):
            raise self._bad(name, "an object", v)
        return v

    def list(self, name: str, default: Any = _MISSING) -> Any:
        v = self._get(name, default)
        if not isinstance(v, list):
            raise self._bad(name, "an array", v)
        return v

    def axis(self, name: str = "axis", default: Any = _MISSING) -> Any:
        """An axis key (name or index), checked for type here, for existence by the
        controller."""
        v = self._get(name, default)
        if v is None and default is None:
            return None
        if isinstance(v, bool) or not isinstance(v, (str, int)):
            raise self._bad(name, "an axis name or index", v)
        return v

    def raw(self, name: str, default: Any = _MISSING) -> Any:
        return self._get(name, default)

    def done(self) -> None:
        extra = sorted(set(self._p) - self._used)
        if extra:
            raise RpcError(INVALID_PARAMS, f"params.{extra[0]}: unknown parameter; valid: "
                           f"{', '.join(sorted(self._used - {'config_version'})) or '(none)'}",
                           {"param": extra[0]})
