"""The core: the controller and its cycle, the clock, axes and their motion execution,
counters, events, PLCopen states, virtual-time jumps. Imports no capability and no back
end; capabilities register hooks on it.

May import: no other sub-package (tests/test_layering.py)."""
