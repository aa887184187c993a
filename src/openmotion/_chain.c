/* The chain planner's arithmetic passes, compiled into openmotion._corner (issue 14: the
 * streaming join re-plans the running chain, a few hundred elements, at every join).
 *
 * One narrow interface on flat lists and float64 buffers; the per-element limits and
 * junction caps come from _chain_prep.c (or lookahead.py's Python path), Python validates
 * every argument and builds the objects around the numbers:
 *
 * - passes(jcap2, acc, length, start2, dec): the look-ahead's backward pass from the
 *   junction caps (v**2) at the decelerations (None: the accelerations), then its forward
 *   pass from start2 (lookahead module doc, step 3) -> (back, fwd) lists;
 * - speeds(fwd, acc, dec, ccap, length): each element's entry, cruise and exit speed
 *   (step 4) -> three lists;
 * - curve(entry, cruise, exit, acc, dec, length, s0, v_first, out): the trapezoids as
 *   the knots of v**2(s) from s0 at v_first (pathexec.curve_from_speeds) written to
 *   out[0, :m] (s) and out[1, :m] (v**2) -> m;
 * - chain_curve(jcap2, acc, dec, ccap, length, start2, s0, out): the three in one
 *   call (no minimum cruise ratio) -> m, or -1 when start2 exceeds what the path allows
 *   at its start (the caller re-plans the slow way and raises there); its C core
 *   chain_knots is _chain_prep.c's prepare_curve's second half;
 * - s_pieces(knots, v2, v, s_end, dwell, lead, out): the constant-acceleration pieces of
 *   s(t) along the knots (pathexec.s_profile's loop) written as the columns t0, p0, v0,
 *   a0, dt, kind (1: a dwell) of out[0..5, :m] -> (m, duration), m = -1 when the curve
 *   stalls at rest before its end;
 * - crossings(p0, v0, a0, j, hi, levels): the times a segment of s(t) reaches a level
 *   (pathaxes._crossings' bisection, 60 halvings), written over hi;
 * - limit_along(limit, axis, weight): a limit lowered by per-axis caps over per-axis
 *   weights (lookahead._limit_along).
 *
 * Every formula repeats the Python operation order it replaced (the oracle in
 * tests/oracle_chain.py), built with -ffp-contract=off: the results are bit for bit the
 * same (tests/test_chain_planner.py). Python's min(a, b) / max(a, b) return the first of
 * equals: spelled out as such.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "_chain.h"

#ifdef __clang__
#pragma STDC FP_CONTRACT OFF
#endif

/* a Python sequence of floats -> a new C array (NULL with an exception set) */
static double *to_doubles(PyObject *seq, Py_ssize_t want, const char *name)
{
    PyObject *fast = PySequence_Fast(seq, name);
    if (fast == NULL) return NULL;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(fast);
    if (want >= 0 && n != want) {
        Py_DECREF(fast);
        PyErr_Format(PyExc_ValueError, "%s: %zd values, expected %zd", name, n, want);
        return NULL;
    }
    double *out = (double *)malloc(sizeof(double) * (size_t)(n > 0 ? n : 1));
    if (out == NULL) {
        Py_DECREF(fast);
        PyErr_NoMemory();
        return NULL;
    }
    PyObject **items = PySequence_Fast_ITEMS(fast);
    for (Py_ssize_t k = 0; k < n; k++) {
        double x = PyFloat_AsDouble(items[k]);
        if (x == -1.0 && PyErr_Occurred()) {
            free(out);
            Py_DECREF(fast);
            return NULL;
        }
        out[k] = x;
    }
    Py_DECREF(fast);
    return out;
}

static PyObject *to_list(const double *x, Py_ssize_t n)
{
    PyObject *out = PyList_New(n);
    if (out == NULL) return NULL;
    for (Py_ssize_t k = 0; k < n; k++) {
        PyObject *f = PyFloat_FromDouble(x[k]);
        if (f == NULL) {
            Py_DECREF(out);
            return NULL;
        }
        PyList_SET_ITEM(out, k, f);
    }
    return out;
}

static Py_ssize_t seq_len(PyObject *seq)
{
    Py_ssize_t n = PySequence_Size(seq);
    return n;
}

/* a writable C-contiguous float64 buffer of at least `rows` x `cols` doubles */
static int out_buffer(PyObject *obj, Py_buffer *b, Py_ssize_t rows, Py_ssize_t cols)
{
    if (PyObject_GetBuffer(obj, b, PyBUF_WRITABLE | PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0)
        return -1;
    if (b->itemsize != 8 || b->format == NULL || strcmp(b->format, "d") != 0 ||
        b->ndim != 2 || b->shape[0] < rows || b->shape[1] < cols) {
        PyBuffer_Release(b);
        PyErr_SetString(PyExc_ValueError, "out must be a float64 array of enough rows "
                                          "and columns");
        return -1;
    }
    return 0;
}

/* ------------------------------------------------------------------ the rules */

/* lookahead._passes: back[0..n], fwd[0..n] */
static void passes(const double *jcap2, const double *acc, const double *length,
                   double start2, const double *dec, Py_ssize_t n, double *back,
                   double *fwd)
{
    for (Py_ssize_t k = 0; k <= n; k++) back[k] = jcap2[k];
    double nxt = back[n];
    for (Py_ssize_t k = n - 1; k >= 0; k--) {
        double dvb = dec == NULL ? 2.0 * acc[k] * length[k] : 2.0 * dec[k] * length[k];
        double x = nxt + dvb;
        double c = jcap2[k];
        nxt = back[k] = c <= x ? c : x;
    }
    double cur = fwd[0] = start2 <= back[0] ? start2 : back[0];
    for (Py_ssize_t k = 0; k < n; k++) {
        double x = cur + 2.0 * acc[k] * length[k];
        double c = back[k + 1];
        cur = fwd[k + 1] = c <= x ? c : x;
    }
}

/* lookahead._peak2 */
static double peak2(double in2, double out2, double a, double d, double length)
{
    if (a == d) return 0.5 * (in2 + out2) + a * length;
    return (d * in2 + a * out2 + 2.0 * a * d * length) / (a + d);
}

/* plan_speeds' step 4: entry, cruise, exit of each element */
static void speeds(const double *fwd, const double *acc, const double *dec,
                   const double *ccap, const double *length, Py_ssize_t n, double *entry,
                   double *cruise, double *exit_)
{
    for (Py_ssize_t k = 0; k < n; k++) {
        double vin = sqrt(fwd[k]), vout = sqrt(fwd[k + 1]);
        double p2 = peak2(fwd[k], fwd[k + 1], acc[k], dec[k], length[k]);
        double top = sqrt(p2);
        double m = ccap[k];
        if (top < m) m = top;  /* min(ccap, sqrt(peak2)) */
        double c = vin;        /* max(vin, vout, m) */
        if (vout > c) c = vout;
        if (m > c) c = m;
        entry[k] = vin;
        cruise[k] = c;
        exit_[k] = vout;
    }
}

/* x ** 2 as CPython's float power computes it: libm's pow(x, 2.0), which rounds
 * differently from x * x now and then; called through a volatile pointer so the compiler
 * cannot turn it into x * x */
static double (*volatile libm_pow)(double, double) = pow;
static double sq(double x) { return libm_pow(x, 2.0); }

/* pathexec.curve_from_speeds: the knots in s[0..m-1], v2[0..m-1] (room for 3n + 1 of
 * each) from s0 at v_first (the first element's entry) over the elements (those of
 * length 0 are skipped); returns m */
static Py_ssize_t curve(const double *entry, const double *cruise, const double *exit_,
                        const double *acc, const double *dec, const double *length,
                        Py_ssize_t n, double s0, double v_first, double *s, double *v2)
{
    Py_ssize_t m = 0;
    s[m] = s0;
    v2[m++] = sq(v_first);
    double pos = s0;
    for (Py_ssize_t k = 0; k < n; k++) {
        double L = length[k];
        if (L == 0.0) continue;
        double a = acc[k], vc2 = sq(cruise[k]);
        double d_acc = (vc2 - sq(entry[k])) / (2.0 * a);
        if (!(d_acc > 0.0)) d_acc = 0.0;
        double d_dec = (vc2 - sq(exit_[k])) / (2.0 * dec[k]);
        if (!(d_dec > 0.0)) d_dec = 0.0;
        if (d_acc + d_dec > L) { /* rounding: no cruise */
            double x = L;
            if (d_acc < x) x = d_acc;
            d_acc = x > 0.0 ? x : 0.0;
            d_dec = L - d_acc;
        }
        if (d_acc > 0.0) {
            s[m] = s[m - 1] + d_acc;
            v2[m++] = vc2;
        }
        double hold = L - d_acc - d_dec;
        if (hold > 0.0) {
            s[m] = s[m - 1] + hold;
            v2[m++] = vc2;
        }
        pos += L;
        s[m] = pos;
        v2[m++] = sq(exit_[k]);
    }
    for (Py_ssize_t k = 0; k < m; k++)
        if (v2[k] < 0.0) v2[k] = 0.0; /* np.maximum(v2, 0.0) */
    /* drop zero-length pieces (the first and the last knot stay) */
    Py_ssize_t w = 1;
    for (Py_ssize_t k = 1; k < m; k++) {
        if (k == m - 1 || s[k] - s[k - 1] > 0.0) {
            s[w] = s[k];
            v2[w++] = v2[k];
        }
    }
    m = m > 0 ? w : 0;
    if (m > 1 && s[m - 2] >= s[m - 1]) { /* np.delete(s, -2) */
        s[m - 2] = s[m - 1];
        v2[m - 2] = v2[m - 1];
        m--;
    }
    return m;
}

/* pathexec.s_profile's loop; returns m (rows written) or -1 (stall), *t_out the duration */
static Py_ssize_t s_pieces(const double *knots, const double *v2, const double *v,
                           Py_ssize_t nk, double s_end, double dwell, double lead,
                           double *t0, double *p0, double *v0, double *a0, double *dtv,
                           double *kind, double *t_out)
{
    double p = knots[0], vcur = v[0], acur = 0.0, t = 0.0;
    Py_ssize_t m = 0;
#define PIECE(DT, KIND)                                                  \
    do {                                                                 \
        double dt_ = (DT);                                               \
        t0[m] = t; p0[m] = p; v0[m] = vcur; a0[m] = acur; dtv[m] = dt_;  \
        kind[m++] = (KIND);                                              \
        p = p + dt_ * (vcur + dt_ * (acur / 2.0 + dt_ * 0.0 / 6.0));     \
        vcur = vcur + dt_ * (acur + dt_ * 0.0 / 2.0);                    \
        acur = acur + dt_ * 0.0;                                         \
        t += dt_;                                                        \
    } while (0)
    if (lead > 0.0) {
        acur = 0.0;
        PIECE(lead, 1.0);
    }
    Py_ssize_t nd = nk - 1, last = nd - 1;
    double top = 0.0; /* v.max(initial=0.0) */
    for (Py_ssize_t k = 0; k < nk; k++)
        if (v[k] > top || v[k] != v[k]) top = v[k];
    double crawl = 2e-6 * top;
    double slack = 1e-9 * (s_end > 1.0 ? s_end : 1.0);
    for (Py_ssize_t k = 0; k < nd; k++) {
        double d = knots[k + 1] - knots[k];
        if (d <= 0.0) continue;
        double a = (v2[k + 1] - v2[k]) / (2.0 * d);
        double vm = v[k] + v[k + 1];
        if (vm <= 0.0 || (2.0 * d / vm > 1e6 && vm < crawl)) {
            if (d <= slack) continue; /* a sliver left by rounding: step over it */
            return -1;
        }
        double dt = 2.0 * d / vm;
        vcur = v[k];
        acur = a;
        if (dt > 0.0) PIECE(dt, 0.0);
        if (dwell > 0.0 && v[k + 1] == 0.0 && k < last) {
            vcur = 0.0;
            acur = 0.0;
            PIECE(dwell, 1.0);
        }
    }
#undef PIECE
    *t_out = t;
    return m;
}

/* ------------------------------------------------------------------ Python wrappers */

PyObject *chain_py_passes(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 5) {
        PyErr_SetString(PyExc_TypeError, "passes(jcap2, acc, length, start2, dec)");
        return NULL;
    }
    Py_ssize_t n = seq_len(args[2]);
    if (n < 0) return NULL;
    double start2 = PyFloat_AsDouble(args[3]);
    if (start2 == -1.0 && PyErr_Occurred()) return NULL;
    PyObject *result = NULL;
    double *jcap2 = NULL, *acc = NULL, *length = NULL, *dec = NULL, *back = NULL;
    jcap2 = to_doubles(args[0], n + 1, "jcap2");
    acc = jcap2 ? to_doubles(args[1], n, "acc") : NULL;
    length = acc ? to_doubles(args[2], n, "length") : NULL;
    if (length == NULL) goto done;
    if (args[4] != Py_None && (dec = to_doubles(args[4], n, "dec")) == NULL) goto done;
    back = (double *)malloc(sizeof(double) * (size_t)(2 * n + 2));
    if (back == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    passes(jcap2, acc, length, start2, dec, n, back, back + n + 1);
    PyObject *b = to_list(back, n + 1), *f = b ? to_list(back + n + 1, n + 1) : NULL;
    if (f != NULL) result = PyTuple_Pack(2, b, f);
    Py_XDECREF(b);
    Py_XDECREF(f);
done:
    free(jcap2);
    free(acc);
    free(length);
    free(dec);
    free(back);
    return result;
}

PyObject *chain_py_speeds(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 5) {
        PyErr_SetString(PyExc_TypeError, "speeds(fwd, acc, dec, ccap, length)");
        return NULL;
    }
    Py_ssize_t n = seq_len(args[4]);
    if (n < 0) return NULL;
    PyObject *result = NULL;
    double *fwd = NULL, *acc = NULL, *dec = NULL, *ccap = NULL, *length = NULL, *o = NULL;
    fwd = to_doubles(args[0], n + 1, "fwd");
    acc = fwd ? to_doubles(args[1], n, "acc") : NULL;
    dec = acc ? to_doubles(args[2], n, "dec") : NULL;
    ccap = dec ? to_doubles(args[3], n, "ccap") : NULL;
    length = ccap ? to_doubles(args[4], n, "length") : NULL;
    if (length == NULL) goto done;
    o = (double *)malloc(sizeof(double) * (size_t)(3 * n + 1));
    if (o == NULL) {
        PyErr_NoMemory();
        goto done;
    }
    speeds(fwd, acc, dec, ccap, length, n, o, o + n, o + 2 * n);
    PyObject *e = to_list(o, n), *c = e ? to_list(o + n, n) : NULL;
    PyObject *x = c ? to_list(o + 2 * n, n) : NULL;
    if (x != NULL) result = PyTuple_Pack(3, e, c, x);
    Py_XDECREF(e);
    Py_XDECREF(c);
    Py_XDECREF(x);
done:
    free(fwd);
    free(acc);
    free(dec);
    free(ccap);
    free(length);
    free(o);
    return result;
}

PyObject *chain_py_curve(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 9) {
        PyErr_SetString(PyExc_TypeError,
                        "curve(entry, cruise, exit, acc, dec, length, s0, v_first, out)");
        return NULL;
    }
    Py_ssize_t n = seq_len(args[5]);
    if (n < 0) return NULL;
    double s0 = PyFloat_AsDouble(args[6]), v_first = PyFloat_AsDouble(args[7]);
    if (PyErr_Occurred()) return NULL;
    PyObject *result = NULL;
    double *x[6] = {NULL, NULL, NULL, NULL, NULL, NULL};
    static const char *names[6] = {"entry", "cruise", "exit", "acc", "dec", "length"};
    for (int q = 0; q < 6; q++)
        if ((x[q] = to_doubles(args[q], n, names[q])) == NULL) goto done;
    Py_buffer b;
    if (out_buffer(args[8], &b, 2, 3 * n + 1) < 0) goto done;
    double *s = (double *)b.buf;
    Py_ssize_t m = curve(x[0], x[1], x[2], x[3], x[4], x[5], n, s0, v_first, s,
                         s + b.shape[1]);
    PyBuffer_Release(&b);
    result = PyLong_FromSsize_t(m);
done:
    for (int q = 0; q < 6; q++) free(x[q]);
    return result;
}

/* plan_speeds' steps 3-4 and curve_from_speeds in one pass (no minimum cruise ratio):
 * the knots in s[0..m-1], v2[0..m-1] (room for 3n + 1 of each) -> m; -1 when start2
 * exceeds what the path allows at its start (plan_speeds raises InfeasibleError), -2 out
 * of memory (an exception set). Shared with _chain_prep.c. */
Py_ssize_t chain_knots(const double *jcap2, const double *acc, const double *dec,
                       const double *ccap, const double *length, Py_ssize_t n,
                       double start2, double s0, double *s, double *v2)
{
    double *w = (double *)malloc(sizeof(double) * (size_t)(5 * n + 3));
    if (w == NULL) {
        PyErr_NoMemory();
        return -2;
    }
    double *back = w, *fwd = w + n + 1, *cr = w + 2 * n + 2;
    passes(jcap2, acc, length, start2, dec, n, back, fwd);
    Py_ssize_t m = -1;
    if (!(start2 > back[0] * (1.0 + 1e-12))) {
        double *entry = back; /* back is no longer needed: entry over it */
        /* fwd is read while entry (over back) is written: distinct ranges */
        speeds(fwd, acc, dec, ccap, length, n, entry, cr, cr + n);
        m = curve(entry, cr, cr + n, acc, dec, length, n, s0, entry[0], s, v2);
    }
    free(w);
    return m;
}

PyObject *chain_py_chain_curve(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 8) {
        PyErr_SetString(PyExc_TypeError, "chain_curve(jcap2, acc, dec, ccap, length, start2, "
                                         "s0, out)");
        return NULL;
    }
    Py_ssize_t n = seq_len(args[4]);
    if (n < 0) return NULL;
    if (n == 0) {
        PyErr_SetString(PyExc_ValueError, "chain_curve: no elements");
        return NULL;
    }
    double start2 = PyFloat_AsDouble(args[5]), s0 = PyFloat_AsDouble(args[6]);
    if (PyErr_Occurred()) return NULL;
    PyObject *result = NULL;
    double *jcap2 = NULL, *acc = NULL, *dec = NULL, *ccap = NULL, *length = NULL;
    jcap2 = to_doubles(args[0], n + 1, "jcap2");
    acc = jcap2 ? to_doubles(args[1], n, "acc") : NULL;
    dec = acc ? to_doubles(args[2], n, "dec") : NULL;
    ccap = dec ? to_doubles(args[3], n, "ccap") : NULL;
    length = ccap ? to_doubles(args[4], n, "length") : NULL;
    if (length == NULL) goto done;
    Py_buffer b;
    if (out_buffer(args[7], &b, 2, 3 * n + 1) < 0) goto done;
    double *s = (double *)b.buf;
    Py_ssize_t m = chain_knots(jcap2, acc, dec, ccap, length, n, start2, s0, s,
                               s + b.shape[1]);
    PyBuffer_Release(&b);
    if (m != -2) result = PyLong_FromSsize_t(m);
done:
    free(jcap2);
    free(acc);
    free(dec);
    free(ccap);
    free(length);
    return result;
}

PyObject *chain_py_s_pieces(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 7) {
        PyErr_SetString(PyExc_TypeError, "s_pieces(knots, v2, v, s_end, dwell, lead, out)");
        return NULL;
    }
    double s_end = PyFloat_AsDouble(args[3]), dwell = PyFloat_AsDouble(args[4]);
    double lead = PyFloat_AsDouble(args[5]);
    if (PyErr_Occurred()) return NULL;
    Py_buffer in[3];
    int held = 0;
    PyObject *result = NULL;
    for (; held < 3; held++) {
        if (PyObject_GetBuffer(args[held], &in[held], PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0)
            goto done;
        if (in[held].itemsize != 8 || in[held].format == NULL ||
            strcmp(in[held].format, "d") != 0 || in[held].ndim != 1) {
            held++;
            PyErr_SetString(PyExc_ValueError, "s_pieces: float64 vectors expected");
            goto done;
        }
    }
    Py_ssize_t nk = in[0].shape[0];
    if (nk < 1 || in[1].shape[0] != nk || in[2].shape[0] != nk) {
        PyErr_SetString(PyExc_ValueError, "s_pieces: knots, v2 and v of one length >= 1");
        goto done;
    }
    Py_buffer b;
    if (out_buffer(args[6], &b, 6, 2 * nk + 1) < 0) goto done;
    double *o = (double *)b.buf;
    Py_ssize_t c = b.shape[1];
    double t = 0.0;
    Py_ssize_t m = s_pieces((double *)in[0].buf, (double *)in[1].buf, (double *)in[2].buf,
                            nk, s_end, dwell, lead, o, o + c, o + 2 * c, o + 3 * c,
                            o + 4 * c, o + 5 * c, &t);
    PyBuffer_Release(&b);
    result = Py_BuildValue("(nd)", m, t);
done:
    for (int q = 0; q < held; q++) PyBuffer_Release(&in[q]);
    return result;
}

/* pathaxes._crossings' bisection: for each level, 60 halvings of [0, hi] in the segment
 * (p0, v0, a0, j) that holds it, hi kept where the cubic is >= the level (in place) */
PyObject *chain_py_crossings(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 6) {
        PyErr_SetString(PyExc_TypeError, "crossings(p0, v0, a0, j, hi, levels)");
        return NULL;
    }
    Py_buffer b[6];
    int held = 0;
    PyObject *result = NULL;
    for (; held < 6; held++) {
        int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (held == 4 ? PyBUF_WRITABLE : 0);
        if (PyObject_GetBuffer(args[held], &b[held], flags) < 0) goto done;
        if (b[held].itemsize != 8 || b[held].format == NULL ||
            strcmp(b[held].format, "d") != 0 || b[held].ndim != 1 ||
            b[held].shape[0] != b[0].shape[0]) {
            held++;
            PyErr_SetString(PyExc_ValueError, "crossings: float64 vectors of one length");
            goto done;
        }
    }
    const double *p0 = b[0].buf, *v0 = b[1].buf, *a0 = b[2].buf, *j = b[3].buf;
    const double *lv = b[5].buf;
    double *hi = b[4].buf;
    for (Py_ssize_t i = 0; i < b[0].shape[0]; i++) {
        double lo = 0.0, h = hi[i];
        for (int it = 0; it < 60; it++) {
            double mid = 0.5 * (lo + h);
            double p = p0[i] + mid * (v0[i] + mid * (a0[i] / 2.0 + mid * j[i] / 6.0));
            if (p < lv[i])
                lo = mid;
            else
                h = mid;
        }
        hi[i] = h;
    }
    result = Py_None;
    Py_INCREF(result);
done:
    for (int q = 0; q < held; q++) PyBuffer_Release(&b[q]);
    return result;
}

/* lookahead._limit_along: min(limit, axis_i / weight_i) over the axes with weight_i > 0
 * (the first of equals, as Python's min) */
PyObject *chain_py_limit_along(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 3) {
        PyErr_SetString(PyExc_TypeError, "limit_along(limit, axis, weight)");
        return NULL;
    }
    double limit = PyFloat_AsDouble(args[0]);
    if (limit == -1.0 && PyErr_Occurred()) return NULL;
    Py_buffer a, w;
    if (PyObject_GetBuffer(args[1], &a, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) return NULL;
    if (PyObject_GetBuffer(args[2], &w, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) {
        PyBuffer_Release(&a);
        return NULL;
    }
    PyObject *result = NULL;
    if (a.itemsize != 8 || w.itemsize != 8 || a.format == NULL || w.format == NULL ||
        strcmp(a.format, "d") != 0 || strcmp(w.format, "d") != 0 ||
        a.len != w.len) {
        PyErr_SetString(PyExc_ValueError, "limit_along: two float64 arrays of one size");
        goto done;
    }
    result = PyFloat_FromDouble(chain_limit_along(limit, a.buf, w.buf, (long)(a.len / 8)));
done:
    PyBuffer_Release(&a);
    PyBuffer_Release(&w);
    return result;
}
