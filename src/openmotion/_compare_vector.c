/* The compare engine's solvers (openmotion._compare): path length: Gauss-Legendre quadrature, VectorCycle pieces, sums and times. */
#include "_compare.h"

/* ------------------------------------------------------------------ path length */
/* Gauss-Legendre nodes and weights, set once from Python (compare_math._GL_X/_GL_W) so the
 * compiled quadrature uses the very floats of the module. */
static double gl_x[8], gl_w[8];
static int gl_set = 0;

/* VectorCycle._gl: the speed sqrt(Q(x)) of piece q integrated over [a, b] */
static double gl(const double *q, double a, double b)
{
    double h = 0.5 * (b - a), acc = 0.0;
    for (int k = 0; k < 8; k++) {
        double x = a + h * (gl_x[k] + 1.0);
        double y = q[0] + x * (q[1] + x * (q[2] + x * (q[3] + x * q[4])));
        acc += y > 0.0 ? gl_w[k] * sqrt(y) : 0.0;
    }
    return h * acc;
}

static double adaptive(const double *q, double a, double b, int depth, double rtol,
                       int max_depth)
{
    double m = 0.5 * (a + b);
    double whole = gl(q, a, b);
    double halves = gl(q, a, m) + gl(q, m, b);
    if (fabs(halves - whole) <= rtol * pymax(fabs(halves), 1e-300) || depth >= max_depth)
        return halves;
    return adaptive(q, a, m, depth + 1, rtol, max_depth)
           + adaptive(q, m, b, depth + 1, rtol, max_depth);
}

/* VectorCycle.time_of: first time > after with s(t) >= d. Returns 1 and *t, or 0. */
int time_of(const Vc *V, double d, double after, double *t_out)
{
    const double *B = V->B, *S = V->S;
    Py_ssize_t nb = V->nb;
    double s_end = S[nb - 1];
    if (d > s_end) {
        if (d - s_end > SNAP_RTOL * pymax(fabs(d), 1.0)) return 0;
        d = s_end;
    }
    Py_ssize_t lo_i = 0, hi_i = nb;  /* searchsorted left */
    while (lo_i < hi_i) {
        Py_ssize_t mid = (lo_i + hi_i) / 2;
        if (S[mid] < d) lo_i = mid + 1; else hi_i = mid;
    }
    Py_ssize_t i = (lo_i > 1 ? lo_i : 1) - 1;
    const double *q = V->Q + 5 * i;
    double u = B[i];
    double lo = pymax(after, u) - u, hi = B[i + 1] - u;
    double su = S[i];
    if (su + gl(q, 0.0, lo) >= d) {
        if (u + lo > after) { *t_out = u + lo; return 1; }
        return 0;
    }
    double x = 0.5 * (lo + hi);
    for (int it = 0; it < 100; it++) {
        double f = su + gl(q, 0.0, x) - d;
        if (f >= 0.0) hi = x; else lo = x;
        double tol = 4.0 * EPS * pymax(fabs(u + x), 1.0);
        if (hi - lo <= tol) { *t_out = u + hi; return 1; }
        double sp = sqrt(pymax(q[0] + x * (q[1] + x * (q[2] + x * (q[3] + x * q[4]))), 0.0));
        double xn = sp > 0.0 ? x - f / sp : NAN;
        if (fabs(xn - x) <= tol) {
            *t_out = f < 0.0 ? u + pymax(xn, x) : u + x;
            return 1;
        }
        if (!(lo < xn && xn < hi)) xn = 0.5 * (lo + hi);
        x = xn;
    }
    *t_out = u + hi;
    return 1;
}

void release_vc(VcBuf *vb)
{
    for (int k = 0; k < vb->held; k++) PyBuffer_Release(&vb->b[k]);
    vb->held = 0;
}

int get_vc(PyObject *B, PyObject *S, PyObject *Q, Vc *V, VcBuf *vb)
{
    PyObject *o[3] = {B, S, Q};
    static const char *names[3] = {"B", "S", "Q"};
    vb->held = 0;
    if (!gl_set) {
        PyErr_SetString(PyExc_RuntimeError, "set_gauss was not called");
        return -1;
    }
    for (int k = 0; k < 3; k++) {
        if (get_vec(o[k], &vb->b[k], names[k]) < 0) { release_vc(vb); return -1; }
        vb->held = k + 1;
    }
    Py_ssize_t nb = vb->b[0].len / 8;
    if (nb < 2 || vb->b[1].len / 8 != nb || vb->b[2].len / 8 != 5 * (nb - 1)) {
        release_vc(vb);
        PyErr_SetString(PyExc_ValueError, "B, S need n >= 2 entries and Q (n - 1) x 5");
        return -1;
    }
    V->B = vb->b[0].buf; V->S = vb->b[1].buf; V->Q = vb->b[2].buf; V->nb = nb;
    return 0;
}

CMP_DOC(set_gauss_doc, "set_gauss(x, w): the 8 Gauss-Legendre nodes and weights.");

PyObject *set_gauss(PyObject *self, PyObject *args)
{
    PyObject *xo, *wo;
    if (!PyArg_ParseTuple(args, "OO", &xo, &wo)) return NULL;
    Py_buffer xb, wb;
    if (get_vec(xo, &xb, "x") < 0) return NULL;
    if (get_vec(wo, &wb, "w") < 0) { PyBuffer_Release(&xb); return NULL; }
    int ok = xb.len == 64 && wb.len == 64;
    if (ok) {
        memcpy(gl_x, xb.buf, 64);
        memcpy(gl_w, wb.buf, 64);
        gl_set = 1;
    }
    PyBuffer_Release(&xb);
    PyBuffer_Release(&wb);
    if (!ok) {
        PyErr_SetString(PyExc_ValueError, "set_gauss needs 8 nodes and 8 weights");
        return NULL;
    }
    Py_RETURN_NONE;
}

CMP_DOC(gl_doc,
"gl(q, a, b) -> integral over [a, b] of sqrt(q0 + q1 x + ... + q4 x^4), 8-point GL");

PyObject *gl_py(PyObject *self, PyObject *args)
{
    double q[5], a, b;
    if (!PyArg_ParseTuple(args, "(ddddd)dd", &q[0], &q[1], &q[2], &q[3], &q[4], &a, &b))
        return NULL;
    if (!gl_set) {
        PyErr_SetString(PyExc_RuntimeError, "set_gauss was not called");
        return NULL;
    }
    return PyFloat_FromDouble(gl(q, a, b));
}

CMP_DOC(adaptive_doc,
"adaptive(q, a, b, rtol, max_depth) -> the integral of gl halved until two levels agree");

PyObject *adaptive_py(PyObject *self, PyObject *args)
{
    double q[5], a, b, rtol;
    int max_depth;
    if (!PyArg_ParseTuple(args, "(ddddd)dddi", &q[0], &q[1], &q[2], &q[3], &q[4], &a, &b,
                          &rtol, &max_depth))
        return NULL;
    if (!gl_set) {
        PyErr_SetString(PyExc_RuntimeError, "set_gauss was not called");
        return NULL;
    }
    return PyFloat_FromDouble(adaptive(q, a, b, 0, rtol, max_depth));
}

/* VectorCycle's construction (compare_math.VectorCycle.__init__, the numpy version is the
 * oracle tests/compare_oracle.vector_pieces / vector_sums), in two steps around the two
 * 8-point dot products, which stay numpy matrix products `(n, 8) @ w` (a BLAS product
 * whose rounding depends on the BLAS kernel and on n: kept as it is, so S is the same
 * floats as before on every machine). */
static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* add x to the breakpoints unless an equal one is there (a Python set keeps the first) */
static void bp_add(double *bp, Py_ssize_t *nb, double x)
{
    for (Py_ssize_t i = 0; i < *nb; i++)
        if (bp[i] == x) return;
    bp[(*nb)++] = x;
}

/* numpy.maximum(y, 0.0) then sqrt: NaN stays NaN, ties give the second argument */
static inline double sq_row(const double *q, double x)
{
    double y = q[0] + x * (q[1] + x * (q[2] + x * (q[3] + x * q[4])));
    return sqrt(y > 0.0 || y != y ? y : 0.0);
}

CMP_DOC(vector_pieces_doc,
"vector_pieces(tracks, weights, ta, t1) -> (B, Q, R) as bytes of float64\n\n"
"VectorCycle's pieces over [ta, t1]: B the breakpoints (ta, t1, every record start and\n"
"velocity root inside, sorted), Q (n, 5) each piece's speed^2 quartic, R (2, n, 8) the\n"
"speed at the nodes of one and of two Gauss-Legendre panels (summed), whose products\n"
"with the weights vector_sums takes. tracks: tracks or history specs (see bank_scan).");

PyObject *vector_pieces(PyObject *self, PyObject *args)
{
    PyObject *tr_o, *w_o;
    double ta, t1;
    if (!PyArg_ParseTuple(args, "OOdd", &tr_o, &w_o, &ta, &t1)) return NULL;
    if (!gl_set) {
        PyErr_SetString(PyExc_RuntimeError, "set_gauss was not called");
        return NULL;
    }
    PyObject *seq = PySequence_Fast(tr_o, "tracks must be a sequence of tracks");
    if (seq == NULL) return NULL;
    Py_ssize_t na = PySequence_Fast_GET_SIZE(seq), got = 0;  /* (any number of axes) */
    Trk *T = calloc((size_t)(na > 0 ? na : 1), sizeof(Trk));
    TrkBuf *tb = calloc((size_t)(na > 0 ? na : 1), sizeof(TrkBuf));
    PyObject *res = NULL;
    double *bp = NULL, *Q = NULL, *R = NULL;
    Py_buffer wb;
    int have_w = 0;
    if (T == NULL || tb == NULL) { PyErr_NoMemory(); goto out; }
    if (na < 1) {
        PyErr_SetString(PyExc_ValueError, "tracks: at least one axis");
        goto out;
    }
    if (get_vec(w_o, &wb, "weights") < 0) goto out;
    have_w = 1;
    if (wb.len != 8 * na) {
        PyErr_SetString(PyExc_ValueError, "weights: one per track");
        goto out;
    }
    const double *w = wb.buf;
    Py_ssize_t cap = 2;
    for (Py_ssize_t i = 0; i < na; i++) {
        if (get_track_in(PySequence_Fast_GET_ITEM(seq, i), ta, t1, &T[i], &tb[i]) < 0) goto out;
        got = i + 1;
        cap += 3 * T[i].n;
    }
    bp = malloc((size_t)cap * sizeof(double));
    if (bp == NULL) { PyErr_NoMemory(); goto out; }
    Py_ssize_t nb = 0;
    bp[nb++] = ta;
    bp_add(bp, &nb, t1);
    for (Py_ssize_t i = 0; i < na; i++) {
        const Trk *tr = &T[i];
        for (Py_ssize_t k = 0; k < tr->n; k++) {
            double a_k = tr->ts[k];
            double b_k = k + 1 < tr->n ? tr->ts[k + 1] : INFINITY;
            if (ta < a_k && a_k < t1) bp_add(bp, &nb, a_k);
            if (b_k <= ta || a_k >= t1) continue;
            double r[2];
            int nr = velocity_roots(tr->v0[k], tr->a0[k], tr->j[k], r);
            for (int q = 0; q < nr; q++) {
                double x = a_k + r[q];
                if (ta < x && x < t1 && x < b_k) bp_add(bp, &nb, x);
            }
        }
    }
    qsort(bp, (size_t)nb, sizeof(double), cmp_double);
    Py_ssize_t n = nb - 1;  /* pieces */
    Q = calloc((size_t)(5 * n + 1), sizeof(double));
    R = malloc((size_t)(16 * n + 1) * sizeof(double));
    if (Q == NULL || R == NULL) { PyErr_NoMemory(); goto out; }
    for (Py_ssize_t i = 0; i < na; i++) {
        const Trk *tr = &T[i];
        double wk = w[i];
        for (Py_ssize_t p = 0; p < n; p++) {
            double u = bp[p], mid = 0.5 * (bp[p] + bp[p + 1]);
            Py_ssize_t k = search_right(tr->ts, 0, tr->n, mid) - 1;
            if (k < 0) k = 0;
            double d0 = u - tr->ts[k], j = tr->j[k];
            double c0 = wk * (tr->v0[k] + d0 * (tr->a0[k] + d0 * j / 2.0));
            double c1 = wk * (tr->a0[k] + d0 * j);
            double c2 = wk * (j / 2.0);
            double *q = Q + 5 * p;
            q[0] += c0 * c0;
            q[1] += 2.0 * c0 * c1;
            q[2] += c1 * c1 + 2.0 * c0 * c2;
            q[3] += 2.0 * c1 * c2;
            q[4] += c2 * c2;
        }
    }
    double *R1 = R, *R2 = R + 8 * n;
    for (Py_ssize_t p = 0; p < n; p++) {
        const double *q = Q + 5 * p;
        double h = bp[p + 1] - bp[p];
        for (int k = 0; k < 8; k++) {
            double g = gl_x[k] + 1.0;
            double x1 = (h / 2.0) * g, xa = (h / 4.0) * g;
            R1[8 * p + k] = sq_row(q, x1);
            R2[8 * p + k] = sq_row(q, xa) + sq_row(q, xa + h / 2.0);
        }
    }
    res = Py_BuildValue("(y#y#y#)", (const char *)bp, (Py_ssize_t)(nb * 8),
                        (const char *)Q, (Py_ssize_t)(5 * n * 8), (const char *)R,
                        (Py_ssize_t)(16 * n * 8));
out:
    for (Py_ssize_t i = 0; i < got; i++) release_track(&tb[i]);
    if (have_w) PyBuffer_Release(&wb);
    Py_DECREF(seq);
    free(T); free(tb); free(bp); free(Q); free(R);
    return res;
}

CMP_DOC(vector_sums_doc,
"vector_sums(B, Q, d1, d2, s0, rtol, max_depth) -> S as bytes of float64\n\n"
"VectorCycle's cumulative lengths from vector_pieces: d1 = R1 @ w, d2 = R2 @ w; a\n"
"piece's length is (h / 4) * d2 unless it differs from (h / 2) * d1 by more than rtol\n"
"(relative), then adaptive(Q[i], 0, h, rtol, max_depth); S = s0 + [0, cumsum].");

PyObject *vector_sums(PyObject *self, PyObject *args)
{
    PyObject *o[4];
    double s0, rtol;
    int max_depth;
    if (!PyArg_ParseTuple(args, "OOOOddi", &o[0], &o[1], &o[2], &o[3], &s0, &rtol,
                          &max_depth))
        return NULL;
    if (!gl_set) {
        PyErr_SetString(PyExc_RuntimeError, "set_gauss was not called");
        return NULL;
    }
    static const char *names[4] = {"B", "Q", "d1", "d2"};
    Py_buffer b[4];
    int held = 0;
    PyObject *res = NULL;
    for (; held < 4; held++)
        if (get_vec(o[held], &b[held], names[held]) < 0) goto out;
    Py_ssize_t nb = b[0].len / 8, n = nb - 1;
    if (nb < 1 || b[1].len != 5 * 8 * n || b[2].len != 8 * n || b[3].len != 8 * n) {
        PyErr_SetString(PyExc_ValueError, "vector_sums: B (n + 1), Q (n, 5), d1 and d2 (n)");
        goto out;
    }
    const double *B = b[0].buf, *Q = b[1].buf, *d1 = b[2].buf, *d2 = b[3].buf;
    res = PyBytes_FromStringAndSize(NULL, nb * 8);
    if (res == NULL) goto out;
    double *S = (double *)PyBytes_AS_STRING(res), c = 0.0;
    S[0] = s0 + 0.0;
    for (Py_ssize_t i = 0; i < n; i++) {
        double h = B[i + 1] - B[i];
        double one = (h / 2.0) * d1[i], two = (h / 4.0) * d2[i];
        if (fabs(two - one) > rtol * pymax(1e-300, fabs(two)))
            two = adaptive(Q + 5 * i, 0.0, h, 0, rtol, max_depth);
        c = i == 0 ? two : c + two;  /* numpy.cumsum */
        S[i + 1] = s0 + c;
    }
out:
    for (int k = 0; k < held; k++) PyBuffer_Release(&b[k]);
    return res;
}

CMP_DOC(vector_at_doc, "vector_at(B, S, Q, t) -> s(t) (VectorCycle.at)");

PyObject *vector_at(PyObject *self, PyObject *args)
{
    PyObject *B, *S, *Q;
    double t;
    if (!PyArg_ParseTuple(args, "OOOd", &B, &S, &Q, &t)) return NULL;
    Vc V;
    VcBuf vb;
    if (get_vc(B, S, Q, &V, &vb) < 0) return NULL;
    Py_ssize_t lo = 0, hi = V.nb;  /* searchsorted right */
    while (lo < hi) {
        Py_ssize_t mid = (lo + hi) / 2;
        if (t < V.B[mid]) hi = mid; else lo = mid + 1;
    }
    Py_ssize_t i = lo - 1;
    if (i > V.nb - 2) i = V.nb - 2;
    if (i < 0) i = 0;
    double s = V.S[i] + gl(V.Q + 5 * i, 0.0, t - V.B[i]);
    release_vc(&vb);
    return PyFloat_FromDouble(s);
}

CMP_DOC(vector_scan_doc,
"vector_scan(B, S, Q, levels, n, after_final, index, t, first_only) -> list\n\n"
"A LevelJob's scan of one window on a path length (VectorCycle B, S, Q): from value\n"
"`index` on, the first time after t that s reaches each value in turn (time_of), until\n"
"one is not reached (first_only: the value at `index` only). Returns [(time, level)].");

PyObject *vector_scan(PyObject *self, PyObject *args)
{
    PyObject *B, *S, *Q, *lv_o, *af_o;
    long long n, index;
    double t;
    int first_only;
    if (!PyArg_ParseTuple(args, "OOOOLOLdp", &B, &S, &Q, &lv_o, &n, &af_o, &index, &t,
                          &first_only))
        return NULL;
    Vc V;
    VcBuf vb;
    if (get_vc(B, S, Q, &V, &vb) < 0) return NULL;
    Levels L;
    Py_buffer lb;
    int held;
    PyObject *res = NULL;
    if (get_levels(lv_o, n, af_o, &L, &lb, &held) < 0) goto done;
    long long size = L.n + L.has_after;
    res = PyList_New(0);
    while (res != NULL && index < size) {
        double lvl = level_at(&L, index), tf;
        if (!time_of(&V, lvl, t, &tf)) break;
        PyObject *it = Py_BuildValue("(dd)", tf, lvl);
        if (it == NULL || PyList_Append(res, it) < 0) { Py_XDECREF(it); Py_CLEAR(res); break; }
        Py_DECREF(it);
        if (first_only) break;
        index++;
        t = tf;
    }
done:
    if (held) PyBuffer_Release(&lb);
    release_vc(&vb);
    return res;
}

CMP_DOC(time_of_doc, "time_of(B, S, Q, d, after) -> first time > after with s >= d, or None");

PyObject *time_of_py(PyObject *self, PyObject *args)
{
    PyObject *B, *S, *Q;
    double d, after, tf;
    if (!PyArg_ParseTuple(args, "OOOdd", &B, &S, &Q, &d, &after)) return NULL;
    Vc V;
    VcBuf vb;
    if (get_vc(B, S, Q, &V, &vb) < 0) return NULL;
    int r = time_of(&V, d, after, &tf);
    release_vc(&vb);
    if (!r) Py_RETURN_NONE;
    return PyFloat_FromDouble(tf);
}
