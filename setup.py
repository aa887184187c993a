"""Build of the compiled inner loops (openmotion._kernel, src/openmotion/_kernel*.c, and
openmotion._compare, src/openmotion/_kernel_compare.c + _compare_*.c: the compare engine's
solvers, and
openmotion._profile, src/openmotion/_profile.c: the jerk-limited profile builder (+
_profile_sample.c: Profile.sample, _profile_knots.c: a chain's axis knots), and
openmotion._corner, src/openmotion/_corner.c: the module, + _blend.c: the line-line corner
blends, + _chain.c: the chain planner's passes); the rest
is declared in pyproject.toml. Plain C against the CPython API: no build tool beyond setuptools.
-ffp-contract=off keeps the compiler from fusing a*b+c, so the kernel's floats are
bit-identical to the Python path's."""

import sys

from setuptools import Extension, setup

flags = [] if sys.platform == "win32" else ["-O2", "-ffp-contract=off", "-fno-fast-math"]

setup(ext_modules=[Extension("openmotion._kernel",
                             ["src/openmotion/_kernel.c", "src/openmotion/_kernel_stepper.c",
                              "src/openmotion/_stepper_axis.c", "src/openmotion/_stepper_scan.c",
                              "src/openmotion/_stepper_solve.c",
                              "src/openmotion/_kernel_rt.c", "src/openmotion/_kernel_record.c",
                              "src/openmotion/_kernel_rowsink.c"],
                             depends=["src/openmotion/_kernel.h",
                                      "src/openmotion/_kernel_stepper.h"],
                             extra_compile_args=flags),
                   Extension("openmotion._compare",
                             ["src/openmotion/_kernel_compare.c"]
                             + [f"src/openmotion/_compare_{job}.c"
                                for job in ("track", "window", "vector", "lines", "scan")],
                             depends=["src/openmotion/_compare.h"],
                             extra_compile_args=flags),
                   Extension("openmotion._profile", ["src/openmotion/_profile.c",
                                                   "src/openmotion/_profile_sample.c",
                                                   "src/openmotion/_profile_knots.c"],
                             depends=["src/openmotion/_profile.h"],
                             extra_compile_args=flags),
                   Extension("openmotion._corner",
                             ["src/openmotion/_corner.c", "src/openmotion/_chain.c",
                              "src/openmotion/_blend.c", "src/openmotion/_chain_prep.c",
                              "src/openmotion/_chain_elem.c"],
                             depends=["src/openmotion/_chain.h", "src/openmotion/_blend.h"],
                             extra_compile_args=flags)])
