"""Safety reactions: end limits, slow-down, alarm, ERC, soft limits, comparators (error
counter), in-position control.

May import: core (tests/test_layering.py)."""
