"""Status snapshots of the machine and the diffs the subscriptions push.

`snapshot` reads everything the operation page shows in one pass under the controller's
lock (so a snapshot is one consistent instant); `diff(old, new)` keeps only the leaves that
changed, nested like the snapshot (Moonraker's notify_status_update), so merging every diff
into the first snapshot gives the current one.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ..control.guard.safety import IO_STATUS_BITS, io_status

if TYPE_CHECKING:
    from .service import MachineService

LAMPS = ("alm", "pel", "mel", "org", "ez", "inp", "sd", "rdy", "erc", "emg", "ltc", "svon")
FIELDS = ("time", "cycles", "estop", "config_version", "speed", "axes", "board", "program",
          "scope", "cycle")


def axis_status(svc: MachineService, ax: Any) -> dict[str, Any]:
    ctl = svc.ctl
    c = ax.counters
    u = ax.units
    word = io_status(ctl, ax.index)
    io = {k: bool(word >> IO_STATUS_BITS[k] & 1) for k in LAMPS}
    io["cmp"] = svc.cmp_active(ax.index)
    h = svc.homings.get(ax.index)
    homing = {"state": "idle", "phase": "", "reason": None} if h is None else {
        "state": h.status.state, "phase": h.status.phase, "reason": h.status.reason}
    return {
        "command": int(c.command), "feedback": int(c.feedback), "error": int(c.error),
        "target": int(round(c.target)),
        "position": round(float(u.to_units(ax.position)), 6),
        "velocity": round(float(u.velocity_to_units(ax.velocity)), 6),
        "state": ax.state.value, "fault": ax.fault, "servo": bool(ax.powered),
        "moving": bool(ax.is_moving), "repeat": svc.repeats.active(ax.index),
        "jog": svc.jogs.jog_of(ax.index), "homing": homing, "io": io,
    }


def board_io(svc: MachineService) -> dict[str, list[bool]]:
    """General digital inputs (electrical levels) and outputs (levels written)."""
    ctl = svc.ctl
    hw = ctl.hardware
    read_out = getattr(hw, "read_output", None)
    di = [bool(hw.read_input(f"di{k}")) for k in range(ctl.config.digital_inputs)]
    do = [bool(read_out(None, f"do{k}")) if read_out is not None else False
          for k in range(ctl.config.digital_outputs)]
    return {"di": di, "do": do}


def snapshot(svc: MachineService, fields: tuple[str, ...] = FIELDS) -> dict[str, Any]:
    ctl = svc.ctl
    out: dict[str, Any] = {}
    with ctl.lock:
        if "time" in fields:
            out["time"] = round(ctl.time, 6)
        if "cycles" in fields:
            out["cycles"] = ctl.cycles
        if "estop" in fields:
            # the EMG input or the latched software E-stop (machine.estop until reset)
            out["estop"] = bool(ctl.estop_active) or svc.estop_reason is not None
        if "config_version" in fields:
            out["config_version"] = svc.config_version
        if "speed" in fields:
            out["speed"] = svc.speed
        if "axes" in fields:
            out["axes"] = {ax.name: axis_status(svc, ax) for ax in ctl.axes}
        if "board" in fields:
            out["board"] = board_io(svc)
        if "program" in fields:
            out["program"] = svc.program.status()
    if "scope" in fields:
        info = svc.scope.info()
        out["scope"] = {"running": info["running"], "scope_version": info["scope_version"],
                        "next": info["next"]}
    if "cycle" in fields:
        st = svc.cycle_stats()
        out["cycle"] = {"busy_us": 0.0, "overruns": 0} if st is None else {
            "busy_us": round(st.mean_busy * 1e6, 1), "overruns": st.overruns}
    return out


def diff(old: dict[str, Any], new: dict[str, Any]) -> dict[str, Any]:
    """The fields of `new` that differ from `old` (nested dicts compared per key)."""
    out: dict[str, Any] = {}
    for k, v in new.items():
        if k not in old:
            out[k] = v
            continue
        o = old[k]
        if isinstance(v, dict) and isinstance(o, dict):
            d = diff(o, v)
            if d:
                out[k] = d
        elif v != o or type(v) is not type(o):
            out[k] = v
    return out


#: what changes every cycle at rest: the clock, the cycle statistics, the scope's count
CLOCK_FIELDS = frozenset(("time", "cycles", "cycle"))


def only_clock(d: dict[str, Any]) -> bool:
    """True when diff `d` holds nothing but the clock (CLOCK_FIELDS and the scope's sample
    count `scope.next`): the machine is at rest as far as a page can show."""
    for k, v in d.items():
        if k == "scope":
            if set(v) - {"next"}:
                return False
        elif k not in CLOCK_FIELDS:
            return False
    return True


def merge(base: dict[str, Any], d: dict[str, Any]) -> dict[str, Any]:
    """Apply a diff to a snapshot in place (the client's side of `diff`)."""
    for k, v in d.items():
        if isinstance(v, dict) and isinstance(base.get(k), dict):
            merge(base[k], v)
        else:
            base[k] = v
    return base
