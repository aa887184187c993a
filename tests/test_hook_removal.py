"""A hook that removes itself (or another hook) inside the cycle: every other hook still runs."""

from __future__ import annotations

from openmotion.control import Controller


def test_a_cycle_hook_removing_itself_does_not_skip_the_next_one():
    ctl = Controller(safety=False)
    seen: list[str] = []

    def once(c, t):
        seen.append("once")
        c.remove_cycle_hook(once)

    def every(c, t):
        seen.append("every")

    ctl.add_cycle_hook(once)
    ctl.add_cycle_hook(every)
    ctl.step()
    ctl.step()
    assert seen == ["once", "every", "every"]

def test_a_hook_removed_by_an_earlier_one_is_not_called_again():
    ctl = Controller(safety=False)
    seen: list[str] = []

    def first(c, t):
        seen.append("first")
        c.remove_cycle_hook(second)

    def second(c, t):
        seen.append("second")

    ctl.add_cycle_hook(first)
    ctl.add_cycle_hook(second)
    ctl.step()
    assert seen == ["first"]
