"""Groups and path execution: group commands, streaming look-ahead, joins, blending,
path-to-axis profiles, pulse accuracy.

May import: core, guard (tests/test_layering.py)."""
