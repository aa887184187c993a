"""Position compare and PSO: the compare engine, its jobs, solvers, outputs and scope,
ZMotion PSO, HSL triggers.

May import: core (tests/test_layering.py)."""
