"""Scenario helper for HSL programs on the simulator: switches, alarms, E-stop, sensors.

Everything is addressed as the library addresses it (global axis numbers, module numbers)
and happens in the network's virtual time: `at=None` means now, `at=t` at network time t.

    sim = HslSim(hsl)
    sim.place_switch(0, "pel", 20_000)        # +EL of axis 0 from pulse 20000 on
    sim.trip_alarm(5, at=0.3)                 # ALM of axis 5 (module 1, CM2)
    sim.press_estop(1)                        # EMG of module 1
    sim.sensor_at(0, channel=1, axis=0, position=50_000)   # DI1 goes high at pulse 50000
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ...errors import MotionError, check_finite, check_int

if TYPE_CHECKING:
    from ...control.core.controller import Controller
    from .library import HslLibrary

AXES_PER_MODULE = 4


class HslSim:
    """Timed events on the simulated modules of an `HslLibrary`."""

    def __init__(self, hsl: HslLibrary) -> None:
        self.hsl = hsl
        self._sensors: dict[int, list[tuple[int, int, float, bool]]] = {}

    def _module(self, m_no: int) -> Controller:
        ctl = self.hsl.network.modules.get(m_no)
        if ctl is None or isinstance(m_no, bool):
            raise MotionError(f"M_No must be one of {sorted(self.hsl.network.modules)}, "
                              f"got {m_no!r}")
        return ctl

    def _axis(self, axis: int) -> tuple[Controller, int]:
        check_int("axis", axis, 0, 62)
        k, cm = divmod(axis, AXES_PER_MODULE)
        ctl = self._module(k)
        if cm >= len(ctl.axes):
            raise MotionError(f"axis {axis} is not on the network")
        return ctl, cm

    def _at(self, ctl: Controller, at: float | None) -> float | None:
        """Network time -> the module's time base (the same clock)."""
        return None if at is None else check_finite("at", at)

    # ------------------------------------------------------------------ axis inputs
    def place_switch(self, axis: int, signal: str, position: float, width: float = 1e9,
                     at: float | None = None) -> None:
        """Put switch `signal` ("pel", "mel", "org", "sd") of `axis` over
        [position, position + width) pulses (negative width: downwards)."""
        ctl, cm = self._axis(axis)
        ctl.hardware.scenario.place_switch(cm, signal, position, width, at=self._at(ctl, at))

    def remove_switch(self, axis: int, signal: str, at: float | None = None) -> None:
        ctl, cm = self._axis(axis)
        ctl.hardware.scenario.remove_switch(cm, signal, at=self._at(ctl, at))

    def trip_alarm(self, axis: int, at: float | None = None) -> None:
        """The drive of `axis` raises ALM."""
        ctl, cm = self._axis(axis)
        ctl.hardware.scenario.trip_alarm(cm, at=self._at(ctl, at))

    def clear_alarm(self, axis: int, at: float | None = None) -> None:
        ctl, cm = self._axis(axis)
        ctl.hardware.scenario.clear_alarm(cm, at=self._at(ctl, at))

    def reset_axis(self, axis: int) -> None:
        """Leave the error stop once its cause is gone (the card's own reset after an
        alarm, limit or E-stop: the next command may move the axis again)."""
        ctl, cm = self._axis(axis)
        ctl.axes[cm].reset()

    # ------------------------------------------------------------------ module inputs
    def press_estop(self, m_no: int, at: float | None = None) -> None:
        """EMG of module `m_no` active: all its axes stop at once (3.12)."""
        ctl = self._module(m_no)
        ctl.hardware.scenario.press_estop(at=self._at(ctl, at))

    def release_estop(self, m_no: int, at: float | None = None) -> None:
        ctl = self._module(m_no)
        ctl.hardware.scenario.release_estop(at=self._at(ctl, at))

    def set_input(self, m_no: int, channel: int, level: bool, at: float | None = None) -> None:
        """General input DI`channel` of module `m_no` (0..3) to `level`."""
        ctl = self._module(m_no)
        check_int("channel", channel, 0, 3)
        ctl.hardware.scenario.set_input(f"di{channel}", bool(level), at=self._at(ctl, at))

    def sensor_at(self, m_no: int, channel: int, axis: int, position: float,
                  level: bool = True) -> None:
        """DI`channel` of module `m_no` goes to `level` the cycle the command position of
        `axis` passes `position` (a cam or light barrier on the machine)."""
        ctl = self._module(m_no)
        check_int("channel", channel, 0, 3)
        actl, cm = self._axis(axis)
        p = check_finite("position", position)
        ax = actl.axes[cm]
        start = ax.position
        up = p >= start
        fired = [False]

        def hook(_c: Controller, _t: float) -> None:
            if not fired[0] and ((ax.position >= p) if up else (ax.position <= p)):
                fired[0] = True
                ctl.hardware.scenario.set_input(f"di{channel}", bool(level))

        actl.add_cycle_hook(hook)

    def read_input(self, m_no: int, channel: int) -> bool:
        """Level of general input DI`channel` of module `m_no`."""
        ctl = self._module(m_no)
        check_int("channel", channel, 0, 3)
        return bool(ctl.hardware.read_input(f"di{channel}"))
