/* The compare engine's solvers (openmotion._compare): the scan driver: job banks and one call per cycle for every native job. */
#include "_compare.h"

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

CMP_DOC(bank_new_doc,
"bank_new(specs) -> bank\n\n"
"Parse the jobs of one scan group once. Each spec: (kind, slots, direction, repeat,\n"
"values, n, after_final, maxerr, t_armed, job_id, action, flag, width, line, output):\n"
"kind 0 a "
"LevelJob on track slots[0] (values: float64 array or (start, step), n of them, then\n"
"after_final or None), 1 a WindowJob on slots (values: float64[n, len(slots)]); action\n"
"2 a LevelJob on a path length, vector slots[0] (values as kind 0, direction unused);\n"
"0 Toggle (flag = first), 1 SetLevel (flag = level), 2 Pulse (flag = active, width);\n"
"line: the index of its OutputLine in bank_scan's `lines`, output: its number (logged).");

PyObject *bank_new(PyObject *self, PyObject *args)
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

int line_ref(PyObject *line, LineRef *L)
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

CMP_DOC(bank_scan_doc,
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

PyObject *bank_scan(PyObject *self, PyObject *args)
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
