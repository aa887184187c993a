"""The program runner's public records: its state, its events and its settings."""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

from ..errors import MotionError
from .convert import ConvertOptions


class RunState(Enum):
    READY = "ready"
    RUNNING = "running"
    PAUSED = "paused"
    DONE = "done"
    ABORTED = "aborted"
    ERROR = "error"


@dataclass(frozen=True)
class RunEvent:
    """Something that happened during the run: output, pause, message, fault, ..."""

    t: float
    kind: str
    line: int
    text: str
    index: int | None = None
    level: bool | None = None


@dataclass(frozen=True)
class RunOptions:
    """Execution settings (see the module docstring and convert.py)."""

    rapid_ratio: float = 1.0
    feed_mode: str = "uniform"
    chord_tol: float = 0.001        # machine units
    acc_time: float = 0.05          # s from rest to the feed (path accel = feed / acc_time)
    window: int = 1024              # commands queued in the group at most
    #: passes: None = the program's own (one; endless when an M99 in the main program
    #: restarts it, as in LinuxCNC, until abort()); N = N passes
    repeat: int | None = None
    single_block: bool = False
    optional_stop: bool = False
    probe_input: str | None = None  # board input the G38.x probe is wired to ("di<n>")
    feed_hold_input: str | None = None  # the feed-stop switch ("di<n>", M53; runoverride)
    adaptive_feed_input: str | None = None  # analog input scaling the feed ("ai<n>", M52)
    spindle_axis: int | str | None = None  # the controller axis that is the spindle
    spindle_acc_time: float = 0.5   # s of a spindle speed ramp
    #: folders holding user M-codes M100-M199 (executables named M1nn; usermcodes.py)
    user_m_path: tuple[str, ...] = ()
    user_m_timeout: float = 60.0    # s (wall clock) a user M-code may run

    def __post_init__(self) -> None:
        ConvertOptions(self.rapid_ratio, self.feed_mode, self.chord_tol)
        a = self.acc_time
        if isinstance(a, bool) or not isinstance(a, (int, float)) or not 0.0 < a < 1e3:
            raise MotionError(f"acc_time must be a number in (0, 1000) s, got {a!r}")
        for name, lo in (("window", 1), ("repeat", 1)):
            v = getattr(self, name)
            if name == "repeat" and v is None:
                continue
            if isinstance(v, bool) or not isinstance(v, int) or v < lo:
                none = " or None (the program's own)" if name == "repeat" else ""
                raise MotionError(f"{name} must be an integer >= {lo}{none}, got {v!r}")
        for name in ("single_block", "optional_stop"):
            if not isinstance(getattr(self, name), bool):
                raise MotionError(f"{name} must be True or False")
        from .usermcodes import check_folders

        object.__setattr__(self, "user_m_path", check_folders("user_m_path",
                                                              self.user_m_path))
        ut = self.user_m_timeout
        if isinstance(ut, bool) or not isinstance(ut, (int, float)) or not 0.0 < ut <= 1e6:
            raise MotionError(f"user_m_timeout must be a number in (0, 1e6] s, got {ut!r}")
        sa = self.spindle_acc_time
        if isinstance(sa, bool) or not isinstance(sa, (int, float)) or not 0.0 < sa < 1e3:
            raise MotionError(f"spindle_acc_time must be a number in (0, 1000) s, got {sa!r}")
        sp = self.spindle_axis
        if sp is not None and (isinstance(sp, bool) or not isinstance(sp, (int, str))):
            raise MotionError(f"spindle_axis must be an axis index or name, got {sp!r}")
        for name in ("probe_input", "feed_hold_input"):
            pi = getattr(self, name)
            if pi is not None and not (isinstance(pi, str) and pi.startswith("di")
                                       and pi[2:].isdigit()):
                raise MotionError(f"{name} must be a board input 'di<n>' or None, got {pi!r}")
        af = self.adaptive_feed_input
        if af is not None and not (isinstance(af, str) and af.startswith("ai")
                                   and af[2:].isdigit()):
            raise MotionError(f"adaptive_feed_input must be an analog input 'ai<n>' or None, "
                              f"got {af!r}")
