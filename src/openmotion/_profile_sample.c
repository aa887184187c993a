/* Profile.sample compiled (openmotion._profile.sample): a piecewise-cubic profile's
 * position, velocity, acceleration and jerk at many instants (profile/segments.py).
 *
 * The same floating-point operations in the same order as the numpy version kept in
 * segments.py (`Profile._sample_numpy`, the oracle of tests/test_profile_sample.py), so the
 * samples are the same floats bit for bit (built with -ffp-contract=off):
 *   before 0:        p = start_p + start_v*t, v = start_v, a = j = 0
 *   at/after the end: p = end_p + end_v*(t - duration), v = end_v, a = j = 0
 *   inside: segment k = (last index with t0[k] <= t, numpy searchsorted side="right" - 1,
 *   clipped to [0, n-1]; a NaN instant takes the last segment as numpy sorts NaN last),
 *   dt = t - t0[k], p = p0 + dt*(v0 + dt*(a0/2 + dt*j/6)), v = v0 + dt*(a0 + dt*j/2),
 *   a = a0 + dt*j.
 */
#include "_profile.h"

#ifdef __clang__
#pragma STDC FP_CONTRACT OFF
#endif

/* numpy's searchsorted(t0, t, side="right") - 1 on a sorted t0, clipped to [0, n-1] */
static Py_ssize_t segment_of(const double *t0, Py_ssize_t n, double t)
{
    if (t != t) return n - 1;
    Py_ssize_t lo = 0, hi = n;
    while (lo < hi) {
        Py_ssize_t mid = lo + ((hi - lo) >> 1);
        if (t0[mid] <= t)
            lo = mid + 1;
        else
            hi = mid;
    }
    Py_ssize_t k = lo - 1;
    return k < 0 ? 0 : k;
}

const char om_profile_sample_doc[] =
             "sample(t0, p0, v0, a0, j, ts, p, v, a, jo, start_p, start_v, end_p, end_v,\n"
             "duration) fills p, v, a, jo (float64, len(ts)) with the profile's samples at\n"
             "ts; the segment columns are contiguous float64 arrays of one length n >= 1.";

PyObject *om_profile_sample(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 15) {
        PyErr_SetString(PyExc_TypeError, "sample takes 15 arguments");
        return NULL;
    }
    double c[5];
    for (int i = 0; i < 5; i++) {
        c[i] = PyFloat_AsDouble(args[10 + i]);
        if (c[i] == -1.0 && PyErr_Occurred()) return NULL;
    }
    const double sp = c[0], sv = c[1], ep = c[2], ev = c[3], dur = c[4];
    Py_buffer b[10];
    int held = 0;
    PyObject *result = NULL;
    for (; held < 10; held++)
        if (om_profile_vec(args[held], &b[held], held >= 6, "sample") < 0) goto done;
    Py_ssize_t n = b[0].len / 8, m = b[5].len / 8;
    for (int k = 1; k < 5; k++)
        if (b[k].len / 8 != n) goto size;
    for (int k = 6; k < 10; k++)
        if (b[k].len / 8 != m) goto size;
    if (n < 1) goto size;
    {
        const double *T0 = b[0].buf, *P0 = b[1].buf, *V0 = b[2].buf, *A0 = b[3].buf,
                     *J = b[4].buf, *ts = b[5].buf;
        double *P = b[6].buf, *V = b[7].buf, *A = b[8].buf, *JO = b[9].buf;
        Py_BEGIN_ALLOW_THREADS
        for (Py_ssize_t i = 0; i < m; i++) {
            double t = ts[i];
            if (t < 0.0) {
                P[i] = sp + sv * t;
                V[i] = sv;
                A[i] = 0.0;
                JO[i] = 0.0;
            } else if (t >= dur) {
                P[i] = ep + ev * (t - dur);
                V[i] = ev;
                A[i] = 0.0;
                JO[i] = 0.0;
            } else {
                Py_ssize_t k = segment_of(T0, n, t);
                double dt = t - T0[k];
                double jk = J[k], ak = A0[k], vk = V0[k];
                P[i] = P0[k] + dt * (vk + dt * (ak / 2.0 + dt * jk / 6.0));
                V[i] = vk + dt * (ak + dt * jk / 2.0);
                A[i] = ak + dt * jk;
                JO[i] = jk;
            }
        }
        Py_END_ALLOW_THREADS
    }
    result = Py_None;
    Py_INCREF(result);
    goto done;
size:
    PyErr_SetString(PyExc_ValueError, "sample: arrays of matching lengths expected");
done:
    for (int k = 0; k < held; k++) PyBuffer_Release(&b[k]);
    return result;
}
