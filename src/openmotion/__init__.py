"""openmotion: a multi-axis motion controller in Python.

Layers (lower never imports higher): config/units -> profile -> path -> hw -> control ->
program -> cli/compat. See docs/architecture.md.
"""

__version__ = "0.1.0"
