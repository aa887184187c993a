/* Shared by the compiled inner loops (openmotion._kernel): includes and buffer access. */
#ifndef OPENMOTION_KERNEL_H
#define OPENMOTION_KERNEL_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

#ifdef __clang__
#pragma STDC FP_CONTRACT OFF
#endif

typedef struct {
    Py_buffer b;
    int held;
} Buf;

static inline int get_buf(PyObject *o, Buf *buf, Py_ssize_t itemsize, const char *name)
{
    if (PyObject_GetBuffer(o, &buf->b, PyBUF_WRITABLE | PyBUF_C_CONTIGUOUS) < 0) return -1;
    buf->held = 1;
    if (buf->b.itemsize != itemsize) {
        PyErr_Format(PyExc_TypeError, "%s: wrong item size", name);
        return -1;
    }
    return 0;
}

static inline void release(Buf *bufs, int n)
{
    for (int k = 0; k < n; k++)
        if (bufs[k].held) PyBuffer_Release(&bufs[k].b);
}

/* _kernel_stepper.c: the simulator's stepper pipeline over a chunk of cycles */
PyObject *kernel_run(PyObject *self, PyObject *args);
extern const char kernel_run_doc[];
/* field counts of its arrays, exported as module constants */
int kernel_layout(PyObject *module);

#endif
