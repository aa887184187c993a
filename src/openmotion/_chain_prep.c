/* The look-ahead's steps 1-2 over a chain's elements in one call (path/lookahead.py
 * `_prepare`): each element's tangential acceleration, deceleration and speed cap, and
 * the v**2 caps of the junctions, compiled into openmotion._corner (issue 14: the
 * streaming join re-plans a few hundred elements at every join, most of them the same
 * objects as at the join before).
 *
 * - prepare(elements, types, feed, accel, decel, dim, vmax, amax, vjump, ratio, scv,
 *   v_end, tangent_chord, junction, memo) -> (live, acc, cap, length, dec, jcap2), the
 *   lists `_prepare` computes (live: the indices of the elements of length > 0), or None
 *   where only the Python path decides (an element type not in the set `types`, a value
 *   that is not a float, an axis count other than `dim`, a Python error on the way, no
 *   element of length > 0): the caller then runs it, which raises where it must;
 * - prepare_curve(<the same 15>, start2, s0, out) -> (m, min_dec): the same followed by
 *   chain_knots (_chain.c) into out[0, :m] (s) and out[1, :m] (v**2), m = -1 when start2
 *   is too fast; or None as prepare.
 *
 * The Python caller validates the scalars and the per-axis limits (vmax, amax, vjump:
 * None or float64 arrays of `dim` values) first. Each formula repeats lookahead.py's
 * operation order (`_limits_of`, `_tangential_decel`, Python's min as the first of
 * equals, x ** 2 as libm's pow); a junction whose tangents turn (chord |u2 - u1| at
 * least `tangent_chord`, below which `_junction_cap`'s angle test is true whatever the
 * rounding of numpy's dot product) is computed by calling `junction` (lookahead.
 * _junction_cap) with (prev, nxt, a_j, scv, amax, vjump): bit for bit the Python result.
 *
 * The memo (a list of capsules, most recent first, at most SLOTS): per call, the
 * elements as weak references and their inputs and results. A call finds the record
 * holding one of its first three elements (with the same dim, ratio, scv and axis
 * limits) and walks both in step: an element that is the same object reuses its length,
 * its limits when its feed and acceleration (and deceleration) are the same, its junction
 * when the element before it is the same one and a_j the same. Weak references keep no
 * element alive; a record is never changed once stored (a new one replaces it), so a
 * Python callback (an attribute, `junction`) running another plan meanwhile is harmless.
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

#define SLOTS 4
#define MAX_DIM CHAIN_MAX_DIM

static const char *MEMO_NAME = "openmotion._corner.prepare_memo";

/* x ** 2 as CPython's float power computes it (see _chain.c's sq) */
static double (*volatile prep_pow)(double, double) = pow;
static double sq(double x) { return prep_pow(x, 2.0); }

/* per element values of a memo record, v[q * n + k] */
enum { V_LEN, V_FEED, V_ACCIN, V_DECIN, V_ACC, V_CAP, V_DEC, V_JA, V_JRAW, NV };

typedef struct {
    Py_ssize_t n;
    long dim;
    double ratio, scv;
    int has[3];             /* vmax, amax, vjump given */
    double ax[3 * MAX_DIM]; /* their values */
    PyObject **refs;        /* n weak references (NULL: not weak-referenceable) */
    Py_ssize_t *jprev;      /* the element of length > 0 before element k (-1: none) */
    double *v;
} Memo;

static void memo_free(Memo *m)
{
    if (m == NULL) return;
    if (m->refs != NULL)
        for (Py_ssize_t k = 0; k < m->n; k++) Py_XDECREF(m->refs[k]);
    free(m->refs);
    free(m->jprev);
    free(m->v);
    free(m);
}

static void memo_capsule_free(PyObject *cap)
{
    memo_free((Memo *)PyCapsule_GetPointer(cap, MEMO_NAME));
}

static Memo *memo_new(Py_ssize_t n)
{
    Memo *m = (Memo *)calloc(1, sizeof(Memo));
    if (m == NULL) return NULL;
    m->n = n;
    m->refs = (PyObject **)calloc((size_t)n, sizeof(PyObject *));
    m->jprev = (Py_ssize_t *)malloc(sizeof(Py_ssize_t) * (size_t)n);
    m->v = (double *)malloc(sizeof(double) * (size_t)(NV * n));
    if (m->refs == NULL || m->jprev == NULL || m->v == NULL) {
        memo_free(m);
        return NULL;
    }
    return m;
}

/* the weak reference `ref` refers to `obj` (alive) */
static int ref_is(PyObject *ref, PyObject *obj)
{
    if (ref == NULL) return 0;
#if PY_VERSION_HEX >= 0x030D0000
    PyObject *o = NULL;
    if (PyWeakref_GetRef(ref, &o) < 0) {
        PyErr_Clear();
        return 0;
    }
    int same = o == obj;
    Py_XDECREF(o);
    return same;
#else
    return PyWeakref_GetObject(ref) == obj;
#endif
}

/* ------------------------------------------------------------------ inputs */

/* a float or an int as check_finite passes it (finite); 0: anything else */
static int real(PyObject *o, double *x)
{
    if (PyFloat_CheckExact(o)) {
        *x = PyFloat_AS_DOUBLE(o);
    } else if (PyLong_CheckExact(o)) {
        *x = PyLong_AsDouble(o);
        if (*x == -1.0 && PyErr_Occurred()) {
            PyErr_Clear();
            return 0;
        }
    } else {
        return 0;
    }
    return isfinite(*x);
}

/* feed/accel/decel as `_per_element` passes them without a message: a number > 0, or a
 * list/tuple of n such numbers; 0: anything else (the Python path decides) */
static int per_element(PyObject *obj, Py_ssize_t n, double *out)
{
    double x;
    if (PyFloat_CheckExact(obj) || PyLong_CheckExact(obj)) {
        if (!real(obj, &x) || !(x > 0.0)) return 0;
        for (Py_ssize_t k = 0; k < n; k++) out[k] = x;
        return 1;
    }
    if (!PyList_CheckExact(obj) && !PyTuple_CheckExact(obj)) return 0;
    if (PySequence_Fast_GET_SIZE(obj) != n) return 0;
    PyObject **it = PySequence_Fast_ITEMS(obj);
    for (Py_ssize_t k = 0; k < n; k++) {
        if (!(PyFloat_CheckExact(it[k]) || PyLong_CheckExact(it[k])) || !real(it[k], &x) ||
            !(x > 0.0))
            return 0;
        out[k] = x;
    }
    return 1;
}

/* an axis limit as `_axis_limits` passes it: None (has 0) or a float64 buffer of dim
 * values, none NaN, all > 0, copied to dst; 0: anything else */
static int axis_values(PyObject *obj, long dim, double *dst, int *has)
{
    *has = 0;
    if (obj == Py_None) return 1;
    Py_buffer b;
    if (PyObject_GetBuffer(obj, &b, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0) {
        PyErr_Clear();
        return 0;
    }
    int ok = b.itemsize == 8 && b.format != NULL && strcmp(b.format, "d") == 0 &&
             b.len == dim * 8;
    if (ok) {
        memcpy(dst, b.buf, (size_t)dim * sizeof(double));
        for (long i = 0; i < dim; i++) ok = ok && dst[i] > 0.0; /* (NaN fails) */
        *has = ok;
    }
    PyBuffer_Release(&b);
    return ok;
}

/* ------------------------------------------------------------------ the core */

enum { A_CTX, A_ELS, A_FEED, A_ACCEL, A_DECEL, A_SCV, A_VSTART, A_VEND, A_VMAX, A_AMAX,
       A_VJUMP, A_RATIO, A_MCR, NARGS };
enum { C_TYPES, C_IS_ELEMENT, C_LINE, C_ARC, C_ARC3D, C_CHORD, C_JUNCTION, C_MEMO, NCTX };

typedef struct {
    Py_ssize_t n, nl;     /* elements, those of length > 0 */
    PyObject **items;     /* n new references */
    double *block;        /* f, a, d (n each), acc, cap, len, dec (nl <= n each), jcap2 */
    double *f, *a, *d;    /* per element: feed, acceleration, deceleration */
    double *acc, *cap, *len, *dec, *jcap2;
    Py_ssize_t *live;     /* nl, followed by oj (n): each element's index in `old` */
    double v_start, v_end, mcr;
    Memo *memo;           /* this call's record (until stored) */
    PyObject *old_cap;    /* the record reused (a reference held for the call) */
} Prep;

static void prep_free(Prep *p)
{
    if (p->items != NULL) {
        for (Py_ssize_t k = 0; k < p->n; k++) Py_XDECREF(p->items[k]);
        free(p->items);
    }
    free(p->block);
    free(p->live);
    memo_free(p->memo);
    Py_XDECREF(p->old_cap);
}

static int same_key(const Memo *m, long dim, double ratio, double scv, const int *has,
                    const double *ax)
{
    if (m->dim != dim || m->ratio != ratio || m->scv != scv) return 0;
    for (int q = 0; q < 3; q++) {
        if (m->has[q] != has[q]) return 0;
        if (has[q] && memcmp(m->ax + q * MAX_DIM, ax + q * MAX_DIM,
                             (size_t)dim * sizeof(double)) != 0)
            return 0;
    }
    return 1;
}

/* junction(prev, nxt, a_j, scv, amax, vjump) -> *out; 0: it raised (cleared) */
static int call_junction(PyObject *const *args, PyObject *fn, PyObject *prev,
                         PyObject *nxt, double a_j, double scv, double *out)
{
    PyObject *aj = PyFloat_FromDouble(a_j), *sv = PyFloat_FromDouble(scv), *r = NULL;
    if (aj != NULL && sv != NULL) {
        PyObject *cargs[6] = {prev, nxt, aj, sv, args[A_AMAX], args[A_VJUMP]};
        r = PyObject_Vectorcall(fn, cargs, 6, NULL);
    }
    Py_XDECREF(aj);
    Py_XDECREF(sv);
    int ok = r != NULL && PyFloat_Check(r);
    if (ok) *out = PyFloat_AS_DOUBLE(r);
    Py_XDECREF(r);
    PyErr_Clear();
    return ok;
}

/* the record of this call stored first in the memo list; the one reused (or the oldest
 * beyond SLOTS) leaves it */
static int memo_store(PyObject *list, Prep *p)
{
    PyObject *cap = PyCapsule_New(p->memo, MEMO_NAME, memo_capsule_free);
    if (cap == NULL) return -1;
    p->memo = NULL; /* the capsule's now */
    Py_ssize_t at = -1, size = PyList_GET_SIZE(list);
    for (Py_ssize_t s = 0; s < size && p->old_cap != NULL; s++)
        if (PyList_GET_ITEM(list, s) == p->old_cap) at = s;
    if (at < 0 && size >= SLOTS) at = size - 1;
    int rc = at >= 0 ? PySequence_DelItem(list, at) : 0;
    if (rc == 0) rc = PyList_Insert(list, 0, cap);
    while (rc == 0 && PyList_GET_SIZE(list) > SLOTS) rc = PySequence_DelItem(list, SLOTS);
    Py_DECREF(cap);
    return rc;
}

/* the memo record holding one of the first three elements (with the same key): its
 * index of element 0 in *base */
static PyObject *memo_find(PyObject *list, const Prep *p, const Memo *key, Py_ssize_t *base)
{
    for (Py_ssize_t s = 0; s < PyList_GET_SIZE(list); s++) {
        PyObject *c = PyList_GET_ITEM(list, s);
        Memo *m = PyCapsule_CheckExact(c) ? (Memo *)PyCapsule_GetPointer(c, MEMO_NAME) : NULL;
        if (m == NULL) {
            PyErr_Clear();
            continue;
        }
        if (!same_key(m, key->dim, key->ratio, key->scv, key->has, key->ax)) continue;
        for (Py_ssize_t i = 0; i < p->n && i < 3; i++)
            for (Py_ssize_t j = 0; j < m->n; j++)
                if (ref_is(m->refs[j], p->items[i])) {
                    *base = j - i;
                    return c;
                }
    }
    return NULL;
}

/* the inputs checked as `_prepare` checks them (0: not all of them pass) */
static int prep_inputs(PyObject *const *args, PyObject *const *ctx, Prep *p, Memo *key,
                       ElemTypes *types)
{
    PyObject *els = args[A_ELS];
    if (!(PyList_CheckExact(els) || PyTuple_CheckExact(els))) return 0;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(els);
    if (n == 0) return 0;
    *types = (ElemTypes){ctx[C_LINE], ctx[C_ARC], ctx[C_ARC3D]};
    /* dim: elements[0].dim */
    PyObject *el0 = PySequence_Fast_ITEMS(els)[0];
    Elem g;
    elem_init(&g, el0, elem_kind(types, el0));
    long dim = 0;
    int ok = elem_dim(&g, &dim);
    elem_clear(&g);
    if (!ok || dim < 1 || dim > MAX_DIM) return 0;
    key->dim = dim;
    for (int q = 0; q < 3; q++)
        if (!axis_values(args[A_VMAX + q], dim, key->ax + q * MAX_DIM, &key->has[q])) return 0;
    double scv;
    if (!real(args[A_SCV], &scv) || !(scv >= 0.0) || !real(args[A_VSTART], &p->v_start) ||
        !(p->v_start >= 0.0) || !real(args[A_VEND], &p->v_end) || !(p->v_end >= 0.0) ||
        !real(args[A_RATIO], &key->ratio) || !(key->ratio > 0.0 && key->ratio < 1.0) ||
        !real(args[A_MCR], &p->mcr) || !(p->mcr >= 0.0 && p->mcr < 1.0))
        return 0;
    key->scv = scv;

    p->items = (PyObject **)malloc(sizeof(PyObject *) * (size_t)n);
    p->block = (double *)malloc(sizeof(double) * (size_t)(8 * n + 1));
    p->live = (Py_ssize_t *)malloc(sizeof(Py_ssize_t) * (size_t)(2 * n));
    if (p->items == NULL || p->block == NULL || p->live == NULL) {
        PyErr_NoMemory();
        return -1;
    }
    PyObject **src = PySequence_Fast_ITEMS(els);
    for (Py_ssize_t k = 0; k < n; k++) {
        p->items[k] = src[k];
        Py_INCREF(src[k]);
    }
    p->n = n;
    p->f = p->block;
    p->a = p->f + n;
    p->d = p->a + n;
    p->acc = p->d + n;
    p->cap = p->acc + n;
    p->len = p->cap + n;
    p->dec = p->len + n;
    p->jcap2 = p->dec + n;
    if (!per_element(args[A_FEED], n, p->f) || !per_element(args[A_ACCEL], n, p->a)) return 0;
    if (args[A_DECEL] == Py_None)
        memcpy(p->d, p->a, sizeof(double) * (size_t)n);
    else if (!per_element(args[A_DECEL], n, p->d))
        return 0;
    return 1;
}

/* el's type is in the set of known element types, or is_element(el) says it is one (and
 * registers openmotion's own) */
static int known(PyObject *const *ctx, PyObject *el)
{
    int c = PySet_Contains(ctx[C_TYPES], (PyObject *)Py_TYPE(el));
    if (c == 0) {
        PyObject *r = PyObject_CallOneArg(ctx[C_IS_ELEMENT], el);
        c = r == Py_True;
        Py_XDECREF(r);
    }
    PyErr_Clear();
    return c == 1;
}

/* step 1 for element k: its length and limits into the record (and the live arrays);
 * 1 done, 0 only the Python path */
static int prep_element(Prep *p, Py_ssize_t k, const Memo *old, Py_ssize_t j,
                        PyObject *const *ctx, const ElemTypes *et, const Lim *lim)
{
    Memo *nm = p->memo;
    Py_ssize_t n = p->n;
    PyObject *el = p->items[k];
    int hit = j >= 0, ok = 0;
#define NEW(q) nm->v[(q) * n + k]
#define OLD(q) old->v[(q) * old->n + j]
    Elem g;
    elem_init(&g, el, elem_kind(et, el));
    double L = 0.0;
    if (hit) {
        L = OLD(V_LEN);
        nm->refs[k] = old->refs[j];
        Py_INCREF(old->refs[j]);
    } else {
        long d = 0;
        if (!known(ctx, el) || !elem_dim(&g, &d) || d != lim->dim || !elem_length(&g, &L))
            goto out;
        if ((nm->refs[k] = PyWeakref_NewRef(el, NULL)) == NULL) PyErr_Clear();
    }
    nm->jprev[k] = -1;
    NEW(V_LEN) = L;
    NEW(V_FEED) = p->f[k];
    NEW(V_ACCIN) = p->a[k];
    NEW(V_DECIN) = p->d[k];
    NEW(V_ACC) = NEW(V_CAP) = NEW(V_DEC) = NEW(V_JA) = NEW(V_JRAW) = 0.0;
    ok = 1;
    if (!(L > 0.0)) goto out;
    double acc, cap, dec;
    ok = 0;
    if (hit && OLD(V_FEED) == p->f[k] && OLD(V_ACCIN) == p->a[k]) {
        acc = OLD(V_ACC);
        cap = OLD(V_CAP);
    } else if (!elem_limits(&g, lim, p->f[k], p->a[k], &acc, &cap)) {
        goto out;
    }
    if (p->d[k] == p->a[k])
        dec = acc; /* (the deceleration's limit is the acceleration's) */
    else if (hit && OLD(V_DECIN) == p->d[k])
        dec = OLD(V_DEC);
    else if (!elem_limits(&g, lim, INFINITY, p->d[k], &dec, NULL))
        goto out;
    NEW(V_ACC) = acc;
    NEW(V_CAP) = cap;
    NEW(V_DEC) = dec;
    Py_ssize_t q = p->nl++;
    p->live[q] = k;
    p->acc[q] = acc;
    p->cap[q] = cap;
    p->len[q] = L;
    p->dec[q] = dec;
    ok = 1;
#undef NEW
#undef OLD
out:
    elem_clear(&g);
    PyErr_Clear();
    return ok;
}

/* step 2: the junction caps (v**2), jcap2[q] at the entry of live element q; 0 only
 * the Python path */
static int prep_junctions(PyObject *const *args, Prep *p, const Memo *old,
                          const Py_ssize_t *oj, const ElemTypes *et, PyObject *junction,
                          double tchord)
{
    Memo *nm = p->memo;
    Py_ssize_t n = p->n, nl = p->nl;
    long dim = nm->dim;
    p->jcap2[0] = sq(p->cap[0]);
    for (Py_ssize_t q = 1; q < nl; q++) {
        Py_ssize_t k = p->live[q], pk = p->live[q - 1], j = oj[k];
        double a_j = p->a[k] < p->a[pk] ? p->a[k] : p->a[pk]; /* min(a[pk], a[k]) */
        double jr;
        if (j >= 0 && oj[pk] >= 0 && old->jprev[j] == oj[pk] &&
            old->v[V_JA * old->n + j] == a_j) {
            jr = old->v[V_JRAW * old->n + j];
        } else {
            double u1[MAX_DIM], u2[MAX_DIM], ss = 0.0;
            if (!elem_tangent(et, p->items[pk], 1, dim, u1) ||
                !elem_tangent(et, p->items[k], 0, dim, u2))
                return 0;
            for (long i = 0; i < dim; i++) {
                double df = u2[i] - u1[i];
                ss += df * df;
            }
            if (sqrt(ss) < tchord)
                jr = INFINITY; /* tangent: _junction_cap's first return */
            else if (!call_junction(args, junction, p->items[pk], p->items[k], a_j, nm->scv,
                                    &jr))
                return 0;
        }
        nm->v[V_JA * n + k] = a_j;
        nm->v[V_JRAW * n + k] = jr;
        nm->jprev[k] = pk;
        double vj = p->cap[q - 1]; /* min(cap[q - 1], cap[q], jr) */
        if (p->cap[q] < vj) vj = p->cap[q];
        if (jr < vj) vj = jr;
        p->jcap2[q] = vj * vj;
    }
    double last = p->cap[nl - 1];
    p->jcap2[nl] = sq(last < p->v_end ? last : p->v_end); /* min(v_end, cap[-1]) ** 2 */
    return 1;
}

/* 1: done (p filled, the memo updated); 0: only the Python path (no exception set);
 * -1: an error (set) */
static int prepare_core(PyObject *const *args, Prep *p)
{
    memset(p, 0, sizeof *p);
    if (elem_names() < 0) return -1;
    PyObject *ctxo = args[A_CTX];
    if (!PyTuple_CheckExact(ctxo) || PyTuple_GET_SIZE(ctxo) != NCTX ||
        !PyAnySet_Check(PyTuple_GET_ITEM(ctxo, C_TYPES)) ||
        !PyList_CheckExact(PyTuple_GET_ITEM(ctxo, C_MEMO))) {
        PyErr_SetString(PyExc_TypeError, "prepare: ctx must be (types, is_element, Line, "
                                         "Arc, Arc3D, tangent_chord, junction, memo)");
        return -1;
    }
    PyObject *const *ctx = &PyTuple_GET_ITEM(ctxo, 0);
    double tchord = PyFloat_AsDouble(ctx[C_CHORD]);
    if (tchord == -1.0 && PyErr_Occurred()) return -1;
    Memo key;
    memset(&key, 0, sizeof key);
    ElemTypes et;
    int rc = prep_inputs(args, ctx, p, &key, &et);
    if (rc <= 0) return rc;
    Py_ssize_t n = p->n, base = 0;
    Lim lim = {key.dim, key.ratio, key.has[0] ? key.ax : NULL,
               key.has[1] ? key.ax + MAX_DIM : NULL};
    PyObject *list = ctx[C_MEMO];
    p->old_cap = memo_find(list, p, &key, &base);
    Py_XINCREF(p->old_cap);
    const Memo *old = p->old_cap ? (Memo *)PyCapsule_GetPointer(p->old_cap, MEMO_NAME) : NULL;
    Memo *nm = p->memo = memo_new(n);
    if (nm == NULL) {
        PyErr_NoMemory();
        return -1;
    }
    nm->dim = key.dim;
    nm->ratio = key.ratio;
    nm->scv = key.scv;
    memcpy(nm->has, key.has, sizeof key.has);
    memcpy(nm->ax, key.ax, sizeof key.ax);
    Py_ssize_t *oj = p->live + n;
    for (Py_ssize_t k = 0; k < n; k++) {
        Py_ssize_t j = base + k;
        oj[k] = old != NULL && j >= 0 && j < old->n && ref_is(old->refs[j], p->items[k])
                    ? j : -1;
        if (!prep_element(p, k, old, oj[k], ctx, &et, &lim)) return 0;
    }
    if (p->nl == 0) return 0;
    if (!prep_junctions(args, p, old, oj, &et, ctx[C_JUNCTION], tchord)) return 0;
    return memo_store(list, p) < 0 ? -1 : 1;
}

static PyObject *list_of(const double *x, Py_ssize_t n)
{
    PyObject *out = PyList_New(n);
    for (Py_ssize_t k = 0; out != NULL && k < n; k++) {
        PyObject *f = PyFloat_FromDouble(x[k]);
        if (f == NULL) {
            Py_CLEAR(out);
            break;
        }
        PyList_SET_ITEM(out, k, f);
    }
    return out;
}

PyObject *chain_py_prepare(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != NARGS) {
        PyErr_SetString(PyExc_TypeError, "prepare(ctx, elements, feed, accel, decel, scv, "
                        "v_start, v_end, vmax, amax, vjump, ratio, mcr)");
        return NULL;
    }
    Prep p;
    int rc = prepare_core(args, &p);
    PyObject *result = NULL;
    if (rc == 0) {
        result = Py_None;
        Py_INCREF(result);
    } else if (rc > 0) {
        PyObject *live = PyList_New(p.nl);
        for (Py_ssize_t q = 0; live != NULL && q < p.nl; q++) {
            PyObject *i = PyLong_FromSsize_t(p.live[q]);
            if (i == NULL) {
                Py_CLEAR(live);
                break;
            }
            PyList_SET_ITEM(live, q, i);
        }
        PyObject *o[6] = {live, list_of(p.acc, p.nl), list_of(p.cap, p.nl),
                          list_of(p.len, p.nl), list_of(p.dec, p.nl),
                          list_of(p.jcap2, p.nl + 1)};
        int ok = 1;
        for (int q = 0; q < 6; q++) ok = ok && o[q] != NULL;
        if (ok)
            result = Py_BuildValue("(OOOOOOdd)", o[0], o[1], o[2], o[3], o[4], o[5],
                                   p.v_start, p.mcr);
        for (int q = 0; q < 6; q++) Py_XDECREF(o[q]);
    }
    prep_free(&p);
    return result;
}

PyObject *chain_py_prepare_curve(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != NARGS + 2) {
        PyErr_SetString(PyExc_TypeError, "prepare_curve(<prepare's arguments>, s0, out)");
        return NULL;
    }
    double s0 = PyFloat_AsDouble(args[NARGS]);
    if (s0 == -1.0 && PyErr_Occurred()) return NULL;
    Prep p;
    int rc = prepare_core(args, &p);
    PyObject *result = NULL;
    if (rc == 0 || (rc > 0 && p.mcr != 0.0)) { /* a minimum cruise ratio: plan_speeds */
        result = Py_None;
        Py_INCREF(result);
    } else if (rc > 0) {
        Py_buffer b;
        if (PyObject_GetBuffer(args[NARGS + 1], &b,
                               PyBUF_WRITABLE | PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) == 0) {
            if (b.itemsize != 8 || b.format == NULL || strcmp(b.format, "d") != 0 ||
                b.ndim != 2 || b.shape[0] < 2 || b.shape[1] < 3 * p.nl + 1) {
                PyErr_SetString(PyExc_ValueError, "out must be a float64 array of 2 rows "
                                                  "and 3 * len(elements) + 1 columns");
            } else {
                double *s = (double *)b.buf;
                Py_ssize_t m = chain_knots(p.jcap2, p.acc, p.dec, p.cap, p.len, p.nl,
                                           p.v_start * p.v_start, s0, s, s + b.shape[1]);
                double dmin = p.dec[0]; /* min(dec): the first of equals */
                for (Py_ssize_t q = 1; q < p.nl; q++)
                    if (p.dec[q] < dmin) dmin = p.dec[q];
                if (m != -2) result = Py_BuildValue("(nd)", m, dmin);
            }
            PyBuffer_Release(&b);
        }
    }
    prep_free(&p);
    return result;
}
