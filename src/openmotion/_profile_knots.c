/* A chain's per-axis knots compiled (openmotion._profile.axis_knots): the positions of the
 * knots and each interval's cubic Hermite coefficients for control/groups/pathaxes.py.
 *
 * The chain's lines and arcs come packed row by row (pathpoints.ElementTable.packed: per
 * element kind, trimmed, offset, stop, blen, radius, k, rs, length, curvature, then the
 * start, end, dirn, centre, e1, e2, lin, helix vectors). Every formula repeats the numpy
 * version's operations in its order (pathaxes._knots_numpy and pathpoints.ElementTable,
 * the oracles of tests/test_path_knots.py), so the floats are the same (built with
 * -ffp-contract=off; cos/sin are the C library's, which numpy also calls unless its own
 * SIMD versions are built for the CPU: then an arc can differ by an ulp). numpy's clip with
 * an array bound and minimum keep the bound on a tie; searchsorted(side="right") puts NaN
 * last. A row of another element kind, or a straight element that is not a line, returns
 * False: the caller then runs the numpy version.
 */
#include "_profile.h"
#include <math.h>
#include <string.h>

#ifdef __clang__
#pragma STDC FP_CONTRACT OFF
#endif

#define KIND 0
#define TRIM 1
#define OFFS 2
#define STOP 3
#define BLEN 4
#define RAD 5
#define KK 6
#define RS 7
#define LEN 8
#define CURV 9
#define NSCAL 10
#define NVEC 8 /* start, end, dirn, centre, e1, e2, lin, helix */
#define LINE 1
#define ARC 2

static inline double np_min(double a, double b)
{
    if (isnan(a)) return a;
    if (isnan(b)) return b;
    return a < b ? a : b;
}

/* np.clip(x, lo, hi) with an array bound: the bound on a tie */
static inline double np_clip(double x, double lo, double hi)
{
    double m = isnan(x) ? x : (x > lo ? x : lo);
    return isnan(m) ? m : (m < hi ? m : hi);
}

static Py_ssize_t locate(const double *cum, Py_ssize_t n_el, double s)
{
    Py_ssize_t lo = 0, hi = n_el + 1;
    if (s != s)
        lo = hi;
    else
        while (lo < hi) {
            Py_ssize_t mid = lo + ((hi - lo) >> 1);
            if (cum[mid] <= s)
                lo = mid + 1;
            else
                hi = mid;
        }
    Py_ssize_t k = lo - 1;
    return k < 0 ? 0 : (k > n_el - 1 ? n_el - 1 : k);
}

/* point (tangent = 0) or unit tangent of row r at local s u; 0, or -1: not a line/arc */
static int eval_row(const double *r, int dim, double u, int tangent, double *out)
{
    const double *start = r + NSCAL, *end = start + dim, *dirn = end + dim,
                 *centre = dirn + dim, *e1 = centre + dim, *e2 = e1 + dim, *lin = e2 + dim,
                 *helix = lin + dim;
    double ub = u;
    if (r[TRIM] != 0.0) ub = np_min(u + r[OFFS], r[STOP]);
    ub = np_clip(ub, 0.0, r[BLEN]);
    int kind = (int)r[KIND];
    if (kind == LINE) {
        if (tangent) {
            memcpy(out, dirn, sizeof(double) * (size_t)dim);
            return 0;
        }
        for (int i = 0; i < dim; i++) out[i] = start[i] + ub * dirn[i];
    } else if (kind == ARC) {
        double phi = ub * r[KK], c = cos(phi), s = sin(phi);
        if (tangent) {
            double rs = r[RS], sq = 0.0;
            for (int i = 0; i < dim; i++) {
                out[i] = rs * (c * e2[i] - s * e1[i]) + helix[i];
                double q = out[i] * out[i];
                sq = i ? sq + q : q;
            }
            double nrm = sqrt(sq);
            for (int i = 0; i < dim; i++) out[i] = out[i] / nrm;
            return 0;
        }
        double rad = r[RAD], f = ub / r[BLEN];
        for (int i = 0; i < dim; i++)
            out[i] = centre[i] + rad * (c * e1[i] + s * e2[i]) + f * lin[i];
    } else {
        return -1;
    }
    if (ub >= r[BLEN])
        memcpy(out, end, sizeof(double) * (size_t)dim);
    if (ub <= 0.0)
        memcpy(out, start, sizeof(double) * (size_t)dim);
    return 0;
}

const char om_axis_knots_doc[] =
    "axis_knots(table, cum, t, s, sd, s_mid, acc, jerk, starts, end, pos, v0, a0, j)\n"
    "fills pos (n x dim) and v0, a0, j ((n-1) x dim) for the knots t with path positions\n"
    "s and speeds sd (s_mid: at the interval midpoints; acc, jerk: s(t)'s at t[:-1]);\n"
    "pos[0] is `starts`, the last knot `end` when end has dim entries (else 0 entries).\n"
    "True when done, False for an element row the numpy version must evaluate.";

PyObject *om_axis_knots(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 14) {
        PyErr_SetString(PyExc_TypeError, "axis_knots takes 14 arguments");
        return NULL;
    }
    Py_buffer b[14];
    int held = 0;
    PyObject *result = NULL;
    double *tmp = NULL;
    for (; held < 14; held++)
        if (om_profile_vec(args[held], &b[held], held >= 10, "axis_knots") < 0) goto done;
    {
        Py_ssize_t n_el = b[1].len / 8 - 1, n = b[2].len / 8;
        Py_ssize_t dim = b[8].len / 8, width = NSCAL + NVEC * dim;
        int has_end = b[9].len / 8 == dim;
        if (n_el < 1 || n < 2 || dim < 1 || b[0].len / 8 != n_el * width ||
            b[3].len / 8 != n || b[4].len / 8 != n || b[5].len / 8 != n - 1 ||
            b[6].len / 8 != n - 1 || b[7].len / 8 != n - 1 || (!has_end && b[9].len) ||
            b[10].len / 8 != n * dim || b[11].len / 8 != (n - 1) * dim ||
            b[12].len / 8 != (n - 1) * dim || b[13].len / 8 != (n - 1) * dim) {
            PyErr_SetString(PyExc_ValueError, "axis_knots: arrays of matching sizes expected");
            goto done;
        }
        const double *tab = b[0].buf, *cum = b[1].buf, *t = b[2].buf, *s = b[3].buf,
                     *sd = b[4].buf, *smid = b[5].buf, *acc = b[6].buf, *jrk = b[7].buf,
                     *starts = b[8].buf, *endp = b[9].buf;
        double *pos = b[10].buf, *V0 = b[11].buf, *A0 = b[12].buf, *J = b[13].buf;
        tmp = PyMem_Malloc(sizeof(double) * 2 * (size_t)dim);
        if (!tmp) {
            PyErr_NoMemory();
            goto done;
        }
        int ok = 1;
        double *t1 = tmp + dim;
        for (Py_ssize_t i = 0; i < n && ok; i++) {
            Py_ssize_t k = locate(cum, n_el, s[i]);
            const double *r = tab + k * width;
            double u = np_clip(s[i] - cum[k], 0.0, r[LEN]);
            if (eval_row(r, (int)dim, u, 0, pos + i * dim) < 0) ok = 0;
        }
        if (ok) {
            memcpy(pos, starts, sizeof(double) * (size_t)dim);
            if (has_end) memcpy(pos + (n - 1) * dim, endp, sizeof(double) * (size_t)dim);
        }
        for (Py_ssize_t i = 0; i + 1 < n && ok; i++) {
            Py_ssize_t k = locate(cum, n_el, smid[i]);
            const double *r = tab + k * width;
            double *v0 = V0 + i * dim, *a0 = A0 + i * dim, *jj = J + i * dim;
            const double *p0 = pos + i * dim, *p1 = p0 + dim;
            if (eval_row(r, (int)dim, np_clip(s[i] - cum[k], 0.0, r[LEN]), 1, v0) < 0 ||
                eval_row(r, (int)dim, np_clip(s[i + 1] - cum[k], 0.0, r[LEN]), 1, t1) < 0) {
                ok = 0;
                break;
            }
            double h = t[i + 1] - t[i];
            if (r[CURV] == 0.0) {
                if ((int)r[KIND] != LINE) {
                    ok = 0;
                    break;
                }
                const double *dirn = r + NSCAL + 2 * dim;
                for (Py_ssize_t d = 0; d < dim; d++) {
                    v0[d] = v0[d] * sd[i];
                    a0[d] = acc[i] * dirn[d];
                    jj[d] = jrk[i] * dirn[d];
                }
                continue;
            }
            for (Py_ssize_t d = 0; d < dim; d++) {
                double w0 = v0[d] * sd[i], w1 = t1[d] * sd[i + 1], dp = p1[d] - p0[d];
                v0[d] = w0;
                a0[d] = (6.0 * dp - h * (4.0 * w0 + 2.0 * w1)) / (h * h);
                jj[d] = (6.0 * h * (w0 + w1) - 12.0 * dp) / (h * h * h);
            }
        }
        result = ok ? Py_True : Py_False;
        Py_INCREF(result);
    }
done:
    PyMem_Free(tmp);
    for (int k = 0; k < held; k++) PyBuffer_Release(&b[k]);
    return result;
}
