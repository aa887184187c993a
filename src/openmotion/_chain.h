/* The chain planner's passes (_chain.c), registered by the openmotion._corner module. */
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

#endif
