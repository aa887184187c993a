"""Servo loops closed in the control layer, filters, compensation (pitch tables, backlash).

May import: core (tests/test_layering.py)."""
