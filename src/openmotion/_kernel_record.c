/* The recorder's rows of the cycles a virtual-time jump crossed (openmotion._kernel.
 * record_rows, called by control/core/jump.record_trace), written straight into the
 * Recorder's ring arrays: per cycle the time on the grid, per axis the command position
 * and velocity (a mover's piece end state plus its command offset, else the axis's value
 * at the jump's start), the feedback counter (Counters.feedback_of: the output pulses or the
 * encoder, plus the offset, wrapped to 28 bits), the state code and the io word (the table
 * lookup of the logical input levels, + the E-stop bit). The same operations as the numpy
 * expressions they replace, so the rows are identical. The rows are written by ring_rows
 * (_kernel_rowsink.c), RowSink's writer: this only takes the arrays apart.
 */
#include "_kernel.h"


const char record_rows_doc[] =
"record_rows(rt, rf, rstate, rio, head, slots, origin, period, n0, trace, pv, idx, ends,\n"
"            cmd_off, ax, nc, table, estop) -> None\n\n"
"Write the rows of cycles n0+1 .. n0+m (m = len(trace)) into the ring rt[R], rf[R, F, n],\n"
"int32 rstate[R, n], int64 rio[R, n] (empty: channel off) from row `head` on (mod R; only\n"
"the last min(m, R - 1) rows). slots: int64[3], the float slot of cmd_pos, fb_pos, cmd_vel\n"
"(-1: off). trace int64[m, n, 3]; pv a list of 2n floats (each axis's position,\n"
"velocity); idx int64[k] the movers; ends a tuple of k float64[>= m, 2]; cmd_off\n"
"float64[k]; ax a list of 3n ints (each axis's feedback from the output pulses?, feedback\n"
"offset, state code); nc int64[n]; table int64[T] (io word of each logical level word).";

/* The 2n floats of pv and 3n ints of ax (Python lists: no array to build per call) into
 * one buffer; NULL with an exception set on a bad list. */
static double *axis_values(PyObject *opv, PyObject *oax, Py_ssize_t *n_out)
{
    if (!PyList_Check(opv) || !PyList_Check(oax)) {
        PyErr_SetString(PyExc_TypeError, "record_rows: pv and ax must be lists");
        return NULL;
    }
    Py_ssize_t n = PyList_GET_SIZE(opv) / 2;
    if (n < 1 || PyList_GET_SIZE(opv) != 2 * n || PyList_GET_SIZE(oax) != 3 * n) {
        PyErr_SetString(PyExc_ValueError, "record_rows: arrays disagree in size");
        return NULL;
    }
    double *v = PyMem_Malloc(sizeof(double) * 2 * n + sizeof(int64_t) * 3 * n);
    if (v == NULL) { PyErr_NoMemory(); return NULL; }
    int64_t *a = (int64_t *)(v + 2 * n);
    for (Py_ssize_t i = 0; i < 2 * n; i++) {
        v[i] = PyFloat_AsDouble(PyList_GET_ITEM(opv, i));
        if (v[i] == -1.0 && PyErr_Occurred()) { PyMem_Free(v); return NULL; }
    }
    for (Py_ssize_t i = 0; i < 3 * n; i++) {
        a[i] = PyLong_AsLongLong(PyList_GET_ITEM(oax, i));
        if (a[i] == -1 && PyErr_Occurred()) { PyMem_Free(v); return NULL; }
    }
    *n_out = n;
    return v;
}

PyObject *record_rows(PyObject *self, PyObject *args)
{
    PyObject *o[4], *oslots, *otr, *opv, *oidx, *ends, *ooff, *oax, *onc, *otab;
    long long head, n0;
    double origin, period;
    int estop;
    if (!PyArg_ParseTuple(args, "OOOOLOddLOOOO!OOOOp", &o[0], &o[1], &o[2], &o[3], &head,
                          &oslots, &origin, &period, &n0, &otr, &opv, &oidx, &PyTuple_Type,
                          &ends, &ooff, &oax, &onc, &otab, &estop))
        return NULL;
    Py_ssize_t n = 0;
    double *pv = axis_values(opv, oax, &n);
    if (pv == NULL) return NULL;
    const int64_t *ax = (const int64_t *)(pv + 2 * n);
    /* slot 6 and 9 (pv, ax) are the lists, parsed above */
    PyObject *objs[12] = {o[0], o[1], o[2], o[3], oslots, otr, NULL, oidx, ooff, NULL, onc,
                          otab};
    static const Py_ssize_t sizes[12] = {8, 8, 4, 8, 8, 8, 0, 8, 8, 0, 8, 8};
    static const char *names[12] = {"rt", "rf", "rstate", "rio", "slots", "trace", "", "idx",
                                    "cmd_off", "", "nc", "table"};
    Buf bufs[12];
    memset(bufs, 0, sizeof bufs);
    for (int k = 0; k < 12; k++)
        if (objs[k] && get_buf(objs[k], &bufs[k], sizes[k], names[k]) < 0) {
            release(bufs, 12);
            PyMem_Free(pv);
            return NULL;
        }
    Py_ssize_t R = bufs[0].b.len / 8, nk = bufs[7].b.len / 8;
    Py_ssize_t m = n ? bufs[5].b.len / (8 * 3 * n) : 0;
    Py_ssize_t F = (R && n) ? bufs[1].b.len / (8 * R * n) : 0;
    const int64_t *slots = bufs[4].b.buf, *idx = bufs[7].b.buf, *table = bufs[11].b.buf;
    Py_ssize_t T = bufs[11].b.len / 8;
    const char *bad = NULL;
    if (R < 2 || bufs[4].b.len != 3 * 8
            || bufs[5].b.len != m * n * 3 * 8 || bufs[1].b.len != R * F * n * 8
            || bufs[8].b.len != nk * 8 || bufs[10].b.len != n * 8
            || (bufs[2].b.len && bufs[2].b.len != R * n * 4)
            || (bufs[3].b.len && bufs[3].b.len != R * n * 8)
            || PyTuple_GET_SIZE(ends) != nk || head < 0 || head >= R)
        bad = "record_rows: arrays disagree in size";
    for (int s = 0; s < 3 && !bad; s++)
        if (slots[s] < -1 || slots[s] >= F) bad = "record_rows: bad slot";
    for (Py_ssize_t k = 0; k < nk && !bad; k++)
        if (idx[k] < 0 || idx[k] >= n) bad = "record_rows: bad mover index";
    if (bad) {
        release(bufs, 12);
        PyMem_Free(pv);
        PyErr_SetString(PyExc_ValueError, bad);
        return NULL;
    }
    Buf *eb = PyMem_Calloc(nk + 1, sizeof(Buf) + sizeof(double *));
    int64_t *mover = PyMem_Malloc(sizeof(int64_t) * (n + 1));
    if (eb == NULL || mover == NULL) {
        PyMem_Free(eb);
        PyMem_Free(mover);
        release(bufs, 12);
        PyMem_Free(pv);
        return PyErr_NoMemory();
    }
    const double **ep = (const double **)(eb + nk + 1);
    int fail = 0;
    for (Py_ssize_t k = 0; k < nk && !fail; k++) {
        if (PyObject_GetBuffer(PyTuple_GET_ITEM(ends, k), &eb[k].b, PyBUF_C_CONTIGUOUS) < 0) {
            fail = 1;
            break;
        }
        eb[k].held = 1;
        ep[k] = eb[k].b.buf;
        if (eb[k].b.itemsize != 8 || eb[k].b.len < m * 2 * 8) {
            PyErr_SetString(PyExc_ValueError, "record_rows: ends too short");
            fail = 1;
        }
    }
    for (Py_ssize_t x = 0; x < n; x++) mover[x] = -1;
    for (Py_ssize_t k = 0; k < nk; k++) mover[idx[k]] = k;
    if (!fail) { /* the rows through the one writer (RowSink's, _kernel_rowsink.c) */
        Ring g = {bufs[0].b.buf, bufs[1].b.buf, bufs[2].b.len ? bufs[2].b.buf : NULL,
                  bufs[3].b.len ? bufs[3].b.buf : NULL, table, R, F, n, T, slots[0],
                  slots[1], slots[2]};
        fail = ring_rows(&g, (Py_ssize_t)head, NULL, origin, period, n0, m, bufs[5].b.buf, pv,
                         ax, mover, ep, bufs[8].b.buf, bufs[10].b.buf, estop) < 0;
    }
    PyMem_Free(mover);
    release(eb, (int)nk);
    PyMem_Free(eb);
    release(bufs, 12);
    PyMem_Free(pv);
    if (fail) return NULL;
    Py_RETURN_NONE;
}
