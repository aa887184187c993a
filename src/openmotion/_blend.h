/* The line-line corner blends (_blend.c), registered by the openmotion._corner module. */
#ifndef OPENMOTION_BLEND_H
#define OPENMOTION_BLEND_H
#include <Python.h>

PyObject *blend_py_line_blend(PyObject *self, PyObject *const *args, Py_ssize_t nargs);
PyObject *blend_py_line_run(PyObject *self, PyObject *const *args, Py_ssize_t nargs);

#endif
