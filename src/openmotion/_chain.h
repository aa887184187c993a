/* The chain planner's passes (_chain.c) and the look-ahead's per-element limits and
 * junction caps (_chain_prep.c), registered by the openmotion._corner module. */
#ifndef OPENMOTION_CHAIN_H
#define OPENMOTION_CHAIN_H
#include <Python.h>

PyObject *chain_py_passes(PyObject *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *chain_py_speeds(PyObject *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *chain_py_curve(PyObject *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *chain_py_chain_curve(PyObject *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *chain_py_s_pieces(PyObject *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *chain_py_limit_along(PyObject *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *chain_py_crossings(PyObject *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *chain_py_prepare(PyObject *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *chain_py_prepare_curve(PyObject *self, PyObject *const *args, Py_ssize_t nargs);

/* _chain.c's steps 3-4 and knots for _chain_prep.c: m, -1 (start too fast), -2 (memory) */
Py_ssize_t chain_knots(const double *jcap2, const double *acc, const double *dec,
                       const double *ccap, const double *length, Py_ssize_t n,
                       double start2, double s0, double *s, double *v2);

/* _chain_elem.c: one path element as the look-ahead's step 1 reads it */
#define CHAIN_MAX_DIM 64
enum { K_OTHER, K_LINE, K_ARC };
typedef struct {
    PyObject *line, *arc, *arc3d; /* path.Line, path.Arc, path.Arc3D */
} ElemTypes;
typedef struct {
    PyObject *el, *frame; /* frame: an arc's _frame (a reference), once read */
    int kind, got_kappa, got_mat, got_aaw;
    double kappa, mat[CHAIN_MAX_DIM], aaw[CHAIN_MAX_DIM];
} Elem;
typedef struct {
    long dim;
    double ratio;              /* arc_tangential_ratio */
    const double *vmax, *amax; /* per-axis limits (NULL: none) */
} Lim;
int elem_names(void);
int elem_kind(const ElemTypes *t, PyObject *el);
void elem_init(Elem *g, PyObject *el, int kind);
void elem_clear(Elem *g);
/* each 1 when read, 0 when only the Python path can (no exception left set) */
int elem_dim(Elem *g, long *dim); /* el.dim (an int) */
int elem_length(Elem *g, double *x);
int elem_kappa(Elem *g);
int elem_tangent(const ElemTypes *t, PyObject *el, int at_end, long dim, double *dst);
/* lookahead._limit_along: min(limit, axis_i / w_i over w_i > 0), the first of equals
 * (axis NULL: no per-axis limit) */
double chain_limit_along(double limit, const double *axis, const double *w, long n);
/* lookahead._limits_of: (tangential acceleration, speed cap); cap NULL: the first only */
int elem_limits(Elem *g, const Lim *lim, double feed, double accel, double *acc,
                double *cap);

#endif
