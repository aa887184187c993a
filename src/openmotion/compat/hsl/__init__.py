"""The ADLINK HSL-4XMO library (HSL_M_* functions) on openmotion's simulator.

`HslLibrary` holds the functions (library.py: system and addressing; motion.py: moves,
interpolation, speed range; io.py: motion I/O, counters, comparators, homing); `errors`
the return codes; `sim` (HslSim) the scenario helper; `functions` the function table.
See docs/porting-hsl.md.
"""

from . import errors, functions, sim
from .errors import HslError, error_message
from .library import HslLibrary
from .sim import HslSim

__all__ = ["HslError", "HslLibrary", "HslSim", "error_message", "errors", "functions", "sim"]
