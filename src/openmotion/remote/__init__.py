"""The remote API of openmotion: `openmotion ui` serves the controller over JSON-RPC 2.0 on
a WebSocket (docs/remote.md); this package's client talks to it from a script.

    from openmotion.remote import connect
    with connect("ws://127.0.0.1:8765/ws") as m:
        print(m.call("machine.info")["axes"])

Only the client is imported here (it needs the `websockets` package); the server side
(`openmotion.remote.server`, `openmotion.remote.service`) is imported by `openmotion ui`.
"""

from .client import ReloadError, RemoteClient, RemoteError, connect

__all__ = ["ReloadError", "RemoteClient", "RemoteError", "connect"]
