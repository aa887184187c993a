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

/* a feedback counter wrapped to 28 bits (Counters.feedback_of), for the recorder's rows */
#define HALF28 ((int64_t)1 << 27)
#define FULL28 ((int64_t)1 << 28)

static inline int64_t wrap28(int64_t x)
{
    if (x >= -HALF28 && x < HALF28) return x; /* the usual case: no division */
    int64_t r = (x + HALF28) % FULL28;
    if (r < 0) r += FULL28;
    return r - HALF28;
}

/* _kernel_stepper.c: the simulator's stepper pipeline over a chunk of cycles */
PyObject *kernel_run(PyObject *self, PyObject *args);
extern const char kernel_run_doc[];
PyObject *kernel_readback(PyObject *self, PyObject *args);
extern const char kernel_readback_doc[];
/* field counts of its arrays, exported as module constants */
int kernel_layout(PyObject *module);

/* A recorder's ring (Recorder._t, _f, _i) as the row writer sees it: rt[R], rf[R, F, n],
 * int32 rstate[R, n] and int64 rio[R, n] (NULL: channel off), the float slots of cmd_pos,
 * fb_pos and cmd_vel (-1: off) and the io word of each logical level word (table[T]). */
typedef struct {
    double *rt, *rf;
    int32_t *rstate;
    int64_t *rio;
    const int64_t *table;
    Py_ssize_t R, F, n, T;
    int64_t sp, sf, sv;
} Ring;

/* _kernel_rowsink.c: the one writer of recorder rows (a step's row, a jump's crossed
 * cycles): rows of cycles n0+1 .. n0+m (times origin + k * period, or *t for m = 1) from
 * ring row head on (mod R; the last min(m, R - 1) kept); per axis x: pv[2x] position and
 * pv[2x+1] velocity, ia[3x] feedback from the output pulses?, ia[3x+1] feedback offset,
 * ia[3x+2] state code; an axis with mover[x] = k >= 0 takes position and velocity from
 * ends[k][2r], ends[k][2r+1] (+ off[k] on the position); tr int64 [m, n, 3] readback; nc
 * int64[n]. 0, or -1 with ValueError set and nothing written (a value not finite). */
int ring_rows(const Ring *g, Py_ssize_t head, const double *t, double origin, double period,
              long long n0, Py_ssize_t m, const int64_t *tr, const double *pv,
              const int64_t *ia, const int64_t *mover, const double *const *ends,
              const double *off, const int64_t *nc, int estop);

/* _kernel_record.c: a jump's crossed cycles into the recorder's ring arrays */
PyObject *record_rows(PyObject *self, PyObject *args);
extern const char record_rows_doc[];
/* _kernel_rowsink.c: the RowSink type (a recorder ring bound once, a row per call) */
int record_types(PyObject *module);

/* _kernel_rt.c: real-time pacing of the compiled cycles (control/core/realtime.py) */
int rt_before_cycle(long long k, int first);  /* wait for cycle k's slot; 1: return at this
                                                 boundary (never when first: a run's first) */
void rt_after_cycle(long long k);  /* cycle k done: record its busy time */
PyObject *rt_paced(PyObject *self, PyObject *args);
PyObject *rt_wait(PyObject *self, PyObject *args);
PyObject *rt_close(PyObject *self, PyObject *args);
PyObject *rt_poll(PyObject *self, PyObject *args);
PyObject *rt_now(PyObject *self, PyObject *args);
PyObject *rt_slot(PyObject *self, PyObject *args);
PyObject *rt_yield(PyObject *self, PyObject *args);
extern const char rt_paced_doc[], rt_wait_doc[], rt_close_doc[], rt_poll_doc[], rt_now_doc[],
    rt_slot_doc[], rt_yield_doc[];

#endif
