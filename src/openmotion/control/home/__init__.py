"""Homing (HSL modes, MCCL phases, sequences) and position latch / touch probe.

May import: core, guard (tests/test_layering.py)."""
