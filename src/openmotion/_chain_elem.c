/* One path element as the look-ahead's step 1 reads it (path/lookahead.py `_limits_of`),
 * for _chain_prep.c: its axis count, length, curvature, per-axis weights and end
 * tangents, and its tangential acceleration and speed cap.
 *
 * The values are the element's own: for any element type its attributes (`length`,
 * `max_curvature`, `max_abs_tangent`, `axis_accel_weight`, `start_tangent`,
 * `end_tangent`, `dim`). For openmotion's Line, Arc and Arc3D (their exact types) the
 * properties are skipped for the instance attributes they return (path/geometry.py,
 * path/arcs.py: a Line's `length`, `direction` (both tangents) and `_abs_dir`, an arc's
 * `_frame.length`, `_frame.t_start`, `_frame.t_end`, `_kappa`, `_mat`, `_aaw`; each
 * property answers its attribute when set and computes it, once, when not: then the
 * property is asked). A Python property call costs more than the rest of an element's
 * step 1 together, and a streaming join reads a hundred new elements.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <string.h>

#include "_chain.h"

#ifdef __clang__
#pragma STDC FP_CONTRACT OFF
#endif

static PyObject *s_length, *s_dim, *s_start, *s_mat, *s_kappa, *s_aaw, *s_tstart, *s_tend,
    *s_frame, *s_direction, *s_abs_dir, *s_pmat, *s_pkappa, *s_paaw, *s_ft_start,
    *s_ft_end;

int elem_names(void)
{
    if (s_ft_end != NULL) return 0;
    struct {
        PyObject **p;
        const char *s;
    } all[] = {{&s_length, "length"}, {&s_dim, "dim"}, {&s_start, "start"},
               {&s_mat, "max_abs_tangent"}, {&s_kappa, "max_curvature"},
               {&s_aaw, "axis_accel_weight"}, {&s_tstart, "start_tangent"},
               {&s_tend, "end_tangent"}, {&s_frame, "_frame"}, {&s_direction, "direction"},
               {&s_abs_dir, "_abs_dir"}, {&s_pmat, "_mat"}, {&s_pkappa, "_kappa"},
               {&s_paaw, "_aaw"}, {&s_ft_start, "t_start"}, {&s_ft_end, "t_end"}};
    for (size_t q = 0; q < sizeof all / sizeof all[0]; q++)
        if (*all[q].p == NULL && (*all[q].p = PyUnicode_InternFromString(all[q].s)) == NULL)
            return -1;
    return 0;
}

int elem_kind(const ElemTypes *t, PyObject *el)
{
    PyObject *tp = (PyObject *)Py_TYPE(el);
    if (tp == t->line) return K_LINE;
    if (tp == t->arc || tp == t->arc3d) return K_ARC;
    return K_OTHER;
}

/* attribute `name` of o; NULL (no exception) when it has none or reading it raised */
static PyObject *attr(PyObject *o, PyObject *name, int optional)
{
    PyObject *r = NULL;
    if (!optional) {
        r = PyObject_GetAttr(o, name);
    } else {
#if PY_VERSION_HEX >= 0x030D0000
        if (PyObject_GetOptionalAttr(o, name, &r) < 0) r = NULL;
#else
        if (_PyObject_LookupAttr(o, name, &r) < 0) r = NULL;
#endif
    }
    if (r == NULL) PyErr_Clear();
    if (r == Py_None) Py_CLEAR(r); /* a cache attribute not set: as absent */
    return r;
}

/* o (a reference taken over) as `dim` doubles: a C-contiguous float64 buffer */
static int vec_of(PyObject *o, long dim, double *dst)
{
    if (o == NULL) return 0;
    Py_buffer b;
    int ok = 0;
    if (PyObject_GetBuffer(o, &b, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) == 0) {
        ok = b.itemsize == 8 && b.format != NULL && strcmp(b.format, "d") == 0 &&
             b.len == dim * 8;
        if (ok) memcpy(dst, b.buf, (size_t)dim * sizeof(double));
        PyBuffer_Release(&b);
    } else {
        PyErr_Clear();
    }
    Py_DECREF(o);
    return ok;
}

/* o (a reference taken over) as a double: a float or an int */
static int num_of(PyObject *o, double *x)
{
    if (o == NULL) return 0;
    int ok = PyFloat_Check(o) || PyLong_CheckExact(o);
    if (ok) {
        *x = PyFloat_AsDouble(o);
        if (*x == -1.0 && PyErr_Occurred()) {
            PyErr_Clear();
            ok = 0;
        }
    }
    Py_DECREF(o);
    return ok;
}

void elem_init(Elem *g, PyObject *el, int kind)
{
    g->el = el;
    g->kind = kind;
    g->frame = NULL;
    g->got_kappa = g->got_mat = g->got_aaw = 0;
}

void elem_clear(Elem *g) { Py_CLEAR(g->frame); }

/* an arc's frame, where its own values live */
static PyObject *frame(Elem *g)
{
    if (g->frame == NULL) g->frame = attr(g->el, s_frame, 1);
    return g->frame;
}

int elem_dim(Elem *g, long *dim)
{
    if (g->kind == K_OTHER) {
        PyObject *d = attr(g->el, s_dim, 0);
        int ok = d != NULL && PyLong_CheckExact(d);
        if (ok) *dim = PyLong_AsLong(d);
        Py_XDECREF(d);
        PyErr_Clear();
        return ok && *dim != -1;
    }
    PyObject *start = attr(g->el, s_start, 0); /* dim: start.size */
    if (start == NULL) return 0;
    Py_buffer b;
    int ok = 0;
    if (PyObject_GetBuffer(start, &b, PyBUF_ND | PyBUF_FORMAT) == 0) {
        ok = b.itemsize > 0;
        if (ok) *dim = (long)(b.len / b.itemsize);
        PyBuffer_Release(&b);
    }
    PyErr_Clear();
    Py_DECREF(start);
    return ok;
}

int elem_length(Elem *g, double *x)
{
    PyObject *o = g->kind == K_ARC && frame(g) != NULL ? frame(g) : g->el;
    return num_of(attr(o, s_length, 0), x);
}

int elem_kappa(Elem *g)
{
    if (g->got_kappa) return 1;
    if (g->kind == K_LINE) {
        g->kappa = 0.0; /* Line.max_curvature */
        return g->got_kappa = 1;
    }
    PyObject *o = g->kind == K_ARC ? attr(g->el, s_pkappa, 1) : NULL;
    if (o == NULL) o = attr(g->el, s_kappa, 0);
    return g->got_kappa = num_of(o, &g->kappa);
}

static int elem_mat(Elem *g, long dim)
{
    if (g->got_mat) return 1;
    PyObject *o = g->kind == K_LINE ? attr(g->el, s_abs_dir, 1)
                  : g->kind == K_ARC ? attr(g->el, s_pmat, 1) : NULL;
    if (o == NULL) o = attr(g->el, s_mat, 0);
    return g->got_mat = vec_of(o, dim, g->mat);
}

/* the per-axis weight of the tangential acceleration: |tangent| on a line, the axis
 * acceleration weight on a curve (the kappa is read) */
static const double *accel_weight(Elem *g, long dim)
{
    if (g->kappa == 0.0 || g->kind == K_LINE) return elem_mat(g, dim) ? g->mat : NULL;
    if (!g->got_aaw) {
        PyObject *o = g->kind == K_ARC ? attr(g->el, s_paaw, 1) : NULL;
        if (o == NULL) o = attr(g->el, s_aaw, 0);
        g->got_aaw = vec_of(o, dim, g->aaw);
    }
    return g->got_aaw ? g->aaw : NULL;
}

int elem_tangent(const ElemTypes *t, PyObject *el, int at_end, long dim, double *dst)
{
    int kind = elem_kind(t, el);
    PyObject *o = NULL;
    if (kind == K_LINE) {
        o = attr(el, s_direction, 0);
    } else if (kind == K_ARC) {
        PyObject *f = attr(el, s_frame, 1);
        if (f != NULL) o = attr(f, at_end ? s_ft_end : s_ft_start, 0);
        Py_XDECREF(f);
    }
    if (o == NULL) o = attr(el, at_end ? s_tend : s_tstart, 0);
    return vec_of(o, dim, dst);
}

double chain_limit_along(double limit, const double *axis, const double *w, long n)
{
    if (axis == NULL) return limit;
    double best = INFINITY;
    int found = 0;
    for (long i = 0; i < n; i++) {
        if (w[i] > 0.0) {
            found = 1;
            double q = axis[i] / w[i];
            if (q < best) best = q;
        }
    }
    return !found || limit <= best ? limit : best;
}

int elem_limits(Elem *g, const Lim *lim, double feed, double accel, double *acc, double *cap)
{
    if (!elem_kappa(g)) return 0;
    const double *w = NULL;
    if (lim->amax != NULL && (w = accel_weight(g, lim->dim)) == NULL) return 0;
    double total = chain_limit_along(accel, lim->amax, w, lim->dim);
    double vmax = feed;
    if (cap != NULL && lim->vmax != NULL) {
        if (!elem_mat(g, lim->dim)) return 0;
        vmax = chain_limit_along(feed, lim->vmax, g->mat, lim->dim);
    }
    if (g->kappa == 0.0) {
        *acc = total;
        if (cap != NULL) *cap = vmax;
        return 1;
    }
    double a_n = sqrt(1.0 - lim->ratio * lim->ratio) * total;
    double x = a_n / g->kappa;
    if (x < 0.0) return 0; /* math.sqrt raises */
    *acc = lim->ratio * total;
    if (cap != NULL) {
        double r = sqrt(x);
        *cap = r < vmax ? r : vmax; /* min(vmax, r) */
    }
    return 1;
}
