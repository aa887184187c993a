/* The compare engine's solvers (openmotion._compare): track arguments (buffers, history specs), the level-crossing events of one track,
 * its range, and the LevelJob entry points. */
#include "_compare.h"

/* ------------------------------------------------------------------ buffers */

int get_vec(PyObject *o, Py_buffer *b, const char *name)
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

void release_track(TrkBuf *tb)
{
    for (int k = 0; k < tb->held; k++) PyBuffer_Release(&tb->b[k]);
    tb->held = 0;
    free(tb->own);
    tb->own = NULL;
}

int get_track(PyObject *o, Trk *t, TrkBuf *tb)
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
Py_ssize_t search_right(const double *x, Py_ssize_t lo, Py_ssize_t hi, double t)
{
    while (lo < hi) {
        Py_ssize_t mid = (lo + hi) / 2;
        if (t < x[mid]) hi = mid; else lo = mid + 1;
    }
    return lo;
}

int get_track_in(PyObject *o, double ta, double t1, Trk *t, TrkBuf *tb)
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
int velocity_roots(double v, double a, double j, double *r)
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

/* compare_roots._refine: Newton inside the sign bracket */
double refine(double c, double v, double a, double j, double lo, double hi, int s_lo,
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

/* compare_roots.level_events: times in (t, t1] where the track reaches `level`; writes
 * them to out (room for max_events(n)) and returns their count */
Py_ssize_t level_events(const Trk *T, double level, double t, double t1,
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

/* compare_math.track_range: (min, max) of the track over [ta, t1] */
void track_range(const Trk *T, double ta, double t1, double *lo_o, double *hi_o)
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

void args_release(TrackArgs *A)
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

int track_args(PyObject *tr_o, PyObject *rg_o, int single, TrackArgs *A)
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

/* ------------------------------------------------------------------ levels */

int get_levels(PyObject *o, long long n, PyObject *after_o, Levels *L, Py_buffer *b,
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

CMP_DOC(level_scan_doc,
"level_scan(track, range, levels, n, after_final, index, t, t1, direction) -> list\n\n"
"A LevelJob's scan of one window on an axis track: from value `index` on, the first\n"
"crossing after t of each value in turn (level_events, first only), skipped when the\n"
"value is out of the track's (min, max) `range` (+- 1e-9 relative); stops at the first\n"
"value not reached. levels: float64 array or (start, step) for start + k * step; n\n"
"values, then after_final (None: none). Returns [(time, level), ...].");

PyObject *level_scan(PyObject *self, PyObject *args)
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

CMP_DOC(level_events_doc,
"level_events(track, level, t, t1, direction=0, first=False) -> list of times\n\n"
"Times in (t, t1] where the track reaches `level` (direction +1 up, -1 down, 0 both;\n"
"the semantics of MotionHistory.crossings, compare_roots docstring).");

PyObject *level_events_py(PyObject *self, PyObject *args)
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

CMP_DOC(track_range_doc,
"track_range(track, ta, t1) -> (min, max) of the track's position over [ta, t1]");

PyObject *track_range_py(PyObject *self, PyObject *args)
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
