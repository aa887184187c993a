/* The openmotion._profile module's shared parts: the buffer helper and the entry points
 * of its other source files (_profile_sample.c, _profile_knots.c). */
#ifndef OPENMOTION_PROFILE_H
#define OPENMOTION_PROFILE_H
#define PY_SSIZE_T_CLEAN
#include <Python.h>

/* A C-contiguous float64 buffer of `o` (writable on request), or -1 with a TypeError
 * naming `who`. */
int om_profile_vec(PyObject *o, Py_buffer *b, int writable, const char *who);

PyObject *om_profile_sample(PyObject *self, PyObject *const *args, Py_ssize_t nargs);
extern const char om_profile_sample_doc[];
PyObject *om_axis_knots(PyObject *self, PyObject *const *args, Py_ssize_t nargs);
extern const char om_axis_knots_doc[];

#endif
