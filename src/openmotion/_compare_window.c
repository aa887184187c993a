/* The compare engine's solvers (openmotion._compare): the window solver (first time every track is inside its window) and its entry points. */
#include "_compare.h"

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
int first_inside(const Trk *T, int na, const double *centre, double maxerr, double t,
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


CMP_DOC(window_scan_doc,
"window_scan(tracks, ranges, points, maxerr, index, t, t1) -> list of times\n\n"
"A WindowJob's scan of one window: from point `index` of points (float64[n, k], one\n"
"column per track), the first time in [t, t1] all tracks are within +-maxerr of the\n"
"point (compare_math.first_inside), then the next point from that time on, until one\n"
"is not reached. ranges: each track's (min, max) over the window, or None.");

PyObject *window_scan(PyObject *self, PyObject *args)
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

CMP_DOC(first_inside_doc,
"first_inside(tracks, centre, maxerr, t, t1, ranges) -> time or None\n\n"
"The first time in [t, t1] every track is within +-maxerr of its centre (float64[k]).");

PyObject *first_inside_py(PyObject *self, PyObject *args)
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

CMP_DOC(positions_doc,
"positions(tracks, times, out)\n\n"
"out[i, k] = position of track k at times[i] (compare_math.positions, every track at\n"
"once); out: a writable C-contiguous float64 (len(times), len(tracks)) array.");

PyObject *positions_py(PyObject *self, PyObject *args)
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

CMP_DOC(solver_checks_doc,
"solver_checks(on) -> (refined, rejected)\n\n"
"Tests: with on, every window candidate dropped unrefined is refined anyway and\n"
"verified to be outside its window (AssertionError otherwise). Returns the counts of\n"
"refined and dropped candidates since the last call, and resets them.");

PyObject *solver_checks(PyObject *self, PyObject *args)
{
    int on;
    if (!PyArg_ParseTuple(args, "p", &on)) return NULL;
    check_rejects = on;
    PyObject *r = Py_BuildValue("(LL)", n_refined, n_rejected);
    n_refined = n_rejected = 0;
    return r;
}
