/* The compare engine's solvers, compiled (openmotion._compare): exact trigger times on
 * piecewise-cubic tracks for every job kind (control/trigger/compare_math.py calls them).
 *
 * A separate extension module (not entries in _kernel.c's method table): it has several
 * entry points of its own, shares no state with the stepper kernel, and its build can
 * change without touching the kernel's table.
 *
 * This file holds the module table and init; the solvers are in _compare_track.c (track
 * arguments, level events, LevelJob), _compare_window.c (WindowJob), _compare_vector.c
 * (path length), _compare_lines.c (output lines, cycle records) and _compare_scan.c (the
 * scan driver), sharing _compare.h.
 *
 * A track is five float64 arrays (ts, p0, v0, a0, j): record k covers [ts[k], ts[k+1]),
 * the last is open-ended (compare_math.Track). Every formula repeats the operation order
 * of the plain-float Python versions kept as oracles in tests/compare_oracle.py, so the
 * times are the same floats (compiled with -ffp-contract=off: no fused multiply-add;
 * Python's max/min are `pymax`/`pymin`, which keep the first argument on ties and NaN).
 */
#include "_compare.h"

#define DEF(n) PyObject *S_##n;
NAMES(DEF)
#undef DEF

/* ------------------------------------------------------------------ module */
static PyMethodDef methods[] = {
    {"level_events", level_events_py, METH_VARARGS, level_events_doc},
    {"level_scan", level_scan, METH_VARARGS, level_scan_doc},
    {"track_range", track_range_py, METH_VARARGS, track_range_doc},
    {"first_inside", first_inside_py, METH_VARARGS, first_inside_doc},
    {"window_scan", window_scan, METH_VARARGS, window_scan_doc},
    {"positions", positions_py, METH_VARARGS, positions_doc},
    {"set_gauss", set_gauss, METH_VARARGS, set_gauss_doc},
    {"gl", gl_py, METH_VARARGS, gl_doc},
    {"adaptive", adaptive_py, METH_VARARGS, adaptive_doc},
    {"vector_at", vector_at, METH_VARARGS, vector_at_doc},
    {"time_of", time_of_py, METH_VARARGS, time_of_doc},
    {"vector_scan", vector_scan, METH_VARARGS, vector_scan_doc},
    {"vector_pieces", vector_pieces, METH_VARARGS, vector_pieces_doc},
    {"vector_sums", vector_sums, METH_VARARGS, vector_sums_doc},
    {"line_set", line_set, METH_VARARGS, line_set_doc},
    {"solver_checks", solver_checks, METH_VARARGS, solver_checks_doc},
    {"bank_new", bank_new, METH_VARARGS, bank_new_doc},
    {"bank_scan", bank_scan, METH_VARARGS, bank_scan_doc},
    {"lines_send", lines_send, METH_VARARGS, lines_send_doc},
    {"plan_records", plan_records, METH_VARARGS, plan_records_doc},
    {"lines_snapshot", lines_snapshot, METH_VARARGS, lines_snapshot_doc},
    {"lines_end", lines_end, METH_VARARGS, lines_end_doc},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_compare",
    "openmotion's compiled compare solvers (control/trigger/compare_math.py).", -1, methods,
    NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__compare(void)
{
#define INTERN(n) if ((S_##n = PyUnicode_InternFromString(#n)) == NULL) return NULL;
    NAMES(INTERN)
#undef INTERN
    return PyModule_Create(&module);
}
