"""The Controller: owns the hardware, the axes and the clock, and runs the cycle.

One cycle (period T, from t0 to t1 = t0 + T):

1. every axis with motion hands the hardware the cubic piece of its profile for [t0, t1]
   (evaluated analytically at the cycle ends, never integrated);
   then the pre-advance hooks run (`add_pre_advance_hook`: timed outputs for [t0, t1]);
2. `hardware.advance(t1)` moves the machine and returns the input edges, time-ordered;
3. each edge goes through the edge-hook list (E-stop and servo alarm are the first two;
   limits, latches and compare subscribe with `add_edge_hook`);
4. every axis finishes a motion that reached its end (counters and input levels are read
   back from the hardware lazily, at most once per cycle, when first looked at);
5. cycle hooks run (`add_cycle_hook`), then the recorder if recording is on.

Virtual time: `step()`, `advance(dt)`, `run_until(condition, timeout)` - deterministic, as
fast as Python goes. Real time: `start_realtime()` paces the same cycle to the wall clock on
a thread; `stop_realtime()`; `with controller.start_realtime(): ...`; `cycle_stats()`.
Registering hooks is controller_hooks.py, changing the period or an axis's settings on a
running machine controller_settings.py (mixins of Controller).
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from ...config import MachineConfig, default_machine
from ...errors import MotionError, check_nonnegative
from ...history import MotionHistory
from ...hw.interface import Hardware, InputEdge
from ...recording import Recorder
from .axis import Axis
from .clock import CycleStats, RealtimePacer, check_period
from .controller_hooks import ControllerHooks
from .controller_settings import (  # noqa: F401 - re-exported (compat.mccl_motion)
    DECODER_FIELDS,
    RECONFIGURABLE,
    ControllerSettings,
)
from .events import EventLog
from .jump import jump, plan_jump, record_now
from .motion import ActiveMotion
from .realtime import AVAILABLE as _COMPILED_RT
from .realtime import HandoverLock, RealtimeExecutor
from .states import AxisState

if TYPE_CHECKING:
    import numpy as np

#: Recorder state channel numbering (the order of AxisState).
STATE_CODES = {st: i for i, st in enumerate(AxisState)}
#: Recorder io channel bits, after HSL get_io_status (seed-facts 2.4); logical levels.
IO_BITS = (("rdy", 0), ("alm", 1), ("pel", 2), ("mel", 3), ("org", 4), ("ez", 9),
           ("ltc", 11), ("sd", 12), ("inp", 13))

#: The back end `Controller(hardware=None)` builds, registered one level up
#: (openmotion/control/__init__.py: the simulator); the core never imports a back end.
_DEFAULT_HARDWARE: Callable[[MachineConfig], Hardware] | None = None
#: (attribute, attach(controller, wanted) -> value): capabilities every new controller gets,
#: in order (servo loops, safety), registered by the packages that provide them.
_ATTACHMENTS: list[tuple[str, Callable[[Any, bool], Any]]] = []


def set_default_hardware(factory: Callable[[MachineConfig], Hardware]) -> None:
    """Choose the back end a Controller built without `hardware` gets (factory(config))."""
    global _DEFAULT_HARDWARE  # noqa: PLW0603 - the composition root sets it once
    if not callable(factory):
        raise MotionError(f"factory must be callable, got {factory!r}")
    _DEFAULT_HARDWARE = factory


def register_attachment(name: str, attach: Callable[[Any, bool], Any]) -> None:
    """Attach a capability to every new Controller as attribute `name`:
    `attach(controller, wanted)` runs at the end of construction (`wanted`: the
    constructor's flag of that name, True when it has none) and returns the value.
    Registering a name again replaces its attach function (same place in the order)."""
    if not isinstance(name, str) or not name.isidentifier():
        raise MotionError(f"name must be an identifier, got {name!r}")
    if not callable(attach):
        raise MotionError(f"attach must be callable, got {attach!r}")
    for k, (n, _) in enumerate(_ATTACHMENTS):
        if n == name:
            _ATTACHMENTS[k] = (name, attach)
            return
    _ATTACHMENTS.append((name, attach))


EdgeHook = Callable[["Controller", InputEdge], None]
CycleHook = Callable[["Controller", float], None]
DueFn = Callable[["Controller"], float]
PreAdvanceHook = Callable[["Controller", float, float], None]
SampleHook = Callable[["Controller", float], None]
FaultHook = Callable[[Axis, str], None]
MotionCheck = Callable[[Axis, ActiveMotion], None]
MotionHook = Callable[[Axis, "ActiveMotion | None"], None]
PeriodHook = Callable[[float, bool], None]
ConfigHook = Callable[[int, Any, bool], None]
JumpObserver = Callable[["Controller", int, int, "np.ndarray", "np.ndarray"], None]


class Controller(ControllerHooks, ControllerSettings):
    """Multi-axis controller over a `Hardware` back end (the simulator by default).

    config: the machine (default `default_machine()`); hardware: a back end implementing
    hw.interface.Hardware (default: the one registered with `set_default_hardware`, the
    simulator `SimMachine(config)`, chosen by openmotion.control); period: interpolation
    period in seconds (default config.cycle_s, 1 ms .. 1 s); history_window_s: how much
    motion history to keep (flat memory); safety: attach the motion I/O reactions
    (`Safety`: end limits, slow-down, alarm, ERC, soft limits, comparators) as
    `ctl.safety` — on by default, as on a real card; `safety=False` leaves only E-stop and
    servo alarm handling.
    """

    def __init__(self, config: MachineConfig | None = None, hardware: Hardware | None = None,
                 *, period: float | None = None, history_window_s: float = 60.0,
                 safety: bool = True) -> None:
        if config is None:
            config = default_machine()
        if not isinstance(config, MachineConfig):
            raise MotionError(f"config must be a MachineConfig, got {type(config).__name__}")
        if not config.axes:
            raise MotionError("config must describe at least one axis")
        self.period = check_period(config.cycle_s if period is None else period)
        if hardware is None:
            if _DEFAULT_HARDWARE is None:
                raise MotionError("hardware is required: no default back end is registered "
                                  "(openmotion.control registers the simulator)")
            hardware = _DEFAULT_HARDWARE(config)
        if not isinstance(hardware, Hardware):
            raise MotionError("hardware must implement openmotion.hw.interface.Hardware")
        if hardware.n_axes != len(config.axes):
            raise MotionError(f"hardware has {hardware.n_axes} axes, config has "
                              f"{len(config.axes)}")
        self.config = config
        self.hardware = hardware
        self._lock = HandoverLock()
        self._t_origin = float(hardware.time)
        self._n = 0
        self._time = self._t_origin
        self.axes: tuple[Axis, ...] = tuple(
            Axis(i, ax, self) for i, ax in enumerate(config.axes))
        self._by_name = {a.name: a for a in self.axes}
        self.history = MotionHistory(len(self.axes), history_window_s, t_start=self._time)
        self._edge_hooks: list[EdgeHook] = [_estop_hook, _alarm_hook]
        # hook -> the signals it acts on (a hook absent here may act on any edge)
        self._edge_signals: dict[EdgeHook, frozenset[str]] = {
            _estop_hook: frozenset({"emg"}), _alarm_hook: frozenset({"alm"})}
        self._cycle_hooks: list[CycleHook] = []
        self._cycle_dues: dict[CycleHook, DueFn] = {}  # hook -> when it must next run
        #: Virtual time jumps over the cycles nothing needs (control/core/jump.py); False runs
        #: every cycle (the reference the jumps are tested against).
        self.virtual_jumps = True
        self._pre_hooks: list[PreAdvanceHook] = []
        self._pre_dues: dict[PreAdvanceHook, DueFn] = {}
        self._jump_observers: list[JumpObserver] = []
        self._sample_hooks: list[tuple[SampleHook, int]] = []
        self._samples = 1  # sub-steps per cycle: lcm of the sample hooks' rates
        self._fault_hooks: list[FaultHook] = []
        self._motion_checks: list[MotionCheck] = []
        self._motion_hooks: list[MotionHook] = []
        self._period_hooks: list[PeriodHook] = []
        self._config_hooks: list[ConfigHook] = []
        self._estop = False
        self._committed: float | None = None  # inside a cycle: the end its pulses reach
        #: cycles that raised (each one became a fault, see `step`)
        self.cycle_errors = 0
        self._inputs: list[dict[str, bool]] = [{} for _ in self.axes]
        self._nc = [{s for s in ("pel", "mel", "org", "sd", "ltc", "ez", "alm", "inp", "rdy")
                     if ax.signal_logic(s) == "nc"} for ax in config.axes]
        self._emg_nc = any(ax.signal_logic("emg") == "nc" for ax in config.axes)
        self.recorder: Any = None
        #: real time on the compiled executor (control/core/realtime.py) when it is built;
        #: False: every cycle stepped in Python by RealtimePacer (the reference)
        self.compiled_realtime = _COMPILED_RT
        self._pacer: RealtimePacer | RealtimeExecutor = RealtimePacer(
            self.step, self.period, self._overran)
        self._rb_cycle = [-1] * len(self.axes)
        #: axis -> (motion, last cycle, origin, period, first cycle, ends): the pieces a
        #: virtual-time jump left queued on the hardware for a motion (jump.py `_feed`)
        self._fed: dict[int, tuple] = {}
        self._estop = self._emg_level_active(hardware.read_input("emg"))
        self.events = EventLog(self)  # faults, limits, latches, home completion, compare
        #: capabilities attached at construction (register_attachment): the closed servo
        #: loops (name -> ServoLoop) and the motion I/O reactions (a `Safety`, or None)
        self.servo_loops: dict[str, Any] = {}
        self.safety: Any = None
        #: homing settings a machine file gave (axis name -> control.home HomeConfig;
        #: filled by openmotion.machine_file.open_machine, empty otherwise)
        self.home_settings: dict[str, Any] = {}
        wanted = {"safety": safety}
        for name, attach in _ATTACHMENTS:
            setattr(self, name, attach(self, wanted.get(name, True)))

    # ------------------------------------------------------------------ lookup
    def axis(self, key: int | str) -> Axis:
        """An axis by name or index; MotionError naming the choices otherwise."""
        if isinstance(key, str):
            ax = self._by_name.get(key)
            if ax is None:
                raise MotionError(f"axis {key!r} is unknown; axes: {', '.join(self._by_name)}")
            return ax
        if isinstance(key, bool) or not isinstance(key, int):
            raise MotionError(f"axis must be a name or an index, got {key!r}")
        if not 0 <= key < len(self.axes):
            raise MotionError(f"axis index must be in [0, {len(self.axes) - 1}], got {key!r}")
        return self.axes[key]

    def __getitem__(self, key: int | str) -> Axis:
        return self.axis(key)

    @property
    def time(self) -> float:
        """Controller time (s): the end of the last cycle run."""
        return self._time

    @property
    def cycles(self) -> int:
        return self._n

    @property
    def estop_active(self) -> bool:
        return self._estop

    @property
    def estop_input_level(self) -> bool:
        """The physical EMG input level that means E-stop: high for a normally open
        contact, low when any axis configures EMG as normally closed."""
        return not self._emg_nc

    @property
    def lock(self) -> HandoverLock:
        """The re-entrant lock every cycle runs under: hold it to read or change several
        pieces of controller state as one step from another thread."""
        return self._lock

    # ------------------------------------------------------------------ inputs
    def input_active(self, axis: int, signal: str) -> bool:
        """Logical level of an axis input (configured NO/NC logic applied)."""
        self._sync(axis)
        return self._inputs[axis].get(signal, False) != (signal in self._nc[axis])

    def alarm_active(self, axis: int) -> bool:
        return self.input_active(axis, "alm")

    def _emg_level_active(self, level: bool) -> bool:
        return level != self._emg_nc

    # ------------------------------------------------------------------ motion checks
    # (add_*/remove_* of every hook: controller_hooks.py; set_period, set_encoder_mode,
    # reconfigure_axis: controller_settings.py)
    def _vet_motion(self, axis: Axis, motion: ActiveMotion) -> None:
        for check in tuple(self._motion_checks):
            check(axis, motion)

    # ------------------------------------------------------------------ convenience
    def enable_all(self) -> None:
        """Enable every axis (see Axis.enable)."""
        for ax in self.axes:
            ax.enable()

    def stop_all(self, *, immediately: bool = False) -> None:
        """Decelerating (or immediate) stop of every axis."""
        for ax in self.axes:
            if immediately:
                ax.stop_immediately()
            else:
                ax.stop()

    def emergency_stop(self, reason: str = "emergency stop") -> None:
        """Software E-stop: every axis stops immediately and goes to ErrorStop."""
        with self._lock:
            for ax in self.axes:
                ax.fault_stop(reason)

    # ------------------------------------------------------------------ the cycle
    def step(self) -> None:
        """Run one cycle (virtual time: the caller paces it). No exception escapes it: a
        failure anywhere in the cycle (a hook, an engine, the hardware) becomes a fault -
        see `_cycle_failed` - and the cycle still ends on time."""
        n = self._n + 1
        try:
            self._step()
        except Exception as err:  # the cycle must go on: safety reactions run in it
            self._cycle_failed(n, err)

    def _cycle_failed(self, n: int, err: Exception) -> None:
        """A cycle raised: every axis still moving stops at once in ErrorStop ("cycle
        error: ..."), a `cycle_error` event records it, and the cycle's time is completed
        (the hardware advanced to its end) so virtual and real time stay exact. Engines
        that can contain their own failures (groups) do so first and never get here."""
        with self._lock:
            self.cycle_errors += 1
            t1 = self._t_origin + n * self.period
            reason = f"cycle error: {type(err).__name__}: {err}"
            # each step is guarded on its own: one failing part must not stop the rest
            for ax in self.axes:
                if ax.is_moving:
                    with contextlib.suppress(Exception):
                        ax.fault_stop(reason)
            if self._n < n:  # the failure came before the hardware reached the cycle end
                with contextlib.suppress(Exception):
                    self._drop_fed()
                with contextlib.suppress(Exception):
                    self.hardware.advance(t1)
                self._n, self._time = n, t1
            self._committed = None
            events = getattr(self, "events", None)
            if events is not None:
                with contextlib.suppress(Exception):
                    events.record("cycle_error", None, self._time, None, reason)

    def _drop_fed(self) -> None:
        """Clear the pieces a jump left queued (jump.py `_feed`): the next cycle is
        commanded otherwise."""
        hw = self.hardware
        for idx in self._fed:
            hw.clear_queue(idx)
        self._fed.clear()

    def _step(self) -> None:
        with self._lock:
            if self._fed:
                self._drop_fed()
            t0 = self._time
            n = self._n + 1
            t1 = self._t_origin + n * self.period
            hw = self.hardware
            for ax in self.axes:
                cmd = ax._command(t0, t1)
                if cmd is not None:
                    hw.command(ax.index, cmd)
            self._committed = t1  # the hardware has every axis's pulses up to t1
            for pre in tuple(self._pre_hooks):
                pre(self, t0, t1)
            edges = hw.advance(t1) if not self._sample_hooks else self._sampled(t0, t1)
            self._finish_cycle(n, edges)

    def _finish_cycle(self, n: int, edges: list[InputEdge]) -> None:
        """The end of cycle n, the hardware advanced there: edge hooks, motion ends, cycle
        hooks, the recorder (lock held)."""
        t1 = self._t_origin + n * self.period
        self._n = n
        self._time = t1
        self._committed = None
        # a hook may remove itself or another one: loop over a snapshot and skip the removed
        # (removing from the live list skipped the hook after it in that cycle)
        if edges:
            hooks = self._edge_hooks
            for e in edges:
                for h in tuple(hooks):
                    if h in hooks:
                        h(self, e)
        origin, period = self._t_origin, self.period
        for ax in self.axes:
            m = ax._motion
            if not (ax._waiting_inp or ax._gated):  # else Axis._cycle_end always runs
                if m is None:
                    continue  # nothing running or awaited: nothing to end
                c = m._end_cycle  # (jump.end_cycle: the first cycle ending at or after
                if c is not None and n < c[2] and c[0] == origin and c[1] == period:
                    continue  # t_end; this cycle ends before it: the motion goes on)
                if m.kind == "velocity":
                    continue  # (never finishes by itself)
            ax._cycle_end(t1)
        cycle_hooks = self._cycle_hooks
        for h in tuple(cycle_hooks):
            if h in cycle_hooks:
                h(self, t1)
        if self.recorder is not None:
            self._record(t1)

    def _run_cycles(self, n: int) -> None:
        """Run up to n cycles: one jump (control/core/jump.py) or one step."""
        with self._lock:
            try:
                land = plan_jump(self, n)
                if land > self._n + 1:
                    jump(self, land)
                    return
            except Exception as err:  # as in step(): nothing escapes the cycle
                self._cycle_failed(self._n + 1, err)
                return
            self.step()

    def _sampled(self, t0: float, t1: float) -> list[InputEdge]:
        """Advance the hardware over [t0, t1] in sub-steps, running the sample hooks."""
        hw = self.hardware
        ns = self._samples
        edges: list[InputEdge] = []
        for k in range(ns):
            tk = t0 + (t1 - t0) * k / ns
            if k:
                edges.extend(hw.advance(tk))
            for hook, per in tuple(self._sample_hooks):
                if k % (ns // per) == 0:
                    hook(self, tk)
        edges.extend(hw.advance(t1))
        return edges

    def _sync(self, axis: int) -> None:
        """Read an axis back from the hardware if not done since the last cycle.

        Counters and input levels are read lazily, at most once per cycle and only when
        someone looks: the values are those at the current controller time either way, and
        the hot path skips a hardware call per idle axis per cycle.
        """
        if self._rb_cycle[axis] != self._n:
            with self._lock:
                rb = self.hardware.read_axis(axis)
                self._rb_cycle[axis] = self._n
                self._inputs[axis] = rb.inputs
                self.axes[axis].counters.update(rb.pulses_out, rb.encoder, self._time)

    def advance(self, dt: float) -> None:
        """Run the cycles covering `dt` seconds of virtual time (rounded up to whole cycles)."""
        dt = check_nonnegative("dt", dt)
        self._check_virtual()
        end = self._n + math.ceil(dt / self.period - 1e-9)
        while self._n < end:
            self._run_cycles(end - self._n)

    def run_until(self, condition: Callable[[], bool], timeout: float, *,
                  event_driven: bool = False) -> bool:
        """Run cycles until `condition()` is true (checked before each cycle); False if
        `timeout` seconds of virtual time pass first. Never raises on timeout.

        event_driven=True promises that the condition only changes when something happens
        (a motion ends or starts, an input edge, a hook acts), never with the position
        between cycles; virtual time may then jump (control/core/jump.py) and the condition is
        checked at each landing. Otherwise every cycle runs.
        """
        if not callable(condition):
            raise MotionError(f"condition must be callable, got {condition!r}")
        timeout = check_nonnegative("timeout", timeout)
        self._check_virtual()
        end = self._n + math.ceil(timeout / self.period - 1e-9)
        while self._n < end:
            if condition():
                return True
            if event_driven:
                self._run_cycles(end - self._n)
            else:
                self.step()
        return bool(condition())

    def wait_motion_done(self, axes: Sequence[int | str] | None = None,
                         timeout: float = 60.0) -> bool:
        """run_until every given axis (default all) reports motion_done == 0."""
        sel = self.axes if axes is None else tuple(self.axis(k) for k in axes)
        return self.run_until(lambda: all(a.motion_done == 0 for a in sel), timeout,
                              event_driven=True)

    def _check_virtual(self) -> None:
        if self._pacer.running:
            raise MotionError("virtual-time calls are not allowed while real-time mode runs")

    # ------------------------------------------------------------------ recording
    def start_recording(self, capacity: int = 60_000, channels: Sequence[str] | None = None,
                        *, spill_path: str | None = None) -> Recorder:
        """Record every cycle into a new `Recorder` (ring buffer of `capacity` cycles,
        default 1 min at 1 ms; `spill_path` keeps older rows in a file). Channels as in
        openmotion.recording (default all)."""
        kwargs: dict[str, Any] = {"spill_path": spill_path}
        if channels is not None:
            kwargs["channels"] = channels
        rec = Recorder(len(self.axes), capacity, **kwargs)
        with self._lock:
            self.recorder = rec
        return rec

    def stop_recording(self) -> Recorder | None:
        """Stop recording; returns the recorder (its data stays readable)."""
        with self._lock:
            rec, self.recorder = self.recorder, None
        return rec

    def _record(self, t: float) -> None:
        if record_now(self, self._n):  # compiled, with a bulk readback (jump.py)
            return
        axes = self.axes
        io = [_io_word(self, ax.index) for ax in axes] if "io" in self.recorder.channels \
            else None
        self.recorder.record(
            t,
            cmd_pos=[ax.position for ax in axes],
            fb_pos=[ax.counters.feedback for ax in axes],
            cmd_vel=[ax.velocity for ax in axes],
            state=[STATE_CODES[ax.state] for ax in axes],
            io=io,
        )

    # ------------------------------------------------------------------ real time
    def start_realtime(self) -> Controller:
        """Pace the cycle to the wall clock on a thread; returns self (a context manager).

        With the compiled executor (`compiled_realtime`, on when the extension is built) the
        cycles virtual time would jump over run in C at their slots, Python only where it
        must act (control/core/realtime.py); otherwise every cycle is a `step` in Python."""
        if self._pacer.running:
            raise MotionError("real-time mode is already running")
        if self.compiled_realtime and _COMPILED_RT:
            if not isinstance(self._pacer, RealtimeExecutor):
                self._pacer = RealtimeExecutor(self, self._overran)
        elif not isinstance(self._pacer, RealtimePacer):
            self._pacer = RealtimePacer(self.step, self.period, self._overran)
        self._pacer.start()
        return self

    def stop_realtime(self) -> None:
        """Stop the real-time thread (re-raises an exception the cycle raised there)."""
        self._pacer.stop()
        if self._pacer.error is not None:
            err, self._pacer.error = self._pacer.error, None
            raise MotionError(f"real-time cycle failed: {err!r}") from err

    @property
    def realtime(self) -> bool:
        return self._pacer.running

    def cycle_stats(self) -> CycleStats:
        """Statistics of the real-time cycles (busy and jitter mean/p99/max, overruns, late
        cycles run in catch-up, the most slots behind, cycles that raised)."""
        return self._pacer.stats()

    def cycle_samples(self) -> dict[str, Any]:
        """The real-time statistics per cycle, in cycle order (seconds; the last 65536
        cycles): "busy", "late" (start lateness), and with the compiled executor "work"
        (Python between the cycles); numpy arrays."""
        return self._pacer.samples()

    def _overran(self, count: int, behind: int) -> None:
        """Real-time pacer: a burst of overruns began; record an `overrun` event."""
        events = getattr(self, "events", None)
        if events is not None:
            with contextlib.suppress(Exception):
                events.record("overrun", None, self._time, None,
                              f"cycle overran its period (overrun {count}, {behind} slots "
                              "behind; the late cycles run in catch-up, none is skipped)")

    def __enter__(self) -> Controller:
        return self

    def __exit__(self, *exc: object) -> None:
        if self._pacer.running:
            self.stop_realtime()

    # ------------------------------------------------------------------ bookkeeping
    def _motion_changed(self, axis: Axis, motion: ActiveMotion | None) -> None:
        """An axis started, re-planned or killed its motion: keep the history in step."""
        if motion is None:
            # killed inside a cycle (a pre-advance or sample hook: a following-error trip):
            # the cycle's pulses are already with the hardware, so the motion ends at t1
            t = self._time if self._committed is None else self._committed
            self.history.truncate(axis.index, t)
        else:
            self.history.append(axis.index, motion.t_start, motion.profile)
        for hook in tuple(self._motion_hooks):
            hook(axis, motion)


# -- built-in edge hooks -------------------------------------------------------------------
def _estop_hook(ctl: Controller, edge: InputEdge) -> None:
    """E-stop input: every axis stops immediately and goes to ErrorStop "emergency stop"."""
    if edge.axis is None and edge.signal == "emg":
        active = ctl._emg_level_active(edge.level)
        ctl._estop = active
        if active:
            for ax in ctl.axes:
                ax.fault_stop("emergency stop", at=edge.time)


def _alarm_hook(ctl: Controller, edge: InputEdge) -> None:
    """Servo alarm (ALM) on an axis: that axis stops (immediately, or decelerating from the
    edge time when `axis.alarm_decelerate`), ErrorStop "servo alarm"."""
    if (edge.axis is not None and edge.signal == "alm"
            and edge.level != ("alm" in ctl._nc[edge.axis])):
        ax = ctl.axes[edge.axis]
        ax.fault_stop("servo alarm", decelerate=ax.alarm_decelerate, at=edge.time)


def _io_word(ctl: Controller, axis: int) -> int:
    """get_io_status-style bit field of an axis's logical input levels (+ EMG bit 6)."""
    ctl._sync(axis)  # one readback; then input_active's rule on each signal
    inputs = ctl._inputs[axis]
    nc = ctl._nc[axis]
    word = 0
    for sig, bit in IO_BITS:
        if inputs.get(sig, False) != (sig in nc):
            word |= 1 << bit
    if ctl._estop:
        word |= 1 << 6
    return word
