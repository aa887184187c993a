/* Shared by the compare engine's compiled solvers (openmotion._compare, _kernel_compare.c and
 * _compare_*.c): includes, constants, the track and argument structs, inline formulas and
 * the functions and entry points one file defines and another uses. */
#ifndef OPENMOTION_COMPARE_H
#define OPENMOTION_COMPARE_H

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

/* the shared names stay private to the module (as when they were static) */
#if defined(__GNUC__)
#pragma GCC visibility push(hidden)
#endif

/* attribute names, interned once (module init): the driver reads job, line and history
 * objects by attribute every cycle */
#define NAMES(X) X(_t) X(_lv) X(_late) X(initial) X(timed) X(_sent_until) X(_written) \
    X(_sent) X(_hold) X(signal) X(index) X(hits) X(ts) X(p0) X(v0) X(a0) X(j) X(lo) X(hi) \
    X(flush) X(forget_before) X(snapshot) X(_snap) X(_snap_t)
#define DECL(n) extern PyObject *S_##n;
NAMES(DECL)
#undef DECL

/* a method's docstring, defined beside it and listed in the module table */
#define CMP_DOC(name, str) const char name[] = PyDoc_STR(str)

static inline double pymax(double a, double b) { return b > a ? b : a; }
static inline double pymin(double a, double b) { return b < a ? b : a; }
static inline int isign(double x) { return x > 0.0 ? 1 : x < 0.0 ? -1 : 0; }

typedef struct {
    const double *ts, *p0, *v0, *a0, *j;
    Py_ssize_t n;
} Trk;

typedef struct {
    Py_buffer b[5];
    int held;
    double *own;  /* rows built from a history spec (get_track_in), freed on release */
} TrkBuf;

/* compare_roots._f: position minus level, snapped to 0 within rounding of the terms */
static inline double snapped(double c, double v, double a, double j, double x, double level,
                             double p)
{
    double f = c + x * (v + x * (a / 2.0 + x * j / 6.0));
    double scale = fabs(level) + fabs(p) + fabs(x * v) + fabs(x * x * a / 2.0)
                   + fabs(x * x * x * j / 6.0);
    return fabs(f) <= 8.0 * EPS * scale ? 0.0 : f;
}

/* the most events level_events can return for a track of n records */
static inline Py_ssize_t max_events(Py_ssize_t n) { return 6 * n + 2; }

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

typedef struct {
    const double *B, *S, *Q;
    Py_ssize_t nb;  /* breakpoints; pieces nb - 1 */
} Vc;

typedef struct {
    Py_buffer b[3];
    int held;
} VcBuf;

/* an OutputLine's edit state, read once per job that fired */
typedef struct {
    PyObject *tl, *ll, *late;
    int initial;
    double sent;
} LineRef;

/* _compare_track.c */
int get_vec(PyObject *o, Py_buffer *b, const char *name);
void release_track(TrkBuf *tb);
int get_track(PyObject *o, Trk *t, TrkBuf *tb);
Py_ssize_t search_right(const double *x, Py_ssize_t lo, Py_ssize_t hi, double t);
int get_track_in(PyObject *o, double ta, double t1, Trk *t, TrkBuf *tb);
int velocity_roots(double v, double a, double j, double *r);
double refine(double c, double v, double a, double j, double lo, double hi, int s_lo,
    double t_base);
Py_ssize_t level_events(const Trk *T, double level, double t, double t1,
    int direction, int first, double *out);
void track_range(const Trk *T, double ta, double t1, double *lo_o, double *hi_o);
void args_release(TrackArgs *A);
int track_args(PyObject *tr_o, PyObject *rg_o, int single, TrackArgs *A);
int get_levels(PyObject *o, long long n, PyObject *after_o, Levels *L, Py_buffer *b,
    int *held);
PyObject *level_events_py(PyObject *self, PyObject *args);
PyObject *level_scan(PyObject *self, PyObject *args);
PyObject *track_range_py(PyObject *self, PyObject *args);
extern const char level_scan_doc[], level_events_doc[], track_range_doc[];

/* _compare_window.c */
int first_inside(const Trk *T, int na, const double *centre, double maxerr, double t,
    double t1, const double *lo, const double *hi, double *x_out);
PyObject *first_inside_py(PyObject *self, PyObject *args);
PyObject *positions_py(PyObject *self, PyObject *args);
PyObject *solver_checks(PyObject *self, PyObject *args);
PyObject *window_scan(PyObject *self, PyObject *args);
extern const char window_scan_doc[], first_inside_doc[], positions_doc[], solver_checks_doc[];

/* _compare_vector.c */
int time_of(const Vc *V, double d, double after, double *t_out);
void release_vc(VcBuf *vb);
int get_vc(PyObject *B, PyObject *S, PyObject *Q, Vc *V, VcBuf *vb);
PyObject *adaptive_py(PyObject *self, PyObject *args);
PyObject *gl_py(PyObject *self, PyObject *args);
PyObject *set_gauss(PyObject *self, PyObject *args);
PyObject *time_of_py(PyObject *self, PyObject *args);
PyObject *vector_at(PyObject *self, PyObject *args);
PyObject *vector_pieces(PyObject *self, PyObject *args);
PyObject *vector_scan(PyObject *self, PyObject *args);
PyObject *vector_sums(PyObject *self, PyObject *args);
extern const char set_gauss_doc[], gl_doc[], adaptive_doc[], vector_pieces_doc[], vector_sums_doc[], vector_at_doc[], vector_scan_doc[], time_of_doc[];

/* _compare_lines.c */
int line_set_one(PyObject *tl, PyObject *ll, int initial, double t, int level,
    double sent_until, PyObject *late);
PyObject *line_set(PyObject *self, PyObject *args);
PyObject *lines_end(PyObject *self, PyObject *args);
PyObject *lines_send(PyObject *self, PyObject *args);
PyObject *lines_snapshot(PyObject *self, PyObject *args);
PyObject *plan_records(PyObject *self, PyObject *args);
extern const char line_set_doc[], lines_send_doc[], plan_records_doc[], lines_snapshot_doc[], lines_end_doc[];

/* _compare_scan.c */
int line_ref(PyObject *line, LineRef *L);
PyObject *bank_new(PyObject *self, PyObject *args);
PyObject *bank_scan(PyObject *self, PyObject *args);
extern const char bank_new_doc[], bank_scan_doc[];

#if defined(__GNUC__)
#pragma GCC visibility pop
#endif

#endif
