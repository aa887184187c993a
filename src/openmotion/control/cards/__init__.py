"""Card models: the HSL network (rings, slaves, axes) and the PCL6045 speed range grid.

May import: core (tests/test_layering.py)."""
