"""Shared pieces of the remote API tests: a served machine and a connected client."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path

from openmotion.config import default_machine, save_machine
from openmotion.remote import connect
from openmotion.remote.client import RemoteClient
from openmotion.remote.server import RemoteServer, ServerThread
from openmotion.remote.service import MachineService
from openmotion.remote.workdir import WorkFolder


@contextlib.contextmanager
def served(file: Path | None = None, token: str | None = None, speed: float = 1.0,
           workdir: WorkFolder | None = None
           ) -> Iterator[tuple[MachineService, ServerThread]]:
    """A MachineService running in real time behind a server on a free port."""
    svc = MachineService(file=file, speed=speed, workdir=workdir)
    server = RemoteServer(svc, token=token)
    svc.start()
    th = ServerThread(server).start()
    try:
        yield svc, th
    finally:
        th.stop()
        svc.shutdown()


def machine_file(folder: Path) -> Path:
    path = folder / "table.toml"
    save_machine(default_machine(), path)
    return path


def client(th: ServerThread, token: str | None = None) -> RemoteClient:
    return connect(th.ws_url, token, timeout=20.0)


def at_rest(axis: str):
    return lambda s: s["axes"][axis]["state"] == "Standstill" and not s["axes"][axis]["moving"]
