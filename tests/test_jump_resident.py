"""Pieces a jump leaves queued at its landing (control/core/jump.py `_feed`,
Controller._fed) and the kernel's piece arena (hw/sim/kernel.py `_sync_pieces`).

A jump queues a motion's pieces to the end of those computed ahead and leaves them queued
when it lands mid-motion; the next jump of the same motion uses them again, a replaced
motion or a cycle stepped on its own drops them. Every sequence runs cycle by cycle through
the Python pipeline (the reference) and jumping with the compiled kernel and must agree
exactly on positions, velocities, pulse counts, encoder counts and states.
"""

from __future__ import annotations

from dataclasses import replace

import pytest

from openmotion.config import MachineConfig, default_machine
from openmotion.control import Controller


def _pair() -> tuple[Controller, Controller]:
    x = default_machine().axes[0]
    cfg = MachineConfig(name="resident", axes=tuple(replace(x, name=f"a{i}") for i in range(3)))
    ref, fast = Controller(cfg), Controller(cfg)
    ref.virtual_jumps = False
    ref.hardware.native = False
    for c in (ref, fast):
        c.enable_all()
    return ref, fast


def _same(ref: Controller, fast: Controller) -> None:
    assert fast.cycles == ref.cycles
    for a, b in zip(ref.axes, fast.axes, strict=True):
        assert b.position == a.position
        assert b.velocity == a.velocity
        assert b.state == a.state
        assert b.motion_done == a.motion_done
        ra, rb = ref.hardware.read_axis(a.index), fast.hardware.read_axis(b.index)
        assert (rb.pulses_out, rb.encoder) == (ra.pulses_out, ra.encoder)


def _moves(c: Controller) -> None:
    for i, ax in enumerate(c.axes):
        ax.move_relative(30_000 + 7_000 * i, max_vel=80_000, tacc=0.05, tdec=0.05,
                         shape="S" if i % 2 else "T")


def test_landing_mid_motion_leaves_pieces_and_the_next_jump_uses_them() -> None:
    ref, fast = _pair()
    for c in (ref, fast):
        _moves(c)
        c.advance(0.1)  # lands mid-motion
    _same(ref, fast)
    hw = fast.hardware
    left = {i: hw.queued(i) for i in range(3)}
    assert all(n > 0 for n in left.values())  # left queued at the landing
    assert set(fast._fed) == {0, 1, 2}
    for c in (ref, fast):
        c.advance(0.05)
    _same(ref, fast)
    assert all(hw.queued(i) == left[i] - 50 for i in range(3))  # nothing queued again
    for c in (ref, fast):
        c.wait_motion_done()
    _same(ref, fast)


@pytest.mark.parametrize("how", ["step", "replan", "stop", "new_move"])
def test_what_a_landing_leaves_is_dropped_when_the_motion_changes(how: str) -> None:
    ref, fast = _pair()
    for c in (ref, fast):
        _moves(c)
        c.advance(0.12)
        ax = c.axes[1]
        if how == "step":  # cycles stepped on their own drop every piece left
            for _ in range(3):
                c.step()
        elif how == "replan":
            ax.change_speed(40_000, 0.03)
        elif how == "stop":
            ax.stop()
        else:
            c.axes[0].stop_immediately()
            c.advance(0.01)
            c.axes[0].move_relative(-5_000, max_vel=50_000, tacc=0.02)
    if how == "step":
        assert not fast._fed and all(fast.hardware.queued(i) == 0 for i in range(3))
    _same(ref, fast)
    for c in (ref, fast):
        c.advance(0.07)
    _same(ref, fast)
    for c in (ref, fast):
        c.wait_motion_done()
    _same(ref, fast)


def test_pieces_cleared_behind_the_controllers_back_are_queued_again() -> None:
    ref, fast = _pair()
    for c in (ref, fast):
        _moves(c)
        c.advance(0.1)
    for i in range(3):  # (the real-time executor does this after a failed run)
        fast.hardware.clear_queue(i)
    for c in (ref, fast):
        c.advance(0.1)
    _same(ref, fast)
    for c in (ref, fast):
        c.wait_motion_done()
    _same(ref, fast)
