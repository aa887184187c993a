"""Slow oracle: the chain planner's passes as Python computed them before they moved to C
(src/openmotion/_chain.c, in openmotion._corner): the look-ahead's backward and forward
passes and cruise speeds (path/lookahead.py), the trapezoids as v**2(s) knots and the
constant-acceleration pieces of s(t) (control/groups/pathexec.py), the times s(t) crosses
the element boundaries (control/groups/pathaxes.py), a limit along per-axis caps
(path/lookahead.py). The equivalence tests
(tests/test_chain_planner.py) compare the compiled passes with these bit for bit."""

from __future__ import annotations

import math

import numpy as np

from openmotion.errors import InfeasibleError
from openmotion.path.lookahead import ElementSpeeds, _peak2
from openmotion.profile.segments import Profile, State


def passes(jcap2: list[float], acc: list[float], length: list[float],
           start2: float, dec: list[float] | None = None) -> tuple[list[float], list[float]]:
    n = len(length)
    dv = [2.0 * a * L for a, L in zip(acc, length, strict=True)]
    back = jcap2[:]
    dvb = dv if dec is None else [2.0 * d * L for d, L in zip(dec, length, strict=True)]
    nxt = back[n]
    for k in range(n - 1, -1, -1):
        x = nxt + dvb[k]
        c = jcap2[k]
        nxt = back[k] = c if c <= x else x
    fwd = [0.0] * (n + 1)
    cur = fwd[0] = start2 if start2 <= back[0] else back[0]
    for k in range(n):
        x = cur + dv[k]
        c = back[k + 1]
        cur = fwd[k + 1] = c if c <= x else x
    return back, fwd


def speeds(fwd: list[float], acc: list[float], dec: list[float], ccap: list[float],
           length: list[float]) -> tuple[list[float], list[float], list[float]]:
    entry, cruise, exit_ = [], [], []
    for k in range(len(length)):
        vin, vout = math.sqrt(fwd[k]), math.sqrt(fwd[k + 1])
        peak2 = _peak2(fwd[k], fwd[k + 1], acc[k], dec[k], length[k])
        entry.append(vin)
        cruise.append(max(vin, vout, min(ccap[k], math.sqrt(peak2))))
        exit_.append(vout)
    return entry, cruise, exit_


def curve_from_speeds(sp: list[ElementSpeeds], s0: float = 0.0) -> tuple[np.ndarray,
                                                                        np.ndarray]:
    ss: list[float] = [s0]
    vv: list[float] = [sp[0].entry ** 2 if sp else 0.0]
    pos = s0
    for e in sp:
        if e.length == 0.0:
            continue
        a, vc2 = e.accel, e.cruise ** 2
        d_acc = max(0.0, (vc2 - e.entry ** 2) / (2.0 * a))
        d_dec = max(0.0, (vc2 - e.exit ** 2) / (2.0 * e.decel))
        if d_acc + d_dec > e.length:
            d_acc = max(0.0, min(e.length, d_acc))
            d_dec = e.length - d_acc
        for d, v2 in ((d_acc, vc2), (e.length - d_acc - d_dec, vc2)):
            if d > 0.0:
                ss.append(ss[-1] + d)
                vv.append(v2)
        pos += e.length
        ss.append(pos)
        vv.append(e.exit ** 2)
    s = np.array(ss)
    v2 = np.maximum(np.array(vv), 0.0)
    keep = np.concatenate([[True], np.diff(s) > 0.0])
    keep[-1] = True
    s, v2 = s[keep], v2[keep]
    if len(s) > 1 and s[-2] >= s[-1]:
        s, v2 = np.delete(s, -2), np.delete(v2, -2)
    return s, v2


def s_profile(curve_s: np.ndarray, curve_v2: np.ndarray, jump: bool, s_end: float,
              breaks, *, dwell: float = 0.0, lead: float = 0.0) -> Profile:
    brk = np.asarray(breaks, dtype=float)
    knots = np.union1d(curve_s, brk[(brk > curve_s[0]) & (brk < s_end)])
    knots = knots[(knots >= curve_s[0]) & (knots <= s_end)]
    v2 = np.maximum(np.interp(knots, curve_s, curve_v2), 0.0)
    v = np.sqrt(v2)
    ds = np.diff(knots)
    dv2 = np.diff(v2)
    p, vcur, acur, t = float(knots[0]), float(v[0]), 0.0, 0.0
    start = State(p, 0.0 if jump else vcur, 0.0)
    rows: list[tuple[float, float, float, float, float]] = []
    dts: list[float] = []
    labels: list[str] = []

    def piece(dt: float, label: str) -> None:
        nonlocal p, vcur, acur, t
        rows.append((t, p, vcur, acur, 0.0))
        dts.append(dt)
        labels.append(label or f"segment {len(labels)}")
        p = p + dt * (vcur + dt * (acur / 2.0 + dt * 0.0 / 6.0))
        vcur = vcur + dt * (acur + dt * 0.0 / 2.0)
        acur = acur + dt * 0.0
        t += dt

    if lead > 0.0:
        acur = 0.0
        piece(lead, "dwell")
    last = len(ds) - 1
    crawl = 2e-6 * float(v.max(initial=0.0))
    dsl, dv2l, vl = ds.tolist(), dv2.tolist(), v.tolist()
    for k in range(len(dsl)):
        d = dsl[k]
        if d <= 0.0:
            continue
        a = dv2l[k] / (2.0 * d)
        vm = vl[k] + vl[k + 1]
        if vm <= 0.0 or (2.0 * d / vm > 1e6 and vm < crawl):
            if d <= 1e-9 * max(1.0, s_end):
                continue
            raise InfeasibleError("path speed curve stalls at rest before its end")
        dt = 2.0 * d / vm
        vcur = vl[k]
        acur = a
        if dt > 0.0:
            piece(dt, "")
        if dwell > 0.0 and vl[k + 1] == 0.0 and k < last:
            vcur = 0.0
            acur = 0.0
            piece(dwell, "dwell")
    arr = np.array(rows, dtype=np.float64).reshape(-1, 5)
    return Profile(t0=arr[:, 0].copy(), p0=arr[:, 1].copy(), v0=arr[:, 2].copy(),
                   a0=arr[:, 3].copy(), j=arr[:, 4].copy(), duration=t, start=start,
                   end=State(float(s_end), 0.0, 0.0), labels=tuple(labels),
                   dt=np.array(dts, dtype=np.float64))


def crossings(sp: Profile, levels: np.ndarray) -> np.ndarray:
    lv = levels[(levels > sp.start.p) & (levels < sp.end.p)]
    n = sp.n_segments
    if not len(lv) or not n:
        return np.zeros(0)
    k = np.clip(np.searchsorted(sp.p0, lv, side="right") - 1, 0, n - 1)
    dts = sp.dt if sp.dt is not None else np.diff(np.append(sp.t0, sp.duration))
    lo, hi = np.zeros(len(lv)), np.asarray(dts, dtype=float)[k].copy()
    p0, v0, a0, j = sp.p0[k], sp.v0[k], sp.a0[k], sp.j[k]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        below = p0 + mid * (v0 + mid * (a0 / 2.0 + mid * j / 6.0)) < lv
        lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
    return np.unique(sp.t0[k] + hi)


def limit_along(limit: float, axis: np.ndarray | None, weight: np.ndarray) -> float:
    if axis is None:
        return limit
    best = math.inf
    found = False
    for a, w in zip(axis.tolist(), weight.tolist(), strict=True):
        if w > 0.0:
            found = True
            q = a / w
            if q < best:
                best = q
    if not found:
        return limit
    return limit if limit <= best else best
