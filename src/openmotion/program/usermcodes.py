"""User M-codes M100-M199 as LinuxCNC runs them: an executable file named M1nn.

LinuxCNC (emctask.cc, docs "M100 to M199"): the file is named exactly `M1nn` (a capital M,
no extension), must be executable, and is looked for in [DISPLAY]PROGRAM_PREFIX, then in
each folder of [RS274NGC]USER_M_PATH; the first found is used. A code without such a file
is the interpreter error "Unknown M code used". The interpreter stops the motion before
it (FINISH(), a queue buster), the task runs `M1nn P Q` with P and Q printed as `%f`
(-1.000000 when the word is absent), waits until it exits, and stops the program with an
error when its exit status is not 0 (or a signal ended it).

Here: `GCodeOptions.user_m_path` / `RunOptions.user_m_path` are the folders (in LinuxCNC's
order: PROGRAM_PREFIX first, then USER_M_PATH); the file is found when the program is
compiled (a missing one is refused there, with file, line, column and word, before
anything moves) and becomes a `UserMCode` record; the runner starts it once the motion
before it has ended and waits for it (`UserCommand`), at most `RunOptions.user_m_timeout`
seconds of wall-clock time.
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import tempfile
import time
from collections.abc import Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ..errors import MotionError
from .words import Word

if TYPE_CHECKING:
    from . import canon
    from .modal import Modal
    from .parser import Block

#: LinuxCNC's value of an absent P or Q word (block->p_number's default).
ABSENT = -1.0


@dataclass(frozen=True, slots=True)
class UserMCode:
    """M100-M199: run the executable `path` with P and Q (`args`, as LinuxCNC formats
    them) once the motion before it has ended, and wait for it to exit."""

    code: int
    p: float
    q: float
    path: str
    line: int
    file: str = ""

    @property
    def args(self) -> list[str]:
        return [self.path, f"{self.p:f}", f"{self.q:f}"]


def check_folders(name: str, value: object) -> tuple[str, ...]:
    """A sequence of existing folders (a user M-code search path), as a tuple of str."""
    if isinstance(value, (str, bytes, os.PathLike)) or not isinstance(value, Iterable):
        raise MotionError(f"{name} must be a list of folders, got {value!r}")
    out = []
    for d in value:
        if not isinstance(d, (str, os.PathLike)):
            raise MotionError(f"{name} must be a list of folders, got {d!r} in it")
        path = os.fspath(d)
        if not os.path.isdir(path):
            raise MotionError(f"{name}: {path!r} is not a folder")
        out.append(path)
    return tuple(out)


def find_user_m(code: int, dirs: Iterable[str]) -> tuple[str | None, str | None]:
    """(path of the executable M<code> in the first folder holding one, None) or (None,
    a non-executable M<code> seen on the way: the reason it is not used)."""
    seen = None
    for d in dirs:
        path = os.path.join(d, f"M{code}")
        if os.path.isfile(path):
            if os.access(path, os.X_OK):
                return path, None
            seen = seen or path
    return None, seen


def m100_m199(m: Modal, b: Block, code: int, pos: int, words: dict[str, Word],
              used: set[str], out: list[canon.Command]) -> None:
    """An M1nn word: the `UserMCode` record, or LinuxCNC's "Unknown M code used"."""
    word = f"M{code}"
    dirs = m.opt.user_m_path
    path, seen = find_user_m(code, dirs)
    if path is None:
        where = f"no executable file {word} in {', '.join(dirs)}" if dirs else \
            "no user M-code folders are set: user_m_path, `openmotion run --user-m-path`"
        why = f"; {seen} is not executable" if seen else ""
        raise b.error(f"Unknown M code used: {word} ({where}{why})", pos, word)
    vals = []
    for letter in "PQ":
        w = words.get(letter)
        if w is None:
            vals.append(ABSENT)
            continue
        used.add(letter)  # any number (the expression evaluator refuses non-finite ones)
        vals.append(w.value)
    out.append(UserMCode(code, vals[0], vals[1], path, b.line, b.file))


class UserCommand:
    """A running user M-code (the runner's request): started at rest, `poll()` each cycle
    until it has exited; `close()` interrupts it and its children (SIGINT to its process
    group, as LinuxCNC's task does with an abandoned command, then SIGKILL to what is
    left of the group, background children included). `block`: wait
    for the exit inside poll (virtual time: the machine clock stands still while the
    program runs; in real time the cycle only polls)."""

    def __init__(self, cmd: UserMCode, timeout: float, block: bool) -> None:
        self.cmd = cmd
        self.timeout = timeout
        self.block = block
        self._log = tempfile.TemporaryFile()  # noqa: SIM115 - closed in _read_log/close
        self.t0 = time.monotonic()
        try:
            self.proc: subprocess.Popen[bytes] | None = subprocess.Popen(
                cmd.args, stdin=subprocess.DEVNULL, stdout=self._log,
                stderr=subprocess.STDOUT, start_new_session=True)  # its own group
        except OSError as exc:
            self._log.close()
            raise MotionError(f"M{cmd.code}: cannot run {cmd.path}: {exc.strerror}") from None
        self.output = ""

    def poll(self) -> bool:
        """True once the program has exited with status 0; MotionError when it failed or
        ran longer than the timeout (it is killed then)."""
        proc = self.proc
        assert proc is not None
        if self.block:
            with contextlib.suppress(subprocess.TimeoutExpired):
                proc.wait(max(0.0, self.timeout - (time.monotonic() - self.t0)))
        status = proc.poll()
        if status is None:
            if time.monotonic() - self.t0 < self.timeout:
                return False
            self.close()
            raise MotionError(f"M{self.cmd.code} ({self.cmd.path}) did not exit within "
                              f"{self.timeout:g} s (RunOptions.user_m_timeout): stopped")
        self.proc = None
        self.output = self._read_log()
        if status != 0:
            how = f"exit status {status}" if status > 0 else \
                f"signal {signal.Signals(-status).name}"
            tail = f"; its output: {self.output[-300:]!r}" if self.output else ""
            raise MotionError(f"M{self.cmd.code} ({' '.join(self.cmd.args)}) ended with "
                              f"{how}: the program stops (LinuxCNC){tail}")
        return True

    def _read_log(self) -> str:
        try:
            self._log.seek(0)
            return self._log.read(100_000).decode("utf-8", "replace").strip()
        finally:
            self._log.close()

    def close(self) -> None:
        proc, self.proc = self.proc, None
        if proc is not None and proc.poll() is None:  # the program and its children
            with contextlib.suppress(ProcessLookupError):
                os.killpg(proc.pid, signal.SIGINT)
            with contextlib.suppress(subprocess.TimeoutExpired):
                proc.wait(0.5)
            with contextlib.suppress(ProcessLookupError):  # what is left of the group
                os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
        if not self._log.closed:
            self._log.close()
