/* The compare engine's solvers, compiled (openmotion._compare): exact trigger times on
 * piecewise-cubic tracks for every job kind (control/trigger/compare_math.py calls them).
 *
 * A separate extension module (not entries in _kernel.c's method table): it has several
 * entry points of its own, shares no state with the stepper kernel, and its build can
 * change without touching the kernel's table.
 *
 * A track is five float64 arrays (ts, p0, v0, a0, j): record k covers [ts[k], ts[k+1]),
 * the last is open-ended (compare_math.Track). Every formula repeats the operation order
 * of the plain-float Python versions kept as oracles in tests/compare_oracle.py, so the
 * times are the same floats (compiled with -ffp-contract=off: no fused multiply-add;
 * Python's max/min are `pymax`/`pymin`, which keep the first argument on ties and NaN).
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef __clang__
#pragma STDC FP_CONTRACT OFF
#endif

#define EPS 2.220446049250313e-16
#define SNAP_RTOL 1e-10
#define MAX_AXES 8

/* attribute names, interned once (module init): the driver reads job, line and history
 * objects by attribute every cycle */
#define NAMES(X) X(_t) X(_lv) X(_late) X(initial) X(timed) X(_sent_until) X(_written) \
    X(_sent) X(_hold) X(signal) X(index) X(hits) X(ts) X(p0) X(v0) X(a0) X(j) X(lo) X(hi) \
    X(flush) X(forget_before) X(snapshot) X(_snap) X(_snap_t)
#define DECL(n) static PyObject *S_##n;
NAMES(DECL)
#undef DECL

static inline double pymax(double a, double b) { return b > a ? b : a; }
static inline double pymin(double a, double b) { return b < a ? b : a; }
static inline int isign(double x) { return x > 0.0 ? 1 : x < 0.0 ? -1 : 0; }

/* ------------------------------------------------------------------ buffers */
typedef struct {
    const double *ts, *p0, *v0, *a0, *j;
    Py_ssize_t n;
} Trk;

typedef struct {
    Py_buffer b[5];
    int held;
    double *own;  /* rows built from a history spec (get_track_in), freed on release */
} TrkBuf;

static int get_vec(PyObject *o, Py_buffer *b, const char *name)
{
    if (PyObject_GetBuffer(o, b, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) return -1;
    const char *f = b->format ? b->format : "B";
    size_t fl = strlen(f);
    if (b->itemsize != 8 || fl == 0 || f[fl - 1] != 'd') {
        PyBuffer_Release(b);
        PyErr_Format(PyExc_TypeError, "%s must be a float64 array", name);
        return -1;
    }
    return 0;
}

static void release_track(TrkBuf *tb)
{
    for (int k = 0; k < tb->held; k++) PyBuffer_Release(&tb->b[k]);
    tb->held = 0;
    free(tb->own);
    tb->own = NULL;
}

static int get_track(PyObject *o, Trk *t, TrkBuf *tb)
{
    tb->held = 0;
    tb->own = NULL;
    PyObject *seq = PySequence_Fast(o, "track must be a sequence of 5 arrays");
    if (seq == NULL) return -1;
    if (PySequence_Fast_GET_SIZE(seq) != 5) {
        Py_DECREF(seq);
        PyErr_SetString(PyExc_ValueError, "track must hold 5 arrays (ts, p0, v0, a0, j)");
        return -1;
    }
    PyObject **items = PySequence_Fast_ITEMS(seq);
    for (int k = 0; k < 5; k++) {
        if (get_vec(items[k], &tb->b[k], "track column") < 0) {
            Py_DECREF(seq);
            release_track(tb);
            return -1;
        }
        tb->held = k + 1;
    }
    Py_DECREF(seq);
    Py_ssize_t n = tb->b[0].len / 8;
    for (int k = 1; k < 5; k++)
        if (tb->b[k].len / 8 != n) {
            release_track(tb);
            PyErr_SetString(PyExc_ValueError, "track columns differ in length");
            return -1;
        }
    if (n == 0) {
        release_track(tb);
        PyErr_SetString(PyExc_ValueError, "track must hold at least one record");
        return -1;
    }
    t->ts = tb->b[0].buf; t->p0 = tb->b[1].buf; t->v0 = tb->b[2].buf;
    t->a0 = tb->b[3].buf; t->j = tb->b[4].buf; t->n = n;
    return 0;
}

/* A track cut from the motion history in place (the driver's per-cycle input, no Python
 * call per axis): spec = (hist, scale, offset, e0, slope, t_ref), hist one axis's record
 * store (history._Track: float64 arrays ts, p0, v0, a0, j, live rows [lo, hi)). The rows
 * of MotionHistory.rows(axis, ta, t1) (those covering [ta, t1] plus the one before), in
 * the frame of compare_math.affine_track: scale * x(t) + offset + e0 + slope * (t - t_ref),
 * each column with affine_track's operation order (the same floats). spec = (hist,): those
 * rows as stored. A 5-sequence is a plain track (get_track). */
static Py_ssize_t search_right(const double *x, Py_ssize_t lo, Py_ssize_t hi, double t)
{
    while (lo < hi) {
        Py_ssize_t mid = (lo + hi) / 2;
        if (t < x[mid]) hi = mid; else lo = mid + 1;
    }
    return lo;
}

static int get_track_in(PyObject *o, double ta, double t1, Trk *t, TrkBuf *tb)
{
    Py_ssize_t len = PyTuple_Check(o) ? PyTuple_GET_SIZE(o) : -1;
    if (len != 6 && len != 1) return get_track(o, t, tb);
    tb->held = 0;
    tb->own = NULL;
    double sc = 1.0, off = 0.0, e0 = 0.0, slope = 0.0, tref = 0.0;
    int raw = len == 1;  /* (hist,): the rows as stored (MotionHistory.rows) */
    PyObject *h;
    if (raw) h = PyTuple_GET_ITEM(o, 0);
    else if (!PyArg_ParseTuple(o, "Oddddd", &h, &sc, &off, &e0, &slope, &tref)) return -1;
    PyObject *names[5] = {S_ts, S_p0, S_v0, S_a0, S_j};
    const double *col[5];
    long long lo, hi;
    PyObject *x = PyObject_GetAttr(h, S_lo);
    if (x == NULL) return -1;
    lo = PyLong_AsLongLong(x);
    Py_DECREF(x);
    if ((x = PyObject_GetAttr(h, S_hi)) == NULL) return -1;
    hi = PyLong_AsLongLong(x);
    Py_DECREF(x);
    if (PyErr_Occurred()) return -1;
    for (int k = 0; k < 5; k++) {
        PyObject *a = PyObject_GetAttr(h, names[k]);
        if (a == NULL) { release_track(tb); return -1; }
        int r = get_vec(a, &tb->b[k], "history column");
        Py_DECREF(a);
        if (r < 0) { release_track(tb); return -1; }
        tb->held = k + 1;
        col[k] = tb->b[k].buf;
        if (tb->b[k].len / 8 < hi) {
            release_track(tb);
            PyErr_SetString(PyExc_ValueError, "history track: rows beyond its arrays");
            return -1;
        }
    }
    if (!(0 <= lo && lo < hi)) {
        release_track(tb);
        PyErr_SetString(PyExc_ValueError, "history track holds no record");
        return -1;
    }
    const double *ts = col[0];
    Py_ssize_t ia = (Py_ssize_t)lo + search_right(ts + lo, 0, (Py_ssize_t)(hi - lo), ta) - 1;
    Py_ssize_t ib = (Py_ssize_t)lo + search_right(ts + lo, 0, (Py_ssize_t)(hi - lo), t1) - 1;
    Py_ssize_t a = ia - 1 > (Py_ssize_t)lo ? ia - 1 : (Py_ssize_t)lo;
    Py_ssize_t b = (ib > a ? ib : a) + 1;
    Py_ssize_t n = b - a;
    double *m = malloc((size_t)(5 * n) * sizeof(double));
    if (m == NULL) { release_track(tb); PyErr_NoMemory(); return -1; }
    for (Py_ssize_t k = 0; k < n && raw; k++)
        for (int c = 0; c < 5; c++) m[c * n + k] = col[c][a + k];
    for (Py_ssize_t k = 0; k < n && !raw; k++) {
        Py_ssize_t r = a + k;
        m[k] = ts[r];
        m[n + k] = sc * col[1][r] + off + e0 + slope * (ts[r] - tref);
        m[2 * n + k] = sc * col[2][r] + slope;
        m[3 * n + k] = sc * col[3][r];
        m[4 * n + k] = sc * col[4][r];
    }
    release_track(tb);  /* (the buffers: the rows are copied) */
    tb->own = m;
    t->ts = m; t->p0 = m + n; t->v0 = m + 2 * n; t->a0 = m + 3 * n; t->j = m + 4 * n;
    t->n = n;
    return 0;
}

/* ------------------------------------------------------------------ level events */
/* crossings.velocity_roots, in its tuple order; returns the count */
static int velocity_roots(double v, double a, double j, double *r)
{
    double h = 0.5 * j;
    if (h == 0.0) {
        if (a != 0.0) { r[0] = -v / a; return 1; }
        return 0;
    }
    double disc = a * a - 4.0 * h * v;
    if (disc < 0.0) return 0;
    double q = -0.5 * (a + copysign(sqrt(disc), a));
    if (q != 0.0) { r[0] = q / h; r[1] = v / q; return 2; }
    r[0] = 0.0;
    return 1;
}

/* compare_roots._f: position minus level, snapped to 0 within rounding of the terms */
static inline double snapped(double c, double v, double a, double j, double x, double level,
                             double p)
{
    double f = c + x * (v + x * (a / 2.0 + x * j / 6.0));
    double scale = fabs(level) + fabs(p) + fabs(x * v) + fabs(x * x * a / 2.0)
                   + fabs(x * x * x * j / 6.0);
    return fabs(f) <= 8.0 * EPS * scale ? 0.0 : f;
}

/* compare_roots._refine: Newton inside the sign bracket */
static double refine(double c, double v, double a, double j, double lo, double hi, int s_lo,
                     double t_base)
{
    double x = 0.5 * (lo + hi);
    double tb = fabs(t_base);
    double a2 = a / 2.0;
    int up = s_lo > 0;
    for (int it = 0; it < 200; it++) {
        double f = c + x * (v + x * (a2 + x * j / 6.0));
        if (up ? (f > 0.0) : (f < 0.0)) lo = x; else hi = x;
        double tol = 2.0 * EPS * (tb + fabs(x));
        if (hi - lo <= tol) return hi;
        double d = v + x * (a + x * j / 2.0);
        double xn = d != 0.0 ? x - f / d : NAN;
        if (!(lo < xn && xn < hi)) xn = 0.5 * (lo + hi);
        else if (fabs(xn - x) <= tol) return xn;
        x = xn;
    }
    return hi;
}

/* the most events level_events can return for a track of n records */
static inline Py_ssize_t max_events(Py_ssize_t n) { return 6 * n + 2; }

/* compare_roots.level_events: times in (t, t1] where the track reaches `level`; writes
 * them to out (room for max_events(n)) and returns their count */
static Py_ssize_t level_events(const Trk *T, double level, double t, double t1,
                               int direction, int first, double *out)
{
    Py_ssize_t n = T->n, k = 0, m = 0;
    while (k + 1 < n && T->ts[k + 1] <= t) k++;
    int have_left = 0, s_left = 0, ends_at_t1 = 0;
    double f_end = 1.0;
    for (; k < n; k++) {
        double tk = T->ts[k];
        if (tk > t1) break;
        double end = k + 1 < n ? T->ts[k + 1] : INFINITY;
        double xa = pymax(t - tk, 0.0), xb = pymin(end, t1) - tk;
        double p = T->p0[k], v = T->v0[k], a = T->a0[k], j = T->j[k];
        double c = p - level;
        double r[2], cuts[4];
        int nr = velocity_roots(v, a, j, r), nc = 0;
        cuts[nc++] = xa;
        double in[2];
        int ni = 0;
        for (int q = 0; q < nr; q++)
            if (xa < r[q] && r[q] < xb) in[ni++] = r[q];
        if (ni == 2 && in[1] < in[0]) { double s = in[0]; in[0] = in[1]; in[1] = s; }
        for (int q = 0; q < ni; q++) cuts[nc++] = in[q];
        cuts[nc++] = xb;
        for (int q = 0; q + 1 < nc; q++) {
            double u = cuts[q], w = cuts[q + 1];
            if (!(w > u)) continue;
            double fu = snapped(c, v, a, j, u, level, p);
            double fw = snapped(c, v, a, j, w, level, p);
            int su = isign(fu), sw = isign(fw);
            if (!have_left) {
                have_left = 1;
                s_left = su;  /* the scan starts at t: no event there */
            } else if ((s_left < 0 && 0 <= fu && direction >= 0)
                       || (s_left > 0 && 0 >= fu && direction <= 0)) {
                out[m++] = tk + u;  /* arrival at a piece start */
                if (first) return m;
            }
            if (su * sw < 0 && (direction == 0 || direction == -su)) {
                out[m++] = tk + refine(c, v, a, j, u, w, su, tk);
                if (first) return m;
            }
            s_left = sw != 0 ? sw : su;
            f_end = fw;
            ends_at_t1 = end >= t1;
        }
    }
    if (ends_at_t1 && f_end == 0.0 && have_left && s_left != 0
            && (direction == 0 || direction == -s_left))
        out[m++] = t1;  /* arrival exactly at the window end */
    return m;
}

/* compare_math.positions at one time */
static inline double position(const Trk *T, double x)
{
    Py_ssize_t lo = 0, hi = T->n;  /* bisect_right */
    while (lo < hi) {
        Py_ssize_t mid = (lo + hi) / 2;
        if (x < T->ts[mid]) hi = mid; else lo = mid + 1;
    }
    Py_ssize_t k = lo - 1 > 0 ? lo - 1 : 0;
    double dt = x - T->ts[k];
    return T->p0[k] + dt * (T->v0[k] + dt * (T->a0[k] / 2.0 + dt * T->j[k] / 6.0));
}

/* compare_math.track_range: (min, max) of the track over [ta, t1] */
static void track_range(const Trk *T, double ta, double t1, double *lo_o, double *hi_o)
{
    double lo = INFINITY, hi = -INFINITY;
    Py_ssize_t n = T->n;
    for (Py_ssize_t k = 0; k < n; k++) {
        double a_k = T->ts[k];
        double b_k = k + 1 < n ? T->ts[k + 1] : INFINITY;
        double u = pymax(a_k, ta), w = pymin(b_k, t1);
        if (w < u) continue;
        double p = T->p0[k], v = T->v0[k], a = T->a0[k], j = T->j[k];
        double xs[4], r[2];
        int nx = 0, nr = velocity_roots(v, a, j, r);
        xs[nx++] = u - a_k;
        xs[nx++] = w - a_k;
        for (int q = 0; q < nr; q++)
            if (u - a_k < r[q] && r[q] < w - a_k) xs[nx++] = r[q];
        for (int q = 0; q < nx; q++) {
            double x = xs[q];
            double y = p + x * (v + x * (a / 2.0 + x * j / 6.0));
            lo = pymin(lo, y);
            hi = pymax(hi, y);
        }
    }
    *lo_o = lo;
    *hi_o = hi;
}

/* ------------------------------------------------------------------ window */
/* The events of level_events(direction 0) one at a time, in time order, with each root
 * refined only when asked (`Stream`): a root inside a monotone piece is first known by its
 * bracket and a rigorous lower bound of the time refine() will return. */
typedef struct {
    int exact;           /* 1: `time` is the event; 0: a root still to refine */
    double time;         /* exact time, or the lower bound */
    double c, v, a, j, u, w, tk;
    int su;
} Pend;

typedef struct {
    const Trk *T;
    double level, t, t1;
    Py_ssize_t k;
    int q, nc;
    double cuts[4], c, p, v, a, j, tk, end;
    int have_left, s_left, ends_at_t1, rec_open, done;
    double f_end;
    Pend pend[3];
    int head, npend;
} Stream;

static void stream_init(Stream *S, const Trk *T, double level, double t, double t1)
{
    memset(S, 0, sizeof *S);
    S->T = T; S->level = level; S->t = t; S->t1 = t1; S->f_end = 1.0;
    while (S->k + 1 < T->n && T->ts[S->k + 1] <= t) S->k++;
}

/* a lower bound of tk + refine(c, v, a, j, u, w, su, tk): the position must travel |f(u)|
 * (less the rounding noise of the polynomial) at no more than the piece's largest speed */
static double root_lower_bound(double c, double v, double a, double j, double u, double w,
                               double fu, double tk)
{
    double sc = fabs(c) + fabs(w * v) + fabs(w * w * a / 2.0) + fabs(w * w * w * j / 6.0);
    double noise = 64.0 * EPS * sc;
    double vm = pymax(fabs(v + u * (a + u * j / 2.0)), fabs(v + w * (a + w * j / 2.0)));
    if (j != 0.0) {
        double xv = -a / j;
        if (u < xv && xv < w) vm = pymax(vm, fabs(v + xv * (a + xv * j / 2.0)));
    }
    vm = vm * (1.0 + 1e-9) + 1e-300;
    double tol = 2.0 * EPS * (fabs(tk) + fabs(w));
    double d = (fabs(fu) - 2.0 * noise) / vm * (1.0 - 1e-9) - 8.0 * tol - 4.0 * EPS * w;
    if (!(d > 0.0)) d = 0.0;
    if (d > w - u) d = w - u;
    double lb = tk + (u + d);
    double base = tk + u;  /* refine never returns below u */
    return lb > base ? lb - 4.0 * EPS * fabs(lb) : base;
}

/* fill S->pend with the next piece's events; 0 when there are none left */
static int stream_fill(Stream *S)
{
    const Trk *T = S->T;
    S->head = S->npend = 0;
    while (!S->done) {
        if (!S->rec_open) {
            if (S->k >= T->n) { S->done = 1; break; }
            double tk = T->ts[S->k];
            if (tk > S->t1) { S->done = 1; break; }
            S->tk = tk;
            S->end = S->k + 1 < T->n ? T->ts[S->k + 1] : INFINITY;
            double xa = pymax(S->t - tk, 0.0), xb = pymin(S->end, S->t1) - tk;
            S->p = T->p0[S->k]; S->v = T->v0[S->k]; S->a = T->a0[S->k]; S->j = T->j[S->k];
            S->c = S->p - S->level;
            double r[2], in[2];
            int nr = velocity_roots(S->v, S->a, S->j, r), ni = 0;
            for (int q = 0; q < nr; q++)
                if (xa < r[q] && r[q] < xb) in[ni++] = r[q];
            if (ni == 2 && in[1] < in[0]) { double x = in[0]; in[0] = in[1]; in[1] = x; }
            S->nc = 0;
            S->cuts[S->nc++] = xa;
            for (int q = 0; q < ni; q++) S->cuts[S->nc++] = in[q];
            S->cuts[S->nc++] = xb;
            S->q = 0;
            S->rec_open = 1;
        }
        if (S->q + 1 >= S->nc) { S->rec_open = 0; S->k++; continue; }
        double u = S->cuts[S->q], w = S->cuts[S->q + 1];
        S->q++;
        if (!(w > u)) continue;
        double c = S->c, v = S->v, a = S->a, j = S->j, tk = S->tk;
        double fu = snapped(c, v, a, j, u, S->level, S->p);
        double fw = snapped(c, v, a, j, w, S->level, S->p);
        int su = isign(fu), sw = isign(fw);
        if (!S->have_left) {
            S->have_left = 1;
            S->s_left = su;
        } else if ((S->s_left < 0 && 0 <= fu) || (S->s_left > 0 && 0 >= fu)) {
            Pend *e = &S->pend[S->npend++];
            e->exact = 1;
            e->time = tk + u;
        }
        if (su * sw < 0) {
            Pend *e = &S->pend[S->npend++];
            e->exact = 0;
            e->c = c; e->v = v; e->a = a; e->j = j; e->u = u; e->w = w; e->tk = tk;
            e->su = su;
            e->time = root_lower_bound(c, v, a, j, u, w, fu, tk);
        }
        S->s_left = sw != 0 ? sw : su;
        S->f_end = fw;
        S->ends_at_t1 = S->end >= S->t1;
        if (S->npend) return 1;
    }
    if (S->done == 1) {
        S->done = 2;  /* the window-end arrival, once */
        if (S->ends_at_t1 && S->f_end == 0.0 && S->have_left && S->s_left != 0) {
            Pend *e = &S->pend[S->npend++];
            e->exact = 1;
            e->time = S->t1;
            return 1;
        }
    }
    return 0;
}

/* Rejecting a candidate without refining it. A root of a monotone piece that refine()
 * would return for the bracket (u, w) is enclosed first by a few cheap Newton steps: when
 * F (the float polynomial refine evaluates) is beyond +-m at both ends of [A, B], with m
 * twice the rounding noise of F plus the largest step refine's stopping rule allows,
 * refine's answer lies in [A - tol, B + tol] (it stops with F > 0 at or just before it and
 * F <= 0 at or just after it, or on a Newton step shorter than tol, which needs |F| <=
 * tol |F'|). If some axis is then farther than its window over that whole time span (its
 * position's change bounded by its speed, plus the evaluation noise), the candidate
 * cannot be inside and is dropped unrefined: the first time inside is the same. */
static int check_rejects = 0;           /* tests: refine rejected candidates and verify */
static long long n_refined = 0, n_rejected = 0;

static inline double poly_f(double c, double v, double a2, double j, double x)
{
    return c + x * (v + x * (a2 + x * j / 6.0));
}

/* [*ta, *tb] (absolute times) holding tk + refine(c, v, a, j, u, w, su, tk); 0 if no
 * enclosure was found (then the candidate is refined) */
static int root_enclosure(const Pend *e, double *ta, double *tb)
{
    double c = e->c, v = e->v, a = e->a, j = e->j, u = e->u, w = e->w, tk = e->tk;
    double a2 = a / 2.0;
    int up = e->su > 0;
    double lo = u, hi = w, x = 0.5 * (u + w);
    for (int it = 0; it < 12; it++) {  /* safeguarded Newton, no exactness needed */
        double f = poly_f(c, v, a2, j, x);
        if (f == 0.0) break;
        if (up ? (f > 0.0) : (f < 0.0)) lo = x; else hi = x;
        double d = v + x * (a + x * j / 2.0);
        double xn = d != 0.0 ? x - f / d : NAN;
        if (lo < xn && xn < hi) {
            int done = fabs(xn - x) <= 4.0 * EPS * fabs(x);
            x = xn;
            if (done) break;
        } else {
            x = 0.5 * (lo + hi);
        }
    }
    double sc = fabs(c) + fabs(w * v) + fabs(w * w * a / 2.0) + fabs(w * w * w * j / 6.0);
    double vm = pymax(fabs(v + u * (a + u * j / 2.0)), fabs(v + w * (a + w * j / 2.0)));
    if (j != 0.0) {
        double xv = -a / j;
        if (u < xv && xv < w) vm = pymax(vm, fabs(v + xv * (a + xv * j / 2.0)));
    }
    vm = vm * (1.0 + 1e-6) + 1e-300;
    double tol = 2.0 * EPS * (fabs(tk) + fabs(w)) * (1.0 + 1e-6);
    double m = 2.0 * (64.0 * EPS * sc) + 2.0 * tol * vm + 1e-300;
    double s = fabs(v + x * (a + x * j / 2.0));
    if (!(s > 0.0) || !isfinite(s)) return 0;
    double delta = 4.0 * m / s + 4.0 * tol + 4.0 * EPS * fabs(x);
    double A = x - delta, B = x + delta;
    if (!(u <= A && B <= w)) return 0;
    double fa = poly_f(c, v, a2, j, A), fb = poly_f(c, v, a2, j, B);
    if (up ? !(fa > m && fb < -m) : !(fa < -m && fb > m)) return 0;
    double lo_t = tk + (A - tol), hi_t = tk + (B + tol);
    *ta = lo_t - 4.0 * EPS * fabs(lo_t);
    *tb = hi_t + 4.0 * EPS * fabs(hi_t);
    return 1;
}

/* is track T farther than lim from c at every time in [ta, tb] (as position() reads it)? */
static int outside_over(const Trk *T, double c, double lim, double ta, double tb)
{
    Py_ssize_t lo = 0, hi = T->n;  /* position()'s record at ta */
    while (lo < hi) {
        Py_ssize_t mid = (lo + hi) / 2;
        if (ta < T->ts[mid]) hi = mid; else lo = mid + 1;
    }
    Py_ssize_t k = lo - 1 > 0 ? lo - 1 : 0;
    if (k + 1 < T->n && T->ts[k + 1] <= tb) return 0;  /* a record starts inside */
    if (k > 0 && ta < T->ts[k]) return 0;
    double p = T->p0[k], v = T->v0[k], a = T->a0[k], j = T->j[k];
    double da = ta - T->ts[k], db = tb - T->ts[k], W = tb - ta;
    if (!(W >= 0.0)) return 0;
    double x = p + da * (v + da * (a / 2.0 + da * j / 6.0));
    double dm = pymax(fabs(da), fabs(db));
    double vmax = fabs(v + da * (a + da * j / 2.0)) + (fabs(a + da * j) + fabs(j) * W) * W;
    double noise = 64.0 * EPS * (fabs(p) + fabs(dm * v) + fabs(dm * dm * a / 2.0)
                                 + fabs(dm * dm * dm * j / 6.0) + fabs(c));
    double gap = fabs(x - c) - (vmax * W * (1.0 + 1e-6) + 2.0 * noise);
    return gap > lim * (1.0 + 1e-12);
}

/* compare_math.first_inside: the first time in [t, t1] every track is within +-maxerr of
 * its centre. Returns 1 and *x, 0 for none, -1 on error. lo/hi: each track's range.
 * The candidates (t, and every crossing of c - maxerr and c + maxerr) are tested in time
 * order as by the eager version (all crossings, sorted): each level's events come in
 * order from its Stream, and a root is refined only while its lower bound is the
 * smallest pending one, so the same first candidate inside is found with fewer roots. */
static int first_inside(const Trk *T, int na, const double *centre, double maxerr, double t,
                        double t1, const double *lo, const double *hi, double *x_out)
{
    double lim[MAX_AXES];
    Stream st[2 * MAX_AXES];
    int axis_of[2 * MAX_AXES];
    int ns = 0;
    for (int i = 0; i < na; i++) {
        double c = centre[i];
        double slack = 1e-9 * (fabs(c) + maxerr + 1.0);
        if (c + maxerr < lo[i] - slack || c - maxerr > hi[i] + slack) return 0;
        lim[i] = maxerr + 1e-12 * (fabs(c) + maxerr + 1.0);
        double lv[2] = {c - maxerr, c + maxerr};
        for (int q = 0; q < 2; q++) {
            if (!(lo[i] - slack <= lv[q] && lv[q] <= hi[i] + slack)) continue;
            stream_init(&st[ns], &T[i], lv[q], t, t1);
            axis_of[ns] = i;
            if (stream_fill(&st[ns])) ns++;
        }
    }
    if (t <= t1) {
        int ok = 1;
        for (int i = 0; i < na && ok; i++)
            ok = fabs(position(&T[i], t) - centre[i]) <= lim[i];
        if (ok) { *x_out = t; return 1; }
    }
    int live = ns;
    while (live > 0) {
        int best = -1;
        for (int s = 0; s < ns; s++) {
            if (st[s].head >= st[s].npend) continue;
            if (best < 0 || st[s].pend[st[s].head].time < st[best].pend[st[best].head].time)
                best = s;
        }
        Pend *e = &st[best].pend[st[best].head];
        if (!e->exact) {
            double ta, tb;
            int out = 0;
            int enc = root_enclosure(e, &ta, &tb);
            if (enc)
                for (int i = 0; i < na && !out; i++)
                    out = i != axis_of[best] && outside_over(&T[i], centre[i], lim[i], ta, tb);
            if (out && check_rejects) {  /* tests: the dropped root really is outside */
                double r = e->tk + refine(e->c, e->v, e->a, e->j, e->u, e->w, e->su, e->tk);
                int in = 1;
                for (int i = 0; i < na && in; i++)
                    in = fabs(position(&T[i], r) - centre[i]) <= lim[i];
                if (in || r < ta || r > tb) {
                    PyErr_Format(PyExc_AssertionError, "rejected root %.17g inside (%d) or "
                                 "outside [%.17g, %.17g]", r, in, ta, tb);
                    return -1;
                }
            }
            if (out) {
                n_rejected++;
                if (++st[best].head >= st[best].npend && !stream_fill(&st[best])) live--;
                continue;
            }
            n_refined++;
            e->time = e->tk + refine(e->c, e->v, e->a, e->j, e->u, e->w, e->su, e->tk);
            e->exact = 1;
            continue;  /* it may no longer be the smallest */
        }
        double x = e->time;
        if (++st[best].head >= st[best].npend && !stream_fill(&st[best])) live--;
        if (!(t <= x && x <= t1)) continue;
        int ok = 1;
        for (int i = 0; i < na && ok; i++)
            ok = fabs(position(&T[i], x) - centre[i]) <= lim[i];
        if (ok) { *x_out = x; return 1; }
    }
    return 0;
}

/* The track and range arguments of an entry point, parsed in one place: `tr_o` one track
 * (single) or a sequence of 1..MAX_AXES tracks; `rg_o` NULL or None (no ranges: +-inf),
 * one (lo, hi) pair (single) or a sequence of them, one per track. On success the caller
 * owns the buffers until args_release; on failure nothing is held. */
typedef struct {
    Trk T[MAX_AXES];
    TrkBuf tb[MAX_AXES];
    double lo[MAX_AXES], hi[MAX_AXES];
    int na;
} TrackArgs;

static void args_release(TrackArgs *A)
{
    for (int i = 0; i < A->na; i++) release_track(&A->tb[i]);
    A->na = 0;
}

static int get_range(PyObject *o, double *lo, double *hi)
{
    PyObject *seq = PySequence_Fast(o, "a range must be a (lo, hi) pair");
    if (seq == NULL) return -1;
    int ok = PySequence_Fast_GET_SIZE(seq) == 2;
    if (!ok) PyErr_SetString(PyExc_ValueError, "a range must be a (lo, hi) pair");
    if (ok) {
        *lo = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(seq, 0));
        ok = !(*lo == -1.0 && PyErr_Occurred());
    }
    if (ok) {
        *hi = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(seq, 1));
        ok = !(*hi == -1.0 && PyErr_Occurred());
    }
    Py_DECREF(seq);
    return ok ? 0 : -1;
}

static int track_args(PyObject *tr_o, PyObject *rg_o, int single, TrackArgs *A)
{
    A->na = 0;
    if (single) {
        if (get_track(tr_o, &A->T[0], &A->tb[0]) < 0) return -1;
        A->na = 1;
    } else {
        PyObject *seq = PySequence_Fast(tr_o, "tracks must be a sequence of tracks");
        if (seq == NULL) return -1;
        Py_ssize_t na = PySequence_Fast_GET_SIZE(seq);
        if (na < 1 || na > MAX_AXES) {
            Py_DECREF(seq);
            PyErr_Format(PyExc_ValueError, "tracks: 1..%d axes, got %zd", MAX_AXES, na);
            return -1;
        }
        for (Py_ssize_t i = 0; i < na; i++) {
            if (get_track(PySequence_Fast_GET_ITEM(seq, i), &A->T[i], &A->tb[i]) < 0) {
                Py_DECREF(seq);
                args_release(A);
                return -1;
            }
            A->na = (int)i + 1;
        }
        Py_DECREF(seq);
    }
    if (rg_o == NULL || rg_o == Py_None) {
        for (int i = 0; i < A->na; i++) { A->lo[i] = -INFINITY; A->hi[i] = INFINITY; }
        return 0;
    }
    if (single) {
        if (get_range(rg_o, &A->lo[0], &A->hi[0]) < 0) { args_release(A); return -1; }
        return 0;
    }
    PyObject *seq = PySequence_Fast(rg_o, "ranges must be a sequence of (lo, hi)");
    if (seq == NULL) { args_release(A); return -1; }
    int bad = PySequence_Fast_GET_SIZE(seq) != A->na;
    if (bad) PyErr_SetString(PyExc_ValueError, "ranges: one (lo, hi) per track");
    for (int i = 0; i < A->na && !bad; i++)
        bad = get_range(PySequence_Fast_GET_ITEM(seq, i), &A->lo[i], &A->hi[i]) < 0;
    Py_DECREF(seq);
    if (bad) { args_release(A); return -1; }
    return 0;
}

PyDoc_STRVAR(window_scan_doc,
"window_scan(tracks, ranges, points, maxerr, index, t, t1) -> list of times\n\n"
"A WindowJob's scan of one window: from point `index` of points (float64[n, k], one\n"
"column per track), the first time in [t, t1] all tracks are within +-maxerr of the\n"
"point (compare_math.first_inside), then the next point from that time on, until one\n"
"is not reached. ranges: each track's (min, max) over the window, or None.");

static PyObject *window_scan(PyObject *self, PyObject *args)
{
    PyObject *tr_o, *rg_o, *pt_o;
    double maxerr, t, t1;
    Py_ssize_t index;
    if (!PyArg_ParseTuple(args, "OOOdndd", &tr_o, &rg_o, &pt_o, &maxerr, &index, &t, &t1))
        return NULL;
    TrackArgs A;
    if (track_args(tr_o, rg_o, 0, &A) < 0) return NULL;
    int na = A.na;
    PyObject *res = NULL;
    Py_buffer pb;
    if (get_vec(pt_o, &pb, "points") < 0) goto done_tracks;
    Py_ssize_t n = pb.len / 8 / na;
    if (n * na * 8 != pb.len) {
        PyErr_SetString(PyExc_ValueError, "points must be float64[n, len(tracks)]");
        goto done_points;
    }
    res = PyList_New(0);
    if (res == NULL) goto done_points;
    const double *pts = pb.buf;
    while (index < n) {
        double x;
        int r = first_inside(A.T, na, pts + index * na, maxerr, t, t1, A.lo, A.hi, &x);
        if (r < 0) { Py_CLEAR(res); break; }
        if (r == 0) break;
        PyObject *f = PyFloat_FromDouble(x);
        if (f == NULL || PyList_Append(res, f) < 0) { Py_XDECREF(f); Py_CLEAR(res); break; }
        Py_DECREF(f);
        index++;
        t = x;
    }
done_points:
    PyBuffer_Release(&pb);
done_tracks:
    args_release(&A);
    return res;
}

PyDoc_STRVAR(first_inside_doc,
"first_inside(tracks, centre, maxerr, t, t1, ranges) -> time or None\n\n"
"The first time in [t, t1] every track is within +-maxerr of its centre (float64[k]).");

static PyObject *first_inside_py(PyObject *self, PyObject *args)
{
    PyObject *tr_o, *c_o, *rg_o;
    double maxerr, t, t1;
    if (!PyArg_ParseTuple(args, "OOdddO", &tr_o, &c_o, &maxerr, &t, &t1, &rg_o)) return NULL;
    TrackArgs A;
    if (track_args(tr_o, rg_o, 0, &A) < 0) return NULL;
    PyObject *res = NULL;
    Py_buffer cb;
    if (get_vec(c_o, &cb, "centre") < 0) goto done;
    if (cb.len != 8 * A.na) {
        PyErr_SetString(PyExc_ValueError, "centre: one coordinate per track");
    } else {
        double x;
        int r = first_inside(A.T, A.na, cb.buf, maxerr, t, t1, A.lo, A.hi, &x);
        if (r > 0) res = PyFloat_FromDouble(x);
        else if (r == 0) res = Py_NewRef(Py_None);
    }
    PyBuffer_Release(&cb);
done:
    args_release(&A);
    return res;
}

PyDoc_STRVAR(positions_doc,
"positions(tracks, times, out)\n\n"
"out[i, k] = position of track k at times[i] (compare_math.positions, every track at\n"
"once); out: a writable C-contiguous float64 (len(times), len(tracks)) array.");

static PyObject *positions_py(PyObject *self, PyObject *args)
{
    PyObject *tr_o, *t_o, *out_o;
    if (!PyArg_ParseTuple(args, "OOO", &tr_o, &t_o, &out_o)) return NULL;
    PyObject *trs = PySequence_Fast(tr_o, "tracks must be a sequence of tracks");
    if (trs == NULL) return NULL;
    PyObject *res = NULL, *ts = NULL;
    double *x = NULL;
    Py_buffer ob;
    int have_out = 0;
    Py_ssize_t na = PySequence_Fast_GET_SIZE(trs);
    ts = PySequence_Fast(t_o, "times must be a sequence");
    if (ts == NULL) goto done;
    if (PyObject_GetBuffer(out_o, &ob, PyBUF_C_CONTIGUOUS | PyBUF_WRITABLE | PyBUF_FORMAT) < 0)
        goto done;
    have_out = 1;
    Py_ssize_t m = PySequence_Fast_GET_SIZE(ts);
    size_t fl = ob.format ? strlen(ob.format) : 0;
    if (ob.itemsize != 8 || fl == 0 || ob.format[fl - 1] != 'd' || ob.len != 8 * m * na) {
        PyErr_SetString(PyExc_ValueError, "out must be float64[len(times), len(tracks)]");
        goto done;
    }
    x = malloc((size_t)(m > 0 ? m : 1) * sizeof(double));
    if (x == NULL) { PyErr_NoMemory(); goto done; }
    for (Py_ssize_t i = 0; i < m; i++) {
        x[i] = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(ts, i));
        if (x[i] == -1.0 && PyErr_Occurred()) goto done;
    }
    double *out = ob.buf;
    for (Py_ssize_t k = 0; k < na; k++) {  /* one track at a time: any number of axes */
        Trk T;
        TrkBuf tb;
        if (get_track(PySequence_Fast_GET_ITEM(trs, k), &T, &tb) < 0) goto done;
        for (Py_ssize_t i = 0; i < m; i++) out[i * na + k] = position(&T, x[i]);
        release_track(&tb);
    }
    res = Py_NewRef(Py_None);
done:
    free(x);
    if (have_out) PyBuffer_Release(&ob);
    Py_XDECREF(ts);
    Py_DECREF(trs);
    return res;
}

/* ------------------------------------------------------------------ levels */
/* The value list of a LevelJob: an array, or start + k * step (LevelSeq); `n` values,
 * then `after` if has_after. */
typedef struct {
    const double *arr;
    double start, step, after;
    long long n;
    int has_after;
} Levels;

static inline double level_at(const Levels *L, long long k)
{
    if (k < L->n) return L->arr ? L->arr[k] : L->start + (double)k * L->step;
    return L->after;
}

static int get_levels(PyObject *o, long long n, PyObject *after_o, Levels *L, Py_buffer *b,
                      int *held)
{
    *held = 0;
    memset(L, 0, sizeof *L);
    L->n = n;
    if (PyTuple_Check(o) && PyTuple_GET_SIZE(o) == 2) {
        if (!PyArg_ParseTuple(o, "dd", &L->start, &L->step)) return -1;
    } else {
        if (get_vec(o, b, "levels") < 0) return -1;
        *held = 1;
        if (b->len / 8 < n) {
            PyErr_SetString(PyExc_ValueError, "levels shorter than their count");
            return -1;
        }
        L->arr = b->buf;
    }
    if (after_o != Py_None) {
        L->after = PyFloat_AsDouble(after_o);
        if (L->after == -1.0 && PyErr_Occurred()) return -1;
        L->has_after = 1;
    }
    return 0;
}

PyDoc_STRVAR(level_scan_doc,
"level_scan(track, range, levels, n, after_final, index, t, t1, direction) -> list\n\n"
"A LevelJob's scan of one window on an axis track: from value `index` on, the first\n"
"crossing after t of each value in turn (level_events, first only), skipped when the\n"
"value is out of the track's (min, max) `range` (+- 1e-9 relative); stops at the first\n"
"value not reached. levels: float64 array or (start, step) for start + k * step; n\n"
"values, then after_final (None: none). Returns [(time, level), ...].");

static PyObject *level_scan(PyObject *self, PyObject *args)
{
    PyObject *tr_o, *rg_o, *lv_o, *af_o;
    double t, t1;
    long long n, index;
    int direction;
    if (!PyArg_ParseTuple(args, "OOOLOLddi", &tr_o, &rg_o, &lv_o, &n, &af_o, &index, &t, &t1,
                          &direction))
        return NULL;
    TrackArgs A;
    if (track_args(tr_o, rg_o, 1, &A) < 0) return NULL;
    const Trk *T = &A.T[0];
    double rlo = A.lo[0], rhi = A.hi[0];
    Levels L;
    Py_buffer lb;
    int held;
    PyObject *res = NULL;
    if (get_levels(lv_o, n, af_o, &L, &lb, &held) < 0) goto done;
    long long size = L.n + L.has_after;
    Py_ssize_t cap = max_events(T->n);
    double *ev = malloc((size_t)cap * sizeof(double));
    if (ev == NULL) { PyErr_NoMemory(); goto done; }
    res = PyList_New(0);
    while (res != NULL && index < size) {
        double lvl = level_at(&L, index);
        double slack = 1e-9 * (fabs(lvl) + 1.0);
        if (!(rlo - slack <= lvl && lvl <= rhi + slack)) break;
        if (level_events(T, lvl, t, t1, direction, 1, ev) == 0) break;
        PyObject *it = Py_BuildValue("(dd)", ev[0], lvl);
        if (it == NULL || PyList_Append(res, it) < 0) { Py_XDECREF(it); Py_CLEAR(res); break; }
        Py_DECREF(it);
        index++;
        t = ev[0];
    }
    free(ev);
done:
    if (held) PyBuffer_Release(&lb);
    args_release(&A);
    return res;
}

PyDoc_STRVAR(level_events_doc,
"level_events(track, level, t, t1, direction=0, first=False) -> list of times\n\n"
"Times in (t, t1] where the track reaches `level` (direction +1 up, -1 down, 0 both;\n"
"the semantics of MotionHistory.crossings, compare_roots docstring).");

static PyObject *level_events_py(PyObject *self, PyObject *args)
{
    PyObject *tr_o;
    double level, t, t1;
    int direction = 0, first = 0;
    if (!PyArg_ParseTuple(args, "Oddd|ip", &tr_o, &level, &t, &t1, &direction, &first))
        return NULL;
    TrackArgs A;
    if (track_args(tr_o, NULL, 1, &A) < 0) return NULL;
    Py_ssize_t cap = max_events(A.T[0].n);
    double *ev = malloc((size_t)cap * sizeof(double));
    PyObject *res = NULL;
    if (ev == NULL) {
        PyErr_NoMemory();
    } else {
        Py_ssize_t m = level_events(&A.T[0], level, t, t1, direction, first, ev);
        res = PyList_New(m);
        for (Py_ssize_t i = 0; res != NULL && i < m; i++) {
            PyObject *f = PyFloat_FromDouble(ev[i]);
            if (f == NULL) { Py_CLEAR(res); break; }
            PyList_SET_ITEM(res, i, f);
        }
        free(ev);
    }
    args_release(&A);
    return res;
}

PyDoc_STRVAR(track_range_doc,
"track_range(track, ta, t1) -> (min, max) of the track's position over [ta, t1]");

static PyObject *track_range_py(PyObject *self, PyObject *args)
{
    PyObject *tr_o;
    double ta, t1;
    if (!PyArg_ParseTuple(args, "Odd", &tr_o, &ta, &t1)) return NULL;
    TrackArgs A;
    if (track_args(tr_o, NULL, 1, &A) < 0) return NULL;
    double lo, hi;
    track_range(&A.T[0], ta, t1, &lo, &hi);
    args_release(&A);
    return Py_BuildValue("(dd)", lo, hi);
}

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

typedef struct {
    const double *B, *S, *Q;
    Py_ssize_t nb;  /* breakpoints; pieces nb - 1 */
} Vc;

/* VectorCycle.time_of: first time > after with s(t) >= d. Returns 1 and *t, or 0. */
static int time_of(const Vc *V, double d, double after, double *t_out)
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

typedef struct {
    Py_buffer b[3];
    int held;
} VcBuf;

static void release_vc(VcBuf *vb)
{
    for (int k = 0; k < vb->held; k++) PyBuffer_Release(&vb->b[k]);
    vb->held = 0;
}

static int get_vc(PyObject *B, PyObject *S, PyObject *Q, Vc *V, VcBuf *vb)
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

PyDoc_STRVAR(set_gauss_doc, "set_gauss(x, w): the 8 Gauss-Legendre nodes and weights.");

static PyObject *set_gauss(PyObject *self, PyObject *args)
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

PyDoc_STRVAR(gl_doc,
"gl(q, a, b) -> integral over [a, b] of sqrt(q0 + q1 x + ... + q4 x^4), 8-point GL");

static PyObject *gl_py(PyObject *self, PyObject *args)
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

PyDoc_STRVAR(adaptive_doc,
"adaptive(q, a, b, rtol, max_depth) -> the integral of gl halved until two levels agree");

static PyObject *adaptive_py(PyObject *self, PyObject *args)
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

PyDoc_STRVAR(vector_pieces_doc,
"vector_pieces(tracks, weights, ta, t1) -> (B, Q, R) as bytes of float64\n\n"
"VectorCycle's pieces over [ta, t1]: B the breakpoints (ta, t1, every record start and\n"
"velocity root inside, sorted), Q (n, 5) each piece's speed^2 quartic, R (2, n, 8) the\n"
"speed at the nodes of one and of two Gauss-Legendre panels (summed), whose products\n"
"with the weights vector_sums takes. tracks: tracks or history specs (see bank_scan).");

static PyObject *vector_pieces(PyObject *self, PyObject *args)
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

PyDoc_STRVAR(vector_sums_doc,
"vector_sums(B, Q, d1, d2, s0, rtol, max_depth) -> S as bytes of float64\n\n"
"VectorCycle's cumulative lengths from vector_pieces: d1 = R1 @ w, d2 = R2 @ w; a\n"
"piece's length is (h / 4) * d2 unless it differs from (h / 2) * d1 by more than rtol\n"
"(relative), then adaptive(Q[i], 0, h, rtol, max_depth); S = s0 + [0, cumsum].");

static PyObject *vector_sums(PyObject *self, PyObject *args)
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

PyDoc_STRVAR(vector_at_doc, "vector_at(B, S, Q, t) -> s(t) (VectorCycle.at)");

static PyObject *vector_at(PyObject *self, PyObject *args)
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

PyDoc_STRVAR(vector_scan_doc,
"vector_scan(B, S, Q, levels, n, after_final, index, t, first_only) -> list\n\n"
"A LevelJob's scan of one window on a path length (VectorCycle B, S, Q): from value\n"
"`index` on, the first time after t that s reaches each value in turn (time_of), until\n"
"one is not reached (first_only: the value at `index` only). Returns [(time, level)].");

static PyObject *vector_scan(PyObject *self, PyObject *args)
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

PyDoc_STRVAR(time_of_doc, "time_of(B, S, Q, d, after) -> first time > after with s >= d, or None");

static PyObject *time_of_py(PyObject *self, PyObject *args)
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

/* ------------------------------------------------------------------ output lines */
/* compare_io.OutputLine.set applied to a sequence of (time, level): the edge lists t (floats,
 * time-ordered) and lv (bools) are edited in place exactly as by one `set` call after the
 * other. Times <= sent_until of sets that changed something are appended to `late`. */
static int lv_of(PyObject *lst, Py_ssize_t k, int initial)
{
    if (k < 0) return initial;
    PyObject *o = PyList_GET_ITEM(lst, k);
    return o == Py_True ? 1 : o == Py_False ? 0 : PyObject_IsTrue(o) > 0;
}

static inline double as_double(PyObject *o)
{
    return PyFloat_Check(o) ? PyFloat_AS_DOUBLE(o) : PyFloat_AsDouble(o);
}

static int line_set_one(PyObject *tl, PyObject *ll, int initial, double t, int level,
                        double sent_until, PyObject *late)
{
    Py_ssize_t n = PyList_GET_SIZE(tl), lo = 0, hi = n;
    while (lo < hi) {  /* bisect_right */
        Py_ssize_t mid = (lo + hi) / 2;
        if (t < as_double(PyList_GET_ITEM(tl, mid))) hi = mid; else lo = mid + 1;
    }
    Py_ssize_t k = lo;
    int before = lv_of(ll, k - 1, initial);
    int after_same = k < n && lv_of(ll, k, initial) == level;
    if (before == level && !after_same) return 0;
    if (t <= sent_until) {
        PyObject *f = PyFloat_FromDouble(t);
        if (f == NULL || PyList_Append(late, f) < 0) { Py_XDECREF(f); return -1; }
        Py_DECREF(f);
    }
    /* the insertion and OutputLine._merge, without moving the lists twice: the new edge
     * at k is followed by edge k (old); drop k+1 (old k) if it repeats the new level, then
     * the new one if it repeats the level before it */
    int drop_next = after_same;  /* lv[k+1] == lv[k] == level */
    int drop_new = before == level;
    if (drop_next && drop_new) {  /* the old edge k goes, nothing is inserted */
        if (PySequence_DelItem(tl, k) < 0 || PySequence_DelItem(ll, k) < 0) return -1;
        return 0;
    }
    if (drop_next) {  /* the new edge replaces the old one at k */
        PyObject *f = PyFloat_FromDouble(t);
        if (f == NULL) return -1;
        if (PyList_SetItem(tl, k, f) < 0) return -1;
        return 0;
    }
    if (drop_new) return 0;  /* unreachable: handled by the early return above */
    PyObject *f = PyFloat_FromDouble(t);
    if (f == NULL) return -1;
    int r = PyList_Insert(tl, k, f);
    Py_DECREF(f);
    if (r < 0 || PyList_Insert(ll, k, level ? Py_True : Py_False) < 0) return -1;
    return 0;
}

PyDoc_STRVAR(line_set_doc,
"line_set(t, lv, initial, times, levels, sent_until, late)\n\n"
"OutputLine.set(times[i], levels[i]) for i in order, on the edge lists t (floats) and lv\n"
"(bools) in place; set times <= sent_until that changed the waveform go to `late`.");

static PyObject *line_set(PyObject *self, PyObject *args)
{
    PyObject *tl, *ll, *ts_o, *lvs_o, *late;
    int initial;
    double sent_until;
    if (!PyArg_ParseTuple(args, "O!O!pOOdO!", &PyList_Type, &tl, &PyList_Type, &ll, &initial,
                          &ts_o, &lvs_o, &sent_until, &PyList_Type, &late))
        return NULL;
    if (PyList_GET_SIZE(tl) != PyList_GET_SIZE(ll)) {
        PyErr_SetString(PyExc_ValueError, "line_set: t and lv differ in length");
        return NULL;
    }
    PyObject *ts = PySequence_Fast(ts_o, "times must be a sequence");
    if (ts == NULL) return NULL;
    PyObject *lvs = PySequence_Fast(lvs_o, "levels must be a sequence");
    if (lvs == NULL) { Py_DECREF(ts); return NULL; }
    Py_ssize_t m = PySequence_Fast_GET_SIZE(ts);
    PyObject *res = NULL;
    if (PySequence_Fast_GET_SIZE(lvs) != m) {
        PyErr_SetString(PyExc_ValueError, "line_set: one level per time");
        goto done;
    }
    for (Py_ssize_t i = 0; i < m; i++) {
        double t = as_double(PySequence_Fast_GET_ITEM(ts, i));
        if (t == -1.0 && PyErr_Occurred()) goto done;
        int level = PyObject_IsTrue(PySequence_Fast_GET_ITEM(lvs, i));
        if (level < 0 || line_set_one(tl, ll, initial, t, level, sent_until, late) < 0)
            goto done;
    }
    res = Py_NewRef(Py_None);
done:
    Py_DECREF(lvs);
    Py_DECREF(ts);
    return res;
}


/* ------------------------------------------------------------------ the scan driver */
/* One call per cycle runs every "native" job of a group (LevelJob on an axis, WindowJob;
 * actions Toggle / SetLevel / Pulse): CompareEngine._scan's loop, LevelJob.scan /
 * WindowJob.scan, the actions' apply_many on the OutputLine edge lists (line_set_one) and
 * every axis's position at each firing, without a Python call per job. A job's fixed
 * description (kind, track slots, values or points, action) is parsed once into a Bank
 * (a capsule, rebuilt when the engine's job set changes); its running state (`index`,
 * `hits`) stays on the job object, read and written here. */
enum { K_LEVEL = 0, K_WINDOW = 1, K_VECTOR = 2 };
enum { A_TOGGLE = 0, A_SET = 1, A_PULSE = 2 };

typedef struct {
    int kind, na, slot[MAX_AXES], direction, repeat, act, flag, line, output;
    Levels L;
    Py_buffer vb;
    int held;
    const double *pts;
    Py_ssize_t npts;
    double maxerr, t_armed, width;
    long long jid;
} Spec;

typedef struct {
    Py_ssize_t n;
    Spec *s;
} Bank;

static void bank_free(PyObject *cap)
{
    Bank *B = PyCapsule_GetPointer(cap, "openmotion._compare.Bank");
    if (B == NULL) return;
    for (Py_ssize_t i = 0; i < B->n; i++)
        if (B->s[i].held) PyBuffer_Release(&B->s[i].vb);
    free(B->s);
    free(B);
}

PyDoc_STRVAR(bank_new_doc,
"bank_new(specs) -> bank\n\n"
"Parse the jobs of one scan group once. Each spec: (kind, slots, direction, repeat,\n"
"values, n, after_final, maxerr, t_armed, job_id, action, flag, width, line, output):\n"
"kind 0 a "
"LevelJob on track slots[0] (values: float64 array or (start, step), n of them, then\n"
"after_final or None), 1 a WindowJob on slots (values: float64[n, len(slots)]); action\n"
"2 a LevelJob on a path length, vector slots[0] (values as kind 0, direction unused);\n"
"0 Toggle (flag = first), 1 SetLevel (flag = level), 2 Pulse (flag = active, width);\n"
"line: the index of its OutputLine in bank_scan's `lines`, output: its number (logged).");

static PyObject *bank_new(PyObject *self, PyObject *args)
{
    PyObject *specs_o;
    if (!PyArg_ParseTuple(args, "O", &specs_o)) return NULL;
    PyObject *seq = PySequence_Fast(specs_o, "specs must be a sequence");
    if (seq == NULL) return NULL;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
    Bank *B = calloc(1, sizeof *B);
    if (B) B->s = calloc((size_t)(n > 0 ? n : 1), sizeof(Spec));
    if (B == NULL || B->s == NULL) {
        free(B);
        Py_DECREF(seq);
        return PyErr_NoMemory();
    }
    PyObject *cap = PyCapsule_New(B, "openmotion._compare.Bank", bank_free);
    if (cap == NULL) { free(B->s); free(B); Py_DECREF(seq); return NULL; }
    for (Py_ssize_t i = 0; i < n; i++) {
        Spec *S = &B->s[i];
        PyObject *slots, *vals, *after;
        long long nv;
        int repeat;
        if (!PyArg_ParseTuple(PySequence_Fast_GET_ITEM(seq, i), "iOipOLOddLiidii", &S->kind,
                              &slots, &S->direction, &repeat, &vals, &nv, &after, &S->maxerr,
                              &S->t_armed, &S->jid, &S->act, &S->flag, &S->width, &S->line,
                              &S->output))
            goto fail;
        S->repeat = repeat;
        B->n = i + 1;  /* (bank_free releases what is held so far) */
        PyObject *sl = PySequence_Fast(slots, "slots must be a sequence");
        if (sl == NULL) goto fail;
        S->na = (int)PySequence_Fast_GET_SIZE(sl);
        if (S->na < 1 || S->na > MAX_AXES) {
            Py_DECREF(sl);
            PyErr_Format(PyExc_ValueError, "slots: 1..%d, got %d", MAX_AXES, S->na);
            goto fail;
        }
        for (int q = 0; q < S->na; q++) {
            S->slot[q] = (int)PyLong_AsLong(PySequence_Fast_GET_ITEM(sl, q));
            if (S->slot[q] < 0) {
                Py_DECREF(sl);
                if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "slots must be >= 0");
                goto fail;
            }
        }
        Py_DECREF(sl);
        if (S->act < 0 || S->act > 2) {
            PyErr_SetString(PyExc_ValueError, "action must be 0, 1 or 2");
            goto fail;
        }
        if (S->kind == K_LEVEL || S->kind == K_VECTOR) {
            if (get_levels(vals, nv, after, &S->L, &S->vb, &S->held) < 0) goto fail;
        } else if (S->kind == K_WINDOW) {
            if (get_vec(vals, &S->vb, "points") < 0) goto fail;
            S->held = 1;
            S->pts = S->vb.buf;
            S->npts = S->vb.len / 8 / S->na;
            if (S->npts * S->na * 8 != S->vb.len) {
                PyErr_SetString(PyExc_ValueError, "points must be float64[n, len(slots)]");
                goto fail;
            }
        } else {
            PyErr_SetString(PyExc_ValueError, "kind must be 0 (level), 1 (window) or 2 "
                            "(path length)");
            goto fail;
        }
    }
    Py_DECREF(seq);
    return cap;
fail:
    Py_DECREF(seq);
    Py_DECREF(cap);
    return NULL;
}

/* growing row buffers of one bank_scan call */
typedef struct {
    double *f;       /* time, value */
    long long *k;    /* job, index, output, state */
    Py_ssize_t m, cap;
} Rows;

static int rows_add(Rows *R, double t, double val, long long jid, long long idx, long long out,
                    long long st)
{
    if (R->m == R->cap) {
        Py_ssize_t cap = R->cap ? 2 * R->cap : 64;
        double *f = realloc(R->f, (size_t)cap * 2 * sizeof(double));
        if (f == NULL) { PyErr_NoMemory(); return -1; }
        R->f = f;
        long long *k = realloc(R->k, (size_t)cap * 4 * sizeof(long long));
        if (k == NULL) { PyErr_NoMemory(); return -1; }
        R->k = k;
        R->cap = cap;
    }
    R->f[2 * R->m] = t; R->f[2 * R->m + 1] = val;
    long long *kk = R->k + 4 * R->m;
    kk[0] = jid; kk[1] = idx; kk[2] = out; kk[3] = st;
    R->m++;
    return 0;
}

/* the rows in time order, equal times in the order they were added (a stable sort: what
 * the engine's log does with the rows of one scan) */
static const double *sort_keys;

static int cmp_row(const void *a, const void *b)
{
    Py_ssize_t i = *(const Py_ssize_t *)a, j = *(const Py_ssize_t *)b;
    double x = sort_keys[2 * i], y = sort_keys[2 * j];
    if (x < y) return -1;
    if (x > y) return 1;
    return i < j ? -1 : i > j;
}

static int rows_sort(Rows *R)
{
    Py_ssize_t m = R->m, q = 1;
    while (q < m && R->f[2 * q] >= R->f[2 * (q - 1)]) q++;
    if (q >= m) return 0;  /* already in order */
    Py_ssize_t *ix = malloc((size_t)m * sizeof(Py_ssize_t));
    double *f = malloc((size_t)m * 2 * sizeof(double));
    long long *k = malloc((size_t)m * 4 * sizeof(long long));
    if (ix == NULL || f == NULL || k == NULL) {
        free(ix); free(f); free(k);
        PyErr_NoMemory();
        return -1;
    }
    for (Py_ssize_t i = 0; i < m; i++) ix[i] = i;
    sort_keys = R->f;  /* (the GIL is held: one sort at a time) */
    qsort(ix, (size_t)m, sizeof(Py_ssize_t), cmp_row);
    for (Py_ssize_t i = 0; i < m; i++) {
        memcpy(f + 2 * i, R->f + 2 * ix[i], 2 * sizeof(double));
        memcpy(k + 4 * i, R->k + 4 * ix[i], 4 * sizeof(long long));
    }
    free(ix);
    free(R->f);
    free(R->k);
    R->f = f;
    R->k = k;
    R->cap = m;
    return 0;
}

/* an OutputLine's edit state, read once per job that fired */
typedef struct {
    PyObject *tl, *ll, *late;
    int initial;
    double sent;
} LineRef;

static int line_ref(PyObject *line, LineRef *L)
{
    L->tl = L->ll = L->late = NULL;
    PyObject *o = PyObject_GetAttr(line, S__t);
    if (o == NULL) return -1;
    L->tl = o; Py_DECREF(o);  /* borrowed: the line holds them during the call */
    if ((o = PyObject_GetAttr(line, S__lv)) == NULL) return -1;
    L->ll = o; Py_DECREF(o);
    if ((o = PyObject_GetAttr(line, S__late)) == NULL) return -1;
    L->late = o; Py_DECREF(o);
    if (!PyList_Check(L->tl) || !PyList_Check(L->ll) || !PyList_Check(L->late)) {
        PyErr_SetString(PyExc_TypeError, "OutputLine edge lists must be lists");
        return -1;
    }
    if ((o = PyObject_GetAttr(line, S_initial)) == NULL) return -1;
    L->initial = PyObject_IsTrue(o);
    Py_DECREF(o);
    if ((o = PyObject_GetAttr(line, S_timed)) == NULL) return -1;
    int timed = PyObject_IsTrue(o);
    Py_DECREF(o);
    L->sent = -INFINITY;
    if (timed) {
        if ((o = PyObject_GetAttr(line, S__sent_until)) == NULL) return -1;
        L->sent = PyFloat_AsDouble(o);
        Py_DECREF(o);
        if (L->sent == -1.0 && PyErr_Occurred()) return -1;
    }
    return L->initial < 0 || timed < 0 ? -1 : 0;
}

static int get_ll_attr(PyObject *o, PyObject *name, long long *out)
{
    PyObject *v = PyObject_GetAttr(o, name);
    if (v == NULL) return -1;
    *out = PyLong_AsLongLong(v);
    Py_DECREF(v);
    return *out == -1 && PyErr_Occurred() ? -1 : 0;
}

static int set_ll_attr(PyObject *o, PyObject *name, long long v)
{
    PyObject *x = PyLong_FromLongLong(v);
    if (x == NULL) return -1;
    int r = PyObject_SetAttr(o, name, x);
    Py_DECREF(x);
    return r;
}

/* one job's scan of (ta, t1]: appends (time, value, index) to hits; returns the count or -1 */
static Py_ssize_t job_scan(const Spec *S, const Trk *T, const double *lo, const double *hi,
                           const Vc *V, long long *index, double ta, double t1, double **hb,
                           Py_ssize_t *hcap, double *ev, Py_ssize_t evcap)
{
    Py_ssize_t m = 0;
#define PUSH(tt, vv, ii) do { \
        if (3 * (m + 1) > *hcap) { \
            Py_ssize_t c_ = *hcap ? 2 * *hcap : 96; \
            double *b_ = realloc(*hb, (size_t)c_ * sizeof(double)); \
            if (b_ == NULL) { PyErr_NoMemory(); return -1; } \
            *hb = b_; *hcap = c_; \
        } \
        (*hb)[3 * m] = (tt); (*hb)[3 * m + 1] = (vv); (*hb)[3 * m + 2] = (double)(ii); m++; \
    } while (0)
    ta = pymax(ta, S->t_armed);
    if (S->kind == K_VECTOR) {  /* LevelJob.scan on a VectorSource (VectorCycle.scan) */
        if (ta >= t1) return 0;
        const Vc *vc = &V[S->slot[0]];
        long long size = S->L.n + S->L.has_after, k = S->repeat ? 0 : *index;
        double t = ta, tf;
        while (k < size) {
            double lvl = level_at(&S->L, k);
            if (!time_of(vc, lvl, t, &tf)) break;
            PUSH(tf, lvl, k);
            if (S->repeat) return m;
            k++;
            t = tf;
        }
        *index = k;
        return m;
    }
    if (S->kind == K_LEVEL) {
        if (ta >= t1) return 0;
        int sl = S->slot[0];
        const Trk *tr = &T[sl];
        if (S->repeat) {
            double lvl = level_at(&S->L, 0);
            double slack = 1e-9 * (fabs(lvl) + 1.0);
            if (!(lo[sl] - slack <= lvl && lvl <= hi[sl] + slack)) return 0;
            if (max_events(tr->n) > evcap) {
                PyErr_SetString(PyExc_RuntimeError, "bank_scan: event buffer too small");
                return -1;
            }
            Py_ssize_t ne = level_events(tr, lvl, ta, t1, S->direction, 0, ev);
            for (Py_ssize_t q = 0; q < ne; q++) PUSH(ev[q], lvl, 0);
            return m;
        }
        long long size = S->L.n + S->L.has_after, k = *index;
        double t = ta;
        while (k < size) {
            double lvl = level_at(&S->L, k);
            double slack = 1e-9 * (fabs(lvl) + 1.0);
            if (!(lo[sl] - slack <= lvl && lvl <= hi[sl] + slack)) break;
            if (level_events(tr, lvl, t, t1, S->direction, 1, ev) == 0) break;
            PUSH(ev[0], lvl, k);
            k++;
            t = ev[0];
        }
        *index = k;
        return m;
    }
    if (ta > t1 || *index >= S->npts) return 0;
    Trk W[MAX_AXES];
    double wlo[MAX_AXES], whi[MAX_AXES];
    for (int q = 0; q < S->na; q++) {
        W[q] = T[S->slot[q]];
        wlo[q] = lo[S->slot[q]];
        whi[q] = hi[S->slot[q]];
    }
    long long k = *index;
    double t = ta;
    while (k < S->npts) {
        double x;
        int r = first_inside(W, S->na, S->pts + k * S->na, S->maxerr, t, t1, wlo, whi, &x);
        if (r < 0) return -1;
        if (r == 0) break;
        PUSH(x, (double)k, k);
        k++;
        t = x;
    }
    *index = k;
    return m;
#undef PUSH
}

PyDoc_STRVAR(bank_scan_doc,
"bank_scan(bank, jobs, tracks, lines, pos_tracks, ta, t1, vectors=()) -> (f, k, pos, done)\n"
"or None\n\n"
"Run the bank's jobs over (ta, t1] in order (CompareEngine._scan for them): each job's\n"
"hits (LevelJob.scan / WindowJob.scan from its `index`), its action on lines[line]\n"
"(apply_many from its `hits`), `index` and `hits` written back. tracks: one per slot;\n"
"jobs: the job objects, in the bank's order. Returns the firings in time order (equal\n"
"times in job order, then hit order) as f (float64[m, 2]:\n"
"time, value), k (int64[m, 4]: job id, point index, output, state), pos (float64[m,\n"
"len(pos_tracks)]: every pos_track at each time) and done (bank positions of the jobs\n"
"that finished), or None when nothing fired or finished. vectors: one VectorCycle's\n"
"(B, S, Q) per vector slot (the path-length jobs' sources).");

static PyObject *bank_scan(PyObject *self, PyObject *args)
{
    PyObject *cap, *jobs_o, *tr_o, *lines_o, *pt_o, *vc_o = NULL;
    double ta, t1;
    if (!PyArg_ParseTuple(args, "OOOOOdd|O", &cap, &jobs_o, &tr_o, &lines_o, &pt_o, &ta, &t1,
                          &vc_o))
        return NULL;
    Bank *B = PyCapsule_GetPointer(cap, "openmotion._compare.Bank");
    if (B == NULL) return NULL;
    if (!PyList_Check(jobs_o) || PyList_GET_SIZE(jobs_o) != B->n || !PyList_Check(tr_o)
            || !PyList_Check(lines_o) || !PyList_Check(pt_o)) {
        PyErr_SetString(PyExc_TypeError, "bank_scan: jobs (one per spec), tracks, lines and "
                        "pos_tracks must be lists");
        return NULL;
    }
    Py_ssize_t nt = PyList_GET_SIZE(tr_o), npt = PyList_GET_SIZE(pt_o);
    Py_ssize_t nl = PyList_GET_SIZE(lines_o);
    PyObject *vseq = vc_o ? PySequence_Fast(vc_o, "vectors must be a sequence of (B, S, Q)")
                          : PyTuple_New(0);
    if (vseq == NULL) return NULL;
    Py_ssize_t nv = PySequence_Fast_GET_SIZE(vseq), vgot = 0;
    Vc *V = calloc((size_t)(nv + 1), sizeof(Vc));
    VcBuf *vb = calloc((size_t)(nv + 1), sizeof(VcBuf));
    Trk *T = calloc((size_t)(nt + npt + 1), sizeof(Trk));
    TrkBuf *tb = calloc((size_t)(nt + npt + 1), sizeof(TrkBuf));
    double *lo = malloc((size_t)(nt + 1) * sizeof(double));
    double *hi = malloc((size_t)(nt + 1) * sizeof(double));
    char *have_rng = calloc((size_t)(nt + 1), 1);
    PyObject *res = NULL, *done = NULL;
    Rows R = {NULL, NULL, 0, 0};
    double *hb = NULL, *ev = NULL;
    Py_ssize_t hcap = 0, got = 0, evcap = 0;
    if (!T || !tb || !lo || !hi || !have_rng || !V || !vb) { PyErr_NoMemory(); goto out; }
    for (; vgot < nv; vgot++) {
        PyObject *bsq = PySequence_Fast_GET_ITEM(vseq, vgot);
        if (!PyTuple_Check(bsq) || PyTuple_GET_SIZE(bsq) != 3) {
            PyErr_SetString(PyExc_TypeError, "bank_scan: each vector must be (B, S, Q)");
            goto out;
        }
        if (get_vc(PyTuple_GET_ITEM(bsq, 0), PyTuple_GET_ITEM(bsq, 1), PyTuple_GET_ITEM(bsq, 2),
                   &V[vgot], &vb[vgot]) < 0)
            goto out;
    }
    for (Py_ssize_t i = 0; i < nt + npt; i++) {
        PyObject *o = i < nt ? PyList_GET_ITEM(tr_o, i) : PyList_GET_ITEM(pt_o, i - nt);
        if (get_track_in(o, ta, t1, &T[i], &tb[i]) < 0) goto out;
        got = i + 1;
        if (max_events(T[i].n) > evcap) evcap = max_events(T[i].n);
    }
    ev = malloc((size_t)(evcap > 0 ? evcap : 1) * sizeof(double));
    done = PyList_New(0);
    if (ev == NULL || done == NULL) { if (!ev) PyErr_NoMemory(); goto out; }
    for (Py_ssize_t i = 0; i < B->n; i++) {
        const Spec *S = &B->s[i];
        if (S->kind == K_VECTOR) {
            if (S->slot[0] >= nv) {
                PyErr_SetString(PyExc_IndexError, "bank_scan: vector slot");
                goto out;
            }
            continue;
        }
        for (int q = 0; q < S->na; q++) {
            int sl = S->slot[q];
            if (sl >= nt) { PyErr_SetString(PyExc_IndexError, "bank_scan: track slot"); goto out; }
            if (!have_rng[sl]) {
                track_range(&T[sl], ta, t1, &lo[sl], &hi[sl]);
                have_rng[sl] = 1;
            }
        }
    }
    for (Py_ssize_t i = 0; i < B->n; i++) {
        const Spec *S = &B->s[i];
        PyObject *job = PyList_GET_ITEM(jobs_o, i);
        long long index, hits;
        if (get_ll_attr(job, S_index, &index) < 0) goto out;
        long long index0 = index;
        Py_ssize_t m = job_scan(S, T, lo, hi, V, &index, ta, t1, &hb, &hcap, ev, evcap);
        if (m < 0) goto out;
        if (index != index0 && set_ll_attr(job, S_index, index) < 0) goto out;
        if (m > 0) {
            if (get_ll_attr(job, S_hits, &hits) < 0) goto out;
            if (S->line < 0 || S->line >= nl) {
                PyErr_SetString(PyExc_IndexError, "bank_scan: line index");
                goto out;
            }
            LineRef L;
            if (line_ref(PyList_GET_ITEM(lines_o, S->line), &L) < 0) goto out;
            Py_ssize_t nlist = PyList_GET_SIZE(L.tl);
            if (PyList_GET_SIZE(L.ll) != nlist) {
                PyErr_SetString(PyExc_ValueError, "OutputLine: t and lv differ in length");
                goto out;
            }
            for (Py_ssize_t q = 0; q < m; q++) {
                double tf = hb[3 * q];
                int st;
                if (S->act == A_TOGGLE) {
                    st = (hits + q) % 2 == 0 ? (S->flag != 0) : (S->flag == 0);
                    if (line_set_one(L.tl, L.ll, L.initial, tf, st, L.sent, L.late) < 0) goto out;
                } else if (S->act == A_SET) {
                    st = S->flag != 0;
                    if (line_set_one(L.tl, L.ll, L.initial, tf, st, L.sent, L.late) < 0) goto out;
                } else {
                    st = S->flag != 0;
                    if (line_set_one(L.tl, L.ll, L.initial, tf, st, L.sent, L.late) < 0
                            || line_set_one(L.tl, L.ll, L.initial, tf + S->width, !st, L.sent,
                                            L.late) < 0)
                        goto out;
                }
                if (rows_add(&R, tf, hb[3 * q + 1], S->jid, (long long)hb[3 * q + 2],
                             S->output, st) < 0)
                    goto out;
            }
            if (set_ll_attr(job, S_hits, hits + m) < 0) goto out;
        }
        int finished = S->kind != K_WINDOW ? (!S->repeat && index >= S->L.n + S->L.has_after)
                                           : index >= S->npts;
        if (finished) {
            PyObject *x = PyLong_FromSsize_t(i);
            if (x == NULL || PyList_Append(done, x) < 0) { Py_XDECREF(x); goto out; }
            Py_DECREF(x);
        }
    }
    if (R.m == 0 && PyList_GET_SIZE(done) == 0) { res = Py_NewRef(Py_None); goto out; }
    if (rows_sort(&R) < 0) goto out;
    /* (no rows but a job done: empty bytes, not None, for a NULL buffer) */
    res = Py_BuildValue("(y#y#y#O)", R.f ? (const char *)R.f : "",
                        (Py_ssize_t)(R.m * 2 * sizeof(double)),
                        R.k ? (const char *)R.k : "", (Py_ssize_t)(R.m * 4 * sizeof(long long)),
                        "", (Py_ssize_t)0, done);
    if (res == NULL) goto out;
    {
        /* positions: every pos_track at each firing time */
        double *P = malloc((size_t)(R.m * npt > 0 ? R.m * npt : 1) * sizeof(double));
        if (P == NULL) { Py_CLEAR(res); PyErr_NoMemory(); goto out; }
        for (Py_ssize_t q = 0; q < R.m; q++)
            for (Py_ssize_t a = 0; a < npt; a++)
                P[q * npt + a] = position(&T[nt + a], R.f[2 * q]);
        PyObject *pb = PyBytes_FromStringAndSize((const char *)P,
                                                 (Py_ssize_t)(R.m * npt * sizeof(double)));
        free(P);
        if (pb == NULL) { Py_CLEAR(res); goto out; }
        PyObject *old = PyTuple_GET_ITEM(res, 2);
        PyTuple_SET_ITEM(res, 2, pb);
        Py_DECREF(old);
    }
out:
    for (Py_ssize_t i = 0; i < got; i++) release_track(&tb[i]);
    for (Py_ssize_t i = 0; i < vgot; i++) release_vc(&vb[i]);
    free(V); free(vb);
    Py_DECREF(vseq);
    free(T); free(tb); free(lo); free(hi); free(have_rng); free(hb); free(ev);
    free(R.f); free(R.k);
    Py_XDECREF(done);
    return res;
}


PyDoc_STRVAR(lines_send_doc,
"lines_send(lines, t0, t1) -> (times, signals, levels) or None\n\n"
"OutputLine.send's bookkeeping for every line at once, when each line's physical level\n"
"(`_written`) is its waveform's level at t0 (nothing late or stretched pending): sets\n"
"_sent, _written, _sent_until = t1, clears _late and _hold, and returns the edges in\n"
"(t0, t1] of every line, line after line, as three flat lists (the form of\n"
"SimMachine.write_outputs_many). None (nothing changed) when a line needs send.");

static int lv_at(PyObject *tl, PyObject *ll, int initial, double t, Py_ssize_t lo,
                 Py_ssize_t *k_out)
{
    Py_ssize_t hi = PyList_GET_SIZE(tl);
    while (lo < hi) {  /* bisect_right */
        Py_ssize_t mid = (lo + hi) / 2;
        if (t < as_double(PyList_GET_ITEM(tl, mid))) hi = mid; else lo = mid + 1;
    }
    *k_out = lo;
    return lv_of(ll, lo - 1, initial);
}

/* extend list `dst` by src[a:b] */
static int extend_slice(PyObject *dst, PyObject *src, Py_ssize_t a, Py_ssize_t b)
{
    for (Py_ssize_t k = a; k < b; k++)
        if (PyList_Append(dst, PyList_GET_ITEM(src, k)) < 0) return -1;
    return 0;
}

static PyObject *lines_send(PyObject *self, PyObject *args)
{
    PyObject *lines_o;
    double t0, t1;
    if (!PyArg_ParseTuple(args, "Odd", &lines_o, &t0, &t1)) return NULL;
    PyObject *seq = PySequence_Fast(lines_o, "lines must be a sequence");
    if (seq == NULL) return NULL;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
    Py_ssize_t *ab = malloc((size_t)(2 * n + 1) * sizeof(Py_ssize_t));
    int *wr = malloc((size_t)(n + 1) * sizeof(int));
    LineRef *LR = malloc((size_t)(n + 1) * sizeof(LineRef));
    PyObject *res = NULL, *ot = NULL, *os = NULL, *ol = NULL, *t1o = NULL;
    if (ab == NULL || wr == NULL || LR == NULL) { PyErr_NoMemory(); goto done; }
    for (Py_ssize_t i = 0; i < n; i++) {  /* check every line first: all or nothing */
        PyObject *line = PySequence_Fast_GET_ITEM(seq, i);
        LineRef *L = &LR[i];
        if (line_ref(line, L) < 0) goto done;
        PyObject *w = PyObject_GetAttr(line, S__written);
        if (w == NULL) goto done;
        int written = PyObject_IsTrue(w);
        Py_DECREF(w);
        if (PyList_GET_SIZE(L->tl) != PyList_GET_SIZE(L->ll)) {
            PyErr_SetString(PyExc_ValueError, "OutputLine: t and lv differ in length");
            goto done;
        }
        Py_ssize_t a, b;
        int l0 = lv_at(L->tl, L->ll, L->initial, t0, 0, &a);
        if (l0 != written) { res = Py_NewRef(Py_None); goto done; }
        wr[i] = lv_at(L->tl, L->ll, L->initial, t1, a, &b);
        ab[2 * i] = a;
        ab[2 * i + 1] = b;
    }
    ot = PyList_New(0); os = PyList_New(0); ol = PyList_New(0);
    t1o = PyFloat_FromDouble(t1);
    if (!ot || !os || !ol || !t1o) goto done;
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *line = PySequence_Fast_GET_ITEM(seq, i);
        const LineRef *L = &LR[i];
        Py_ssize_t a = ab[2 * i], b = ab[2 * i + 1];
        PyObject *ts = PyList_GetSlice(L->tl, a, b);
        PyObject *ls = PyList_GetSlice(L->ll, a, b);
        PyObject *sent = ts && ls ? PyTuple_Pack(2, ts, ls) : NULL;
        int bad = sent == NULL
            || PyObject_SetAttr(line, S__sent, sent) < 0
            || PyObject_SetAttr(line, S__written, wr[i] ? Py_True : Py_False) < 0
            || PyObject_SetAttr(line, S__sent_until, t1o) < 0
            || PyObject_SetAttr(line, S__hold, Py_False) < 0
            || PyList_SetSlice(L->late, 0, PyList_GET_SIZE(L->late), NULL) < 0;
        if (!bad && b > a) {
            PyObject *sig = PyObject_GetAttr(line, S_signal);
            bad = sig == NULL || extend_slice(ot, L->tl, a, b) < 0
                  || extend_slice(ol, L->ll, a, b) < 0;
            for (Py_ssize_t k = a; !bad && k < b; k++) bad = PyList_Append(os, sig) < 0;
            Py_XDECREF(sig);
        }
        Py_XDECREF(sent);
        Py_XDECREF(ts);
        Py_XDECREF(ls);
        if (bad) goto done;
    }
    res = PyTuple_Pack(3, ot, os, ol);
done:
    Py_XDECREF(ot); Py_XDECREF(os); Py_XDECREF(ol); Py_XDECREF(t1o);
    free(ab);
    free(wr);
    free(LR);
    Py_DECREF(seq);
    return res;
}

/* ------------------------------------------------------------------ cycle bookkeeping */
PyDoc_STRVAR(plan_records_doc,
"plan_records(hists, t1, old=None) -> bytes, or bool with old\n\n"
"The record in force just before t1 (MotionHistory.record_at(axis, nextafter(t1, -inf)))\n"
"of every history record store in hists (history._Track), as bytes; with `old` (bytes of\n"
"an earlier call on the same stores): True when every one is still the same record.");

static PyObject *plan_records(PyObject *self, PyObject *args)
{
    PyObject *hs_o, *old = Py_None;
    double t1;
    if (!PyArg_ParseTuple(args, "Od|O", &hs_o, &t1, &old)) return NULL;
    PyObject *seq = PySequence_Fast(hs_o, "hists must be a sequence");
    if (seq == NULL) return NULL;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
    double *rec = malloc((size_t)(6 * n + 1) * sizeof(double));
    PyObject *res = NULL;
    if (rec == NULL) { PyErr_NoMemory(); goto done; }
    double tb = nextafter(t1, -INFINITY);
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *h = PySequence_Fast_GET_ITEM(seq, i);
        PyObject *x = PyObject_GetAttr(h, S_lo);
        long long lo = x ? PyLong_AsLongLong(x) : -1;
        Py_XDECREF(x);
        x = PyErr_Occurred() ? NULL : PyObject_GetAttr(h, S_hi);
        long long hi = x ? PyLong_AsLongLong(x) : -1;
        Py_XDECREF(x);
        if (PyErr_Occurred()) goto done;
        PyObject *names[5] = {S_ts, S_p0, S_v0, S_a0, S_j};
        Py_buffer b[5];
        int held = 0, bad = 0;
        for (int k = 0; k < 5 && !bad; k++) {
            PyObject *a = PyObject_GetAttr(h, names[k]);
            bad = a == NULL || get_vec(a, &b[k], "history column") < 0;
            Py_XDECREF(a);
            if (!bad) held++;
            if (!bad && b[k].len / 8 < hi) {
                PyErr_SetString(PyExc_ValueError, "history track: rows beyond its arrays");
                bad = 1;
            }
        }
        if (!bad && !(0 <= lo && lo <= hi)) {
            PyErr_SetString(PyExc_ValueError, "history track: bad live rows");
            bad = 1;
        }
        if (!bad) {
            const double *ts = b[0].buf;
            Py_ssize_t k = (Py_ssize_t)lo + search_right(ts + lo, 0, (Py_ssize_t)(hi - lo), tb)
                           - 1;
            double *r = rec + 6 * i;
            if (k < lo) {
                memset(r, 0, 6 * sizeof(double));
            } else {
                r[0] = 1.0;
                for (int q = 0; q < 5; q++) r[1 + q] = ((const double *)b[q].buf)[k];
            }
        }
        for (int k = 0; k < held; k++) PyBuffer_Release(&b[k]);
        if (bad) goto done;
    }
    if (old == Py_None) {
        res = PyBytes_FromStringAndSize((const char *)rec, (Py_ssize_t)(6 * n * sizeof(double)));
    } else {
        if (!PyBytes_Check(old) || PyBytes_GET_SIZE(old) != (Py_ssize_t)(6 * n * sizeof(double))) {
            PyErr_SetString(PyExc_ValueError, "plan_records: old must be bytes of these stores");
            goto done;
        }
        const double *o = (const double *)PyBytes_AS_STRING(old);
        int same = 1;  /* (as the tuples compare: floats by value) */
        for (Py_ssize_t i = 0; i < n && same; i++) {
            if (o[6 * i] != rec[6 * i]) same = 0;
            else if (rec[6 * i] != 0.0)
                for (int q = 1; q < 6 && same; q++) same = o[6 * i + q] == rec[6 * i + q];
        }
        res = PyBool_FromLong(same);
    }
done:
    free(rec);
    Py_DECREF(seq);
    return res;
}

PyDoc_STRVAR(lines_snapshot_doc,
"lines_snapshot(lines, t) -> list of OutputLine.snapshot(t), one per line");

static PyObject *lines_snapshot(PyObject *self, PyObject *args)
{
    PyObject *lines_o;
    double t;
    if (!PyArg_ParseTuple(args, "Od", &lines_o, &t)) return NULL;
    PyObject *seq = PySequence_Fast(lines_o, "lines must be a sequence");
    if (seq == NULL) return NULL;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
    PyObject *res = PyList_New(n);
    for (Py_ssize_t i = 0; res != NULL && i < n; i++) {
        PyObject *line = PySequence_Fast_GET_ITEM(seq, i);
        LineRef L;
        if (line_ref(line, &L) < 0) { Py_CLEAR(res); break; }
        Py_ssize_t lo = 0, hi = PyList_GET_SIZE(L.tl);
        while (lo < hi) {  /* bisect_left */
            Py_ssize_t mid = (lo + hi) / 2;
            if (as_double(PyList_GET_ITEM(L.tl, mid)) < t) lo = mid + 1; else hi = mid;
        }
        PyObject *ts = PyList_GetSlice(L.tl, lo, PyList_GET_SIZE(L.tl));
        PyObject *ls = PyList_GetSlice(L.ll, lo, PyList_GET_SIZE(L.ll));
        PyObject *it = ts && ls ? PyTuple_Pack(3, L.initial ? Py_True : Py_False, ts, ls) : NULL;
        Py_XDECREF(ts);
        Py_XDECREF(ls);
        if (it == NULL) { Py_CLEAR(res); break; }
        PyList_SET_ITEM(res, i, it);
    }
    Py_DECREF(seq);
    return res;
}

PyDoc_STRVAR(lines_end_doc,
"lines_end(lines, hw, t0, t1, keep)\n\n"
"The cycle end of every line: line.flush(hw, t0, t1) and line.forget_before(keep), each\n"
"called only when it has something to do (a timed line with nothing late needs no\n"
"flush; a waveform with no edge before keep needs no forget).");

static PyObject *lines_end(PyObject *self, PyObject *args)
{
    PyObject *lines_o, *hw, *t0o, *t1o, *keepo;
    if (!PyArg_ParseTuple(args, "OOO!O!O!", &lines_o, &hw, &PyFloat_Type, &t0o, &PyFloat_Type,
                          &t1o, &PyFloat_Type, &keepo))
        return NULL;
    double keep = PyFloat_AS_DOUBLE(keepo);
    PyObject *seq = PySequence_Fast(lines_o, "lines must be a sequence");
    if (seq == NULL) return NULL;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *line = PySequence_Fast_GET_ITEM(seq, i);
        PyObject *o = PyObject_GetAttr(line, S_timed);
        int timed = o ? PyObject_IsTrue(o) : -1;
        Py_XDECREF(o);
        if (timed < 0) goto fail;
        int need = !timed;
        if (timed) {
            if ((o = PyObject_GetAttr(line, S__late)) == NULL) goto fail;
            Py_ssize_t nl = PyObject_Length(o);
            Py_DECREF(o);
            if (nl < 0) goto fail;
            need = nl > 0;
        }
        if (need) {
            PyObject *r = PyObject_CallMethodObjArgs(line, S_flush, hw, t0o, t1o, NULL);
            if (r == NULL) goto fail;
            Py_DECREF(r);
        }
        if ((o = PyObject_GetAttr(line, S__t)) == NULL) goto fail;
        int forget = 0;
        if (PyList_Check(o) && PyList_GET_SIZE(o) > 0) {
            forget = as_double(PyList_GET_ITEM(o, 0)) < keep;
        } else if (!PyList_Check(o)) {
            forget = 1;  /* (not a list: let the method decide) */
        }
        Py_DECREF(o);
        if (PyErr_Occurred()) goto fail;
        if (forget) {
            PyObject *r = PyObject_CallMethodObjArgs(line, S_forget_before, keepo, NULL);
            if (r == NULL) goto fail;
            Py_DECREF(r);
        }
    }
    Py_DECREF(seq);
    Py_RETURN_NONE;
fail:
    Py_DECREF(seq);
    return NULL;
}

PyDoc_STRVAR(solver_checks_doc,
"solver_checks(on) -> (refined, rejected)\n\n"
"Tests: with on, every window candidate dropped unrefined is refined anyway and\n"
"verified to be outside its window (AssertionError otherwise). Returns the counts of\n"
"refined and dropped candidates since the last call, and resets them.");

static PyObject *solver_checks(PyObject *self, PyObject *args)
{
    int on;
    if (!PyArg_ParseTuple(args, "p", &on)) return NULL;
    check_rejects = on;
    PyObject *r = Py_BuildValue("(LL)", n_refined, n_rejected);
    n_refined = n_rejected = 0;
    return r;
}

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
