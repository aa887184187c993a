"""One axis of the simulated machine: its drive, transmission, switches and encoder, and its
run over a span of time.

`SimAxis.run(ta, tb, raw)` lets the plant produce its monotone motor pieces for the pulse
generator's command, moves transmission (backlash, pitch error), switches and decoder along
them, and appends every switch/index edge at the exact time the load crosses its threshold,
with the decoded count at that instant. An armed edge stop (EdgeStopHardware) is found by a
dry scan first; the axis then runs up to it, holds the count emitted, and runs on.
`SimMachine` (machine.py) owns the axes, the board I/O and the scenario.
"""

from __future__ import annotations

import copy
from typing import TYPE_CHECKING

from openmotion.config import DRIVE_TYPES, AxisConfig
from openmotion.errors import MotionError, check_nonnegative
from openmotion.hw.interface import AXIS_INPUTS, AXIS_OUTPUTS

from .cubic import Cubic
from .encoder import Decoder, EncoderWiring, default_wiring
from .mechanics import PitchTable, Transmission
from .pieces import Piece
from .plant import StepperPlant
from .pulses import PulseGenerator
from .switches import IndexSwitch, Switch

if TYPE_CHECKING:
    from .dcservo import DCServoPlant
    from .servo import ServoPlant

#: Safety bound on toggles of one switch within one piece (an EZ window per revolution).
_MAX_TOGGLES = 100_000
_INPUT_INDEX = {sig: i for i, sig in enumerate(AXIS_INPUTS)}


class SimAxis:
    """Everything the sim keeps for one axis, and its run over a span of time."""

    def __init__(self, index: int, cfg: AxisConfig, wiring: EncoderWiring | None) -> None:
        drv = cfg.drive
        if drv.type not in DRIVE_TYPES:
            raise MotionError(f"axes[{index}].drive.type must be one of {DRIVE_TYPES}, "
                              f"got {drv.type!r}")
        self.index = index
        self.cfg = cfg
        self.gen = PulseGenerator()
        if drv.type == "servo":
            from .servo import ServoPlant
            self.plant: StepperPlant | ServoPlant | DCServoPlant = ServoPlant(drv)
        elif drv.type == "dc_servo":
            from .dcservo import DCServoPlant
            self.plant = DCServoPlant(cfg)
        else:
            self.plant = StepperPlant(drv.type == "ideal_stepper", drv.pullout_speed,
                                      drv.pullout_accel)
        self.is_servo = drv.type == "servo"
        self.is_dc = drv.type == "dc_servo"  # motor driven by command_effort, not pulses
        check_nonnegative(f"axes[{index}].drive.backlash", drv.backlash)
        screw = cfg.pulses_per_rev * cfg.gear_ratio
        self.trans = Transmission(drv.backlash, PitchTable(drv.pitch_error, screw))
        self.y = self.trans.y_of(0.0)
        self.decoder = Decoder(wiring or default_wiring(cfg), cfg, self.y)
        self.nc = {s: cfg.logic.get(s, "no") == "nc" for s in (*AXIS_INPUTS, "emg")}
        self.switches: dict[str, Switch | IndexSwitch] = {}
        for name in ("pel", "mel", "org", "sd"):
            sc = getattr(cfg, name)
            if sc is not None:
                self.switches[name] = Switch(sc.position, sc.width, sc.hysteresis, self.y)
        wiring_ = wiring or default_wiring(cfg)
        self.z_flip = wiring_.invert_z != cfg.invert_z
        lines = cfg.encoder_lines_per_rev
        ez_width = cfg.pulses_per_rev / (4.0 * lines) if lines > 0 else 1.0
        self.switches["ez"] = IndexSwitch(float(cfg.pulses_per_rev), ez_width, self.y)
        self.outputs = {s: False for s in AXIS_OUTPUTS}
        self.alarm = False
        self.not_ready = False  # the drive drops RDY without an alarm (scenario)
        # armed edge stops: signal -> (electrical level, direction 0/+1/-1); see arm_stop
        self.armed: dict[str, tuple[bool, int]] = {}
        self.stop_time: float | None = None
        # pieces of the current run, with the state at each piece's start (for peeks)
        self.record: list[tuple[Piece, float, tuple[int, int, int]]] = []
        self.run_start: tuple[float, tuple[int, int, int]] = (self.trans.z, self._dec_state())

    # -- levels ----------------------------------------------------------------------------
    def active(self, sig: str) -> bool:
        sw = self.switches.get(sig)
        if sig == "ltc" and sw is None:
            sw = self.switches.get("sd")
        if sw is not None:
            return sw.active
        if sig == "alm":
            return self.alarm
        if sig == "rdy" and self.not_ready:
            return False
        if sig == "rdy" and self.is_dc:
            return self.outputs["svon"] and not self.alarm
        if sig == "rdy":
            return self.plant.ready(self.outputs["svon"], self.alarm) if self.is_servo \
                else not self.alarm
        if sig == "inp":
            return self.plant.in_position if self.is_servo else True
        return False

    def level(self, sig: str) -> bool:
        i = _INPUT_INDEX.get(sig)
        if i is None:  # a hidden switch (a probe's interval bound, hw/sim/probe.py)
            return self.active(sig) != self.nc[sig]
        return self.levels()[i]

    def levels(self) -> tuple[bool, ...]:
        """Electrical level of every input, in AXIS_INPUTS order: active XOR the contact
        is NC (LTC shares the SD pin and its contact type while no LTC switch is placed;
        EZ also XOR the wiring's Z inversion)."""
        sws, nc = self.switches, self.nc
        pel, mel, org, sd = (sws.get("pel"), sws.get("mel"), sws.get("org"), sws.get("sd"))
        ltc = sws.get("ltc")
        shared = ltc is None
        if shared:
            ltc = sd
        ez = sws.get("ez")
        return ((pel is not None and pel.active) != nc["pel"],
                (mel is not None and mel.active) != nc["mel"],
                (org is not None and org.active) != nc["org"],
                (sd is not None and sd.active) != nc["sd"],
                (ltc is not None and ltc.active) != nc["sd" if shared else "ltc"],
                ((ez is not None and ez.active) != nc["ez"]) != self.z_flip,
                self.active("alm") != nc["alm"],
                self.active("inp") != nc["inp"],
                self.active("rdy") != nc["rdy"])

    def _dec_state(self) -> tuple[int, int, int]:
        d = self.decoder
        return (d.q, d.last_dir, d.count)

    def encoder_at(self, t: float) -> int:
        """Decoded count at time t within the current run (t >= run start)."""
        rec = self.record
        k = len(rec) - 1
        while k >= 0 and rec[k][0].t0 > t:
            k -= 1
        if k < 0:
            return self.run_start[1][2] if not rec else rec[0][2][2]
        piece, z0, st = rec[k]
        return self._peek(piece, z0, st, piece.m_at(t))

    def _peek(self, piece: Piece, z0: float, st: tuple[int, int, int], m: float) -> int:
        d = piece.direction
        y = self.trans.y_of(self.trans.z_after(z0, m, d))
        dec = self.decoder
        q1 = dec.index_after(y, st[0], d)
        return st[2] + dec.increment(st[0], q1, st[1])

    # -- running over [ta, tb] ------------------------------------------------------------------
    def run(self, ta: float, tb: float, raw: list) -> None:
        """Move this axis over [ta, tb], appending its raw edges (time, axis, signal, level,
        own decoded count)."""
        armed = [s for s in self.armed if s in self.switches and s != "ez"]
        if armed and not self.is_dc and self.gen.te > ta:
            self._run_armed(ta, tb, raw, armed)
        else:
            self._run_pieces(ta, tb, raw, self.plant.pieces(self.gen, ta, tb))

    def _run_pieces(self, ta: float, tb: float, raw: list, pieces: list[Piece]) -> None:
        if pieces:
            self.scan(pieces, raw)
        if self.is_servo:
            self.plant.status_edges(self, ta, tb, raw)

    def _run_armed(self, ta: float, tb: float, raw: list, armed: list[str]) -> None:
        """`run` with an armed switch: find the first armed edge on the pieces without
        touching the switches; if there is one, run again up to its time (plant and count
        restored), hold the command there, and run on to tb."""
        rec = self.gen.record
        saved = (self.gen.count, copy.copy(self.plant), rec.mark() if rec is not None else 0)
        pieces = self.plant.pieces(self.gen, ta, tb)
        hit = self._first_armed(pieces, armed)
        if hit is None:
            self._run_pieces(ta, tb, raw, pieces)
            return
        ts, sig = hit
        self.gen.count, self.plant, mark = saved
        if rec is not None:
            rec.rewind(mark)
        n0 = len(raw)
        self._run_pieces(ta, ts, raw, self.plant.pieces(self.gen, ta, ts))
        if not any(e[1] == self.index and e[2] == sig for e in raw[n0:]):
            # rounding left the motor a hair short of the switch: the edge is at ts
            sw = self.switches[sig]
            sw.active = not sw.active
            raw.append((ts, self.index, sig, self.level(sig), self.decoder.count))
        self.cut_pulses(ts)
        self._run_pieces(ts, tb, raw, self.plant.pieces(self.gen, ts, tb))

    def _first_armed(self, pieces: list[Piece], armed: list[str]) -> tuple[float, str] | None:
        """(time, signal) of the first armed switch edge on `pieces` (a dry scan)."""
        trans = self.trans
        dry = {s: copy.copy(self.switches[s]) for s in armed}
        z, y = trans.z, self.y
        for p in pieces:
            d = p.direction
            if d == 0:
                continue
            z1 = trans.z_after(z, p.m1, d)
            y1 = trans.y_of(z1)
            best: tuple[float, str] | None = None
            for s, sw in dry.items():
                level, want = self.armed[s]
                yy = y
                for _ in range(_MAX_TOGGLES):
                    thr = sw.next_threshold(yy, d)
                    if thr is None or (y1 < thr if d > 0 else y1 >= thr):
                        break
                    sw.active = not sw.active
                    if (sw.active != self.nc[s]) == level and want in (0, d):
                        t = p.time_at(trans.motor_level(thr, d))[0]
                        if best is None or t < best[0]:
                            best = (t, s)
                        break
                    yy = thr
            if best is not None:
                return best
            z, y = z1, y1
        return None

    def cut_pulses(self, t: float) -> None:
        """The pulse output stops at time t: the command holds the count emitted.

        A card's command is its count; holding the float command instead would leave it up
        to half a pulse off the count (a switch tripped by pulse k fires with the command at
        k -/+ 1/2), and the next move would start between pulses.
        """
        self.set_command(Cubic(float(self.gen.count)), t, t, t)
        self.stop_time = t

    def set_command(self, cubic: Cubic, tc: float, te: float, now: float) -> None:
        """Give the pulse generator `cubic` over [tc, te] (recorded at time `now`)."""
        self.gen.set(cubic, tc, te)
        if self.gen.record is not None:
            self.gen.record.command(now, cubic, tc, te)

    def armed_hit(self, sig: str, level: bool, t: float) -> None:
        """An input changed at time t (now): cut the pulses if armed for it."""
        arm = self.armed.get(sig)
        if arm is None or arm[0] != level:
            return
        v = self.gen.vel(t)
        d = 1 if v > 0.0 else (-1 if v < 0.0 else 0)
        if arm[1] in (0, d):
            self.cut_pulses(t)

    def scan(self, pieces: list[Piece], raw: list) -> None:
        """Move along the motor `pieces`: transmission, switches and decoder, appending
        every switch/index edge at its exact time."""
        trans = self.trans
        dec = self.decoder
        for p in pieces:
            d = p.direction
            z0 = trans.z
            st = (dec.q, dec.last_dir, dec.count)
            self.record.append((p, z0, st))
            if d == 0:
                continue
            z1 = trans.z_after(z0, p.m1, d)
            y1 = trans.y_of(z1)
            y = self.y
            if y1 != y:
                for name, sw in self.switches.items():
                    thr = sw.next_threshold(y, d)  # most pieces cross no switch
                    if thr is None or (y1 < thr if d > 0 else y1 >= thr):
                        continue
                    self._scan_switch(name, sw, p, z0, st, y1, raw)
            trans.z = z1
            self.y = y1
            dec.advance(y1, d)

    def _scan_switch(self, name: str, sw: Switch | IndexSwitch, p: Piece,
                     z0: float, st: tuple[int, int, int], y1: float, raw: list) -> None:
        d = p.direction
        y = self.y
        for _ in range(_MAX_TOGGLES):
            thr = sw.next_threshold(y, d)
            if thr is None or (y1 < thr if d > 0 else y1 >= thr):
                return
            t, m = p.time_at(self.trans.motor_level(thr, d))
            sw.active = not sw.active
            own = self._peek(p, z0, st, m)
            raw.append((t, self.index, name, self.level(name), own))
            if name == "sd" and "ltc" not in self.switches:
                raw.append((t, self.index, "ltc", self.level("ltc"), own))
            y = thr
