"""The working folder: the only place file-path methods may read or write.

Served beyond 127.0.0.1 (`--host`), the token holder must not read or write any file the
server's user can: `program.load {path}`, `machine.load {path}` and `machine.save {path}`
are confined to one folder (`--workdir DIR`, else the machine file's folder). Relative paths
count from that folder; a path that resolves outside it (`..`, an absolute path elsewhere, a
symbolic link out) is refused naming the parameter and the folder.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from ..errors import MotionError

LOCAL_HOSTS = ("127.0.0.1", "localhost", "::1")


@dataclass(frozen=True)
class WorkFolder:
    """`folder` None and `restricted` False: any path (local use, as before)."""

    folder: Path | None = None
    restricted: bool = False

    @classmethod
    def for_server(cls, host: str, workdir: str | None, machine: str | None) -> WorkFolder:
        """--workdir always confines; beyond 127.0.0.1 the machine file's folder does
        when no --workdir is given (neither: every file-path method is refused)."""
        if workdir is not None:
            p = Path(workdir)
            if not p.is_dir():
                raise MotionError(f"--workdir {workdir!r}: no such folder")
            return cls(p.resolve(), True)
        if host in LOCAL_HOSTS:
            return cls()
        if machine is not None:
            return cls(Path(machine).resolve().parent, True)
        return cls(None, True)

    def resolve(self, param: str, path: str) -> Path:
        """`path` as the file to use, or MotionError naming `param` when it lies outside."""
        if not self.restricted:
            return Path(path)
        if self.folder is None:
            raise MotionError(f"{param}: file paths are refused: the server has no working "
                              f"folder (start it with --workdir DIR or --machine FILE), got "
                              f"{path!r}")
        p = Path(path)
        full = (p if p.is_absolute() else self.folder / p).resolve()
        if full != self.folder and self.folder not in full.parents:
            raise MotionError(f"{param} must lie in the working folder "
                              f"{os.fspath(self.folder)!r} (only its files may be read or "
                              f"written; --workdir), got {path!r}")
        return full
