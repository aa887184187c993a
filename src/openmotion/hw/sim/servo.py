"""Servo drive: the motor follows the pulse command through a second-order lag.

    x'' + 2*z*w*x' + w**2 * x = w**2 * r(t),   w = 2*pi*bandwidth_hz, z = damping,

with r = command position + bias (the drive's deviation counter is cleared at servo-on and
by ERC, which sets bias so that the error is zero at that instant: no jump). The command
is a cubic or a hold over each stretch, so the motion is solved exactly, not integrated:

    x = x_p + e,   x_p = r - A r' + (A**2 - B) r'' + (2AB - A**3) r''',   A = 2z/w, B = 1/w**2

(the series (1 + A D + B D**2)**-1 r, exact for a cubic), and e solves the homogeneous
equation from the state at the stretch start (under-, critically or over-damped closed
form). x' is sampled on a grid (2 steps per stretch, and 2 per 1/w) to cut it into
monotone pieces; crossing times are then found to ~1e-13 s by safeguarded Newton on the
exact x(t). INP (|r - x| <= inp_band and |x'| <= inp_band * w) is sampled on the same grid
and its edges bisected to 1e-12 s. Accuracy limit: two zeros of x' (a reversal and back)
or an INP flicker within one grid step (<= 0.5 ms per 1 ms cycle) are not seen.

Servo off (SVON false) or alarm: the motor stays put (x' = 0) and INP is false. RDY is
true while SVON is on and there is no alarm.
"""

from __future__ import annotations

import math

from openmotion.config import DriveConfig
from openmotion.errors import check_nonnegative, check_positive

from .cubic import Cubic
from .pieces import Piece, SmoothPiece
from .pulses import PulseGenerator

#: Below this error (pulses) and speed (pulses/s) a holding servo is taken as settled.
SETTLE_POS = 1e-9
SETTLE_VEL = 1e-6
#: Grid for finding zeros of x' and INP changes: at least this many steps per stretch and
#: 2 per 1/w (a stretch of one 1 ms cycle at 30 Hz bandwidth: 2 steps of 0.5 ms).
_MIN_SAMPLES = 2
_SAMPLES_PER_RAD = 2.0


class _Solution:
    """Exact motor motion over one stretch with polynomial input, local time s = t - tau."""

    __slots__ = ("tau", "p", "r", "kind", "k1", "k2", "c1", "c2", "alpha")

    def __init__(self, tau: float, r: Cubic, x0: float, v0: float, w: float, z: float
                 ) -> None:
        a = 2.0 * z / w
        b = 1.0 / (w * w)
        c2 = a * a - b
        c3 = 2.0 * a * b - a ** 3
        self.tau = tau
        self.r = r
        self.p = Cubic(r.p0 - a * r.v0 + c2 * r.a0 + c3 * r.j,
                       r.v0 - a * r.a0 + c2 * r.j,
                       r.a0 - a * r.j,
                       r.j)
        e0 = x0 - self.p.p0
        de0 = v0 - self.p.v0
        if abs(z - 1.0) < 1e-9:
            self.kind = 0  # critical: e = (k1 + k2 s) exp(-w s)
            self.alpha = w
            self.k1, self.k2 = e0, de0 + w * e0
            self.c1 = self.c2 = 0.0
        elif z < 1.0:
            wd = w * math.sqrt(1.0 - z * z)
            self.kind = 1  # under: e = exp(-z w s)(k1 cos wd s + k2 sin wd s)
            self.alpha = z * w
            self.k1, self.k2 = e0, (de0 + z * w * e0) / wd
            self.c1, self.c2 = wd, 0.0
        else:
            q = math.sqrt(z * z - 1.0)
            r1, r2 = -w * (z - q), -w * (z + q)
            self.kind = 2  # over: e = k1 exp(r1 s) + k2 exp(r2 s)
            self.alpha = 0.0
            self.k1 = (de0 - r2 * e0) / (r1 - r2)
            self.k2 = e0 - self.k1
            self.c1, self.c2 = r1, r2

    def _e(self, s: float) -> tuple[float, float]:
        """Homogeneous part and its derivative at local time s."""
        k1, k2 = self.k1, self.k2
        if self.kind == 1:
            wd, al = self.c1, self.alpha
            ex = math.exp(-al * s)
            co, si = math.cos(wd * s), math.sin(wd * s)
            e = ex * (k1 * co + k2 * si)
            de = ex * ((k2 * wd - al * k1) * co - (k1 * wd + al * k2) * si)
            return e, de
        if self.kind == 0:
            w = self.alpha
            ex = math.exp(-w * s)
            return (k1 + k2 * s) * ex, (k2 - w * (k1 + k2 * s)) * ex
        e1, e2 = k1 * math.exp(self.c1 * s), k2 * math.exp(self.c2 * s)
        return e1 + e2, self.c1 * e1 + self.c2 * e2

    def x(self, t: float) -> float:
        s = t - self.tau
        return self.p.pos(s) + self._e(s)[0]

    def v(self, t: float) -> float:
        s = t - self.tau
        return self.p.vel(s) + self._e(s)[1]

    def state(self, t: float) -> tuple[float, float]:
        s = t - self.tau
        e, de = self._e(s)
        return self.p.pos(s) + e, self.p.vel(s) + de

    def sample(self, t: float) -> tuple[float, float, float]:
        """(x, x', r - x) at time t with one evaluation of the homogeneous part."""
        s = t - self.tau
        e, de = self._e(s)
        x = self.p.pos(s) + e
        return x, self.p.vel(s) + de, self.r.pos(s) - x

    def error(self, t: float) -> float:
        """Following error r - x (pulses)."""
        s = t - self.tau
        return self.r.pos(s) - self.p.pos(s) - self._e(s)[0]


class ServoPlant:
    """Servo motor + drive of one axis (exact 2nd-order response)."""

    __slots__ = ("w", "z", "band", "vband", "x", "v", "bias", "active", "in_position",
                 "_segs")

    def __init__(self, drv: DriveConfig) -> None:
        bw = check_positive("drive.bandwidth_hz", drv.bandwidth_hz)
        self.z = check_positive("drive.damping", drv.damping)
        self.band = check_nonnegative("drive.inp_band", drv.inp_band)
        self.w = 2.0 * math.pi * bw
        #: INP also needs the motor nearly stopped: below band * w pulses/s
        self.vband = self.band * self.w
        self.x = 0.0
        self.v = 0.0
        self.bias = 0.0
        self.active = False
        self.in_position = False
        self._segs: list[tuple[float, float, _Solution | None, list, list]] = []

    def motor(self, gen: PulseGenerator) -> float:
        return self.x

    def ready(self, svon: bool, alarm: bool) -> bool:
        return svon and not alarm

    def set_outputs(self, t: float, gen: PulseGenerator, svon: bool, alarm: bool,
                    erc: bool) -> None:
        """Apply SVON / alarm / an ERC pulse at time t (the plant's state is at t)."""
        active = svon and not alarm
        if active and (not self.active or erc):
            self.bias = self.x - gen.pos(t)  # deviation counter cleared
        if not active:
            self.v = 0.0
        self.active = active
        self.in_position = active and self._inp(self.bias + gen.pos(t) - self.x, self.v)

    def _inp(self, err: float, vel: float) -> bool:
        return abs(err) <= self.band and abs(vel) <= self.vband

    def pieces(self, gen: PulseGenerator, ta: float, tb: float) -> list[Piece]:
        """Monotone motor pieces over [ta, tb]; advances state and the pulse count."""
        gen.stretches(ta, tb)  # the pulse count follows the command whatever the motor does
        self._segs = []
        if tb <= ta:
            return []
        if not self.active:
            self._segs.append((ta, tb, None, [], []))
            return []
        out: list[Piece] = []
        tc, te = gen.tc, gen.te
        bounds = sorted({ta, tb, *(x for x in (tc, te) if ta < x < tb)})
        for k in range(len(bounds) - 1):
            t0, t1 = bounds[k], bounds[k + 1]
            moving = tc <= t0 and t1 <= te and te > tc
            if moving:
                c, s = gen.cubic, t0 - tc
                r = Cubic(c.pos(s) + self.bias, c.vel(s), c.acc(s), c.j)
            else:
                r = Cubic(gen.pos(t0) + self.bias)
                if abs(self.x - r.p0) < SETTLE_POS and abs(self.v) < SETTLE_VEL:
                    self.x, self.v = r.p0, 0.0  # settled: no motion, no pieces
                    self._segs.append((t0, t1, None, [], []))
                    continue
            sol = _Solution(t0, r, self.x, self.v, self.w, self.z)
            grid = self._grid(t0, t1)
            samples = [sol.sample(t) for t in grid]
            self._segs.append((t0, t1, sol, grid, samples))
            self._monotone(sol, grid, samples, out)
            self.x, self.v = samples[-1][0], samples[-1][1]
        return out

    def _grid(self, t0: float, t1: float) -> list[float]:
        n = max(_MIN_SAMPLES, math.ceil((t1 - t0) * self.w * _SAMPLES_PER_RAD))
        h = (t1 - t0) / n
        return [t0 + i * h for i in range(n)] + [t1]

    def _monotone(self, sol: _Solution, grid: list[float], samples: list, out: list[Piece]
                  ) -> None:
        cuts = [grid[0]]
        vs = [smp[1] for smp in samples]
        for i in range(len(grid) - 1):
            if (vs[i] > 0.0) != (vs[i + 1] > 0.0) and vs[i + 1] != 0.0 and vs[i] != 0.0:
                cuts.append(_bisect(lambda t: sol.v(t) > 0.0, grid[i], grid[i + 1]))
        cuts.append(grid[-1])
        for i in range(len(cuts) - 1):
            a, b = cuts[i], cuts[i + 1]
            if b <= a:
                continue
            xa = samples[0][0] if i == 0 else sol.x(a)
            xb = samples[-1][0] if i == len(cuts) - 2 else sol.x(b)
            if xb != xa:
                out.append(SmoothPiece(sol.x, sol.v, a, b, 1 if xb > xa else -1, xa, xb))

    def status_edges(self, ax, ta: float, tb: float, raw: list) -> None:
        """Append INP edges over the run just simulated (exact to ~1e-12 s)."""
        for t0, _t1, sol, grid, samples in self._segs:
            if sol is None:
                now = self.active and self._inp(0.0, 0.0)
                if now != self.in_position:
                    self.in_position = now
                    raw.append((t0, ax.index, "inp", ax.level("inp"), None))
                continue

            def inp(t: float, sol: _Solution = sol) -> bool:
                return self._inp(sol.error(t), sol.v(t))

            state = self.in_position
            for i in range(len(grid)):
                _, v, err = samples[i]
                now = self._inp(err, v)
                if now != state:
                    te = grid[i] if i == 0 else _bisect(lambda t, s=state: inp(t) == s,
                                                        grid[i - 1], grid[i])
                    self.in_position = now
                    state = now
                    raw.append((te, ax.index, "inp", ax.level("inp"), None))


def _bisect(pred, lo: float, hi: float) -> float:
    """First time in (lo, hi] where pred turns from pred(lo) (to ~1e-12 s)."""
    p_lo = pred(lo)
    for _ in range(60):
        if hi - lo <= 1e-12:
            break
        mid = 0.5 * (lo + hi)
        if pred(mid) == p_lo:
            lo = mid
        else:
            hi = mid
    return hi

