"""PCL6045 (HSL-4XMO) point-to-point moves: T-curve and S-curve with StrVel, Tacc/Tdec, VS.

Semantics (HSL-4XMO manual §4.6 "Trapezoidal Motion", "S-curve Profile Motion", fig. 4-10):

* The pulse rate jumps from 0 to StrVel at the start, ramps to MaxVel in Tacc, cruises,
  ramps back to StrVel in Tdec and jumps to 0 at the end (a stepper starting and stopping
  inside its start-stop rate).
* T-curve: accel = (MaxVel - StrVel)/Tacc, decel = (MaxVel - StrVel)/Tdec (constant).
* S-curve: each ramp = constant-jerk region covering VS of velocity, a linear
  (constant-acceleration) region, and a constant-jerk region covering VS. VS = 0 means no
  linear region (pure S), the same as VS = (MaxVel - StrVel)/2. Valid VS: [0, dv/2].
  (seed-facts 1.2: the manual's "from (MaxVel - StrVel) to MaxVel" must read
  "from (MaxVel - VS) to MaxVel".)
* Automatic velocity decrease: when the distance is too short to reach MaxVel, MaxVel (and
  with it Tacc, Tdec, VSacc, VSdec) is lowered while StrVel, acceleration and jerk stay.

`MoveSpec` carries the parameters; `MoveSpec.plan` returns a `MovePlan` with the profile and
the effective (possibly lowered) parameters. `trapezoid` and `scurve` are the plain entry
points that return only the profile.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from ..errors import (
    MotionError,
    check_distance,
)
from ..limits import check_pulses, check_quantity
from .segments import Profile, ProfileBuilder, empty_profile

# S-curve ramp algebra (one ramp covering dv = MaxVel - StrVel in time Tacc):
#   jerk region: a goes 0 -> A in tj = A/J and covers VS = J*tj**2/2 = A**2/(2J) of velocity,
#   so tj = 2*VS/A; linear region covers dv - 2*VS at A, lasting (dv - 2*VS)/A.
#   Tacc = 2*tj + (dv - 2*VS)/A = (dv + 2*VS)/A   =>   A = (dv + 2*VS)/Tacc,
#   J = A/tj = A**2/(2*VS).  VS = 0 (pure S) is VS = dv/2:  A = 2*dv/Tacc, J = 4*dv/Tacc**2.
# A ramp of x = V - StrVel under (A, J) with x < A**2/J = 2*VS has no linear region:
#   peak accel sqrt(J*x), duration 2*sqrt(x/J).  Otherwise duration x/A + A/J.
# Every ramp's acceleration is symmetric about its midpoint, so its mean velocity is
# (StrVel + V)/2 and its distance (StrVel + V)/2 * duration (T-curve included).


@dataclass(frozen=True)
class Rates:
    """Acceleration/deceleration (pulses/s^2) and jerks (pulses/s^3; inf for a T-curve)."""

    accel: float
    decel: float
    jerk_acc: float
    jerk_dec: float


@dataclass(frozen=True)
class MoveSpec:
    """PCL6045 move parameters: shape 'T' or 'S', StrVel, MaxVel (pps), Tacc, Tdec (s),
    VSacc, VSdec (pps, S-curve only; 0 = pure S); `dec_shape` 'T' or 'S' gives the
    deceleration its own shape (MCCL MCC_SetPtPDecType; "" = `shape`). Validated on
    construction."""

    shape: str
    str_vel: float
    max_vel: float
    tacc: float
    tdec: float
    vs_acc: float = 0.0
    vs_dec: float = 0.0
    dec_shape: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.shape, str) or self.shape not in ("T", "S"):
            raise MotionError(f"shape must be 'T' or 'S', got {self.shape!r}")
        if not isinstance(self.dec_shape, str) or self.dec_shape not in ("", "T", "S"):
            raise MotionError(f"dec_shape must be 'T', 'S' or '' (as shape), got "
                              f"{self.dec_shape!r}")
        sv = check_quantity("str_vel", self.str_vel, "pps", zero=True)
        mv = check_quantity("max_vel", self.max_vel, "pps")
        if mv < sv:
            raise MotionError(f"max_vel must be >= str_vel ({sv!r}), got {self.max_vel!r}")
        ta = check_quantity("tacc", self.tacc, "seconds")
        td = check_quantity("tdec", self.tdec, "seconds")
        half = (mv - sv) / 2.0
        vals = {"str_vel": sv, "max_vel": mv, "tacc": ta, "tdec": td}
        for name in ("vs_acc", "vs_dec"):
            vs = check_quantity(name, getattr(self, name), "pps", zero=True)
            if vs > half:
                raise MotionError(
                    f"{name} must be in [0, (max_vel - str_vel)/2 = {half:g}], "
                    f"got {getattr(self, name)!r}"
                )
            vals[name] = vs
        for name, x in vals.items():
            object.__setattr__(self, name, x)

    def derived(self, **changes: float) -> MoveSpec:
        """This spec with `changes`, computed by the controller rather than given by a user.

        A derived spec (a lowered MaxVel and its shorter ramps, an on-the-fly remainder, a
        homing phase) is held to the profile's own rules (finite, times > 0, StrVel <= MaxVel,
        VS within half the span) but not to the user ranges of docs/ranges.md: the
        automatic velocity decrease of a 0.002-pulse move derives a Tdec under 1 ns, and
        refusing it would refuse a valid user move.
        """
        vals = {f.name: changes.get(f.name, getattr(self, f.name)) for f in fields(self)}
        sv, mv, ta, td = (float(vals[k]) for k in ("str_vel", "max_vel", "tacc", "tdec"))
        va, vd = float(vals["vs_acc"]), float(vals["vs_dec"])
        numbers = (sv, mv, ta, td, va, vd)
        if not all(math.isfinite(x) for x in numbers) or ta <= 0.0 or td <= 0.0 \
                or sv < 0.0 or mv < sv or min(va, vd) < 0.0 \
                or max(va, vd) > (mv - sv) / 2.0 * (1.0 + 1e-12) + 1e-300:
            raise MotionError(f"derived move parameters are invalid: {vals!r}")
        new = object.__new__(MoveSpec)
        for k, x in zip(("str_vel", "max_vel", "tacc", "tdec", "vs_acc", "vs_dec"), numbers,
                        strict=True):
            object.__setattr__(new, k, x)
        object.__setattr__(new, "shape", self.shape)
        object.__setattr__(new, "dec_shape", self.dec_shape)
        return new

    @property
    def decel_shape(self) -> str:
        """The deceleration's shape ('T' or 'S')."""
        return self.dec_shape or self.shape

    @property
    def rates(self) -> Rates:
        """Acceleration, deceleration and jerks implied by the parameters."""
        dv = self.max_vel - self.str_vel
        a, ja = (dv / self.tacc, math.inf) if self.shape == "T" else \
            _s_rates(dv, self.tacc, self.vs_acc)
        d, jd = (dv / self.tdec, math.inf) if self.decel_shape == "T" else \
            _s_rates(dv, self.tdec, self.vs_dec)
        return Rates(a, d, ja, jd)

    def plan(self, distance: float, start: float = 0.0) -> MovePlan:
        """Plan a relative move of `distance` pulses from position `start` (at rest)."""
        dist = check_distance("distance", distance)
        p0 = check_pulses("start", start)
        return _plan(self, dist, p0)


@dataclass(frozen=True)
class MovePlan:
    """A planned move: the profile and the parameters the hardware would really run.

    `effective` is the spec after the automatic velocity decrease (equal to `spec` when
    MaxVel is reached); `rates` are unchanged by the decrease; `t_decel` is when the final
    deceleration begins (the HSL p_change cut-off); `reduced` tells whether MaxVel was lowered.
    """

    profile: Profile
    spec: MoveSpec
    effective: MoveSpec
    rates: Rates
    t_decel: float
    reduced: bool


def _s_rates(dv: float, t: float, vs: float) -> tuple[float, float]:
    """(A, J) of one S ramp covering dv in time t with jerk regions of vs (0 = pure S)."""
    if dv <= 0.0:
        return 0.0, math.inf
    vs = dv / 2.0 if vs == 0.0 else vs
    a = (dv + 2.0 * vs) / t
    return a, a * a / (2.0 * vs)


def ramp_time(x: float, accel: float, jerk: float) -> float:
    """Duration of a ramp covering x >= 0 of velocity from a = 0 to a = 0 (PCL shape)."""
    if x <= 0.0:
        return 0.0
    if math.isinf(jerk):
        return x / accel
    if x >= accel * accel / jerk:
        return x / accel + accel / jerk
    return 2.0 * math.sqrt(x / jerk)


def _ramp_time_dx(x: float, accel: float, jerk: float) -> float:
    """d ramp_time / dx (for Newton)."""
    if math.isinf(jerk) or x >= accel * accel / jerk:
        return 1.0 / accel
    return 1.0 / math.sqrt(max(x, 1e-300) * jerk)


def ramp_distance(v_low: float, v_high: float, accel: float, jerk: float) -> float:
    """Distance of a PCL ramp between v_low and v_high (either direction)."""
    return (v_low + v_high) / 2.0 * ramp_time(abs(v_high - v_low), accel, jerk)


def _peak_excess(dist: float, s: float, dv: float, r: Rates) -> float:
    """x = V - StrVel such that ramp up + ramp down covers `dist` exactly (0 < x < dv).

    T-curve: (V**2 - s**2)/2 * (1/a + 1/d) = dist, closed form.  S-curve: the distance
    D(x) = (2s + x)/2 * (Ta(x) + Td(x)) is continuous and strictly increasing, so a Newton
    iteration kept inside a shrinking bracket [lo, hi] converges to double precision.
    """
    if math.isinf(r.jerk_acc) and math.isinf(r.jerk_dec):
        k = 1.0 / r.accel + 1.0 / r.decel
        v = math.sqrt(s * s + 2.0 * dist / k)
        return min(max(v - s, 0.0), dv)

    def f(x: float) -> tuple[float, float]:
        tt = ramp_time(x, r.accel, r.jerk_acc) + ramp_time(x, r.decel, r.jerk_dec)
        dt = _ramp_time_dx(x, r.accel, r.jerk_acc) + _ramp_time_dx(x, r.decel, r.jerk_dec)
        return (2.0 * s + x) / 2.0 * tt - dist, tt / 2.0 + (2.0 * s + x) / 2.0 * dt

    lo, hi = 0.0, dv
    x = dv
    for _ in range(200):
        fx, dfx = f(x)
        if fx == 0.0:
            return x
        if fx > 0.0:
            hi = x
        else:
            lo = x
        nx = x - fx / dfx if dfx > 0.0 else 0.5 * (lo + hi)
        if not lo < nx < hi:
            nx = 0.5 * (lo + hi)
        if nx == x or hi - lo <= 4.0 * math.ulp(hi):
            return nx
        x = nx
    return 0.5 * (lo + hi)


def append_ramp(b: ProfileBuilder, v1: float, accel: float, jerk: float,
                label: str) -> ProfileBuilder:
    """Append a PCL ramp from b's velocity (acceleration 0) to v1 (move frame).

    T: one constant-acceleration segment. S: jerk region, linear region (if the velocity
    change exceeds 2*VS = accel**2/jerk), jerk region; the peak acceleration is lowered to
    sqrt(jerk*dv) otherwise. Ends with acceleration 0.
    """
    v0 = b.state.v
    x = abs(v1 - v0)
    sg = 1.0 if v1 >= v0 else -1.0
    if x == 0.0:
        pass
    elif math.isinf(jerk):
        b.segment(x / accel, 0.0, accel=sg * accel, label=label)
    else:
        if x >= accel * accel / jerk:
            tj, tl = accel / jerk, x / accel - accel / jerk
        else:
            tj, tl = math.sqrt(x / jerk), 0.0
        b.segment(tj, sg * jerk, accel=0.0, label=f"{label} jerk-in")
        b.segment(tl, 0.0, label=f"{label} const-acc")
        b.segment(tj, -sg * jerk, label=f"{label} jerk-out")
    b.set_acceleration(0.0)
    return b


def _ramps_distance(s: float, v: float, r: Rates) -> float:
    return ramp_distance(s, v, r.accel, r.jerk_acc) + ramp_distance(s, v, r.decel, r.jerk_dec)


def _plan(spec: MoveSpec, dist: float, p0: float) -> MovePlan:
    if dist == 0.0:
        return MovePlan(empty_profile(p0), spec, spec, spec.rates, 0.0, False)
    r = spec.rates
    s, dv, d = spec.str_vel, spec.max_vel - spec.str_vel, abs(dist)
    full = ramp_distance(s, spec.max_vel, r.accel, r.jerk_acc) + ramp_distance(
        s, spec.max_vel, r.decel, r.jerk_dec
    )
    b = ProfileBuilder(p0, s, direction=1.0 if dist > 0 else -1.0, v_before=0.0)
    if dv == 0.0 or full <= d:
        x, t_cruise, eff, reduced = dv, (d - full) / spec.max_vel, spec, False
    else:
        v = s + _peak_excess(d, s, dv, r)
        # V - StrVel in floats differs from the root by up to ulp(StrVel); step V down
        # until the ramps do not overshoot, and let a (near-zero) cruise take the rest
        for _ in range(64):
            used = _ramps_distance(s, v, r)
            if used <= d or v <= s:
                break
            v = math.nextafter(v, -math.inf)
        eff = _reduced_spec(spec, r, max(v, s))
        x, reduced = eff.max_vel - s, True
        used = _ramps_distance(s, s + x, r)
        t_cruise = max(0.0, d - used) / (s + x) if s + x > 0.0 else 0.0
    v = s + x
    append_ramp(b, v, r.accel, r.jerk_acc, "accel")
    # snap off the integration rounding so the decel ramp covers exactly V - StrVel
    # (matters when V - StrVel is tiny next to StrVel)
    b.set_velocity(v)
    b.segment(t_cruise, 0.0, accel=0.0, label="cruise")
    t_decel = b.time
    append_ramp(b, s, r.decel, r.jerk_dec, "decel")
    prof = b.build(end_p=p0 + dist, end_v=0.0)
    return MovePlan(prof, spec, eff, r, t_decel, reduced)


def _reduced_spec(spec: MoveSpec, r: Rates, v: float) -> MoveSpec:
    """Spec with MaxVel lowered to v and Tacc, Tdec, VS lowered to keep accel and jerk."""
    s = spec.str_vel
    x = v - s
    if x <= 0.0:  # only by rounding, when StrVel dwarfs the distance
        return spec.derived(max_vel=s, vs_acc=0.0, vs_dec=0.0)
    tacc = ramp_time(x, r.accel, r.jerk_acc)
    tdec = ramp_time(x, r.decel, r.jerk_dec)
    half = x / 2.0

    def vs(given: float, rate: float, jerk: float) -> float:
        if math.isinf(jerk):  # VS is ignored by a T ramp; keep it valid
            return min(given, half)
        return given if rate * rate / (2.0 * jerk) <= half else half

    return spec.derived(max_vel=v, tacc=tacc, tdec=tdec,
                        vs_acc=vs(spec.vs_acc, r.accel, r.jerk_acc),
                        vs_dec=vs(spec.vs_dec, r.decel, r.jerk_dec))


def _spec(shape: str, str_vel: float, max_vel: float, tacc: float, tdec: float,
          vs_acc: float = 0.0, vs_dec: float = 0.0) -> MoveSpec:
    return MoveSpec(shape, str_vel, max_vel, tacc, tdec, vs_acc, vs_dec)


def trapezoid(distance: float, str_vel: float, max_vel: float, tacc: float, tdec: float,
              *, start: float = 0.0) -> Profile:
    """PCL6045 T-curve move of `distance` pulses (HSL_M_start_tr_move)."""
    return _spec("T", str_vel, max_vel, tacc, tdec).plan(distance, start).profile


def scurve(distance: float, str_vel: float, max_vel: float, tacc: float, tdec: float,
           vs_acc: float, vs_dec: float, *, start: float = 0.0) -> Profile:
    """PCL6045 S-curve move of `distance` pulses (HSL_M_start_sr_move)."""
    return _spec("S", str_vel, max_vel, tacc, tdec, vs_acc, vs_dec).plan(distance, start).profile
