/* The line-line corner blend, compiled (openmotion._corner): the numbers of the arc that
 * rounds the corner of two lines within a tolerance, and of the two trimmed lines, in one
 * call (path/blend.py's closed form; the derivation is in its module doc).
 *
 * A separate extension module with one narrow interface: float64 buffers and floats in,
 * the rows of the three new elements written into one caller's buffer and their scalars
 * returned. Python validates the user's arguments first and builds the Line/Arc3D objects
 * around the rows (path/blend.py `_line_line`); this file only does the arithmetic, which
 * a streaming G-code job runs for every command (about 60 small numpy operations each in
 * Python). The Python construction is kept as the oracle (tests/oracle_blend.py): the
 * formulas repeat its operation order, so the results differ from it only where numpy's
 * dot product (BLAS, which may fuse multiply-adds) and its element-wise cos/arctan2/hypot
 * round differently from these plain C loops: by rounding (tests/test_path_blend.py
 * checks 1e-9 relative).
 *
 * Rows of `out` (each `dim` doubles), in this order: centre, e1, e2, arc start (= first
 * line's new end), arc end (= second line's new start), via (the arc's midpoint), lin
 * (the arc's end correction), arc start tangent, arc end tangent, helix (zeros), the arc's
 * max |tangent| per axis, its axis acceleration weight, the first line's direction, its
 * |direction|, the second line's direction, its |direction|.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <string.h>

#include "_chain.h"

#ifdef __clang__
#pragma STDC FP_CONTRACT OFF
#endif

#define TANGENT_ANGLE 1e-6  /* blend.TANGENT_ANGLE */
#define REVERSAL_ANGLE 1e-6 /* blend.REVERSAL_ANGLE */
#define MAX_DIM 64
#define ROWS 16

enum { CENTRE, E1, E2, A_START, A_END, VIA, LIN, T_START, T_END, HELIX, MAT, AAW, U1, ABS1,
       U2, ABS2 };

static double dot(const double *a, const double *b, int n)
{
    double s = a[0] * b[0];
    for (int i = 1; i < n; i++) s += a[i] * b[i];
    return s;
}

/* np.add.reduce(t*t): the first square plus the sum of the rest */
static double sumsq(const double *t, int n)
{
    double rest = 0.0;
    for (int i = 1; i < n; i++) rest += t[i] * t[i];
    return t[0] * t[0] + rest;
}

static double vnorm(const double *a, int n) { return sqrt(dot(a, a, n)); }

/* Line.between(start, end): its length and direction (and |direction|) */
static double line_between(const double *start, const double *end, double *u, double *au,
                           int n)
{
    double delta[MAX_DIM], q[MAX_DIM];
    double big = 0.0;
    int nan = 0;
    for (int i = 0; i < n; i++) {
        delta[i] = end[i] - start[i];
        double a = fabs(delta[i]);
        if (a != a) nan = 1;
        else if (a > big) big = a;
    }
    if (nan) big = NAN; /* np.max propagates NaN */
    double length;
    if (big > 0.0) {
        for (int i = 0; i < n; i++) q[i] = delta[i] / big;
        length = big * vnorm(q, n);
        for (int i = 0; i < n; i++) u[i] = delta[i] / length;
    } else {
        length = 0.0;
        for (int i = 0; i < n; i++) u[i] = 0.0;
    }
    for (int i = 0; i < n; i++) au[i] = fabs(u[i]);
    return length;
}

/* _Frame._tangent_one(s) of a circle (no helix) */
static void tangent_one(double s, double radius, double sweep, double length,
                        const double *e1, const double *e2, double *t, int n)
{
    double phi = s * (sweep / length);
    double c = cos(phi), sn = sin(phi), k = radius * sweep;
    for (int i = 0; i < n; i++) t[i] = k * (c * e2[i] - sn * e1[i]) + 0.0;
    double norm = sqrt(sumsq(t, n));
    for (int i = 0; i < n; i++) t[i] = t[i] / norm;
}

static int get(PyObject *obj, Py_buffer *b, Py_ssize_t n, int writable)
{
    if (PyObject_GetBuffer(obj, b, PyBUF_C_CONTIGUOUS | (writable ? PyBUF_WRITABLE : 0)) < 0)
        return -1;
    if (b->len != n * (Py_ssize_t)sizeof(double)) {
        PyBuffer_Release(b);
        PyErr_SetString(PyExc_ValueError, "buffer of the wrong size");
        return -1;
    }
    return 0;
}

PyDoc_STRVAR(line_blend_doc,
"line_blend(out, start, corner, end, u1, u2, len1, len2, tol, frac)\n"
"The corner start -> corner -> end of two lines (directions u1, u2, lengths len1, len2)\n"
"rounded within tol (each line trimmed by at most frac of it): None when the corner is\n"
"straight or a reversal, else (first length, second length, radius, sweep, arc length,\n"
"curvature, deviation) with the rows of the module doc written into out.");

static PyObject *py_line_blend(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 10) {
        PyErr_SetString(PyExc_TypeError, "line_blend takes 10 arguments");
        return NULL;
    }
    double len1 = PyFloat_AsDouble(args[6]), len2 = PyFloat_AsDouble(args[7]);
    double tol = PyFloat_AsDouble(args[8]), frac = PyFloat_AsDouble(args[9]);
    if (PyErr_Occurred()) return NULL;
    Py_buffer b[6];
    int held = 0;
    PyObject *result = NULL;
    if (PyObject_GetBuffer(args[1], &b[0], PyBUF_C_CONTIGUOUS) < 0) return NULL;
    held = 1;
    Py_ssize_t n = b[0].len / (Py_ssize_t)sizeof(double);
    if (n < 1 || n > MAX_DIM) {
        PyErr_SetString(PyExc_ValueError, "line_blend: 1 to 64 axes");
        goto done;
    }
    for (int k = 2; k <= 5; k++) {
        if (get(args[k], &b[held], n, 0) < 0) goto done;
        held++;
    }
    if (get(args[0], &b[held], ROWS * n, 1) < 0) goto done;
    held++;
    const double *p0 = b[0].buf, *corner = b[1].buf, *p2 = b[2].buf, *u1 = b[3].buf,
                 *u2 = b[4].buf;
    double *out = b[5].buf;
    int dim = (int)n;
    double *centre = out + CENTRE * n, *e1 = out + E1 * n, *e2 = out + E2 * n,
           *a_start = out + A_START * n, *a_end = out + A_END * n, *via = out + VIA * n,
           *lin = out + LIN * n, *helix = out + HELIX * n, *mat = out + MAT * n,
           *aaw = out + AAW * n;
    double dm[MAX_DIM], dp[MAX_DIM], diff[MAX_DIM];
    for (int i = 0; i < dim; i++) {
        dm[i] = u1[i] - u2[i];
        dp[i] = u1[i] + u2[i];
        diff[i] = u2[i] - u1[i];
    }
    double cos_t = vnorm(dm, dim) / 2.0;
    double sin_t = vnorm(dp, dim) / 2.0;
    double turn = 2.0 * atan2(cos_t, sin_t);
    if (turn < TANGENT_ANGLE || M_PI - turn < REVERSAL_ANGLE) {
        result = Py_None;
        Py_INCREF(result);
        goto done;
    }
    double d_tol = tol * (1.0 + sin_t) / cos_t;
    double d = frac * len1; /* min(): the first of equals, as Python's */
    if (frac * len2 < d) d = frac * len2;
    if (d_tol < d) d = d_tol;
    double radius = d * sin_t / cos_t;
    double dn = vnorm(diff, dim), off = d / cos_t;
    for (int i = 0; i < dim; i++) {
        double normal = diff[i] / dn;
        centre[i] = corner[i] + normal * off;
        a_start[i] = corner[i] - u1[i] * d;
        a_end[i] = corner[i] + u2[i] * d;
        e1[i] = -(u1[i] * cos_t + normal);
    }
    double p = dot(e1, u1, dim);
    for (int i = 0; i < dim; i++) e1[i] = e1[i] - p * u1[i];
    double en = vnorm(e1, dim);
    for (int i = 0; i < dim; i++) e1[i] = e1[i] / en;
    p = dot(u1, e1, dim);
    for (int i = 0; i < dim; i++) e2[i] = u1[i] - p * e1[i];
    en = vnorm(e2, dim);
    for (int i = 0; i < dim; i++) e2[i] = e2[i] / en;
    /* Arc3D._planned and _Frame.__post_init__ (no helix) */
    double r = radius, sw = turn;
    double ch = cos(sw / 2), sh = sin(sw / 2), c = cos(sw), sn = sin(sw);
    double length = fabs(r * sw); /* math.hypot(r*sw, 0) */
    for (int i = 0; i < dim; i++) {
        helix[i] = 0.0;
        via[i] = centre[i] + r * (ch * e1[i] + sh * e2[i]);
        double last = centre[i] + r * (c * e1[i] + sn * e2[i]) + 0.0;
        lin[i] = 0.0 + (a_end[i] - last);
    }
    tangent_one(0.0, r, sw, length, e1, e2, out + T_START * n, dim);
    tangent_one(length, r, sw, length, e1, e2, out + T_END * n, dim);
    double kappa = r / (r * r + 0.0 * 0.0);
    /* _Frame.max_abs_tangent and axis_accel_weight */
    double k = r * sw / length;
    for (int i = 0; i < dim; i++) {
        double amp = hypot(e1[i], e2[i]);
        double m;
        if (sw >= M_PI) {
            m = 1.0;
        } else {
            double a = atan2(e1[i], e2[i]), bb = a + sw;
            double ca = fabs(cos(a)), cb = fabs(cos(bb));
            m = floor(bb / M_PI) > floor(a / M_PI) ? 1.0 : (ca >= cb || ca != ca ? ca : cb);
        }
        mat[i] = k * amp * m + 0.0 / length;
        aaw[i] = amp + 0.0 / length;
    }
    double l1 = line_between(p0, a_start, out + U1 * n, out + ABS1 * n, dim);
    double l2 = line_between(a_end, p2, out + U2 * n, out + ABS2 * n, dim);
    double dev = d * (1.0 - sin_t) / cos_t;
    result = Py_BuildValue("(ddddddd)", l1, l2, radius, turn, length, kappa, dev);
done:
    for (int q = 0; q < held; q++) PyBuffer_Release(&b[q]);
    return result;
}

static PyMethodDef methods[] = {
    {"line_blend", (PyCFunction)(void (*)(void))py_line_blend, METH_FASTCALL,
     line_blend_doc},
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
