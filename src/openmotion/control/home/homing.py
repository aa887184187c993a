"""Homing: one table-driven state machine for the 13 HSL home modes and MCCL phased homing.

A `Homing` runs the phases of control.home.homing_modes on one axis, inside the controller's
cycle (an edge hook finds the triggers at their exact time, a cycle hook sequences the
phases), with the axis in the PLCopen Homing state. Run stages (LinuxCNC homing.c style):

  SEARCH   moving in the phase's direction; entered when a phase starts (from rest: a ramp
           to the phase speed, a cruise of at most `search_range`, a stop); left on the
           wanted edge (-> the phase's reaction) or when the move ends without it (fault
           "not found").
  STOP     decelerating after a trigger; left at rest (+ settle_s) -> next phase.
  MOVE     a positioning move (escape offset, final move to home); left at rest.
  DONE / ERROR / ABORTED   final; counters cleared on DONE.

Before the table: if the first phase's signal is already active, the axis first leaves it
(StrVel, against the search) and backs off by `org_offset` - "back off until the switch
releases, then by the offset" (anchors.md, b9). An end limit met while searching (not part of
the mode) faults the axis, unless `auto_search` (HSL home_search, figure 4-29): then the
axis reverses, passes ORG, backs off by `org_offset` and runs the table again.

Deceleration budget: after a trigger the axis runs at most one cycle at speed, then a ramp;
`overrun(v) = v*T + stop distance(v)` must not exceed `max_overrun` when given (refused at
start otherwise), so a trigger never runs the axis into a hard stop. Moves ramp from rest at
a = (MaxVel - StrVel)/Tacc (or with `jerk` as S-curves); no StrVel jump.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import TYPE_CHECKING

from ...errors import MotionError
from ...hw.interface import InputEdge
from ...profile.pcl import MoveSpec
from ...profile.ramps import ramp_accel, ramp_jerk
from ...profile.segments import Profile, ProfileBuilder
from ..core import planning
from ..core.states import AxisState
from ..guard.safety import Safety
from .homeconf import default_home
from .homing_modes import (
    EZ_COUNT_BASE,
    HomeConfig,
    HomeStatus,
    Phase,
    uses,
)
from .pulserule import half_pulse, pulse_count

if TYPE_CHECKING:
    from ..core.axis import Axis
    from ..core.controller import Controller

S = AxisState
#: The input edges a homing acts on (its edge hook ignores every other signal).
HOMING_SIGNALS = ("pel", "mel", "org", "ez")


def _has_index(axis: Axis) -> bool:
    # [low] assumption: quadrature (A/B) encoders carry the Z index; pulse inputs do not.
    return axis.config.encoder_mode.startswith("ab")


class Homing:
    """The home sequence of one axis. `start()`, then run the controller; `status`.

    `config` None: the machine file's homing settings for the axis (`ctl.home_settings`,
    which `openmotion.open_machine` fills from `[axes.<name>.home]`), else the default
    (`homeconf.default_home`: mode 0 towards -1 at 2 % / 20 % of the axis's max speed, as
    open_machine gives an axis without a home table)."""

    def __init__(self, ctl: Controller, axis: int | str, config: HomeConfig | None = None,
                 *, safety: Safety | None = None, escape_only: bool = False) -> None:
        ax = ctl.axis(axis)
        what = "config"
        if config is None:
            config = ctl.home_settings.get(ax.name)
            what = f"ctl.home_settings[{ax.name!r}]"
            if config is None:
                config = default_home(ax)
        if not isinstance(config, HomeConfig):
            raise MotionError(f"{what} must be a HomeConfig, got {type(config).__name__}")
        self.ctl = ctl
        self.axis = ax
        self.config = config
        self.status = HomeStatus()
        table = config.phases()
        if uses(table, "ez") and not _has_index(self.axis):
            raise MotionError(f"mode {config.mode!r} needs the EZ index; axis "
                              f"{self.axis.name} has encoder_mode "
                              f"{self.axis.config.encoder_mode!r} (no index)")
        self._table = table
        self._escape_only = escape_only
        # the Safety attached to this controller, if any: its limit / soft-limit reactions
        # are suspended while homing handles them itself
        self.safety = safety if safety is not None else Safety.of(ctl)
        self._suspended: tuple[str, ...] = ()
        self._plan: list[Phase] = []
        self._k = 0
        self._stage = "idle"
        self._hits = 0
        self._wait_on = False
        self._t_rest = 0.0
        self._t_begin = 0.0
        self._recovered = False
        self._after_move: str = ""
        self._edge_p = 0.0

    # ------------------------------------------------------------------ public
    @property
    def running(self) -> bool:
        return self.status.state == "running"

    @property
    def done(self) -> bool:
        return self.status.state == "done"

    def overrun(self, speed: float) -> float:
        """Travel after a trigger at `speed`: one cycle at speed + the stop distance."""
        c = self.config
        b = ProfileBuilder(0.0, speed)
        if c.jerk is None:
            ramp_accel(b, 0.0, c.decel)
        else:
            ramp_jerk(b, 0.0, c.decel, c.jerk)
        return speed * self.ctl.period + b.state.p

    def start(self) -> None:
        """Validate, enter Homing and start the first phase. Refused (MotionError, nothing
        changed) if the axis cannot move, the budget is exceeded or a speed is too high."""
        c = self.config
        ax = self.axis
        for name in ("str_vel", "max_vel"):
            ax.check_speed(name, getattr(c, name))
        if c.max_overrun is not None:
            worst = self.overrun(c.max_vel)
            if worst > c.max_overrun:
                raise MotionError(
                    f"max_vel {c.max_vel:g} pps overruns a trigger by {worst:.1f} pulses, "
                    f"more than max_overrun {c.max_overrun:g}: lower max_vel or tacc")
        if self.running:
            raise MotionError(f"axis {ax.name}: homing already running")
        saved = (self.status, self._t_begin, self._plan, self._k, self._recovered,
                 self._suspended, self._stage)
        ax.begin_homing()
        try:
            self._start_sequence()
        except BaseException:
            # atomic: whatever failed, nothing stays attached and the axis is as it was
            self.ctl.remove_edge_hook(self._on_edge)
            self.ctl.remove_cycle_hook(self._on_cycle)
            if self.safety is not None:
                for sig in self._suspended:
                    self.safety.resume(ax.index, sig)
            (self.status, self._t_begin, self._plan, self._k, self._recovered,
             self._suspended, self._stage) = saved
            ax.end_homing()
            raise

    def _start_sequence(self) -> None:
        """The part of start() after the axis entered Homing (undone if it raises)."""
        c = self.config
        ax = self.axis
        if self.safety is not None:
            el = self._el_name(1)
            uses_el = uses(self._table, "el") or c.auto_search
            self._suspended = (el, "soft") if uses_el else ("soft",)
            for sig in self._suspended:
                self.safety.suspend(ax.index, sig)
        self.status = HomeStatus(state="running")
        self._t_begin = self.ctl.time
        self._plan = list(self._table)
        self._k = 0
        self._recovered = False
        self.ctl.add_edge_hook(self._on_edge, signals=HOMING_SIGNALS)
        self.ctl.add_cycle_hook(self._on_cycle, due=self._due)
        first = self._plan[0]
        if self._escape_only:  # HSL escape_home: leave the switch, back off, no counters
            self._plan = []
            if self._active(self._sig(first)):
                self._escape_then_table(first)
            else:
                self._finish("done", None)
                ax.end_homing()
            return
        ahead = self._el_name(first.direction)
        if first.signal != "el" and self._active(ahead):
            if not c.auto_search:
                self._fail(f"homing: starts on the {ahead.upper()} limit (auto_search off)")
                return
            self._recover()
            return
        if first.edge == "on" and self._active(self._sig(first)):
            self._escape_then_table(first)
            return
        self._begin_phase()

    def abort(self) -> None:
        """Abort homing (MCC_AbortGoHome): decelerating stop, status 'aborted'."""
        if self.running:
            self._finish("aborted", "aborted by abort()")
            self.axis.stop()

    # ------------------------------------------------------------------ helpers
    def _abs(self, d: int) -> int:
        return d * self.config.direction

    def _el_name(self, d: int) -> str:
        return "pel" if self._abs(d) > 0 else "mel"

    def _sig(self, ph: Phase) -> str:
        # "el" is always the limit in the home direction (escapes move away from it)
        return self._el_name(1) if ph.signal == "el" else ph.signal

    def _active(self, sig: str) -> bool:
        return self.ctl.input_active(self.axis.index, sig)

    def _logical(self, e: InputEdge) -> bool:
        return e.level != (self.axis.config.signal_logic(e.signal) == "nc")

    def _state_now(self) -> tuple[float, float, float]:
        """(p, v, a) of the axis now, command-counter frame."""
        ax = self.axis
        m = ax.motion
        off = ax.counters.command_offset
        if m is None:
            return ax.position, 0.0, 0.0
        p, v, a = m.state(self.ctl.time)
        return p + off, v, a

    def _run(self, profile: Profile) -> None:
        c = self.config
        j = c.jerk if c.jerk is not None else c.decel / self.ctl.period
        try:
            self.axis.run_profile(profile, stop_accel=c.decel, stop_jerk=j,
                                  replace_running=self.axis.motion is not None)
        except MotionError as err:  # refused (e.g. by a safety motion check): stop here
            if self.running:
                self._fail(f"homing: move refused in phase {self.status.phase!r}: {err}")

    def _ramp(self, b: ProfileBuilder, v1: float) -> None:
        c = self.config
        v0 = b.state.v
        slower = abs(v1) < abs(v0) or v1 * v0 < 0.0
        acc = c.decel if slower else c.accel
        if c.jerk is None:
            ramp_accel(b, v1, acc, label="homing ramp")
        else:
            ramp_jerk(b, v1, acc, c.jerk, label="homing ramp")

    def _cruise(self, v: float) -> None:
        """From the current state: ramp to v (signed), cruise search_range, stop."""
        p, v0, a = self._state_now()
        b = ProfileBuilder(p, v0, a if self.config.jerk is not None else 0.0)
        self._ramp(b, v)
        b.segment(self.config.search_range / abs(v), label="homing search")
        self._ramp(b, 0.0)
        self._run(b.build())

    def _decelerate(self) -> None:
        p, v, a = self._state_now()
        b = ProfileBuilder(p, v, a if self.config.jerk is not None else 0.0)
        self._ramp(b, 0.0)
        self._run(b.build())

    def _move_to(self, target: float) -> None:
        c = self.config
        p = self.axis.position
        if target == p:
            return
        v = c.speed("str")  # StrVel (HSL); MaxVel/10 (MCCL phase 3)
        if c.jerk is None:
            spec = MoveSpec("T", 0.0, v, c.tacc, c.tacc, 0.0, 0.0)
            # the speed reached at the homing acceleration, not in Tacc
            spec = spec.derived(tacc=v / c.accel, tdec=v / c.decel)
            prof = planning.position_move(spec, p, target)
        else:
            prof = planning.jerk_move(p, target, v, c.accel, c.jerk,
                                      None if c.tdec is None else c.decel)
        self._run(prof)

    # ------------------------------------------------------------------ sequencing
    def _log(self, text: str) -> None:
        self.status.phase = text
        self.status.history.append(text)

    def _begin_phase(self) -> None:
        ph = self._plan[self._k]
        self._log(ph.name)
        self._hits = 0
        sig = self._sig(ph)
        self._wait_on = ph.edge == "off" and not self._active(sig)
        self._stage = "search"
        v = self._abs(ph.direction) * self.config.speed(ph.speed)
        _, v_now, _ = self._state_now()
        if v_now == 0.0 or math.copysign(1.0, v_now) != math.copysign(1.0, v):
            self._cruise(v)

    def _escape_then_table(self, first: Phase) -> None:
        """Leave the active switch against the search, back off, then run the table."""
        esc = Phase(f"escape {first.signal.upper()}", first.signal, "off", -1, "str", "stop")
        self._plan = [esc] if self._escape_only else [esc, *self._table]
        self._after_move = ""
        self._begin_phase()

    def _recover(self) -> None:
        """Auto search (HSL figure 4-29): reverse at MaxVel, pass ORG, back off, restart."""
        self._recovered = True
        table = list(self._table)
        rev = [Phase("reverse to ORG", "org", "on", -1, "max", "pass"),
               Phase("pass ORG", "org", "off", -1, "max", "stop")]
        # then the table again, its first search slowly (figure 4-29 "search again")
        table[0] = replace(table[0], speed="str")
        self._plan = [*rev, *table]
        self._k = 0
        self._stage = "search"
        _, v, _ = self._state_now()
        if v != 0.0:
            self._decelerate()
            self._stage = "stop"
            self._log("limit: slow down")
            self._k = -1  # the stop leads to phase 0 of the new plan
            return
        self._begin_phase()

    def _next(self) -> None:
        ph = self._plan[self._k] if self._k >= 0 else None
        if ph is not None and ph.name.startswith(("escape", "pass ORG")) and \
                self.config.org_offset > 0.0 and self._after_move != ph.name:
            self._after_move = ph.name
            self._stage = "move"
            self._log("back off by org_offset")
            d = self._abs(ph.direction)
            # the offset counts from the release edge, not from where the stop ended
            target = round(self._edge_p + d * self.config.org_offset)
            if (target - self.axis.position) * d > 0.0:
                self._move_to(target)
            if self.axis.motion is not None:
                return
        self._after_move = ""
        self._k += 1
        if self._k < len(self._plan):
            self._begin_phase()
        else:
            self._final()

    def _final(self) -> None:
        st = self.status
        if self._escape_only:
            self.axis.end_homing()
            self._finish("done", None)
            return
        if st.mark is None:
            self._fail("homing: sequence ended without a home mark")
            return
        c = self.config
        self._stage = "final"
        self._t_rest = -1.0
        if c.final == "mark":
            self._log("move to home")
            self._move_to(float(self._home_target()))

    def _home_target(self) -> int:
        """Command position that puts the load on mark + home_offset.

        The switch or index sits on the load, so the home is where the *encoder* read at
        the marking edge: target = p_now + (enc_mark - enc_now)/ratio (+ offset), taken at
        rest. Servo drives only: it removes the following error the command had at the
        edge. Steppers use the command mark (the motor is the pulse count, and the encoder
        read at the very instant a pulse trips the switch is ambiguous by one count).
        """
        st = self.status
        cnt = self.axis.counters
        off = round(self.config.home_offset)
        if st.mark_encoder is None or not self.axis.config.drive.type.endswith("servo"):
            return round(st.mark) + off
        enc_now = cnt.encoder_raw()
        return round(self.axis.position + (st.mark_encoder - enc_now) / cnt.move_ratio) + off

    def _complete(self) -> None:
        """Clear command, feedback, error and general counters (not the target recorder)."""
        ax = self.axis
        cnt = ax.counters
        st = self.status
        c = self.config
        rel = 0
        enc_rel = 0
        if c.final == "stay":  # the home (mark + offset) reads 0; the axis rests elsewhere
            home = st.mark + c.home_offset
            rel = round(ax.position - home)
            enc_rel = round(rel * cnt.move_ratio)
            if st.mark_encoder is not None and ax.config.drive.type.endswith("servo"):
                raw_enc = cnt.encoder_raw()
                enc_rel = raw_enc - st.mark_encoder - round(c.home_offset * cnt.move_ratio)
        cnt.reset_all()
        if rel:
            cnt.set_command(rel)
        if enc_rel:
            cnt.set_feedback(enc_rel)
        cnt.reset_error()
        ax.end_homing()
        self._finish("done", None)
        self.ctl.events.record("home_done", ax.index, self.ctl.time, ax.position,
                               f"home mode {self.config.mode}")
        if self.safety is not None and self.safety.settings(ax.index).erc_width > 0.0:
            self.safety.pulse_erc(ax.index)  # ERC one-shot on home completion (HSL 4.7)

    def _finish(self, state: str, reason: str | None) -> None:
        self.status.state = state
        self.status.reason = reason
        self._stage = state
        if self.safety is not None:
            for sig in self._suspended:
                self.safety.resume(self.axis.index, sig)
            self._suspended = ()
        self.ctl.remove_edge_hook(self._on_edge)
        self.ctl.remove_cycle_hook(self._on_cycle)

    def _fail(self, reason: str) -> None:
        self._finish("error", reason)
        self.axis.fault_stop(reason)

    # ------------------------------------------------------------------ hooks
    def _trigger(self, ph: Phase, e: InputEdge) -> None:
        ax = self.axis
        off = ax.counters.command_offset
        st = self.ctl.history.state_at(ax.index, e.time)
        p = st.p
        if not ax.config.drive.type.endswith("servo"):
            # a stepper's edge is fired by a pulse: mark that pulse's count (pulserule)
            p = float(pulse_count(p, st.v, half_pulse(self.ctl.hardware)))
        self._edge_p = p + off
        if ph.mark:
            self.status.mark = self._edge_p
            self.status.mark_time = e.time
            self.status.mark_encoder = e.encoders[ax.index] if e.encoders else None
        then = ph.then
        if then == "el":
            then = "stop" if self.config.el_stop == "decel" else "halt"
        if then == "pass":
            self._next()
        elif then == "slow":
            v = self._abs(ph.direction) * self.config.speed("str")
            self._cruise(v)
            self._next()
        elif then == "halt":
            ax.stop_immediately()
            ax.begin_homing()
            self._stage = "stop"
            self._t_rest = -1.0
        else:
            self._decelerate()
            self._stage = "stop"
            self._t_rest = -1.0

    def _on_edge(self, ctl: Controller, e: InputEdge) -> None:
        if e.axis != self.axis.index or not self.running or self.axis.state is not S.HOMING:
            return
        active = self._logical(e)
        v = ctl.history.state_at(e.axis, e.time).v
        moving = 0 if v == 0.0 else (1 if v > 0 else -1)
        ph = self._plan[self._k] if 0 <= self._k < len(self._plan) else None
        searching = self._stage == "search" and ph is not None
        if e.signal in ("pel", "mel") and active and moving == (1 if e.signal == "pel" else -1):
            if searching and ph.signal == "el" and self._sig(ph) == e.signal:
                self._trigger(ph, e)
                return
            if self.config.auto_search and not self._recovered and searching and \
                    self._abs(ph.direction) == self.config.direction and \
                    uses(self._table, "org"):
                self._log(f"{e.signal.upper()} hit: reverse")
                self._recover()
                return
            self._fail(f"homing: {e.signal.upper()} limit hit in phase "
                       f"{self.status.phase!r}")
            return
        if not searching or self._sig(ph) != e.signal or moving != self._abs(ph.direction):
            return
        if self._wait_on:
            if active:
                self._wait_on = False
            return
        if active != (ph.edge == "on"):
            return
        self._hits += 1
        need = self.config.ez_count + EZ_COUNT_BASE if ph.ez_counted else 1
        if self._hits >= need:
            self._trigger(ph, e)

    def _due(self, ctl: Controller) -> float:
        """When `_on_cycle` may next act (Controller.add_cycle_hook): now while the axis
        left Homing or rests in a stage that moves on; the timeout; the end of a settle
        time; never while the axis moves (its motion's end and the edges land a jump)."""
        if not self.running:
            return math.inf
        ax = self.axis
        if ax.state is not S.HOMING:
            return -math.inf
        # (a margin below the exact instants: landing a cycle early only costs a step)
        due = self._t_begin + self.config.timeout_s - 1e-9
        if ax.is_moving:
            return due
        stage = self._stage
        if stage in ("stop", "final"):
            if self._t_rest < 0.0:
                return -math.inf
            return min(due, self._t_rest + self.config.settle_s - 1e-9)
        if stage in ("search", "move"):
            return -math.inf
        return due

    def _on_cycle(self, ctl: Controller, t: float) -> None:
        if not self.running:
            return
        ax = self.axis
        if ax.state is not S.HOMING:
            why = ax.fault if ax.state is S.ERROR_STOP else f"axis {ax.state.value}"
            self._finish("aborted", f"homing aborted: {why}")
            return
        if t - self._t_begin > self.config.timeout_s:
            self._fail(f"homing: timeout after {self.config.timeout_s:g} s in phase "
                       f"{self.status.phase!r}")
            return
        if ax.is_moving:
            return
        stage = self._stage
        if stage == "search":
            ph = self._plan[self._k]
            self._fail(f"homing: {ph.signal.upper()} not found within search_range "
                       f"in phase {ph.name!r}")
        elif stage == "stop":
            if self._t_rest < 0.0:
                self._t_rest = t
            if t - self._t_rest + 1e-12 < self.config.settle_s:
                return
            ph = self._plan[self._k] if self._k >= 0 else None
            if ph is not None and ph.must_stay_on and not self._active(self._sig(ph)):
                self._fail("homing: stopped past the home sensor (MCCL phase 0): lower "
                           "the homing speed")
                return
            self._next()
        elif stage == "move":
            self._next()
        elif stage == "final":
            if self._t_rest < 0.0:
                self._t_rest = t
            if t - self._t_rest + 1e-12 >= self.config.settle_s:
                self._complete()


# -- HSL-style entry points -------------------------------------------------------------
def home_move(ctl: Controller, axis: int | str, config: HomeConfig) -> Homing:
    """Start homing `axis` with `config` (HSL_M_home_move); returns the running Homing."""
    h = Homing(ctl, axis, config)
    h.start()
    return h


def home_search(ctl: Controller, axis: int | str, config: HomeConfig) -> Homing:
    """Auto home search (HSL_M_home_search, figure 4-29): as home_move, and an end limit met
    while searching reverses the axis past ORG, backs off by org_offset and searches again
    slowly."""
    return home_move(ctl, axis, replace(config, auto_search=True))


def escape_home(ctl: Controller, axis: int | str, config: HomeConfig) -> Homing:
    """Leave ORG (HSL_M_escape_home): if ORG is active, move against the home direction at
    StrVel until it releases, then by org_offset. Counters are not touched."""
    h = Homing(ctl, axis, replace(config, mode=0), escape_only=True)
    h.start()
    return h
