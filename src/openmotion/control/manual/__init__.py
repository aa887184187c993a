"""Manual motion: jogging (continuous, pulse, space).

May import: core, groups (tests/test_layering.py)."""
