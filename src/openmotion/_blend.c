/* The line-line corner blend, compiled (registered by openmotion._corner): the numbers of
 * the arc that rounds the corner of two lines within a tolerance, and of the two trimmed
 * lines (path/blend.py's closed form; the derivation is in its module doc), for one corner
 * (`line_blend`, behind the public blend_corner) or for a run of lines corner after
 * corner (`line_run`, the streaming join: each corner's first line is the previous
 * corner's trimmed second, and the group's "does the blend pay" test,
 * groupstream._blend_pays, decides which corners keep their blend).
 *
 * One narrow interface: float64 buffers and floats in, the rows of the new elements
 * written into the caller's buffer and their scalars returned (or written). Python builds
 * the Line/Arc3D objects around the rows; this file only does the arithmetic. The numpy
 * construction is kept as the oracle (tests/oracle_blend.py): the formulas repeat its
 * operation order, so the results differ from it only where numpy's dot product (BLAS,
 * which may fuse multiply-adds) and its element-wise cos/arctan2/hypot round differently
 * from these plain C loops: by rounding (tests/test_path_blend.py checks 1e-9 relative).
 * `line_run` is `line_blend` corner after corner bit for bit, and its pay test is
 * groupstream._blend_pays's float arithmetic in the same order (tests/test_blend_run.py).
 *
 * Rows of a corner (each `dim` doubles), in this order: centre, e1, e2, arc start (= first
 * line's new end), arc end (= second line's new start), via (the arc's midpoint), lin
 * (the arc's end correction), arc start tangent, arc end tangent, the arc's max |tangent|
 * per axis, its axis acceleration weight, the first line's direction, its |direction|, the
 * second line's direction, its |direction| (the arc's helix is zero: not written).
 * `line_run` reads three rows per line (start, end, direction) and its lengths; it writes
 * each corner's rows and, per corner, 8 scalars (kept: 1 or 0, then line_blend's seven),
 * and returns how many corners it did: it stops before a line whose start is not exactly
 * the end of the line before (the caller takes that corner with blend_corner's checks).
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <string.h>

#include "_blend.h"

#ifdef __clang__
#pragma STDC FP_CONTRACT OFF
#endif

#define TANGENT_ANGLE 1e-6  /* blend.TANGENT_ANGLE */
#define REVERSAL_ANGLE 1e-6 /* blend.REVERSAL_ANGLE */
#define MAX_DIM 64
#define ROWS 15
#define SCALARS 7 /* first length, second length, radius, sweep, arc length, kappa, dev */

enum { CENTRE, E1, E2, A_START, A_END, VIA, LIN, T_START, T_END, MAT, AAW, U1, ABS1, U2,
       ABS2 };
enum { L1, L2, RADIUS, TURN, LENGTH, KAPPA, DEV };

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

/* Python's min(a, b) and max(a, b): the first unless the second is smaller (larger) */
static double pymin(double a, double b) { return b < a ? b : a; }
static double pymax(double a, double b) { return b > a ? b : a; }

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

/* The corner p0 -> corner -> p2 of two lines (directions u1, u2, lengths len1, len2)
 * rounded within tol: 0 when it is straight or a reversal, else 1 with the rows of the
 * module doc in `out` and the scalars (enum above) in `sc`. */
static int corner_blend(double *out, double *sc, const double *p0, const double *corner,
                        const double *p2, const double *u1, const double *u2, double len1,
                        double len2, double tol, double frac, int dim)
{
    double *centre = out + CENTRE * dim, *e1 = out + E1 * dim, *e2 = out + E2 * dim,
           *a_start = out + A_START * dim, *a_end = out + A_END * dim, *via = out + VIA * dim,
           *lin = out + LIN * dim, *mat = out + MAT * dim, *aaw = out + AAW * dim;
    double dm[MAX_DIM], dp[MAX_DIM], diff[MAX_DIM];
    if (dim < 1) return 0; /* (the callers pass 1 to 64 axes) */
    for (int i = 0; i < dim; i++) {
        dm[i] = u1[i] - u2[i];
        dp[i] = u1[i] + u2[i];
        diff[i] = u2[i] - u1[i];
    }
    double cos_t = vnorm(dm, dim) / 2.0;
    double sin_t = vnorm(dp, dim) / 2.0;
    double turn = 2.0 * atan2(cos_t, sin_t);
    if (turn < TANGENT_ANGLE || M_PI - turn < REVERSAL_ANGLE) return 0;
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
        via[i] = centre[i] + r * (ch * e1[i] + sh * e2[i]);
        double last = centre[i] + r * (c * e1[i] + sn * e2[i]) + 0.0;
        lin[i] = 0.0 + (a_end[i] - last);
    }
    tangent_one(0.0, r, sw, length, e1, e2, out + T_START * dim, dim);
    tangent_one(length, r, sw, length, e1, e2, out + T_END * dim, dim);
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
    sc[L1] = line_between(p0, a_start, out + U1 * dim, out + ABS1 * dim, dim);
    sc[L2] = line_between(a_end, p2, out + U2 * dim, out + ABS2 * dim, dim);
    sc[RADIUS] = radius;
    sc[TURN] = turn;
    sc[LENGTH] = length;
    sc[KAPPA] = r / (r * r + 0.0 * 0.0);
    sc[DEV] = d * (1.0 - sin_t) / cos_t;
    return 1;
}

/* groupstream._blend_pays for a blend between two lines (no arc next to the corner) */
static double pay_time(double dist, double v0, double feed, double accel)
{
    dist = pymax(0.0, dist);
    double d_acc = (feed * feed - v0 * v0) / (2.0 * accel);
    if (dist <= d_acc) return (sqrt(v0 * v0 + 2.0 * accel * dist) - v0) / accel;
    return (feed - v0) / accel + (dist - d_acc) / feed;
}

static int blend_pays(const double *sc, double accel, double feed, double v_corner,
                      double trim1, double trim2)
{
    double length = sc[LENGTH], kappa = sc[KAPPA];
    if (kappa <= 0.0 || length <= 0.0) return 1;
    double radius = 1.0 / kappa;
    double phi = length / radius;
    double d = phi < M_PI * (1.0 - 1e-9) ? radius * tan(0.5 * phi) : NAN;
    if (!(isfinite(d) && d >= 0.0)) d = pymax(0.0, 0.5 * (trim1 + trim2));
    double v_c = pymin(feed, sqrt(sqrt(0.75) * accel * radius));
    double reach = pymin(sc[L1], sc[L2]) + d;
    double span = pymin(d + feed * feed / (2.0 * accel), reach);
    v_corner = pymin(v_corner, feed);
    return length / v_c + 2.0 * pay_time(pymax(0.0, span - d), v_c, feed, accel)
           < 2.0 * pay_time(span, v_corner, feed, accel);
}

/* a C-contiguous buffer of exactly n doubles (n < 0: any size, checked by the caller) */
static int get(PyObject *obj, Py_buffer *b, Py_ssize_t n, int writable)
{
    if (PyObject_GetBuffer(obj, b, PyBUF_C_CONTIGUOUS | (writable ? PyBUF_WRITABLE : 0)) < 0)
        return -1;
    if (b->len % (Py_ssize_t)sizeof(double) != 0
        || (n >= 0 && b->len != n * (Py_ssize_t)sizeof(double))) {
        PyBuffer_Release(b);
        PyErr_SetString(PyExc_ValueError, "buffer of the wrong size");
        return -1;
    }
    return 0;
}

static Py_ssize_t axes_of(Py_buffer *b)
{
    Py_ssize_t n = b->len / (Py_ssize_t)sizeof(double);
    if (n < 1 || n > MAX_DIM) {
        PyErr_SetString(PyExc_ValueError, "1 to 64 axes");
        return -1;
    }
    return n;
}

PyObject *blend_py_line_blend(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
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
    if (get(args[1], &b[0], -1, 0) < 0) return NULL;
    held = 1;
    Py_ssize_t n = axes_of(&b[0]);
    if (n < 0) goto done;
    for (int k = 2; k <= 5; k++) {
        if (get(args[k], &b[held], n, 0) < 0) goto done;
        held++;
    }
    if (get(args[0], &b[held], ROWS * n, 1) < 0) goto done;
    held++;
    double sc[SCALARS];
    if (!corner_blend(b[5].buf, sc, b[0].buf, b[1].buf, b[2].buf, b[3].buf, b[4].buf, len1,
                      len2, tol, frac, (int)n)) {
        result = Py_None;
        Py_INCREF(result);
        goto done;
    }
    result = Py_BuildValue("(ddddddd)", sc[L1], sc[L2], sc[RADIUS], sc[TURN], sc[LENGTH],
                           sc[KAPPA], sc[DEV]);
done:
    for (int q = 0; q < held; q++) PyBuffer_Release(&b[q]);
    return result;
}

PyObject *blend_py_line_run(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 8) {
        PyErr_SetString(PyExc_TypeError, "line_run takes 8 arguments");
        return NULL;
    }
    double tol = PyFloat_AsDouble(args[6]), frac = PyFloat_AsDouble(args[7]);
    if (PyErr_Occurred()) return NULL;
    int pays = args[4] != Py_None;
    Py_buffer b[6];
    int held = 0;
    PyObject *result = NULL;
    /* args: out, scal, geo (per line: start, end, direction), lengths, accel, feed, tol,
     * frac */
    if (get(args[3], &b[0], -1, 0) < 0) return NULL;
    held = 1;
    Py_ssize_t m = b[0].len / (Py_ssize_t)sizeof(double) - 1; /* corners */
    if (m < 1) {
        PyErr_SetString(PyExc_ValueError, "line_run: at least two lines");
        goto done;
    }
    if (get(args[2], &b[1], -1, 0) < 0) goto done;
    held = 2;
    Py_ssize_t n = b[1].len / (Py_ssize_t)sizeof(double) / (3 * (m + 1));
    if (n < 1 || n > MAX_DIM || b[1].len != 3 * (m + 1) * n * (Py_ssize_t)sizeof(double)) {
        PyErr_SetString(PyExc_ValueError, "line_run: 3 rows of 1 to 64 axes per line");
        goto done;
    }
    struct { int arg; Py_ssize_t size; int writable; } want[] = {
        {0, m * ROWS * n, 1}, {1, m * (SCALARS + 1), 1}, {4, m, 0}, {5, m, 0}};
    for (int q = 0; q < (pays ? 4 : 2); q++) {
        if (get(args[want[q].arg], &b[held], want[q].size, want[q].writable) < 0) goto done;
        held++;
    }
    const double *lengths = b[0].buf, *geo = b[1].buf;
    double *out = b[2].buf, *scal = b[3].buf;
    const double *accel = pays ? b[4].buf : NULL, *feed = pays ? b[5].buf : NULL;
    int dim = (int)n;
    /* the current first line: its start, direction and length (its end is line k's) */
    const double *cur_start = geo, *cur_u = geo + 2 * n;
    double cur_len = lengths[0];
    Py_ssize_t k = 0;
    for (; k < m; k++) {
        double *rows = out + k * ROWS * n, *sc = scal + k * (SCALARS + 1);
        const double *corner = geo + (3 * k + 1) * n, *next = geo + 3 * (k + 1) * n;
        const double *from = next, *end = next + n, *u = next + 2 * n;
        int same = 1;
        for (int i = 0; i < dim; i++) same &= from[i] == corner[i];
        if (!same) break; /* not where the line before ends: the caller's (a gap check) */
        double len = lengths[k + 1];
        int keep = 0;
        /* blend_corner: no blend next to a zero-length line */
        if (cur_len != 0.0 && len != 0.0
            && corner_blend(rows, sc + 1, cur_start, corner, end, cur_u, u, cur_len, len,
                            tol, frac, dim))
            keep = !pays || blend_pays(sc + 1, accel[k], feed[k], 0.0,
                                       cur_len - sc[1 + L1], len - sc[1 + L2]);
        sc[0] = keep;
        if (keep) {
            cur_start = rows + A_END * n;
            cur_u = rows + U2 * n;
            cur_len = sc[1 + L2];
        } else {
            cur_start = from; /* the second line as it was */
            cur_u = u;
            cur_len = len;
        }
    }
    result = PyLong_FromSsize_t(k);
done:
    for (int q = 0; q < held; q++) PyBuffer_Release(&b[q]);
    return result;
}
