/* The openmotion._corner module: the compiled line-line corner blends (_blend.c, the
 * formulas of path/blend.py) and the chain planner's passes (_chain.c). One narrow
 * interface: float64 buffers and floats in, rows written into the caller's buffers.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include "_blend.h"
#include "_chain.h"

static PyMethodDef methods[] = {
    /* the line-line corner blends (_blend.c, its module doc) */
    {"line_blend", (PyCFunction)(void (*)(void))blend_py_line_blend, METH_FASTCALL,
     "line_blend(out, start, corner, end, u1, u2, len1, len2, tol, frac): one corner."},
    {"line_run", (PyCFunction)(void (*)(void))blend_py_line_run, METH_FASTCALL,
     "line_run(out, scal, geo, lengths, accel, feed, tol, frac): the corners of a run of "
     "lines, one after the other."},
    /* the chain planner's passes (_chain.c, its module doc) */
    {"passes", (PyCFunction)(void (*)(void))chain_py_passes, METH_FASTCALL,
     "passes(jcap2, acc, length, start2, dec) -> (back, fwd): the look-ahead's passes."},
    {"speeds", (PyCFunction)(void (*)(void))chain_py_speeds, METH_FASTCALL,
     "speeds(fwd, acc, dec, ccap, length) -> (entry, cruise, exit)."},
    {"curve", (PyCFunction)(void (*)(void))chain_py_curve, METH_FASTCALL,
     "curve(entry, cruise, exit, acc, dec, length, s0, v_first, out) -> knots written."},
    {"chain_curve", (PyCFunction)(void (*)(void))chain_py_chain_curve, METH_FASTCALL,
     "chain_curve(jcap2, acc, dec, ccap, length, start2, s0, out) -> knots "
     "written, or -1 (start too fast)."},
    {"s_pieces", (PyCFunction)(void (*)(void))chain_py_s_pieces, METH_FASTCALL,
     "s_pieces(knots, v2, v, s_end, dwell, lead, out) -> (rows, duration); rows -1: "
     "stall."},
    {"crossings", (PyCFunction)(void (*)(void))chain_py_crossings, METH_FASTCALL,
     "crossings(p0, v0, a0, j, hi, levels): the bisection of pathaxes._crossings, hi in "
     "place."},
    {"limit_along", (PyCFunction)(void (*)(void))chain_py_limit_along, METH_FASTCALL,
     "limit_along(limit, axis, weight) -> min(limit, axis_i/weight_i over weight_i > 0)."},
    /* the look-ahead's per-element limits and junction caps (_chain_prep.c) */
    {"prepare", (PyCFunction)(void (*)(void))chain_py_prepare, METH_FASTCALL,
     "prepare(elements, types, feed, accel, decel, dim, vmax, amax, vjump, ratio, scv, "
     "v_end, tangent_chord, junction, memo) -> (live, acc, cap, length, dec, jcap2) or None."},
    {"prepare_curve", (PyCFunction)(void (*)(void))chain_py_prepare_curve, METH_FASTCALL,
     "prepare_curve(<prepare's>, start2, s0, out) -> (knots written or -1, min dec) or None."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_corner",
    "Compiled line-line corner blend (path/blend.py) and chain planner passes (_chain.c).",
    -1,
    methods,
};

PyMODINIT_FUNC PyInit__corner(void) { return PyModule_Create(&module); }
