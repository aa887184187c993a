/* The jerk-limited profile builder, compiled (openmotion._profile): the phase times of the
 * time-optimal rest-to-rest move and its seven polynomial pieces, for one axis, for several
 * axes synchronised to one duration, and for arrays of moves (profile/jerk.py and
 * profile/batch.py call it; the derivation is in jerk.py's module notes).
 *
 * A separate extension module: it shares no state with the runtime kernel and has a narrow
 * interface of its own (floats and float64 buffers in, phase times or piece columns out).
 * Python validates the user's arguments first and builds the Profile objects around the
 * pieces; this file only does the arithmetic of the inner loop.
 *
 * Every formula repeats the operation order of the plain-float Python version kept as the
 * oracle in tests/jerk_oracle.py, so the results are the same floats bit for bit (built with
 * -ffp-contract=off: no fused multiply-add; x ** y is pow(x, y) as in CPython; Python's
 * min/max are `pymin`/`pymax`, which keep the first argument on ties; `fsum` is the exactly
 * rounded sum of math.fsum).
 *
 * Piece columns: a bytearray of 6*n doubles, field-major (t0[n], p0[n], v0[n], a0[n], j[n],
 * dt[n]); a piece exists only for a phase that lasts (dt > 0); the mask's bit k says that
 * phase k (jerk.PHASE_LABELS order) has its piece.
 */
#include "_profile.h"
#include <math.h>
#include <string.h>

#ifdef __clang__
#pragma STDC FP_CONTRACT OFF
#endif

#define NEWTON_STEPS 10 /* jerk.NEWTON_STEPS */
#define NFIELDS 6

static inline double pymin(double a, double b) { return b < a ? b : a; }
static inline double pymax(double a, double b) { return b > a ? b : a; }

/* ------------------------------------------------------------- exact sum (math.fsum) */
/* Shewchuk's partials with the final round-half-even correction; finite inputs only. */
static double fsum(const double *xs, int n)
{
    double p[16];
    int np_ = 0;
    for (int i = 0; i < n; i++) {
        double x = xs[i];
        int k = 0;
        for (int m = 0; m < np_; m++) {
            double y = p[m];
            if (fabs(x) < fabs(y)) {
                double t = x;
                x = y;
                y = t;
            }
            double hi = x + y;
            double yr = hi - x;
            double lo = y - yr;
            if (lo != 0.0) p[k++] = lo;
            x = hi;
        }
        np_ = k;
        if (x != 0.0) p[np_++] = x;
    }
    double hi = 0.0, lo = 0.0;
    if (np_ > 0) {
        hi = p[--np_];
        while (np_ > 0) {
            double x = hi, y = p[--np_];
            hi = x + y;
            double yr = hi - x;
            lo = y - yr;
            if (lo != 0.0) break;
        }
        if (np_ > 0 && ((lo < 0.0 && p[np_ - 1] < 0.0) || (lo > 0.0 && p[np_ - 1] > 0.0))) {
            double y = lo * 2.0, x = hi + y, yr = x - hi;
            if (y == yr) hi = x;
        }
    }
    return hi;
}

/* math.fsum of seven finite values, fast: a cascade of exact two-sums gives the float sum
 * s and error terms e_k with s + sum(e_k) exact; r = fl(s + fl(sum e_k)) is the exactly
 * rounded sum whenever the rest, bounded by |e2| + 8u*sum|e_k|, stays strictly inside half
 * the gap to r's neighbours. Otherwise (near a tie, or r = 0) the full `fsum` decides. */
static double fsum7(const double *x)
{
    double s = x[0], c = 0.0, ca = 0.0;
    for (int k = 1; k < 7; k++) {
        double t = s + x[k];
        double bp = t - s;
        double e = (s - (t - bp)) + (x[k] - bp);
        s = t;
        c += e;
        ca += fabs(e);
    }
    double r = s + c;
    double bp = r - s;
    double e2 = (s - (r - bp)) + (c - bp);
    double up = nextafter(r, INFINITY) - r, down = r - nextafter(r, 0.0);
    double half = 0.5 * (up < down ? up : down);
    if (fabs(e2) + 8.0 * 1.1102230246251565e-16 * ca < half) return r;
    return fsum(x, 7);
}

/* ------------------------------------------------------------ closed-form pieces */
static void ramp(double v, double x, double j, double *tj, double *ta)
{
    if (v * j >= x * x) {
        *tj = x / j;
        *ta = v / x - x / j;
    } else {
        *tj = sqrt(v / j);
        *ta = 0.0;
    }
}

static double ramp_distance(double v, double x, double j)
{
    if (v * j >= x * x) return v * (v / x + x / j) / 2.0;
    return v * sqrt(v / j);
}

static double mixed_root(double length, double h, double j, double u_hi)
{
    double sj = sqrt(j);
    double u = u_hi, c;
    c = pow(2.0 * h * length, 0.25);
    if (c < u) u = c;
    c = pow(length * sj, 1.0 / 3.0);
    if (c < u) u = c;
    c = sqrt(2.0 * j * length / h);
    if (c < u) u = c;
    for (int k = 0; k < NEWTON_STEPS; k++) {
        double u2 = u * u;
        double g = u2 * u2 / (2.0 * h) + u2 * u / sj + u2 * h / (2.0 * j) - length;
        double dg = 2.0 * u2 * u / h + 3.0 * u2 / sj + u * h / j;
        if (g <= 0.0 || dg <= 0.0) break;
        double nxt = u - g / dg;
        if (!(nxt < u)) break;
        u = nxt;
    }
    return u;
}

static double peak_velocity(double length, double v_max, double a_max, double d_max,
                            double j_max)
{
    if (ramp_distance(v_max, a_max, j_max) + ramp_distance(v_max, d_max, j_max) <= length)
        return v_max;
    double lo = pymin(a_max, d_max), hi = pymax(a_max, d_max);
    double v2 = hi * hi / j_max;
    if (ramp_distance(v2, hi, j_max) + ramp_distance(v2, lo, j_max) <= length) {
        double k = (1.0 / a_max + 1.0 / d_max) / 2.0;
        double c = (a_max + d_max) / (2.0 * j_max);
        return 2.0 * length / (c + sqrt(c * c + 4.0 * k * length));
    }
    if (length <= 2.0 * lo * lo * lo / (j_max * j_max))
        return pow(length * sqrt(j_max) / 2.0, 2.0 / 3.0);
    double u = mixed_root(length, lo, j_max, sqrt(v2));
    return pymin(u * u, v_max);
}

/* The seven phase times of a move of `length` > 0 with peak velocity vp (cruise capped at
 * v_cap when has_cap). */
static void times_at(double length, double v_max, double a_max, double d_max, double j_max,
                     double vp, int has_cap, double v_cap, double *out)
{
    if (has_cap && v_cap < vp) {
        vp = v_cap;
    } else if (vp < v_max && vp * j_max < pow(pymin(a_max, d_max), 2.0)) {
        /* pure jerk triangle: tj straight from L = 2*J*tj**3 */
        double tj = pow(length / (2.0 * j_max), 1.0 / 3.0);
        out[0] = out[2] = out[4] = out[6] = tj;
        out[1] = out[3] = out[5] = 0.0;
        return;
    }
    double tj1, ta, tj2, td;
    ramp(vp, a_max, j_max, &tj1, &ta);
    ramp(vp, d_max, j_max, &tj2, &td);
    double rest = length - ramp_distance(vp, a_max, j_max) - ramp_distance(vp, d_max, j_max);
    out[0] = tj1;
    out[1] = ta;
    out[2] = tj1;
    out[3] = pymax(0.0, rest / vp);
    out[4] = tj2;
    out[5] = td;
    out[6] = tj2;
}

static void phase_times(double length, double v_max, double a_max, double d_max,
                        double j_max, double *out)
{
    if (length <= 0.0) {
        for (int k = 0; k < 7; k++) out[k] = 0.0;
        return;
    }
    times_at(length, v_max, a_max, d_max, j_max,
             peak_velocity(length, v_max, a_max, d_max, j_max), 0, 0.0, out);
}

static int all_finite(const double *t)
{
    for (int k = 0; k < 7; k++)
        if (!isfinite(t[k])) return 0;
    return 1;
}

/* T(vc) = T_acc/2 + T_dec/2 + L/vc and dT/dvc */
static void capped_duration(double vc, double length, double a_max, double d_max,
                            double j_max, double *t, double *dt)
{
    double xs[2] = {a_max, d_max};
    *t = length / vc;
    *dt = -length / (vc * vc);
    for (int k = 0; k < 2; k++) {
        double x = xs[k];
        if (vc * j_max >= x * x) {
            *t += (vc / x + x / j_max) / 2.0;
            *dt += 0.5 / x;
        } else {
            *t += sqrt(vc / j_max);
            *dt += 0.5 / sqrt(vc * j_max);
        }
    }
}

/* Cruise cap vc whose capped move lasts exactly t_target (>= the optimum); hi: the move's
 * peak velocity. Newton from L/T (or the both-limits quadratic's root), bracketed. */
static double synced_cap(double length, double t_target, double a_max, double d_max,
                         double j_max, double hi)
{
    double lo = length / t_target;
    double k = 0.5 * (1.0 / a_max + 1.0 / d_max);
    double c = (a_max + d_max) / (2.0 * j_max);
    double b = t_target - c;
    double disc = b * b - 4.0 * k * length;
    double vc = lo;
    if (b > 0.0 && disc >= 0.0) {
        double q = (b + sqrt(disc)) / (2.0 * k);
        if (lo < q && q < hi && q * j_max >= pow(pymax(a_max, d_max), 2.0)) vc = q;
    }
    for (int it = 0; it < 200; it++) {
        double t, dt;
        capped_duration(vc, length, a_max, d_max, j_max, &t, &dt);
        double err = t - t_target;
        if (err == 0.0) return vc;
        if (err > 0.0)
            lo = vc;
        else
            hi = vc;
        double nxt = dt < 0.0 ? vc - err / dt : 0.5 * (lo + hi);
        if (!(lo < nxt && nxt < hi)) nxt = 0.5 * (lo + hi);
        if (nxt == lo || nxt == hi || hi - lo <= 4e-16 * hi) break;
        vc = nxt;
    }
    return vc;
}

/* The pieces of the phases that last, written at column offset `at` of `cols` (6 fields of
 * `stride` doubles each); returns the mask, *t_end the end time. */
static int build_pieces(double start, double distance, const double *times, double a_max,
                        double d_max, double j_max, double *cols, Py_ssize_t stride,
                        Py_ssize_t at, double *t_end)
{
    double dr = distance >= 0.0 ? 1.0 : -1.0;
    double tj1 = times[0], ta = times[1], tv = times[3], tj2 = times[4], td = times[5];
    double a_pk = pymin(a_max, j_max * tj1);
    double d_pk = pymin(d_max, j_max * tj2);
    double z = 0.0 * dr, ap = a_pk * dr, dn = -d_pk * dr;
    double jp = j_max * dr, jn = -j_max * dr;
    const double dts[7] = {tj1, ta, tj1, tv, tj2, td, tj2};
    const double acc[7] = {z, ap, ap, z, z, dn, dn};
    const double jerk[7] = {jp, z, jn, z, jn, z, jp};
    double p = start, v = 0.0 * dr, t = 0.0;
    int mask = 0;
    Py_ssize_t n = at;
    for (int k = 0; k < 7; k++) {
        double dt = dts[k], a0 = acc[k], jk = jerk[k];
        if (!(dt > 0.0)) continue;
        if (cols != NULL) {
            cols[n] = t;
            cols[stride + n] = p;
            cols[2 * stride + n] = v;
            cols[3 * stride + n] = a0;
            cols[4 * stride + n] = jk;
            cols[5 * stride + n] = dt;
        }
        n++;
        mask |= 1 << k;
        p = p + dt * (v + dt * (a0 / 2.0 + dt * jk / 6.0));
        v = v + dt * (a0 + dt * jk / 2.0);
        t += dt;
    }
    *t_end = t;
    return mask;
}

static int count_pieces(const double *times)
{
    int n = 0;
    for (int k = 0; k < 7; k++) n += times[k] > 0.0;
    return n;
}

/* ------------------------------------------------------------------ arguments */
static int floats(PyObject *const *args, Py_ssize_t nargs, Py_ssize_t want, double *out,
                  const char *fn)
{
    if (nargs != want) {
        PyErr_Format(PyExc_TypeError, "%s takes %zd arguments", fn, want);
        return -1;
    }
    for (Py_ssize_t k = 0; k < want; k++) {
        PyObject *o = args[k];
        out[k] = PyFloat_CheckExact(o) ? PyFloat_AS_DOUBLE(o) : PyFloat_AsDouble(o);
        if (out[k] == -1.0 && PyErr_Occurred()) return -1;
    }
    return 0;
}

static PyObject *times_tuple(const double *t)
{
    PyObject *out = PyTuple_New(7);
    if (out == NULL) return NULL;
    for (int k = 0; k < 7; k++) {
        PyObject *x = PyFloat_FromDouble(t[k]);
        if (x == NULL) {
            Py_DECREF(out);
            return NULL;
        }
        PyTuple_SET_ITEM(out, k, x);
    }
    return out;
}

/* ------------------------------------------------------------------ entry points */
PyDoc_STRVAR(phase_times_doc,
             "phase_times(length, v_max, a_max, d_max, j_max) -> the seven phase times\n"
             "of the fastest rest-to-rest move of `length` >= 0 (validated limits).");

static PyObject *py_phase_times(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    double x[5], t[7];
    if (floats(args, nargs, 5, x, "phase_times") < 0) return NULL;
    phase_times(x[0], x[1], x[2], x[3], x[4], t);
    return times_tuple(t);
}

PyDoc_STRVAR(duration_doc,
             "duration(length, v_max, a_max, d_max, j_max) -> math.fsum of the phase times,\n"
             "or None when a phase time is not finite.");

static PyObject *py_duration(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    double x[5], t[7];
    if (floats(args, nargs, 5, x, "duration") < 0) return NULL;
    phase_times(x[0], x[1], x[2], x[3], x[4], t);
    if (!all_finite(t)) Py_RETURN_NONE;
    return PyFloat_FromDouble(fsum7(t));
}

PyDoc_STRVAR(rest_to_rest_doc,
             "rest_to_rest(start, distance, v_max, a_max, d_max, j_max) -> (columns, mask,\n"
             "end time) of the fastest move of `distance` from `start`, or None when a\n"
             "phase time is not finite.");

static PyObject *py_rest_to_rest(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    double x[6], t[7], t_end;
    if (floats(args, nargs, 6, x, "rest_to_rest") < 0) return NULL;
    phase_times(fabs(x[1]), x[2], x[3], x[4], x[5], t);
    if (!all_finite(t)) Py_RETURN_NONE;
    Py_ssize_t n = count_pieces(t);
    PyObject *buf = PyByteArray_FromStringAndSize(NULL, NFIELDS * n * (Py_ssize_t)sizeof(double));
    if (buf == NULL) return NULL;
    int mask = build_pieces(x[0], x[1], t, x[3], x[4], x[5],
                            (double *)PyByteArray_AS_STRING(buf), n, 0, &t_end);
    return Py_BuildValue("(Nid)", buf, mask, t_end);
}

#define MAX_STACK_AXES 16

PyDoc_STRVAR(synced_doc,
             "synced(distances, starts, v_max, a_max, d_max, j_max) -> (T, columns, masks)\n"
             "for axes that start together and all last T (sequences of validated floats,\n"
             "one per axis); masks[i] is -1 for an axis that does not move (it dwells).\n"
             "None when a phase time is not finite. With T <= 0 there are no pieces.");

static PyObject *py_synced(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 6) {
        PyErr_SetString(PyExc_TypeError, "synced takes 6 arguments");
        return NULL;
    }
    PyObject *seq[6] = {NULL};
    PyObject *result = NULL;
    double stack[MAX_STACK_AXES * 14];
    double *mem = stack;
    Py_ssize_t n = -1;
    for (int k = 0; k < 6; k++) {
        seq[k] = PySequence_Fast(args[k], "synced: sequences of floats expected");
        if (seq[k] == NULL) goto done;
        Py_ssize_t len = PySequence_Fast_GET_SIZE(seq[k]);
        if (n < 0) n = len;
        if (len != n) {
            PyErr_SetString(PyExc_ValueError, "synced: one value per axis expected");
            goto done;
        }
    }
    if (n > MAX_STACK_AXES) {
        mem = PyMem_Malloc((size_t)n * 14 * sizeof(double));
        if (mem == NULL) {
            PyErr_NoMemory();
            goto done;
        }
    }
    /* per axis: 6 inputs (distance, start, v, a, d, j), 7 times, 1 peak velocity */
    for (Py_ssize_t i = 0; i < n; i++) {
        double *ax = mem + 14 * i;
        for (int k = 0; k < 6; k++) {
            PyObject *o = PySequence_Fast_GET_ITEM(seq[k], i);
            ax[k] = PyFloat_CheckExact(o) ? PyFloat_AS_DOUBLE(o) : PyFloat_AsDouble(o);
            if (ax[k] == -1.0 && PyErr_Occurred()) goto done;
        }
    }
    double t_sync = 0.0;
    int first = 1;
    for (Py_ssize_t i = 0; i < n; i++) {
        double *ax = mem + 14 * i, *tm = ax + 6, *vp = ax + 13;
        double len = fabs(ax[0]);
        if (ax[0] != 0.0) {
            *vp = peak_velocity(len, ax[2], ax[3], ax[4], ax[5]);
            times_at(len, ax[2], ax[3], ax[4], ax[5], *vp, 0, 0.0, tm);
        } else {
            *vp = 0.0;
            for (int k = 0; k < 7; k++) tm[k] = 0.0;
        }
        if (!all_finite(tm)) {
            result = Py_None;
            Py_INCREF(result);
            goto done;
        }
    }
    for (Py_ssize_t i = 0; i < n; i++) { /* max() of the fsum durations, first on ties */
        double d = fsum7(mem + 14 * i + 6);
        if (first || d > t_sync) t_sync = d;
        first = 0;
    }
    PyObject *masks = PyTuple_New(n);
    if (masks == NULL) goto done;
    Py_ssize_t total = 0;
    if (t_sync > 0.0) {
        for (Py_ssize_t i = 0; i < n; i++) {
            double *ax = mem + 14 * i, *tm = ax + 6;
            if (ax[0] == 0.0) continue;
            if (fsum7(tm) < t_sync) {
                double len = fabs(ax[0]);
                double cap = synced_cap(len, t_sync, ax[3], ax[4], ax[5], ax[13]);
                times_at(len, ax[2], ax[3], ax[4], ax[5], ax[13], 1, cap, tm);
            }
            total += count_pieces(tm);
        }
    }
    PyObject *buf = PyByteArray_FromStringAndSize(NULL, NFIELDS * total * (Py_ssize_t)sizeof(double));
    if (buf == NULL) {
        Py_DECREF(masks);
        goto done;
    }
    double *cols = (double *)PyByteArray_AS_STRING(buf);
    Py_ssize_t at = 0;
    for (Py_ssize_t i = 0; i < n; i++) {
        double *ax = mem + 14 * i, *tm = ax + 6, t_end;
        int mask = 0;
        if (t_sync > 0.0) {
            if (ax[0] == 0.0) {
                mask = -1;
            } else {
                mask = build_pieces(ax[1], ax[0], tm, ax[3], ax[4], ax[5], cols, total, at,
                                    &t_end);
                at += count_pieces(tm);
            }
        }
        PyTuple_SET_ITEM(masks, i, PyLong_FromLong(mask));
    }
    result = Py_BuildValue("(dNN)", t_sync, buf, masks);
done:
    for (int k = 0; k < 6; k++) Py_XDECREF(seq[k]);
    if (mem != stack) PyMem_Free(mem);
    return result;
}

int om_profile_vec(PyObject *o, Py_buffer *b, int writable, const char *who)
{
    int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (writable ? PyBUF_WRITABLE : 0);
    if (PyObject_GetBuffer(o, b, flags) < 0) return -1;
    const char *f = b->format ? b->format : "B";
    size_t fl = strlen(f);
    if (b->itemsize != 8 || fl == 0 || f[fl - 1] != 'd') {
        PyBuffer_Release(b);
        PyErr_Format(PyExc_TypeError, "%s: float64 arrays expected", who);
        return -1;
    }
    return 0;
}

PyDoc_STRVAR(phases_many_doc,
             "phases_many(length, v_max, a_max, d_max, j_max, out, totals) fills `out`\n"
             "(contiguous float64, n*7 phase times or, with totals, n fsum durations; NaN\n"
             "where a time is not finite) from n validated moves (contiguous float64).");

static PyObject *py_phases_many(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 7) {
        PyErr_SetString(PyExc_TypeError, "phases_many takes 7 arguments");
        return NULL;
    }
    int totals = PyObject_IsTrue(args[6]);
    if (totals < 0) return NULL;
    Py_buffer b[6];
    int held = 0;
    PyObject *result = NULL;
    for (; held < 6; held++)
        if (om_profile_vec(args[held], &b[held], held == 5, "phases_many") < 0) goto done;
    Py_ssize_t n = b[0].len / 8;
    for (int k = 1; k < 5; k++)
        if (b[k].len / 8 != n) {
            PyErr_SetString(PyExc_ValueError, "phases_many: arrays of one length expected");
            goto done;
        }
    if (b[5].len / 8 != (totals ? n : 7 * n)) {
        PyErr_SetString(PyExc_ValueError, "phases_many: out has the wrong size");
        goto done;
    }
    const double *L = b[0].buf, *V = b[1].buf, *A = b[2].buf, *D = b[3].buf, *J = b[4].buf;
    double *out = b[5].buf;
    Py_BEGIN_ALLOW_THREADS
    for (Py_ssize_t i = 0; i < n; i++) {
        double t[7];
        phase_times(L[i], V[i], A[i], D[i], J[i], t);
        if (totals)
            out[i] = all_finite(t) ? fsum7(t) : NAN;
        else
            memcpy(out + 7 * i, t, sizeof t);
    }
    Py_END_ALLOW_THREADS
    result = Py_None;
    Py_INCREF(result);
done:
    for (int k = 0; k < held; k++) PyBuffer_Release(&b[k]);
    return result;
}

static PyMethodDef methods[] = {
    {"phase_times", (PyCFunction)(void (*)(void))py_phase_times, METH_FASTCALL, phase_times_doc},
    {"duration", (PyCFunction)(void (*)(void))py_duration, METH_FASTCALL, duration_doc},
    {"rest_to_rest", (PyCFunction)(void (*)(void))py_rest_to_rest, METH_FASTCALL,
     rest_to_rest_doc},
    {"synced", (PyCFunction)(void (*)(void))py_synced, METH_FASTCALL, synced_doc},
    {"phases_many", (PyCFunction)(void (*)(void))py_phases_many, METH_FASTCALL,
     phases_many_doc},
    {"sample", (PyCFunction)(void (*)(void))om_profile_sample, METH_FASTCALL,
     om_profile_sample_doc},
    {"axis_knots", (PyCFunction)(void (*)(void))om_axis_knots, METH_FASTCALL,
     om_axis_knots_doc},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_profile",
    "Compiled jerk-limited profile builder (phase times and polynomial pieces).", -1,
    methods,
};

PyMODINIT_FUNC PyInit__profile(void) { return PyModule_Create(&module); }
